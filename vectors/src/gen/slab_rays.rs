//! The slab ray placements shared by the vector generator (`gen::slab`) and the stress suite
//! (`raypipe stress`): a random box, and a ray starting on one of its faces, aimed at a point
//! of its surface, or starting inside it. Each draws from the caller's stream in a fixed order
//! (stated per function), so a caller's cases stay the same bits whichever module builds them.

use datapath::rng::SplitMix64;

/// A box of three slabs: per axis, in the order x, y, z, a centre `center[a] + scale·U(−1, 1)`
/// and a half-extent `scale·U(0.01, 0.5)` — or, when `zero_extent` and a coin (`below(2) == 0`,
/// drawn before the extent) says so, 0 (the slab is one plane). Returns `(lo, hi)`.
pub fn random_box(r: &mut SplitMix64, scale: f64, center: [f64; 3], zero_extent: bool) -> ([f64; 3], [f64; 3]) {
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    for a in 0..3 {
        let c = center[a] + scale * r.range(-1.0, 1.0);
        let e = if zero_extent && r.below(2) == 0 { 0.0 } else { scale * r.range(0.01, 0.5) };
        lo[a] = c - e;
        hi[a] = c + e;
    }
    (lo, hi)
}

/// The origin on a face: an axis `a = below(3)`, `o[a]` = `lo[a]` or `hi[a]` (coin), the other
/// two coordinates uniform inside their slabs (in axis order); then one direction component
/// `d[below(3)]` becomes +0 or −0 (coin).
pub fn origin_on_face(r: &mut SplitMix64, lo: &[f64; 3], hi: &[f64; 3], o: &mut [f64; 3], d: &mut [f64; 3]) {
    let a = r.below(3) as usize;
    o[a] = if r.below(2) == 0 { lo[a] } else { hi[a] };
    for b in (0..3).filter(|&b| b != a) {
        o[b] = r.range(lo[b], hi[b]);
    }
    let z = r.below(3) as usize;
    d[z] = if r.below(2) == 0 { 0.0 } else { -0.0 };
}

/// The direction from `o` to a point of the box's surface: a point uniform inside the box, then
/// its first `1 + below(3)` coordinates moved to `lo` or `hi` (a coin each): a face, an edge or
/// a corner. Returns `point − o`.
pub fn toward_surface(r: &mut SplitMix64, lo: &[f64; 3], hi: &[f64; 3], o: &[f64; 3]) -> [f64; 3] {
    let mut p: [f64; 3] = std::array::from_fn(|a| r.range(lo[a], hi[a]));
    for a in 0..1 + r.below(3) as usize {
        p[a] = if r.below(2) == 0 { lo[a] } else { hi[a] };
    }
    std::array::from_fn(|a| p[a] - o[a])
}

/// An origin uniform inside the box (in axis order).
pub fn inside(r: &mut SplitMix64, lo: &[f64; 3], hi: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|a| r.range(lo[a], hi[a]))
}
