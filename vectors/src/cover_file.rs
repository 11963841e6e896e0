//! A coverage file (`--cover FILE` of `raypipe ops`, `verify` and `stress`, read back by
//! `raypipe cover`): the counts of a run's coverage with the manifest that defines each coverage
//! model the run measured (one per unit, format and options: `verify` measures the RTI unit and
//! every slab variant of every format), so that runs and shards merge exactly (counts added bin
//! by bin) with each other and with vector sets of the same unit, format and options.
//!
//! JSON: `{"kind": "raypipe coverage", "version": 2, "command": …, "models": [{"manifest":
//! {…}, "vectors": N, "counts": [[bin counts of coverpoint 0], …]}, …]}`, the coverpoints in
//! the order [`Coverage::model`] gives for that manifest. Version 1 (one model: `manifest`,
//! `vectors` and `counts` at the top level) is read too.

use crate::cover::{Coverage, RowBins};
use crate::manifest::{Class, Manifest};

/// The `kind` of a coverage file.
pub const KIND: &str = "raypipe coverage";

/// The file's text for the coverage `c` of each model `m` in `models`, measured by `command`.
pub fn write(models: &[(Manifest, Coverage)], command: &str) -> String {
    let models: Vec<serde_json::Value> = models
        .iter()
        .map(|(m, c)| {
            let counts: Vec<Vec<u64>> =
                c.coverpoints.iter().map(|p| p.bins.iter().map(|b| b.count).collect()).collect();
            serde_json::json!({ "manifest": m, "vectors": c.vectors, "counts": counts })
        })
        .collect();
    let j = serde_json::json!({ "kind": KIND, "version": 2, "command": command, "models": models });
    serde_json::to_string_pretty(&j).expect("coverage serialises") + "\n"
}

/// Whether `text` looks like a coverage file (raypipe wrote it).
pub fn is_coverage(text: &str) -> bool {
    text.lines().take(3).any(|l| l.contains(KIND))
}

/// The manifest and coverage of every model a coverage file holds (each checked against the
/// model its manifest defines).
pub fn read(text: &str) -> Result<Vec<(Manifest, Coverage)>, String> {
    let j: serde_json::Value = serde_json::from_str(text).map_err(|e| format!("not a coverage file: {e}"))?;
    if j["kind"] != KIND {
        return Err(format!("not a coverage file (kind \"{KIND}\")"));
    }
    match j["version"].as_u64() {
        Some(1) => Ok(vec![model(&j)?]),
        Some(2) => {
            let ms = j["models"].as_array().ok_or("models: not a list")?;
            if ms.is_empty() {
                return Err("models: empty (the run measured nothing)".into());
            }
            ms.iter().enumerate().map(|(i, x)| model(x).map_err(|e| format!("model {}: {e}", i + 1))).collect()
        }
        _ => Err(format!("not a coverage file this raypipe reads (kind \"{KIND}\", version 1 or 2)")),
    }
}

/// One model's manifest and counts.
fn model(j: &serde_json::Value) -> Result<(Manifest, Coverage), String> {
    let m: Manifest = serde_json::from_value(j["manifest"].clone()).map_err(|e| format!("manifest: {e}"))?;
    let mut c = Coverage::model(&m);
    let counts: Vec<Vec<u64>> = serde_json::from_value(j["counts"].clone()).map_err(|e| format!("counts: {e}"))?;
    if counts.len() != c.coverpoints.len() || counts.iter().zip(&c.coverpoints).any(|(k, p)| k.len() != p.bins.len()) {
        return Err(format!(
            "counts do not fit the coverage model of the file's manifest (written by raypipe {} at git {}, read by raypipe {}: a file from another build, whose model differs, or an edited one)",
            m.raypipe_version,
            m.git,
            env!("CARGO_PKG_VERSION")
        ));
    }
    for (p, k) in c.coverpoints.iter_mut().zip(counts) {
        for (b, n) in p.bins.iter_mut().zip(k) {
            b.count = n;
        }
    }
    c.vectors = j["vectors"].as_u64().ok_or("vectors: not a count")?;
    Ok((m, c))
}

/// Coverage counts as an engine accumulator: flat bin counts in model order (empty until the
/// first row), merged by adding (so the result does not depend on chunking or threads).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CoverCounts {
    /// Bin counts, coverpoint after coverpoint (empty: nothing counted).
    pub bins: Vec<u64>,
    /// Rows counted.
    pub vectors: u64,
}

