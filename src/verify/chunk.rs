//! What one chunk of `verify` does, and the per-format pass that runs the chunks on the engine.
//!
//! For each ray of a chunk (ray `i` and its test list are drawn from (seed, i) alone, see
//! [`crate::scene::RayGen`] and [`test_list`]), its tests are cut into blocks of [`BLOCK`]
//! triangles; per block:
//!
//! 1. gather: the model's stored triangles into the kernel's columns, the quantised triangles
//!    (the format's values in f64) into nine f64 columns — converted from the model's columns
//!    where the format converts a column at vector speed, else gathered;
//! 2. model: the fastest bit-identical batch path ([`datapath::simd::rti_batch`]);
//! 3. bound: the error bound in f64 lanes ([`datapath::bound::verdict_block`], the static
//!    filter first), equal to its scalar code: per lane decisive or not, and the exact decision;
//! 4. judge: a lane that is a decisive miss of both the model and the bound only counts (as a
//!    test, decisive, and a skipped divide when it is one); every other lane gets the golden
//!    Möller–Trumbore ([`golden::block::intersect_block`], equal to [`golden::intersect`]'s hit
//!    and t; no counted-only lane reads it) and is judged: the counts, the t-error histograms
//!    and the first violation, by the one rule [`crate::judge::violation`]; the min-capture
//!    unit and the golden closest hit run along the ray's blocks;
//! 5. slab: the boxes of the same triangles through every variant's batch path, against the
//!    f64 slab test's decision in lanes ([`golden::block::slab_block_flags`], shared by the
//!    variants) and the exact rational decision where f64 cannot decide (an interval within
//!    [`CLOSE_REL`] of empty, or the model disagreeing).
//!
//! The chunk's accumulators are merged by the engine; nothing else outlives the chunk.

use super::clock::Clock;
use super::counts::{RtiCounts, SlabCounts};
use super::{FormatReport, SlabReport, VerifyConfig};
use crate::scene::Scene;
use datapath::bound::{self, BlockOpts, BlockRay};
use datapath::bound_filter::{verdict_block_filtered, verdict_lanes_filtered, Constants, Maxima, SetMaxima};
use datapath::rng::SplitMix64;
use datapath::rti::{Capture, HitsSoa, RaysSoa, Rti, RtiOut, Tri, TrisSoa};
use datapath::simd::draw::below_column;
use datapath::simd::gather::gather;
use datapath::simd::mask::{bits, ones, words};
use datapath::simd::{self, Kernel};
use datapath::slab::{BoxesSoa, Slab, SlabConfig, SlabOutSoa};
use datapath::Format;
use engine::{First, Hist, Merge, Progress};
use golden::block::{intersect_block, slab_block_flags, Level};
use golden::{Ray64, Tri64};
use std::time::Instant;

/// Stream number of the per-ray test lists in [`SplitMix64::for_item`].
pub const LIST_STREAM: u64 = 0x7e57;

/// How close to empty (relative, [`golden::block::slab_block_flags`]) a golden f64 slab
/// interval may be before the exact decision settles the lane.
pub const CLOSE_REL: f64 = 1e-9;

/// The model's batch calls are timed on every `TIME_EVERY`-th ray (ray index a multiple of it:
/// ray 0 always), and its rate is their tests over their time — a sample, so that the clock's
/// readings (a dozen per block) do not slow the pass; which rays are timed depends on nothing
/// but their index.
pub const TIME_EVERY: u64 = 8;

/// Tests per block: the columns of one block (15 model columns, 9 + 6 f64 columns, outputs)
/// stay in L1/L2 while the model, golden and bound read them.
pub const BLOCK: usize = 256;

/// Blocks a worker runs straight through the per-test bound after one where the static filter
/// certified fewer than an eighth of the lanes (then it tries the filter again): a speed
/// choice only, every lane's verdict is the per-test bound's either way.
pub const FILTER_REST: u32 = 15;

/// Triangles tested per ray: every triangle of a scene with at most `sample`, else `sample`.
pub fn tests_per_ray(scene: &Scene, sample: usize) -> usize {
    scene.tris.len().min(sample)
}

/// Ray `i`'s test list into `out`: every triangle when the scene has at most `sample`, else
/// its target followed by `sample - 1` triangles drawn with `SplitMix64::for_item(seed,
/// LIST_STREAM, i).below(n)`.
pub fn test_list(n: usize, sample: usize, seed: u64, i: u64, target: usize, out: &mut Vec<u32>) {
    out.clear();
    if n <= sample {
        out.extend(0..n as u32);
        return;
    }
    out.push(target as u32);
    let mut r = SplitMix64::for_item(seed, LIST_STREAM, i);
    out.resize(sample, 0);
    below_column(Kernel::Avx512Fp16, &mut r, n as u64, &mut out[1..]);
}

/// The `explain` command line of one test, in the scene's normalised coordinates (with
/// `--inject NAME` when the model runs with that bank fault).
pub fn explain_cmd(fmt: &str, ray: &Ray64, tri: &Tri64, scale: f64, inject: Option<&str>) -> String {
    let j = |xs: &[f64]| xs.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(",");
    let tv: Vec<f64> = tri.v.iter().flatten().copied().collect();
    let x = inject.map(|n| format!(" --inject {n}")).unwrap_or_default();
    format!(
        "raypipe explain --format {fmt} --ray {},{} --tri {}{x}  # scene coordinates x {scale:?}",
        j(&ray.o),
        j(&ray.d),
        j(&tv)
    )
}

