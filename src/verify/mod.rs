//! `raypipe verify`: every chosen format's RTI model and slab variants against the golden
//! reference on a scene's rays, with the property check (decisive cases must agree; t within
//! its bound; a conservative slab variant never misses), error statistics and model
//! throughput. A thin client of the streaming engine: [`chunk`] says what one chunk of rays
//! does, the engine runs the chunks and merges their accumulators.

pub mod chunk;
pub mod clock;
pub mod counts;
pub mod cover;

use crate::scene::Scene;
use datapath::rti::RtiConfig;
use datapath::{with_format, AnyFormat};
use serde::{Deserialize, Serialize};

/// What to run.
#[derive(Clone, Debug)]
pub struct VerifyConfig {
    /// Formats to verify.
    pub formats: Vec<AnyFormat>,
    /// Number of rays.
    pub rays: u64,
    /// Seed of the ray generator.
    pub seed: u64,
    /// RTI options.
    pub rti: RtiConfig,
    /// Scenes with at most this many triangles are tested exhaustively per ray; larger ones
    /// test each ray against its target triangle and `sample - 1` seeded random others.
    pub sample: usize,
    /// Threads and rays per chunk (the results do not depend on either).
    pub engine: engine::Engine,
    /// Show progress on stderr (when it is a terminal and the run lasts over a second).
    pub progress: bool,
    /// An RTI fault of the bank (`faults::bank`) the model runs with: a deliberately wrong
    /// model, to see the judge catch it on this scene (None: the model itself).
    pub inject: Option<&'static faults::bank::Spec>,
}

/// Rays per chunk of `verify` by default: enough work per chunk (128 rays × up to 512 tests)
/// that merging a chunk's accumulators into the run's is rare, with still dozens of chunks
/// per thread for a few thousand rays (16 until 2026-12-07: 4–21 % slower on two threads).
pub const CHUNK_RAYS: u64 = 128;

impl VerifyConfig {
    /// A configuration with every core, the default chunk and no progress output.
    pub fn new(formats: Vec<AnyFormat>, rays: u64, seed: u64, rti: RtiConfig, sample: usize) -> Self {
        VerifyConfig {
            formats,
            rays,
            seed,
            rti,
            sample,
            engine: engine::Engine::new(CHUNK_RAYS),
            progress: false,
            inject: None,
        }
    }
}

/// Results for one format.
#[derive(Clone, Debug, Serialize)]
pub struct FormatReport {
    /// Format name.
    pub format: String,
    /// Bits per value.
    pub width: u32,
    /// Ray–triangle tests run.
    pub tests: u64,
    /// Tests whose error bound makes the decision certain.
    pub decisive: u64,
    /// Reference hits: the exact decision on the quantised inputs (f64 filter, then exact
    /// rational arithmetic; see `crate::judge`).
    pub golden_hits: u64,
    /// Model hits.
    pub model_hits: u64,
    /// Model miss where the reference hits.
    pub false_misses: u64,
    /// Model hit where the reference misses.
    pub false_hits: u64,
    /// Tests the f64 filter could not decide, decided by exact rational arithmetic.
    pub exact: u64,
    /// Property failures (must be 0).
    pub violations: u64,
    /// Tests where both hit.
    pub shared_hits: u64,
    /// Median |t − t_golden| in units of the format's ulp at t_golden.
    pub t_err_ulps_median: f64,
    /// Largest |t − t_golden| in ulps.
    pub t_err_ulps_max: f64,
    /// Median |t − t_golden| / |t_golden|.
    pub t_err_rel_median: f64,
    /// Largest relative t error.
    pub t_err_rel_max: f64,
    /// Rays whose min-capture result names a different triangle (or hit/miss) than the golden closest hit.
    pub closest_disagreements: u64,
    /// Throughput of the fastest bit-identical batch path (the SIMD kernel for f32 / fp16) inside
    /// this run: tests over the time spent in the model's batch calls summed over threads, on
    /// the calls of every 8th ray (`chunk::TIME_EVERY`), million tests per second per thread
    /// (the gather into its columns not included).
    pub mtests_per_s: f64,
    /// Tests per second of wall time for this format's whole pass (rays generated, model,
    /// golden, bound, judging and the slab variants), in millions.
    pub judged_mtests_per_s: f64,
    /// Tests whose valid bit was cleared at stage 7: the work a valid-gated divide stage (and
    /// everything after it) skips.
    pub divide_skipped: u64,
    /// The first property failure, as an `explain` command line.
    pub first_violation: Option<String>,
    /// The first test (by ray, then test) where the model's hit/miss differs from the exact
    /// decision, decisive or not, as an `explain` command line.
    pub first_disagreement: Option<String>,
}

