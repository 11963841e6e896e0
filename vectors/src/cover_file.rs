//! A coverage file (`--cover FILE` of `raypipe ops`, read back by `raypipe cover`): the counts of
//! a run's coverage with the manifest that defines its coverage model, so that runs and shards
//! merge exactly (counts added bin by bin) with each other and with vector sets of the same
//! unit, format and options.
//!
//! JSON: `{"kind": "raypipe coverage", "version": 1, "command": …, "manifest": {…},
//! "vectors": N, "counts": [[bin counts of coverpoint 0], …]}`, the coverpoints in the order
//! [`Coverage::model`] gives for that manifest.

use crate::cover::Coverage;
use crate::manifest::Manifest;

/// The `kind` of a coverage file.
pub const KIND: &str = "raypipe coverage";

/// The file's text for coverage `c` of model `m`, measured by `command`.
pub fn write(c: &Coverage, m: &Manifest, command: &str) -> String {
    let counts: Vec<Vec<u64>> = c.coverpoints.iter().map(|p| p.bins.iter().map(|b| b.count).collect()).collect();
    let j = serde_json::json!({
        "kind": KIND,
        "version": 1,
        "command": command,
        "manifest": m,
        "vectors": c.vectors,
        "counts": counts,
    });
    serde_json::to_string_pretty(&j).expect("coverage serialises") + "\n"
}

/// Whether `text` looks like a coverage file (raypipe wrote it).
pub fn is_coverage(text: &str) -> bool {
    text.lines().take(3).any(|l| l.contains(KIND))
}

/// The manifest and coverage a coverage file holds (checked against the model its manifest
/// defines).
pub fn read(text: &str) -> Result<(Manifest, Coverage), String> {
    let j: serde_json::Value = serde_json::from_str(text).map_err(|e| format!("not a coverage file: {e}"))?;
    if j["kind"] != KIND || j["version"] != 1 {
        return Err(format!("not a coverage file (kind \"{KIND}\", version 1)"));
    }
    let m: Manifest = serde_json::from_value(j["manifest"].clone()).map_err(|e| format!("manifest: {e}"))?;
    let mut c = Coverage::model(&m);
    let counts: Vec<Vec<u64>> = serde_json::from_value(j["counts"].clone()).map_err(|e| format!("counts: {e}"))?;
    if counts.len() != c.coverpoints.len() || counts.iter().zip(&c.coverpoints).any(|(k, p)| k.len() != p.bins.len()) {
        return Err("counts do not fit the coverage model of the file's manifest".into());
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
