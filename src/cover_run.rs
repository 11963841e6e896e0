//! The functional coverage of an engine run (`--cover FILE` of `verify`, `stress` and `ops`):
//! every test the run judged, counted as a row of its unit's coverage model (`vectors::cover`)
//! — the inputs as the format holds them, the expected outputs and every stage signal of the
//! fault-free model — in one accumulator per model that merges by adding counts, so the file
//! does not depend on threads, chunking or shards (shards' files merge to the one-pass file).
//!
//! The pass runs after the run's own pass and beside it, not inside it: the run's report, its
//! hot path and its speed are those of a run without `--cover`.

use datapath::rti::{Ray, Rti, RtiConfig, Tri};
use datapath::slab::{Aabb, Slab};
use datapath::{AnyFormat, Format};
use vectors::cover::{Coverage, RowBins};
use vectors::cover_file::{CoverCounts, RunModel};
use vectors::gen::{Request, Unit};
use vectors::manifest::Manifest;

/// Several models' coverage counts as one engine accumulator (model k's counts at k).
#[derive(Clone, Debug, Default)]
pub struct CoverAcc(pub Vec<CoverCounts>);

impl CoverAcc {
    /// `n` models, nothing counted.
    pub fn new(n: usize) -> Self {
        CoverAcc(vec![CoverCounts::default(); n])
    }
}

impl engine::Merge for CoverAcc {
    fn merge(&mut self, other: Self) {
        if self.0.len() < other.0.len() {
            self.0.resize(other.0.len(), CoverCounts::default());
        }
        for (a, b) in self.0.iter_mut().zip(other.0) {
            a.merge_counts(b);
        }
    }
}

/// The RTI unit's model in `format` with options `rti`, its class bins `classes` (name, what
/// it covers, tests).
pub fn rti_model(
    format: AnyFormat,
    rti: RtiConfig,
    classes: &[(&str, &str, usize)],
    command: &str,
) -> Result<RunModel, String> {
    let mut req = Request::new(Unit::Rti, format);
    req.rti = rti;
    req.command = command.into();
    RunModel::new(&req, Some(classes))
}

/// The slab unit's model in `format`, variant `variant`, its class bins `classes`.
pub fn slab_model(
    format: AnyFormat,
    variant: &str,
    classes: &[(&str, &str, usize)],
    command: &str,
) -> Result<RunModel, String> {
    let mut req = Request::new(Unit::Slab, format);
    req.slab_variant = variant.into();
    req.command = command.into();
    RunModel::new(&req, Some(classes))
}

/// The traverse unit's model in `format`: slab variant `variant`, the BVH `tree`, the first `n`
/// leaves, `levels` level pipelines, its class bins `classes`.
pub fn traverse_model(
    format: AnyFormat,
    variant: &str,
    tree: vectors::traverse::TreeInput,
    (n, levels): (usize, usize),
    classes: &[(&str, &str, usize)],
    command: &str,
) -> Result<RunModel, String> {
    let mut req = Request::new(Unit::Traverse, format);
    req.slab_variant = variant.into();
    req.tree = Some(tree);
    req.leaves = n;
    req.max_levels = levels;
    req.count = 1;
    req.command = command.into();
    RunModel::new(&req, Some(classes))
}

/// A worker's row buffers: the input, expected-output and stage-signal rows of one test.
pub struct Rows {
    contents: Vec<Vec<Vec<u64>>>,
    hits: Vec<(usize, usize)>,
}

impl Default for Rows {
    fn default() -> Self {
        Rows { contents: vec![vec![Vec::new()]; 3], hits: Vec::new() }
    }
}