impl CoverCounts {
    /// Counts the (coverpoint, bin) pairs `hits` of one row; `offsets[p]` is coverpoint p's
    /// first bin in the flat order and `total` the bins of the model.
    pub fn add(&mut self, hits: &[(usize, usize)], offsets: &[usize], total: usize) {
        if self.bins.is_empty() {
            self.bins = vec![0; total];
        }
        for &(p, b) in hits {
            self.bins[offsets[p] + b] += 1;
        }
        self.vectors += 1;
    }

    /// Adds another accumulator's counts.
    pub fn merge_counts(&mut self, o: CoverCounts) {
        if o.bins.is_empty() {
            return;
        }
        if self.bins.is_empty() {
            self.bins = vec![0; o.bins.len()];
        }
        for (a, b) in self.bins.iter_mut().zip(o.bins) {
            *a += b;
        }
        self.vectors += o.vectors;
    }

    /// The counts as the coverage of model `c` (a copy of `c` with these counts).
    pub fn into_coverage(self, c: &Coverage) -> Coverage {
        let mut out = c.clone();
        let mut k = 0;
        for p in &mut out.coverpoints {
            for b in &mut p.bins {
                b.count = self.bins.get(k).copied().unwrap_or(0);
                k += 1;
            }
        }
        out.vectors = self.vectors;
        out
    }
}

/// Each coverpoint's first bin in the flat order, and the model's bin count.
pub fn offsets(c: &Coverage) -> (Vec<usize>, usize) {
    let mut v = Vec::with_capacity(c.coverpoints.len());
    let mut k = 0;
    for p in &c.coverpoints {
        v.push(k);
        k += p.bins.len();
    }
    (v, k)
}

/// One coverage model of a run (`--cover` of `verify`, `stress`, `ops`): the manifest that
/// defines it, its empty coverage and each coverpoint's place in the flat counts.
pub struct RunModel {
    /// The manifest (of a set of the run's unit, format and options, with the run's classes).
    pub manifest: Manifest,
    /// The model, every count 0.
    pub model: Coverage,
    offsets: Vec<usize>,
    total: usize,
    /// The traverse unit: the set's files with its tree images (the per-vector files empty),
    /// what [`RowBins::with_set`] needs; other units: empty.
    images: Vec<Vec<Vec<u64>>>,
}

impl RunModel {
    /// The model of the sets `req` describes; with `classes` (name, what it covers, tests of
    /// the class in the run) in place of the set's classes: the class bins are then the run's
    /// stimulus classes.
    pub fn new(req: &crate::gen::Request, classes: Option<&[(&str, &str, usize)]>) -> Result<Self, String> {
        let set = crate::gen::generate(req)?;
        let images = if set.manifest.unit == "traverse" {
            let mut rows = crate::read::set_rows(&set)?;
            // keep the tree images only (the per-vector files are the first two: inputs, expected)
            for r in rows.iter_mut().take(2) {
                r.clear();
            }
            rows
        } else {
            Vec::new()
        };
        let mut manifest = set.manifest;
        if let Some(classes) = classes {
            manifest.classes = classes
                .iter()
                .enumerate()
                .map(|(id, &(name, covers, count))| Class {
                    id: id as u32,
                    name: name.into(),
                    covers: covers.into(),
                    count,
                })
                .collect();
        }
        manifest.command = req.command.clone();
        let model = Coverage::model(&manifest);
        let (offsets, total) = offsets(&model);
        Ok(RunModel { manifest, model, offsets, total, images })
    }

    /// This model's row lookup (for the traverse unit with the set's tree, to re-run each ray).
    pub fn row_bins(&self) -> Result<RowBins, String> {
        RowBins::new(&self.manifest).with_set(&self.images)
    }

    /// The traverse unit: the set's tree images as [`crate::read::tree_images`] reads them
    /// (the root entry row and each level's banks); other units: an error.
    pub fn tree_images(&self) -> Result<(&[u64], Vec<crate::read::BankImages<'_>>), String> {
        crate::read::tree_images(&self.manifest, &self.images)
    }

    /// Counts row 0 of `contents` (every file's row, unpacked) into `acc`; `bins` is this
    /// model's lookup, `hits` scratch space.
    pub fn count(
        &self,
        bins: &RowBins,
        contents: &[Vec<Vec<u64>>],
        hits: &mut Vec<(usize, usize)>,
        acc: &mut CoverCounts,
    ) -> Result<(), String> {
        hits.clear();
        bins.hits(contents, 0, hits)?;
        acc.add(hits, &self.offsets, self.total);
        Ok(())
    }

    /// The manifest and the coverage of counts `acc`.
    pub fn finish(&self, acc: CoverCounts) -> (Manifest, Coverage) {
        (self.manifest.clone(), acc.into_coverage(&self.model))
    }
}