/// One format's RTI results: the counters, the t errors of shared hits in ulps and relative,
/// the first violation and the first disagreement by (ray, test), and the nanoseconds spent in
/// the model's batch calls.
#[derive(Default, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct RtiAcc {
    counts: RtiCounts,
    ulps: Hist,
    rels: Hist,
    first: First<(u64, u64), String>,
    disagree: First<(u64, u64), String>,
    /// The model's timed batch calls ([`TIME_EVERY`]): [`Clock`] ticks while the pass runs,
    /// nanoseconds once [`accumulate_format`] converts them.
    model_ns: u64,
    /// The tests in those calls.
    #[serde(default)]
    model_tests: u64,
}

impl Merge for RtiAcc {
    fn merge(&mut self, o: Self) {
        self.counts.merge(o.counts);
        self.ulps.merge(o.ulps);
        self.rels.merge(o.rels);
        self.first.merge(o.first);
        self.disagree.merge(o.disagree);
        self.model_ns += o.model_ns;
        self.model_tests += o.model_tests;
    }
}

/// One slab variant's results: the counters and the nanoseconds in its batch calls.
#[derive(Default, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct SlabAcc {
    counts: SlabCounts,
    /// As [`RtiAcc::model_ns`].
    model_ns: u64,
    /// As [`RtiAcc::model_tests`].
    #[serde(default)]
    model_tests: u64,
}

impl Merge for SlabAcc {
    fn merge(&mut self, o: Self) {
        self.counts.merge(o.counts);
        self.model_ns += o.model_ns;
        self.model_tests += o.model_tests;
    }
}

/// A slab variant ready to run.
struct Variant<F: Format> {
    name: &'static str,
    slab: Slab<F>,
    conservative: bool,
}

/// One triangle's data as the blocks gather it, in one record (one random access per test):
/// the model's stored triangle, the triangle's box in f64 and that box stored in the format
/// (outward-rounded; the same for every variant). The fields a pass does not use hold
/// defaults. (The quantised triangle is converted from the model's where the format converts a
/// column in vector lanes — binary32, binary16, bfloat16, e8mM, fixed point with AVX-512DQ —
/// or kept in [`Setup::qs`].) 64-byte aligned, the model's triangle and the stored box first:
/// the RTI gather and the stored-box gather read one line of a record.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Rec<V> {
    m: [V; 9],
    s: [V; 6],
    b: [f64; 6],
}

/// A ray's static-filter constants from the scene's bounds (`None` where the scene has none):
/// the bound's, and the reference decision's f64 filter's once a block needs them.
struct RayConsts {
    /// The quantised ray, as the bound and the filters read it.
    bray: BlockRay,
    maxima: Option<Maxima>,
    bound: Option<Constants>,
    f64_filter: std::cell::OnceCell<Option<Constants>>,
}

/// What every chunk of one format's pass shares (O(scene), built once).
struct Setup<'a, F: Format> {
    cfg: &'a VerifyConfig,
    scene: &'a Scene,
    /// The ray generator (the scene's bounds, computed once).
    gen: crate::scene::RayGen,
    rti: Rti<F>,
    with_rti: bool,
    recs: Vec<Rec<F::V>>,
    /// Per triangle the quantised triangle (the format's values in f64), where the format
    /// does not convert a column at vector speed; empty where it does.
    qs: Vec<[f64; 9]>,
    /// The quantised columns are converted from the model's ([`Format::fast_f64_column`]).
    q_from_m: bool,
    /// Bounds over every quantised triangle of the scene: each ray's static-filter constants
    /// (of the bound and of the reference decision's f64 filter) come from them once, for all
    /// of its blocks.
    set: SetMaxima,
    variants: Vec<Variant<F>>,
    /// The round-to-nearest variants (indices into `variants`), which one shared batch may
    /// run together on a ray's blocks ([`simd::slab_ray_shared`]).
    shared: Vec<usize>,
    opts: BlockOpts,
    /// The reference decision's f64 filter as block options ([`crate::judge::f64_filter_opts`]).
    fopts: BlockOpts,
    faces: golden::Faces,
    level: Level,
    name: String,
    /// The model timings' clock (started with the pass).
    clock: Clock,
    /// Every ray tests every triangle in order, in at most [`KEPT_BLOCKS`] blocks: each block's
    /// lane set keeps its gathered inputs.
    kept: bool,
}

/// Blocks of a ray, at most, whose lanes a worker keeps one set each for when every ray tests
/// every triangle in order (a scene of at most `sample` triangles, in at most this many blocks):
/// each block's gathered triangles and boxes are then the same for every ray and stay in its set
/// (a speed choice: gathered again, they would be the same values).
pub const KEPT_BLOCKS: usize = 4;

/// The columns the model kernels, the bound and the golden read and write for one block of
/// a ray, at one block size (its inputs gathered from the records, its outputs).
struct Lanes<V> {
    rays: RaysSoa<V>,
    tris: TrisSoa<V>,
    out: HitsSoa<V>,
    cols: [Vec<f64>; 9],
    bcols: [Vec<f64>; 6],
    boxes: BoxesSoa<V>,
    sout: SlabOutSoa<V>,
    /// The outputs of a shared batch, one per variant of [`Setup::shared`].
    souts: Vec<SlabOutSoa<V>>,
    /// The ray whose values `rays` holds in every lane.
    ray: Option<u64>,
    /// The inputs (tris, cols, bcols, boxes) hold the gathered block for good (a kept block of
    /// an every-triangle list, [`KEPT_BLOCKS`]).
    kept: bool,
}