/// The whole run.
#[derive(Clone, Debug, Serialize)]
pub struct VerifyReport {
    /// Scene name.
    pub scene: String,
    /// Triangles in the scene.
    pub triangles: usize,
    /// The power of two applied to the scene's coordinates.
    pub scale: f64,
    /// Rays cast.
    pub rays: u64,
    /// Ray seed.
    pub seed: u64,
    /// Triangles tested per ray.
    pub tests_per_ray: usize,
    /// Per-format results.
    pub formats: Vec<FormatReport>,
    /// Slab unit results per format and variant.
    pub slab: Vec<SlabReport>,
    /// No property failed.
    pub passed: bool,
    /// Formats in which no test was decisive: the property was not tested there.
    pub inconclusive: Vec<String>,
    /// The bank fault the model ran with (`--inject`), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub injected: Option<String>,
}

impl VerifyReport {
    /// The exit outcome: a failure, else inconclusive when a format had no decisive test.
    pub fn outcome(&self) -> crate::Outcome {
        match (self.passed, self.inconclusive.is_empty()) {
            (false, _) => crate::Outcome::Fail,
            (true, false) => crate::Outcome::Inconclusive,
            (true, true) => crate::Outcome::Pass,
        }
    }
}

/// Runs every format on the scene: per format one engine pass over the rays, the RTI model and
/// Runs every format over the engine's rays and reports.
pub fn verify(cfg: &VerifyConfig, scene: &Scene) -> VerifyReport {
    finish(accumulate(cfg, scene))
}

/// What a verify run accumulates (a shard's partial result): the scene's facts the report
/// prints and one accumulator per format.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VerifyData {
    /// Scene name.
    pub scene: String,
    /// Triangles.
    pub triangles: usize,
    /// Coordinate scale.
    pub scale: f64,
    /// Rays of the whole run.
    pub rays: u64,
    /// Seed.
    pub seed: u64,
    /// Tests per ray.
    pub tests_per_ray: usize,
    /// Per format, in the run's order.
    pub formats: Vec<chunk::FormatAcc>,
    /// The bank fault the model ran with, if any.
    #[serde(default)]
    pub injected: Option<String>,
}

impl VerifyData {
    /// Adds another shard's data of the same run.
    pub fn merge(&mut self, o: VerifyData) -> Result<(), String> {
        if self.formats.len() != o.formats.len() {
            return Err("partials disagree on the formats".into());
        }
        if self.injected != o.injected {
            return Err("partials disagree on the injected fault".into());
        }
        for (a, b) in self.formats.iter_mut().zip(o.formats) {
            a.merge(b)?;
        }
        Ok(())
    }
}

impl crate::partial::Consistent for VerifyData {
    fn check(&self, share: &dyn Fn(u64, u64) -> u64) -> Result<(), String> {
        self.check_formats(share(0, self.rays).checked_mul(self.tests_per_ray as u64))
    }
}

impl crate::partial::Sharded for VerifyData {
    const COMMAND: &'static str = "verify";
    type Report = VerifyReport;
    fn add(&mut self, other: Self) -> Result<(), String> {
        self.merge(other)
    }
    fn finish(self) -> Result<VerifyReport, String> {
        Ok(finish(self))
    }
    fn render(r: &VerifyReport) -> String {
        render(r)
    }
    fn outcome(r: &VerifyReport) -> crate::Outcome {
        r.outcome()
    }
}

