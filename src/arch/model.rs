//! The cycle counts of the thesis hardware on a scene's events ([`SceneEvents`]).
//!
//! **RTI accelerator** (thesis ch. 4). The host hands it one leaf at a time: the leaf's
//! triangles (contiguous in DRAM) and the list of rays that test the leaf. With n pipelines,
//! b = min(buffers, c) interleaved ray buffers used and a triangle cadence of
//! c = assemble + broadcast cycles, one *round* takes up to n·b of the leaf's rays; a leaf with
//! R rays and T triangles takes ⌈R / (n·b)⌉ rounds, the last one partial, and costs, in RTI
//! cycles:
//!
//! * ray load: ⌈R · ray_bytes / dram_bytes_per_cycle⌉ (the DMA streams the leaf's ray list, which
//!   is contiguous in DRAM, into the ray buffers round by round; a partial DRAM word is only
//!   paid at the end of the list);
//! * triangle stream: c · T per round (each triangle is assembled, broadcast, and held for c
//!   cycles, one cycle per ray buffer; assembly of the next triangle is double-buffered, so
//!   the stream never pauses within a round);
//! * drain: rti_latency per round (the last triangle's tests reach the min-capture units);
//! * result store: ⌈R · result_bytes / dram_bytes_per_cycle⌉.
//!
//! Serially (the thesis's sequence: load, stream, store, round after round) a leaf costs the
//! sum; with `overlap_io` it costs max(rounds · (c·T + rti_latency), load + store) (the DMA
//! loads and stores while the triangles stream: the larger of compute and I/O). A leaf no ray
//! tests costs nothing. Each term is non-increasing in n, b and the DRAM width, so more
//! pipelines, buffers or bandwidth never make the model slower.
//!
//! **Traversal core** (thesis ch. 5). L level pipelines back to back; a ray enters the first
//! one and flows through all of them, one level per pipeline; a restart (back traversal)
//! recirculates it from the last pipeline into the first. The entry takes `ports` ray-passes per
//! cycle, shared by new and recirculated rays, so the core's cycles are
//! ⌈passes · trips / ports⌉ + L · level_latency, where a tree deeper than L levels needs
//! trips = ⌈depth / L⌉ trips through the core per pass and the second term fills and drains the
//! pipeline once.
//!
//! **Not counted**: loading the BVH into BRAM and the triangles into DRAM, the host building
//! the leaf ray lists and its per-leaf commands, DRAM latency and refresh (only bandwidth is
//! counted, and only for the RTI side's rays and results: the traversal core's ray reads and
//! result writes are taken to keep pace), contention between the two sides' DRAM traffic, and
//! shading. The two sides run one after the other (traversal, then the leaves' RTI tests):
//! `total_s` is the sum; `overlapped_s`, the larger of the two, is the bound if they overlapped.

use super::{ArchParams, SceneEvents};
use serde::Serialize;

/// The RTI accelerator's cycles on a scene, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RtiCycles {
    /// Rounds over all leaves.
    pub rounds: u64,
    /// Cycles loading rays.
    pub ray_load: u64,
    /// Cycles streaming triangles.
    pub stream: u64,
    /// Cycles draining the pipelines.
    pub drain: u64,
    /// Cycles storing results.
    pub store: u64,
    /// Total cycles (the sum, or with `overlap_io` the overlapped rounds).
    pub total: u64,
    /// RTI tests performed.
    pub tests: u64,
}

/// The cycles of one leaf with `rays` rays and `tris` triangles, added to `c`.
pub fn leaf_cycles(p: &ArchParams, rays: u64, tris: u64, c: &mut RtiCycles) {
    if rays == 0 {
        return;
    }
    let dram = p.dram_bytes_per_cycle as u64;
    let rounds = rays.div_ceil(p.packet());
    let load = (rays * p.ray_bytes as u64).div_ceil(dram);
    let store = (rays * p.result_bytes as u64).div_ceil(dram);
    let stream = rounds * p.cadence() * tris;
    let drain = rounds * p.rti_latency as u64;
    c.rounds += rounds;
    c.ray_load += load;
    c.stream += stream;
    c.drain += drain;
    c.store += store;
    c.total += if p.overlap_io { (stream + drain).max(load + store) } else { load + stream + drain + store };
    c.tests += rays * tris;
}

/// The RTI accelerator's cycles on every leaf of `e`.
pub fn rti_cycles(p: &ArchParams, e: &SceneEvents) -> RtiCycles {
    let mut c = RtiCycles::default();
    for (&t, &r) in e.leaf_tris.iter().zip(&e.leaf_rays) {
        leaf_cycles(p, r, t as u64, &mut c);
    }
    c
}

/// The traversal core's cycles on `e`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TravCycles {
    /// Trips through the L level pipelines per pass (⌈depth / L⌉, at least 1).
    pub trips: u64,
    /// Entry slots used: passes × trips.
    pub slots: u64,
    /// Fill and drain: L × level latency.
    pub fill: u64,
    /// ⌈slots / ports⌉ + fill.
    pub total: u64,
}

/// The traversal core's cycles on `e`.
pub fn trav_cycles(p: &ArchParams, e: &SceneEvents) -> TravCycles {
    let trips = (e.depth as u64).div_ceil(p.levels as u64).max(1);
    let slots = e.passes * trips;
    let fill = p.levels as u64 * p.level_latency as u64;
    TravCycles { trips, slots, fill, total: slots.div_ceil(p.ports as u64) + fill }
}

/// The model's answer for one scene, leaf size and parameter set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// Triangles per leaf at most.
    pub leaf_size: u32,
    /// RTI pipelines.
    pub pipelines: u32,
    /// RTI side.
    pub rti: RtiCycles,
    /// Traversal side.
    pub trav: TravCycles,
    /// RTI seconds.
    pub rti_s: f64,
    /// Traversal seconds.
    pub trav_s: f64,
    /// Traversal then RTI: the sum.
    pub total_s: f64,
    /// The larger of the two (both sides overlapped).
    pub overlapped_s: f64,
    /// RTI tests per second of RTI time.
    pub rti_rate: f64,
    /// Share of the pipelines' cycles that test a ray against a triangle.
    pub rti_utilisation: f64,
    /// Rays per second of traversal time.
    pub trav_rate: f64,
    /// BRAM bits of the tree (boxes and address words).
    pub bram_bits: u64,
}

/// Evaluates the model.
pub fn estimate(p: &ArchParams, e: &SceneEvents) -> Estimate {
    let rti = rti_cycles(p, e);
    let trav = trav_cycles(p, e);
    let rti_s = rti.total as f64 / (p.rti_mhz * 1e6);
    let trav_s = trav.total as f64 / (p.trav_mhz * 1e6);
    let rate = |n: f64, s: f64| if s > 0.0 { n / s } else { 0.0 };
    Estimate {
        leaf_size: e.leaf_size,
        pipelines: p.pipelines,
        rti,
        trav,
        rti_s,
        trav_s,
        total_s: rti_s + trav_s,
        overlapped_s: rti_s.max(trav_s),
        rti_rate: rate(rti.tests as f64, rti_s),
        rti_utilisation: rti.tests as f64 / (rti.total as f64 * p.pipelines as f64).max(1.0),
        trav_rate: rate(e.rays as f64, trav_s),
        bram_bits: p.bram_bits(e.bram_boxes),
    }
}