impl<V: Copy + Default> Lanes<V> {
    /// A set of `n` lanes.
    fn new(n: usize) -> Self {
        let z = V::default();
        let mut l = Lanes {
            rays: RaysSoa::default(),
            tris: TrisSoa::default(),
            out: HitsSoa::default(),
            cols: std::array::from_fn(|_| vec![0.0; n]),
            bcols: std::array::from_fn(|_| vec![0.0; n]),
            boxes: BoxesSoa::default(),
            sout: SlabOutSoa::default(),
            souts: (0..datapath::slab::SLAB_VARIANTS.len()).map(|_| SlabOutSoa::default()).collect(),
            ray: None,
            kept: false,
        };
        l.rays.resize(n, z);
        l.tris.resize(n, z);
        l.out.resize(n);
        l.boxes.min.iter_mut().chain(l.boxes.max.iter_mut()).for_each(|c| c.resize(n, z));
        for o in std::iter::once(&mut l.sout).chain(&mut l.souts) {
            o.hit.resize(n, false);
            o.t_near.resize(n, z);
            o.t_far.resize(n, z);
        }
        l
    }
}

/// A worker's reusable buffers (no allocation per chunk after the first).
struct Scratch<V> {
    list: Vec<u32>,
    /// The block lane sets: per block of the ray where the ray's blocks are kept
    /// ([`KEPT_BLOCKS`]), else one for full blocks and one for a ray's last, shorter block
    /// (every ray's list has the same length, so no set changes size).
    sets: Vec<Lanes<V>>,
    ghit: Vec<bool>,
    gt: Vec<f64>,
    dec: Vec<bool>,
    ehit: Vec<bool>,
    terr: Vec<f64>,
    shit: Vec<bool>,
    /// Lanes whose golden f64 interval is within [`CLOSE_REL`] of empty: exact decides.
    sclose: Vec<bool>,
    /// Lanes the static filter certified.
    cert: Vec<bool>,
    /// Blocks left to run without the static filter (see [`FILTER_REST`]).
    filter_rest: u32,
    /// The f64 filter of the reference decision (decisive, hit, t bound) at each lane that is
    /// not decisive (the lanes [`Setup::rti_lane`] reads it for); other lanes hold stale values.
    fdec: Vec<bool>,
    fhit: Vec<bool>,
    fterr: Vec<f64>,
    exact: Vec<u8>,
    prepared: Vec<datapath::slab::SlabRay<V>>,
}

impl<V: Copy + Default> Scratch<V> {
    fn new() -> Self {
        let f = || vec![0.0; BLOCK];
        let b = || vec![false; BLOCK];
        Scratch {
            list: Vec::new(),
            sets: Vec::new(),
            ghit: b(),
            gt: f(),
            dec: b(),
            ehit: b(),
            terr: f(),
            shit: b(),
            sclose: b(),
            cert: b(),
            filter_rest: 0,
            fdec: b(),
            fhit: b(),
            fterr: f(),
            exact: vec![0; BLOCK],
            prepared: Vec::new(),
        }
    }
}

/// The index in `sets` of the lane set of block `b` (`n` lanes) of a ray, made the first time
/// (`kept`: the ray's blocks are kept, one set each; else one set for full blocks and one for a
/// ray's last, shorter block).
fn lane_set<V: Copy + Default>(sets: &mut Vec<Lanes<V>>, b: usize, n: usize, kept: bool) -> usize {
    let j = if kept { b } else { usize::from(n != BLOCK) };
    while sets.len() <= j {
        sets.push(Lanes::new(n));
    }
    if sets[j].tris.len() != n {
        // (a list of another length: not in one run, whose lists all have one length)
        sets[j] = Lanes::new(n);
    }
    j
}

fn cols<const N: usize>(c: &[Vec<f64>; N], n: usize) -> [&[f64]; N] {
    std::array::from_fn(|k| &c[k][..n])
}

