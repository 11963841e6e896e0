//! The fixed-point batch path: `qI.F` formats of at most 32 bits on 64-bit integer lanes, bit
//! for bit the scalar model of [`Fixed`] (every rounding and overflow mode, either division
//! mode), for the RTI unit and for single operations.
//!
//! The scalar model forms products and quotients exactly in i128. With a total width w ≤ 32
//! every raw value lies in [−2^31, 2^31 − 1], so the lanes need no i128:
//!
//! * **+ −**: the exact sum of two raw values fits i64 (|a ± b| ≤ 2^32); then the overflow mode.
//! * **×**: the exact product of two raw values fits i64 (|a·b| ≤ 2^62; it is formed as a
//!   signed 32 × 32 → 64-bit multiply); `p / 2^F` rounded by the mode from the arithmetic
//!   shift `q = p >> F` (floor, i.e. toward −∞) and the dropped bits `r = p & (2^F − 1)`
//!   (0 ≤ r < 2^F): toward +∞ adds 1 when r ≠ 0, toward zero adds 1 when r ≠ 0 and p < 0, to
//!   nearest-even adds 1 when r > 2^(F−1) or r = 2^(F−1) and q is odd; then the overflow mode.
//! * **÷** (`a / b`, b ≠ 0): the numerator `n = a·2^F` (|n| ≤ 2^62, and exact in binary64:
//!   it has the ≤ 32 significant bits of a) and the denominator `d = |b|` (sign moved to n)
//!   are converted to binary64 exactly; `q0 = ⌊RN(n / d)⌋`. While |n / d| < 2^53 the
//!   binary64 quotient's error is below one unit and `q0` is ⌊n / d⌋ or ⌊n / d⌋ + 1, so the
//!   remainder `r = n − q0·d` (computed modulo 2^64, exact because the true value is small)
//!   lies in [−d, d): one step (`r < 0`: q0 − 1, r + d) gives the floor and 0 ≤ r < d, from
//!   which the rounding mode decides as for ×. A quotient reaches 2^53 only when w − 1 + F
//!   ≥ 53; such formats take a second correction step (q0 + ⌊RN(r / d)⌋, |r / d| ≤ 2^10)
//!   before the final one. Under saturation a quotient that large saturates whatever its
//!   low bits. `b = 0` gives the most positive value for a > 0, the most negative for a < 0,
//!   0 for 0 / 0, as in the model. The reciprocal mode is `a × (1 / b)`, both rounded.
//! * **Overflow**: saturate clamps to [−2^(w−1), 2^(w−1) − 1]; wrap keeps the low w bits,
//!   sign-extended (`(x << (64 − w)) >> (64 − w)`).
//! * **Compares** are integer compares; |x| is `fit(|x|)` (the most negative value saturates
//!   or wraps, as in the model).
//!
//! One formulation of the RTI stage table, `rti_vec`, runs on a lane type of the `Ops`
//! trait: AVX-512F + DQ registers of 8 lanes (`zmm::Z`: vpmuldq, vpsraq, vpminsq/vpmaxsq,
//! vcvtqq2pd, vdivpd, vcvtpd2qq toward −∞, vpmullq), AVX2 registers of 4 lanes holding
//! biased values (`ymm::Y`: order, min, max and saturation as binary64 operations, division
//! from a shared reciprocal estimate, see its documentation) and portable arrays of 4 lanes
//! on which each operation is the branch-free scalar function of this module (`Port`, for
//! the saturating formats whose products exceed `ymm::Y`'s range). Every mode is a const
//! parameter, so no lane decides a mode; the slots after the last full vector run the scalar
//! model.

use crate::format::Fixed;
use crate::rti::{HitsSoa, RaysSoa, Rti, TrisSoa};
use crate::simd::select::{Kernel, SlabRays};
use crate::slab::{BoxesSoa, Slab, SlabOutSoa, SlabRay, SlabRaysSoa};
use crate::stage::Op;
use crate::Format as _;

#[macro_use]
mod lanes;
#[cfg(target_arch = "x86_64")]
mod isa;
#[cfg(test)]
mod tests;
#[cfg(target_arch = "x86_64")]
mod ymm;
#[cfg(target_arch = "x86_64")]
mod zmm;

use lanes::Lanes;
pub use lanes::WIDEST_FIXED;

/// The kernel `rti_batch_fixed` / `op_batch_fixed` use for this format on this machine:
/// formats of at most 32 bits on i64 lanes, the scalar model otherwise.
pub fn kernel_fixed(f: &Fixed) -> Kernel {
    let k = crate::simd::select::best_kernel(Lanes::of(f).is_some(), WIDEST_FIXED);
    // the 8-lane kernel also needs AVX-512DQ (64-bit multiplies and conversions)
    #[cfg(target_arch = "x86_64")]
    if k == Kernel::Avx512 && !std::arch::is_x86_feature_detected!("avx512dq") {
        return Kernel::Avx2;
    }
    k
}