impl Rows {
    /// Counts one RTI test of class `class` (the ray and triangle as the format holds them) into
    /// `acc` under model `run` with its lookup `bins`.
    pub fn rti<F: Format>(
        &mut self,
        (run, bins): (&RunModel, &RowBins),
        rti: &Rti<F>,
        class: u64,
        ray: &Ray<F::V>,
        tri: &Tri<F::V>,
        acc: &mut CoverCounts,
    ) {
        let f = &rti.fmt;
        let inputs = &mut self.contents[0][0];
        inputs.clear();
        inputs.push(class);
        inputs.extend(ray.o.iter().chain(&ray.d).chain([&ray.tmin, &ray.tmax]).map(|&v| f.to_bits(v)));
        inputs.extend(tri.v.iter().flatten().map(|&v| f.to_bits(v)));
        let [expected, stages] = vectors::gen::rti_out_rows(rti, ray, tri, &datapath::fault::NoFault);
        self.contents[1][0] = expected;
        self.contents[2][0] = stages;
        // the rows are the RTI unit's own layout: every field of the model is there
        run.count(bins, &self.contents, &mut self.hits, acc).expect("an RTI row of its own unit");
    }

    /// Counts one slab test of class `class` (the ray's inputs as the format holds them and the
    /// stored box) into `acc` under model `run`.
    pub fn slab<F: Format>(
        &mut self,
        (run, bins): (&RunModel, &RowBins),
        slab: &Slab<F>,
        class: u64,
        ray: [F::V; 8],
        b: &Aabb<F::V>,
        acc: &mut CoverCounts,
    ) {
        let f = &slab.fmt;
        let inputs = &mut self.contents[0][0];
        inputs.clear();
        inputs.push(class);
        inputs.extend(ray.iter().chain(&b.min).chain(&b.max).map(|&v| f.to_bits(v)));
        let [expected, stages] = vectors::gen::slab_out_rows(slab, &inputs[1..], &datapath::fault::NoFault);
        self.contents[1][0] = expected;
        self.contents[2][0] = stages;
        run.count(bins, &self.contents, &mut self.hits, acc).expect("a slab row of its own unit");
    }

    /// Counts one ray of class `class` (`bits`: o, d, tmin, tmax as the format holds them)
    /// traversed on `hw` (the model's own tree) for the first `n` leaves into `acc` under model
    /// `run`, whose lookup `bins` re-runs it for its path events.
    #[allow(clippy::too_many_arguments)]
    pub fn traverse<F: Format>(
        &mut self,
        (run, bins): (&RunModel, &RowBins),
        slab: &Slab<F>,
        hw: &datapath::bvh::HwTree<Aabb<F::V>>,
        n: usize,
        class: u64,
        bits: &[u64; 8],
        acc: &mut CoverCounts,
    ) {
        let inputs = &mut self.contents[0][0];
        inputs.clear();
        inputs.push(class);
        inputs.extend_from_slice(bits);
        self.contents[1][0] = vectors::traverse::ray_row(slab, hw, n, bits, &datapath::fault::NoFault);
        run.count(bins, &self.contents, &mut self.hits, acc).expect("a traverse row of its own unit");
    }
}

/// The models' coverage of counts `acc` (model k: `acc.0[k]`, nothing when absent).
pub fn finish(models: &[RunModel], acc: CoverAcc) -> Vec<(Manifest, Coverage)> {
    let mut counts = acc.0.into_iter();
    models.iter().map(|m| m.finish(counts.next().unwrap_or_default())).collect()
}

/// Writes the coverage file `path` (atomically; the path was checked before the run) and
/// prints one line per model on stderr.
pub fn write(path: &std::path::Path, models: &[(Manifest, Coverage)], command: &str) -> Result<(), String> {
    vectors::outdir::atomic_write(path, vectors::cover_file::write(models, command).as_bytes())?;
    for (_, c) in models {
        let (hit, bins) = c.totals();
        eprintln!(
            "coverage, {}: {hit} of {bins} reachable bins ({:.1} %), {} rows",
            c.title(),
            100.0 * hit as f64 / bins.max(1) as f64,
            c.vectors
        );
    }
    eprintln!("coverage written to {} (raypipe cover {} reports and merges it)", path.display(), path.display());
    Ok(())
}