impl<F: Format + 'static> Setup<'_, F>
where
    F::V: 'static + Default + Send,
{
    fn chunk(&self, s: &mut Scratch<F::V>, rays: std::ops::Range<u64>) -> (RtiAcc, Vec<SlabAcc>) {
        let f = &self.rti.fmt;
        let w = |v: F::V| f.to_f64(v);
        let mut acc = RtiAcc::default();
        let mut sacc: Vec<SlabAcc> = self.variants.iter().map(|_| SlabAcc::default()).collect();
        // the lane sets, out of the scratch while its other buffers are lent beside one
        let mut sets = std::mem::take(&mut s.sets);
        for i in rays {
            let (ray, target) = self.gen.ray(self.scene, i);
            test_list(self.scene.tris.len(), self.cfg.sample, self.cfg.seed, i, target, &mut s.list);
            // the ray in the format once: the model's ray, its values in f64 (the quantised ray)
            // and every slab variant's stage 0 (`Slab::prepare` is `prepare_encoded` on these
            // same encodings)
            let mray = self.rti.ray(ray.o, ray.d, ray.tmin, ray.tmax);
            let rq = Ray64 { o: mray.o.map(w), d: mray.d.map(w), tmin: w(mray.tmin), tmax: w(mray.tmax) };
            let mut prepared = std::mem::take(&mut s.prepared);
            prepared.clear();
            prepared.extend(self.variants.iter().map(|v| v.slab.prepare_encoded(mray.o, mray.d, mray.tmin, mray.tmax)));
            let bray = BlockRay { o: rq.o, d: rq.d, tmin: rq.tmin, tmax: rq.tmax };
            let maxima = self.set.for_ray(bray);
            let pre = RayConsts {
                bray,
                maxima,
                bound: maxima.map(|m| Constants::new(self.opts, bray, m)),
                f64_filter: std::cell::OnceCell::new(),
            };
            let timed = i % TIME_EVERY == 0;
            let mut cap = Capture::default();
            let mut gbest: Option<(usize, f64)> = None;
            let list = std::mem::take(&mut s.list);
            for (b, blk) in list.chunks(BLOCK).enumerate() {
                let base = b * BLOCK;
                let j = lane_set(&mut sets, b, blk.len(), self.kept);
                let l = &mut sets[j];
                if self.with_rti {
                    self.rti_block(s, l, &mut acc, &ray, &rq, &mray, &pre, blk, base, i, timed, &mut cap, &mut gbest);
                }
                if !self.variants.is_empty() {
                    self.slab_block(s, l, &mut sacc, &rq, &prepared, blk, timed);
                }
                // a kept block's inputs stay (the next ray's block b is the same triangles)
                l.kept = self.kept;
            }
            if self.with_rti {
                let same = match (gbest, cap.hit) {
                    (None, false) => true,
                    (Some((gi, _)), true) => list[gi] == list[cap.id as usize],
                    _ => false,
                };
                acc.counts.closest_disagreements += !same as u64;
            }
            s.list = list;
            s.prepared = prepared;
        }
        s.sets = sets;
        (acc, sacc)
    }

    /// The `explain` command of one test of this run.
    fn explain(&self, ray: &Ray64, tri: &Tri64) -> String {
        explain_cmd(&self.name, ray, tri, self.scene.scale, self.cfg.inject.map(|x| x.name))
    }

    /// One block of a ray's RTI tests: gather, model, bound (static filter first), then the
    /// golden on the lanes judged one by one, and the judge. A lane that is decisive with
    /// neither the model nor the bound's exact decision hitting (most lanes) only counts as a
    /// test, a decisive test and, when the model's divide was skipped, a skipped divide (it
    /// has no disagreement, no violation — `judge::violation` of such a lane is `None` — no
    /// shared hit, and neither the capture unit nor the golden closest hit takes it, nor reads
    /// the golden's hit or t); those counts are taken on bit masks, every other lane is judged
    /// one by one in lane order.
    #[allow(clippy::too_many_arguments)]
    fn rti_block(
        &self,
        s: &mut Scratch<F::V>,
        l: &mut Lanes<F::V>,
        acc: &mut RtiAcc,
        ray: &Ray64,
        rq: &Ray64,
        mray: &datapath::rti::Ray<F::V>,
        pre: &RayConsts,
        blk: &[u32],
        base: usize,
        ray_index: u64,
        timed: bool,
        cap: &mut Capture<F::V>,
        gbest: &mut Option<(usize, f64)>,
    ) {
        let n = blk.len();
        // every lane holds the ray: written in the first block of the ray that uses the set
        if l.ray != Some(ray_index) {
            l.rays.fill(mray);
            l.ray = Some(ray_index);
        }
        // the model's triangles, and the quantised triangles: the model's values in f64
        // (Rti::tri stores from_f64 of each coordinate, so to_f64 of the model's column is the
        // quantised column), converted where the format converts a column at vector speed, else
        // gathered from the records. A kept block holds both from an earlier ray (the same values)
        if !l.kept {
            let [[a, b, c], [d, e, f], [g, h, i]] = &mut l.tris.v;
            gather(
                Kernel::Avx512Fp16,
                &self.recs,
                blk,
                true,
                |r| &r.m,
                [a, b, c, d, e, f, g, h, i].map(|x| &mut x[..]),
            );
            if self.q_from_m {
                for (c, col) in l.cols.iter_mut().enumerate() {
                    self.rti.fmt.to_f64_column(&l.tris.v[c / 3][c % 3][..n], &mut col[..n]);
                }
            } else {
                gather(Kernel::Avx512Fp16, &self.qs, blk, true, |r| r, l.cols.each_mut().map(|x| &mut x[..]));
            }
        }
        let t0 = timed.then(|| self.clock.now());
        match self.cfg.inject {
            None => {
                simd::rti_batch(&self.rti, &l.rays, &l.tris, &mut l.out);
            }
            Some(spec) => {
                // a deliberately wrong model: the bank fault's stage model, lane by lane
                let x = faults::inject::Injected::new(spec);
                for (k, &ti) in blk.iter().enumerate() {
                    x.next_test();
                    let m = &self.recs[ti as usize].m;
                    let tri = Tri { v: std::array::from_fn(|p| std::array::from_fn(|a| m[3 * p + a])) };
                    let o = self.rti.trace_faulty(mray, &tri, &mut datapath::probe::NoProbe, &x);
                    (l.out.valid[k], l.out.hit[k], l.out.t[k], l.out.u[k], l.out.v[k]) =
                        (o.valid, o.hit, o.t, o.u, o.v);
                }
            }
        }
        if let Some(t0) = t0 {
            acc.model_ns += self.clock.since(t0);
            acc.model_tests += n as u64;
        }
        let bray = pre.bray;
        // the static filter first (its constants from the scene's bounds, the ray's, where
        // they exist): a lane its block constants certify gets the per-test
        // bound's verdict without running it (datapath::bound_filter); after a block where it
        // certified few lanes (a coarse format: its constants grow with the block), the next
        // FILTER_REST blocks go straight to the per-test bound — the same verdicts either way
        if s.filter_rest > 0 {
            s.filter_rest -= 1;
            bound::verdict_block(
                Kernel::Avx512Fp16,
                self.opts,
                bray,
                cols(&l.cols, n),
                &mut s.dec[..n],
                &mut s.ehit[..n],
                &mut s.terr[..n],
            );
        } else {
            let k = verdict_block_filtered(
                Kernel::Avx512Fp16,
                self.opts,
                bray,
                cols(&l.cols, n),
                pre.bound.as_ref(),
                &mut s.dec[..n],
                &mut s.ehit[..n],
                &mut s.terr[..n],
                &mut s.cert[..n],
            );
            if k < n / 8 {
                s.filter_rest = FILTER_REST;
            }
        }
        // the reference decision's f64 filter on the lanes that are not decisive, packed (each
        // lane's verdict is the scalar one wherever it sits); rti_lane reads it for those lanes
        // (its constants computed for the ray's first block that has such a lane)
        let fpre = if s.dec[..n].iter().all(|&d| d) {
            None
        } else {
            pre.f64_filter.get_or_init(|| pre.maxima.map(|m| Constants::new(self.fopts, bray, m))).as_ref()
        };
        verdict_lanes_filtered(
            Kernel::Avx512Fp16,
            self.fopts,
            bray,
            cols(&l.cols, n),
            fpre,
            &s.dec[..n],
            &mut s.fdec[..n],
            &mut s.fhit[..n],
            &mut s.fterr[..n],
        );
        // every lane's counts on masks, and the lanes judged one by one: all but the decisive
        // misses of both the model and the bound's exact decision (those only count)
        let mut judged = [0u64; BLOCK / 64];
        let mut k = 0;
        for (x, (w, len)) in words(n).enumerate() {
            let r = w..w + len;
            let (dec, mhit, ehit, valid) =
                (bits(&s.dec[r.clone()]), bits(&l.out.hit[r.clone()]), bits(&s.ehit[r.clone()]), bits(&l.out.valid[r]));
            let all = u64::MAX >> (64 - len);
            let c = &mut acc.counts;
            c.tests += len as u64;
            c.decisive += u64::from(dec.count_ones());
            c.divide_skipped += u64::from((all & !valid).count_ones());
            judged[x] = all & !(dec & !mhit & !ehit);
            k += judged[x].count_ones() as usize;
        }
        // the golden Möller–Trumbore on the judged lanes only: no other lane reads it (its
        // reference is the bound's decisive miss, its t is never compared); the whole block
        // in lanes when many are judged, else lane by lane (the same function on one lane)
        if k > n / 8 {
            intersect_block(self.level, rq, self.faces, cols(&l.cols, n), &mut s.ghit[..n], &mut s.gt[..n]);
        } else {
            for (x, (w, _)) in words(n).enumerate() {
                for j in ones(judged[x]) {
                    let i = w + j;
                    let c: [&[f64]; 9] = std::array::from_fn(|c| &l.cols[c][i..i + 1]);
                    intersect_block(self.level, rq, self.faces, c, &mut s.ghit[i..i + 1], &mut s.gt[i..i + 1]);
                }
            }
        }
        for (x, (w, _)) in words(n).enumerate() {
            for j in ones(judged[x]) {
                self.rti_lane(s, l, acc, ray, rq, blk, base, w + j, ray_index, cap, gbest);
            }
        }
    }

    /// The judge of one RTI lane beyond its test, decisive and skipped-divide counts
    /// ([`Self::rti_block`]): the reference decision (a lane that is not decisive reads the f64
    /// filter's verdict from the block's lanes), hits, disagreements, the property, the t
    /// errors, the capture unit and the golden closest hit.
    #[allow(clippy::too_many_arguments)]
    fn rti_lane(
        &self,
        s: &Scratch<F::V>,
        l: &Lanes<F::V>,
        acc: &mut RtiAcc,
        ray: &Ray64,
        rq: &Ray64,
        blk: &[u32],
        base: usize,
        k: usize,
        ray_index: u64,
        cap: &mut Capture<F::V>,
        gbest: &mut Option<(usize, f64)>,
    ) {
        let f = &self.rti.fmt;
        let c = &mut acc.counts;
        let (mhit, dec) = (l.out.hit[k], s.dec[k]);
        let (gt, mt) = (s.gt[k], f.to_f64(l.out.t[k]));
        // the reference decision (crate::judge::decide): a decisive case's is the bound's;
        // the rest go through the f64 filter, then exact arithmetic
        let gh = if dec {
            s.ehit[k]
        } else {
            let tq = Tri64 { v: std::array::from_fn(|p| std::array::from_fn(|a| l.cols[3 * p + a][k])) };
            let (h, by) = crate::judge::reference_after(&self.rti, rq, &tq, (s.fdec[k], s.fhit[k]), s.ghit[k]);
            c.exact += by.fell_through() as u64;
            h
        };
        c.reference_hits += gh as u64;
        c.model_hits += mhit as u64;
        c.false_misses += (gh && !mhit) as u64;
        c.false_hits += (!gh && mhit) as u64;
        if mhit != gh {
            let tri = &self.scene.tris[blk[k] as usize];
            acc.disagree.offer((ray_index, (base + k) as u64), || {
                let what = if gh { "false miss" } else { "false hit" };
                let how = if dec { "decisive" } else { "within the error bound" };
                format!("{what} ({how}): {}", self.explain(ray, tri))
            });
        }
        // the property, the one rule of crate::judge (a decisive case's reference is the
        // bound's exact decision)
        if let Some(why) = crate::judge::violation(dec, mhit, gh, gh, mt, gt, s.terr[k]) {
            c.violations += 1;
            let tri = &self.scene.tris[blk[k] as usize];
            acc.first.offer((ray_index, (base + k) as u64), || format!("{why}: {}", self.explain(ray, tri)));
        }
        if mhit && gh {
            c.shared_hits += 1;
            let e = (mt - gt).abs();
            acc.ulps.add(e / f.ulp(gt));
            acc.rels.add(e / gt.abs().max(f64::MIN_POSITIVE));
        }
        let out = RtiOut { valid: l.out.valid[k], hit: mhit, t: l.out.t[k], u: l.out.u[k], v: l.out.v[k] };
        self.rti.capture(cap, &out, (base + k) as u32);
        if gh && gbest.is_none_or(|(_, bt)| gt < bt) {
            *gbest = Some((base + k, gt));
        }
    }

    /// One block of a ray's slab tests, every variant: the golden f64 slab test once, then per
    /// variant the model and the judge. A lane whose golden interval is not close to empty and
    /// whose model agrees with the golden (most lanes) counts as a test and, when it hits, an
    /// exact hit (the golden decides it; no false hit or miss) on bit masks; every other lane
    /// takes the exact rational decision (computed once per lane for all variants).
    #[allow(clippy::too_many_arguments)]
    fn slab_block(
        &self,
        s: &mut Scratch<F::V>,
        l: &mut Lanes<F::V>,
        sacc: &mut [SlabAcc],
        rq: &Ray64,
        prepared: &[datapath::slab::SlabRay<F::V>],
        blk: &[u32],
        timed: bool,
    ) {
        let n = blk.len();
        // a kept block holds its gathered boxes from an earlier ray (the same values)
        if !l.kept {
            gather(
                Kernel::Avx512Fp16,
                &self.recs,
                blk,
                !self.with_rti,
                |r| &r.b,
                l.bcols.each_mut().map(|x| &mut x[..]),
            );
            let ([a, b, c], [d, e, f]) = (&mut l.boxes.min, &mut l.boxes.max);
            gather(Kernel::Avx512Fp16, &self.recs, blk, false, |r| &r.s, [a, b, c, d, e, f].map(|x| &mut x[..]));
        }
        // the golden hit, and whether the golden interval is too close to empty to trust
        // (|far − near| ≤ 1e-9 · max(1, |near|, |far| if finite)), once for all variants
        slab_block_flags(
            self.level,
            rq.o,
            rq.d,
            rq.tmin,
            rq.tmax,
            cols(&l.bcols, n),
            CLOSE_REL,
            &mut s.shit[..n],
            &mut s.sclose[..n],
        );
        // the exact decision of each lane, computed at most once for all variants (0: not yet)
        s.exact[..n].fill(0);
        // the golden hits and the close lanes as bit masks, word by word, once for all variants
        let (mut gw, mut cw) = ([0u64; BLOCK / 64], [0u64; BLOCK / 64]);
        for (x, (w, len)) in words(n).enumerate() {
            (gw[x], cw[x]) = (bits(&s.shit[w..w + len]), bits(&s.sclose[w..w + len]));
        }
        // the round-to-nearest variants in one shared batch where it applies (the same bits
        // as each alone), on the rays not timed: a timed ray runs each variant alone, so that
        // each keeps its own rate
        let k = self.shared.len();
        let shared = !timed && k >= 2 && {
            let pick = |j: usize| self.shared[j.min(k - 1)];
            let group: [&Slab<F>; 8] = std::array::from_fn(|j| &self.variants[pick(j)].slab);
            let rays: [&datapath::slab::SlabRay<F::V>; 8] = std::array::from_fn(|j| &prepared[pick(j)]);
            simd::slab_ray_shared(&group[..k], &rays[..k], &l.boxes, &mut l.souts[..k]).is_some()
        };
        for (i, ((v, sr), acc)) in self.variants.iter().zip(prepared).zip(sacc.iter_mut()).enumerate() {
            let out = match self.shared.iter().position(|&j| j == i).filter(|_| shared) {
                Some(j) => &l.souts[j],
                None => {
                    let t0 = timed.then(|| self.clock.now());
                    simd::slab_ray(&v.slab, sr, &l.boxes, &mut l.sout);
                    if let Some(t0) = t0 {
                        acc.model_ns += self.clock.since(t0);
                        acc.model_tests += n as u64;
                    }
                    &l.sout
                }
            };
            let c = &mut acc.counts;
            c.tests += n as u64;
            for (x, (w, len)) in words(n).enumerate() {
                let (hit, g, close) = (bits(&out.hit[w..w + len]), gw[x], cw[x]);
                let all = u64::MAX >> (64 - len);
                let settled = all & !close & !(hit ^ g);
                c.exact_hits += u64::from((settled & g).count_ones());
                for j in ones(all & !settled) {
                    let k = w + j;
                    let (hit, g) = (out.hit[k], s.shit[k]);
                    c.exact_calls += 1;
                    if s.exact[k] == 0 {
                        let b = &self.recs[blk[k] as usize].b;
                        // verify's rays and boxes are finite; a ray that overflowed the format
                        // has no exact decision and counts as the f64 reference says
                        let e =
                            golden::slab_exact(rq.o, rq.d, rq.tmin, rq.tmax, [b[0], b[1], b[2]], [b[3], b[4], b[5]])
                                .unwrap_or(g);
                        s.exact[k] = 1 + e as u8;
                    }
                    let exact = s.exact[k] == 2;
                    c.exact_hits += exact as u64;
                    c.false_misses += (exact && !hit) as u64;
                    c.false_hits += (!exact && hit) as u64;
                }
            }
        }
    }
}