/// [`Rti::batch`] for a fixed-point format on the fastest kernel available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn rti_batch_fixed(rti: &Rti<Fixed>, rays: &RaysSoa<i64>, tris: &TrisSoa<i64>, out: &mut HitsSoa<i64>) -> Kernel {
    crate::simd::select::rti_dispatch(
        rti,
        rays,
        tris,
        out,
        kernel_fixed(&rti.fmt),
        #[cfg(target_arch = "x86_64")]
        (isa::rti_avx2, isa::rti_avx512, None),
    )
}

/// `Add`, `Sub`, `Mul` or `Div` (in the format's division mode) of a fixed-point format on
/// whole columns, `out[i] = a[i] op b[i]`, on the fastest kernel available; the model's bits.
///
/// # Panics
/// If the slice lengths differ or `op` is `Logic`.
pub fn op_batch_fixed(f: &Fixed, op: Op, a: &[i64], b: &[i64], out: &mut [i64]) -> Kernel {
    assert!(a.len() == b.len() && b.len() == out.len(), "batch lengths differ");
    assert!(op != Op::Logic, "op_batch_fixed computes arithmetic only");
    let which = kernel_fixed(f);
    #[cfg(target_arch = "x86_64")]
    match which {
        // SAFETY: `which` names a kernel only after run-time feature detection, and only for
        // formats with lanes.
        Kernel::Avx2 => {
            unsafe { isa::op_avx2(f, op, a, b, out) };
            return which;
        }
        Kernel::Scalar => {}
        _ => {
            unsafe { isa::op_avx512(f, op, a, b, out) };
            return which;
        }
    }
    let _ = which;
    for i in 0..out.len() {
        out[i] = match op {
            Op::Add => f.add(a[i], b[i]),
            Op::Sub => f.sub(a[i], b[i]),
            Op::Mul => f.mul(a[i], b[i]),
            _ => f.div(a[i], b[i]),
        };
    }
    Kernel::Scalar
}

/// The kernel `slab_batch_fixed` / `slab_ray_fixed` use for this unit: as [`kernel_fixed`],
/// every variant.
pub fn slab_kernel_fixed(s: &Slab<Fixed>) -> Kernel {
    kernel_fixed(&s.fmt)
}

/// The slab unit on the kernel `slab_kernel_fixed` names, through `datapath::simd`'s dispatch.
fn slab_fixed(s: &Slab<Fixed>, rays: SlabRays<'_, i64>, boxes: &BoxesSoa<i64>, out: &mut SlabOutSoa<i64>) -> Kernel {
    crate::simd::select::slab_dispatch(
        s,
        rays,
        boxes,
        out,
        slab_kernel_fixed(s),
        #[cfg(target_arch = "x86_64")]
        (isa::slab_avx2, isa::slab_avx512, None),
    )
}

/// [`Slab::batch`] for a fixed-point format on the fastest kernel available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn slab_batch_fixed(
    s: &Slab<Fixed>,
    rays: &SlabRaysSoa<i64>,
    boxes: &BoxesSoa<i64>,
    out: &mut SlabOutSoa<i64>,
) -> Kernel {
    slab_fixed(s, SlabRays::Pairs(rays), boxes, out)
}

/// [`Slab::batch_ray`] (one ray, many boxes) for a fixed-point format on the fastest kernel
/// available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn slab_ray_fixed(s: &Slab<Fixed>, ray: &SlabRay<i64>, boxes: &BoxesSoa<i64>, out: &mut SlabOutSoa<i64>) -> Kernel {
    slab_fixed(s, SlabRays::One(ray), boxes, out)
}

/// [`slab_ray_fixed`] of each `(group[j], rays[j])` into `outs[j]` — the same bits — with
/// the planes and comparator chains computed once: the round-to-nearest variants of one format
/// (fixed point has no NaN, so they differ only in the widening) whose prepared rays have the
/// same origin, 1/d and t interval. `None`, nothing written, when the group does not qualify
/// (see `datapath::simd::slab_ray_shared`).
pub fn slab_ray_shared_fixed(
    group: &[&Slab<Fixed>],
    rays: &[&SlabRay<i64>],
    boxes: &BoxesSoa<i64>,
    outs: &mut [SlabOutSoa<i64>],
) -> Option<Kernel> {
    crate::simd::select::shared_dispatch(
        group,
        rays,
        boxes,
        outs,
        |_| true,
        slab_kernel_fixed,
        #[cfg(target_arch = "x86_64")]
        (isa::slab_shared_avx2, isa::slab_shared_avx512, None),
    )
}