impl VerifyData {
    /// Checks every format's accumulators; `tests`: each unit's test count, when known.
    pub fn check_formats(&self, tests: Option<u64>) -> Result<(), String> {
        self.formats.iter().try_for_each(|f| f.check(tests))
    }
}

/// Runs every format over the engine's shard of the rays.
pub fn accumulate(cfg: &VerifyConfig, scene: &Scene) -> VerifyData {
    VerifyData {
        scene: scene.name.clone(),
        triangles: scene.tris.len(),
        scale: scene.scale,
        rays: cfg.rays,
        seed: cfg.seed,
        tests_per_ray: chunk::tests_per_ray(scene, cfg.sample),
        formats: cfg
            .formats
            .iter()
            .map(|f| with_format!(*f, |f| chunk::accumulate_format(f, cfg, scene, true)))
            .collect(),
        injected: cfg.inject.map(|x| x.name.to_string()),
    }
}

/// The report of (merged) data.
pub fn finish(d: VerifyData) -> VerifyReport {
    let mut formats = Vec::new();
    let mut slab = Vec::new();
    for f in d.formats {
        let (r, s) = f.finish();
        formats.extend(r);
        slab.extend(s);
    }
    let slab_ok = slab.iter().all(|r| !r.conservative || r.false_misses == 0);
    VerifyReport {
        scene: d.scene,
        triangles: d.triangles,
        scale: d.scale,
        rays: d.rays,
        seed: d.seed,
        tests_per_ray: d.tests_per_ray,
        passed: formats.iter().all(|f| f.violations == 0) && slab_ok,
        inconclusive: formats.iter().filter(|f| f.decisive == 0).map(|f| f.format.clone()).collect(),
        formats,
        slab,
        injected: d.injected,
    }
}

/// The options that change a verify run's results, for a partial's `args`.
pub fn args(cfg: &VerifyConfig) -> serde_json::Value {
    serde_json::json!({
        "formats": cfg.formats.iter().map(|f| f.to_string()).collect::<Vec<_>>(),
        "rays": cfg.rays,
        "seed": cfg.seed,
        "rti": format!("{:?}", cfg.rti),
        "sample": cfg.sample,
        "inject": cfg.inject.map(|x| x.name),
    })
}

/// boxes of the triangles each ray is tested against (axis-aligned walls give zero-extent boxes).
pub fn verify_slab(cfg: &VerifyConfig, scene: &Scene) -> Vec<SlabReport> {
    cfg.formats.iter().flat_map(|f| with_format!(*f, |f| chunk::run_format(f, cfg, scene, false)).1).collect()
}