fn rate(tests: u64, ns: u64) -> f64 {
    if ns > 0 {
        tests as f64 / ns as f64 * 1e3
    } else {
        0.0
    }
}

/// One format's results over the engine's shard of the rays, before the report: what a
/// partial result carries and [`FormatAcc::merge`] adds up (every field an exact monoid;
/// the nanosecond sums are timings, which a merged report adds up too).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FormatAcc {
    name: String,
    width: u32,
    rti: Option<RtiAcc>,
    /// Per slab variant the format accepts: its name, whether it is conservative, its results.
    slab: Vec<(String, bool, SlabAcc)>,
    wall_ns: u64,
}

impl FormatAcc {
    /// The format's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Adds another shard's results of the same format (refused when they are not).
    pub fn merge(&mut self, o: FormatAcc) -> Result<(), String> {
        let shape = |a: &FormatAcc| {
            (a.name.clone(), a.width, a.rti.is_some(), a.slab.iter().map(|v| (v.0.clone(), v.1)).collect::<Vec<_>>())
        };
        if shape(self) != shape(&o) {
            return Err(format!("partials disagree on format {}: {:?} vs {:?}", self.name, shape(self), shape(&o)));
        }
        if let (Some(a), Some(b)) = (self.rti.as_mut(), o.rti) {
            a.merge(b);
        }
        for (a, b) in self.slab.iter_mut().zip(o.slab) {
            a.2.merge(b.2);
        }
        self.wall_ns += o.wall_ns;
        Ok(())
    }

