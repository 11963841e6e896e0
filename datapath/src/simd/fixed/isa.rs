//! The per-instruction-set kernels: AVX2 on [`ymm::Y`] (portable 4-lane arrays for the
//! formats it does not admit), AVX-512F + DQ on [`zmm::Z`]; the RTI and slab ones in the signatures of `datapath::simd`'s dispatch tables
//! (lanes `0..full`, a multiple of the lane count).

use super::lanes::*;
use super::{ymm, zmm};
use crate::format::{DivMode, Fixed, FxOverflow};
use crate::rti::{Cull, HitsSoa, RaysSoa, Rti, TrisSoa};
use crate::simd::select::SlabRays;
use crate::slab::{BoxesSoa, Slab, SlabOutSoa, SlabRay};
use crate::stage::Op;

/// The constants of a format the dispatch accepted (`kernel_fixed` names a kernel only
/// for formats that have them).
fn lanes(f: &Fixed) -> Lanes {
    Lanes::of(f).expect("the dispatch checked the format")
}

/// The RTI loop on lanes `x` for `rti`'s modes.
#[inline(always)]
fn rti_any<X: Ops>(
    x: &X,
    rti: &Rti<Fixed>,
    rays: &RaysSoa<i64>,
    tris: &TrisSoa<i64>,
    out: &mut HitsSoa<i64>,
    full: usize,
) {
    let backface = rti.cull == Cull::Backface;
    by_modes!(&rti.fmt, rti_loop, X, x, rti.det_thr, backface, rays, tris, out, full)
}

/// AVX2 (4 lanes).
#[target_feature(enable = "avx2")]
pub(super) fn rti_avx2(
    rti: &Rti<Fixed>,
    rays: &RaysSoa<i64>,
    tris: &TrisSoa<i64>,
    out: &mut HitsSoa<i64>,
    full: usize,
) {
    let c = lanes(&rti.fmt);
    if ymm::Y::fits(&c, rti.fmt.overflow == FxOverflow::Wrap) {
        // SAFETY: this function's features
        rti_any(&unsafe { ymm::Y::new(c) }, rti, rays, tris, out, full)
    } else {
        rti_any(&Port::<4>(c), rti, rays, tris, out, full)
    }
}

/// AVX-512F + DQ (8 lanes).
#[target_feature(enable = "avx512f,avx512dq")]
pub(super) fn rti_avx512(
    rti: &Rti<Fixed>,
    rays: &RaysSoa<i64>,
    tris: &TrisSoa<i64>,
    out: &mut HitsSoa<i64>,
    full: usize,
) {
    // SAFETY: this function's features
    let z = unsafe { zmm::Z::new(lanes(&rti.fmt)) };
    rti_any(&z, rti, rays, tris, out, full)
}

/// The slab loop on lanes `x` for the unit's modes.
#[inline(always)]
fn slab_any<X: Ops>(
    x: &X,
    s: &Slab<Fixed>,
    rays: SlabRays<'_, i64>,
    boxes: &BoxesSoa<i64>,
    out: &mut SlabOutSoa<i64>,
    full: usize,
) {
    by_modes!(&s.fmt, slab_loop, X, x, &s.cfg, rays, boxes, out, full)
}

/// AVX2 (4 lanes).
#[target_feature(enable = "avx2")]
pub(super) fn slab_avx2(
    s: &Slab<Fixed>,
    rays: SlabRays<'_, i64>,
    boxes: &BoxesSoa<i64>,
    out: &mut SlabOutSoa<i64>,
    full: usize,
) {
    let c = lanes(&s.fmt);
    if ymm::Y::fits(&c, s.fmt.overflow == FxOverflow::Wrap) {
        // SAFETY: this function's features
        slab_any(&unsafe { ymm::Y::new(c) }, s, rays, boxes, out, full)
    } else {
        slab_any(&Port::<4>(c), s, rays, boxes, out, full)
    }
}

/// AVX-512F + DQ (8 lanes).
#[target_feature(enable = "avx512f,avx512dq")]
pub(super) fn slab_avx512(
    s: &Slab<Fixed>,
    rays: SlabRays<'_, i64>,
    boxes: &BoxesSoa<i64>,
    out: &mut SlabOutSoa<i64>,
    full: usize,
) {
    // SAFETY: this function's features
    let z = unsafe { zmm::Z::new(lanes(&s.fmt)) };
    slab_any(&z, s, rays, boxes, out, full)
}

/// The shared slab loop (several round-to-nearest variants, one ray) on lanes `x` for the
/// format's modes.
#[inline(always)]
fn slab_shared_any<X: Ops>(
    x: &X,
    group: &[&Slab<Fixed>],
    r: &SlabRay<i64>,
    boxes: &BoxesSoa<i64>,
    outs: &mut [SlabOutSoa<i64>],
    full: usize,
) {
    by_modes!(&group[0].fmt, slab_shared_loop, X, x, group, r, boxes, outs, full)
}

/// AVX2 (4 lanes).
#[target_feature(enable = "avx2")]
pub(super) fn slab_shared_avx2(
    group: &[&Slab<Fixed>],
    r: &SlabRay<i64>,
    boxes: &BoxesSoa<i64>,
    outs: &mut [SlabOutSoa<i64>],
    full: usize,
) {
    let c = lanes(&group[0].fmt);
    if ymm::Y::fits(&c, group[0].fmt.overflow == FxOverflow::Wrap) {
        // SAFETY: this function's features
        slab_shared_any(&unsafe { ymm::Y::new(c) }, group, r, boxes, outs, full)
    } else {
        slab_shared_any(&Port::<4>(c), group, r, boxes, outs, full)
    }
}

/// AVX-512F + DQ (8 lanes).
#[target_feature(enable = "avx512f,avx512dq")]
pub(super) fn slab_shared_avx512(
    group: &[&Slab<Fixed>],
    r: &SlabRay<i64>,
    boxes: &BoxesSoa<i64>,
    outs: &mut [SlabOutSoa<i64>],
    full: usize,
) {
    // SAFETY: this function's features
    let z = unsafe { zmm::Z::new(lanes(&group[0].fmt)) };
    slab_shared_any(&z, group, r, boxes, outs, full)
}

/// AVX2 (4 lanes).
#[target_feature(enable = "avx2")]
pub(super) fn op_avx2(f: &Fixed, op: Op, a: &[i64], b: &[i64], out: &mut [i64]) {
    let c = lanes(f);
    if ymm::Y::fits(&c, f.overflow == FxOverflow::Wrap) {
        // SAFETY: this function's features
        let y = unsafe { ymm::Y::new(c) };
        by_modes!(f, op_loop, ymm::Y, &y, op, a, b, out)
    } else {
        let x = Port::<4>(c);
        by_modes!(f, op_loop, Port<4>, &x, op, a, b, out)
    }
}

/// AVX-512F + DQ (8 lanes).
#[target_feature(enable = "avx512f,avx512dq")]
pub(super) fn op_avx512(f: &Fixed, op: Op, a: &[i64], b: &[i64], out: &mut [i64]) {
    // SAFETY: this function's features
    let z = unsafe { zmm::Z::new(lanes(f)) };
    by_modes!(f, op_loop, zmm::Z, &z, op, a, b, out)
}