/// The report as a text table.
pub fn render(r: &VerifyReport) -> String {
    let mut s = format!(
        "raypipe verify: scene {} ({} triangles, coordinates x {:?}), {} rays, seed {}, {} tests per ray\n\n",
        r.scene, r.triangles, r.scale, r.rays, r.seed, r.tests_per_ray
    );
    if let Some(name) = &r.injected {
        let what = faults::bank::by_name(name).map_or("", |x| x.what);
        s += &format!("injected fault: {name} ({what}): the model is wrong on purpose; the run must fail\n\n");
    }
    s += &format!(
        "{:<16} {:>9} {:>9} {:>7} {:>8} {:>8} {:>7} {:>7} {:>6} {:>10} {:>10} {:>9} {:>9} {:>8} {:>9}\n",
        "format",
        "tests",
        "decisive",
        "exact",
        "g-hits",
        "m-hits",
        "f-miss",
        "f-hit",
        "viol",
        "t ulp med",
        "t ulp max",
        "t rel med",
        "t rel max",
        "closest≠",
        "Mtests/s"
    );
    for f in &r.formats {
        s += &format!(
            "{:<16} {:>9} {:>9} {:>7} {:>8} {:>8} {:>7} {:>7} {:>6} {:>10.3} {:>10.3} {:>9.2e} {:>9.2e} {:>8} {:>9.2}\n",
            f.format,
            f.tests,
            f.decisive,
            f.exact,
            f.golden_hits,
            f.model_hits,
            f.false_misses,
            f.false_hits,
            f.violations,
            f.t_err_ulps_median,
            f.t_err_ulps_max,
            f.t_err_rel_median,
            f.t_err_rel_max,
            f.closest_disagreements,
            f.mtests_per_s
        );
    }
    s += "\ng-hits, f-miss, f-hit: against the exact decision on the same quantised inputs (an f64 filter; exact: the tests it could not decide, decided in exact rational arithmetic); t errors against the golden f64 t; viol: decisive tests (error bound clear of every threshold) where hit/miss differs or the t error exceeds its bound.\n";
    s += "skipped work: tests whose valid bit clears at stage 7, so a valid-gated divide stage skips them: ";
    s += &r
        .formats
        .iter()
        .map(|f| format!("{} {:.1}%", f.format, 100.0 * f.divide_skipped as f64 / f.tests.max(1) as f64))
        .collect::<Vec<_>>()
        .join(", ");
    s += "\n";
    for f in r.formats.iter() {
        if let Some(d) = &f.first_disagreement {
            s += &format!("first disagreement, {}: {d}\n", f.format);
        }
    }
    s += &render_slab(&r.slab);
    if r.passed && !r.inconclusive.is_empty() {
        s += &format!(
            "property: INCONCLUSIVE: no decisive test in {} (every test's error bound straddles a threshold: degenerate triangles, or coordinates too large for the format): the run proved nothing there\n",
            r.inconclusive.join(", ")
        );
    } else if r.passed {
        s += "property: PASS (no violations)\n";
    } else {
        s += "property: FAIL\n";
        for f in r.formats.iter().filter(|f| f.violations > 0) {
            s += &format!(
                "  {}: {} violations; first: {}\n",
                f.format,
                f.violations,
                f.first_violation.as_deref().unwrap_or("")
            );
        }
    }
    s
}

/// Slab results for one format and variant.
#[derive(Clone, Debug, Serialize)]
pub struct SlabReport {
    /// Format name.
    pub format: String,
    /// Variant name.
    pub variant: String,
    /// The variant promises zero false misses.
    pub conservative: bool,
    /// Ray–box tests run.
    pub tests: u64,
    /// Exact hits (rational decision on the quantised ray and the original box).
    pub exact_hits: u64,
    /// Model miss where the exact test hits.
    pub false_misses: u64,
    /// Model hit where the exact test misses.
    pub false_hits: u64,
    /// Tests settled by the exact rational decision (near the boundary or disagreeing with f64).
    pub exact_calls: u64,
    /// Throughput of the fastest bit-identical batch path (the SIMD kernel for f32 / fp16) inside
    /// this run, million tests per second per thread (see [`FormatReport::mtests_per_s`]).
    pub mtests_per_s: f64,
}

/// The slab results as a text table.
pub fn render_slab(rows: &[SlabReport]) -> String {
    let mut s = format!(
        "\nslab (BVI) unit: boxes = bounding boxes of the tested triangles; false misses / hits against the exact rational decision\n\n{:<16} {:<14} {:>9} {:>9} {:>8} {:>8} {:>9}\n",
        "format", "variant", "tests", "exact-hit", "f-miss", "f-hit", "Mtests/s"
    );
    for r in rows {
        s += &format!(
            "{:<16} {:<14} {:>9} {:>9} {:>8} {:>8} {:>9.2}{}\n",
            r.format,
            r.variant,
            r.tests,
            r.exact_hits,
            r.false_misses,
            r.false_hits,
            r.mtests_per_s,
            if r.conservative && r.false_misses > 0 { "  <- VIOLATION: conservative variant missed" } else { "" }
        );
    }
    s
}