    /// Checks a format's accumulators read from a partial: every count within its total, hits
    /// split into shared and false ones, a first violation exactly when violations are
    /// counted, a first disagreement exactly when false hits or misses are, histogram totals
    /// equal to the shared hits, and `tests` (when `tests` is known) the tests of the shard's
    /// rays.
    pub fn check(&self, tests: Option<u64>) -> Result<(), String> {
        use crate::partial::require;
        let name = &self.name;
        if let Some(a) = &self.rti {
            let RtiCounts {
                tests: t,
                decisive: dec,
                reference_hits: gh,
                model_hits: mh,
                false_misses: fm,
                false_hits: fh,
                violations: viol,
                shared_hits: shared,
                closest_disagreements: closest,
                divide_skipped: skipped,
                exact,
            } = a.counts;
            let le = |x: u64, y: u64, what: &str, of: &str| {
                require(x <= y, || format!("{name}: {what} ({x}) exceed {of} ({y})"))
            };
            if let Some(want) = tests {
                require(t == want, || format!("{name}: {t} RTI tests, but the shard's rays make {want}"))?;
            }
            le(dec, t, "decisive tests", "tests")?;
            le(gh, t, "reference hits", "tests")?;
            le(mh, t, "model hits", "tests")?;
            le(skipped, t, "skipped divides", "tests")?;
            le(exact, t - dec, "exact-arithmetic tests", "undecided tests")?;
            le(viol, dec, "violations", "decisive tests")?;
            le(closest, t, "closest-hit disagreements", "tests")?;
            require(gh == shared + fm && mh == shared + fh, || {
                format!("{name}: hits do not add up: reference {gh} = shared {shared} + false misses {fm}, model {mh} = shared {shared} + false hits {fh}")
            })?;
            require((viol > 0) == a.first.0.is_some(), || {
                format!(
                    "{name}: {viol} violations counted but the first-violation record is {}",
                    if a.first.0.is_some() { "present" } else { "missing" }
                )
            })?;
            require((fm + fh > 0) == a.disagree.0.is_some(), || {
                format!(
                    "{name}: {} disagreements counted but the first-disagreement record is {}",
                    fm + fh,
                    if a.disagree.0.is_some() { "present" } else { "missing" }
                )
            })?;
            for (h, what) in [(&a.ulps, "ulp"), (&a.rels, "relative")] {
                h.check().map_err(|e| format!("{name}: t {what} errors: {e}"))?;
                require(h.count() + h.invalid() == shared, || {
                    format!(
                        "{name}: the t {what} error histogram holds {} values, shared hits are {shared}",
                        h.count() + h.invalid()
                    )
                })?;
            }
        }
        for (variant, _, a) in &self.slab {
            let SlabCounts { tests: t, exact_hits: eh, false_misses: fm, false_hits: fh, exact_calls: calls } =
                a.counts;
            if let Some(want) = tests {
                require(t == want, || format!("{name} {variant}: {t} slab tests, but the shard's rays make {want}"))?;
            }
            require(eh <= t && fm <= eh && fh <= t - eh && calls <= t, || {
                format!("{name} {variant}: slab counts do not fit: tests {t}, exact hits {eh}, false misses {fm}, false hits {fh}, exact calls {calls}")
            })?;
        }
        Ok(())
    }

    /// The format's RTI report (when it ran the RTI unit) and one slab report per variant.
    pub fn finish(self) -> (Option<FormatReport>, Vec<SlabReport>) {
        let rep = self.rti.map(|acc| {
            let c = acc.counts;
            FormatReport {
                format: self.name.clone(),
                width: self.width,
                tests: c.tests,
                decisive: c.decisive,
                golden_hits: c.reference_hits,
                model_hits: c.model_hits,
                false_misses: c.false_misses,
                false_hits: c.false_hits,
                violations: c.violations,
                shared_hits: c.shared_hits,
                t_err_ulps_median: acc.ulps.median(),
                t_err_ulps_max: acc.ulps.max(),
                t_err_rel_median: acc.rels.median(),
                t_err_rel_max: acc.rels.max(),
                closest_disagreements: c.closest_disagreements,
                divide_skipped: c.divide_skipped,
                exact: c.exact,
                mtests_per_s: rate(acc.model_tests, acc.model_ns),
                judged_mtests_per_s: rate(c.tests, self.wall_ns),
                first_violation: acc.first.into_inner(),
                first_disagreement: acc.disagree.into_inner(),
            }
        });
        let slab = self
            .slab
            .into_iter()
            .map(|(variant, conservative, a)| SlabReport {
                format: self.name.clone(),
                variant,
                conservative,
                tests: a.counts.tests,
                exact_hits: a.counts.exact_hits,
                false_misses: a.counts.false_misses,
                false_hits: a.counts.false_hits,
                exact_calls: a.counts.exact_calls,
                mtests_per_s: rate(a.model_tests, a.model_ns),
            })
            .collect();
        (rep, slab)
    }
}

/// The bounding box (min x, y, z, max x, y, z) of a triangle's vertices: the box each slab test
/// of `verify` tests.
pub fn tri_box(v: &[[f64; 3]; 3]) -> [f64; 6] {
    let lo = |a: usize| v.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min);
    let hi = |a: usize| v.iter().map(|p| p[a]).fold(f64::NEG_INFINITY, f64::max);
    [lo(0), lo(1), lo(2), hi(0), hi(1), hi(2)]
}

/// One format's pass over every ray on the engine: the RTI report (when `with_rti`) and one
/// slab report per variant the format accepts.
pub fn run_format<F: Format + 'static>(
    fmt: F,
    cfg: &VerifyConfig,
    scene: &Scene,
    with_rti: bool,
) -> (Option<FormatReport>, Vec<SlabReport>)
where
    F::V: 'static + Default + Send + Sync,
{
    accumulate_format(fmt, cfg, scene, with_rti).finish()
}

/// One format's pass over the engine's shard of the rays, as an accumulator.
pub fn accumulate_format<F: Format + 'static>(fmt: F, cfg: &VerifyConfig, scene: &Scene, with_rti: bool) -> FormatAcc
where
    F::V: 'static + Default + Send + Sync,
{
    let rti = Rti::new(fmt, cfg.rti);
    let f = &rti.fmt;
    let q = |x: f64| f.to_f64(f.from_f64(x));
    // only the variants the format accepts (a conservative promise it cannot keep is refused)
    let variants: Vec<Variant<F>> = SlabConfig::variants_for(f)
        .into_iter()
        .map(|name| {
            let sc = SlabConfig::named(name).expect("built-in variant");
            Variant { name, conservative: sc.is_conservative(f), slab: Slab::new(*f, sc) }
        })
        .collect();
    let recs: Vec<Rec<F::V>> = scene
        .tris
        .iter()
        .map(|t| {
            let b = tri_box(&t.v);
            let m = if with_rti {
                let m = rti.tri(t.v).v;
                std::array::from_fn(|k| m[k / 3][k % 3])
            } else {
                [F::V::default(); 9]
            };
            // box storage does not depend on the variant
            let s = match variants.first() {
                Some(v) => {
                    let a =
                        v.slab.store_box([b[0], b[1], b[2]], [b[3], b[4], b[5]]).unwrap_or_else(|_| v.slab.empty_box());
                    [a.min[0], a.min[1], a.min[2], a.max[0], a.max[1], a.max[2]]
                }
                None => [F::V::default(); 6],
            };
            Rec { m, b, s }
        })
        .collect();
    // the quantised triangles, kept only where they are not converted from the model's
    let q_from_m = f.fast_f64_column();
    let qs: Vec<[f64; 9]> = if with_rti && !q_from_m {
        scene.tris.iter().map(|t| std::array::from_fn(|k| q(t.v[k / 3][k % 3]))).collect()
    } else {
        Vec::new()
    };
    // the static filter's bounds over the quantised triangles: the columns' values exactly
    let set = if !with_rti {
        SetMaxima::of(std::iter::empty())
    } else if q_from_m {
        SetMaxima::of(recs.iter().map(|r| r.m.map(|v| f.to_f64(v))))
    } else {
        SetMaxima::of(qs.iter().copied())
    };
    let setup = Setup {
        cfg,
        scene,
        gen: scene.ray_gen(cfg.seed),
        with_rti,
        recs,
        qs,
        q_from_m,
        set,
        shared: (0..variants.len()).filter(|&j| !variants[j].slab.cfg.directed).collect(),
        variants,
        opts: BlockOpts {
            em: f.error_model(),
            div: f.div_mode(),
            cull: rti.cull,
            det_threshold: f.to_f64(rti.det_thr),
        },
        fopts: crate::judge::f64_filter_opts(&rti),
        faces: crate::judge::faces(&rti),
        level: crate::golden_level(),
        name: f.name(),
        rti: rti.clone(),
        clock: Clock::start(),
        kept: scene.tris.len() <= cfg.sample && scene.tris.len().div_ceil(BLOCK) <= KEPT_BLOCKS,
    };
    let progress = Progress::new(cfg.engine.shard_items(cfg.rays), "rays", !cfg.progress);
    progress.message(format!("{} ({} tests per ray)", setup.name, tests_per_ray(scene, cfg.sample)));
    let wall = Instant::now();
    let (mut acc, mut sacc) = engine::run(&cfg.engine, cfg.rays, &progress, Scratch::new, |s, r| setup.chunk(s, r));
    let wall_ns = wall.elapsed().as_nanos() as u64;
    // the model timings from clock ticks to nanoseconds
    acc.model_ns = setup.clock.to_ns(acc.model_ns);
    for a in &mut sacc {
        a.model_ns = setup.clock.to_ns(a.model_ns);
    }
    progress.finish();
    // an empty run merges nothing: one empty accumulator per variant
    let sacc = if sacc.is_empty() { setup.variants.iter().map(|_| SlabAcc::default()).collect() } else { sacc };
    FormatAcc {
        name: setup.name.clone(),
        width: f.width(),
        rti: with_rti.then_some(acc),
        slab: setup.variants.iter().zip(sacc).map(|(v, a)| (v.name.to_string(), v.conservative, a)).collect(),
        wall_ns,
    }
}
