//! The per-format entry points: for binary32, binary16, bfloat16 and the custom `eEmM` layouts,
//! which kernel a unit gets and its batch call (RTI, slab pairs, one slab ray, the soft-float
//! operations), each falling back to the scalar model.

use super::kernels;
use super::select::*;
use crate::format::{Bf16, F16Half, F32Native, Ieee, IeeeBackend, Soft, Subnormals};
use crate::rti::{HitsSoa, RaysSoa, Rti, TrisSoa};
use crate::slab::{BoxesSoa, Slab, SlabOutSoa, SlabRay, SlabRaysSoa};
use crate::Format as _;
use half::f16;

/// The widest kernel binary32 has (AVX512-FP16 adds nothing to binary32).
pub const WIDEST_F32: Kernel = Kernel::Avx512;
/// The widest kernel binary16 has.
pub const WIDEST_F16: Kernel = Kernel::Avx512Fp16;

/// The kernel `rti_batch_f32` uses for this unit on this machine (and this thread's cap):
/// IEEE subnormals or FTZ (flushed in the lanes), the canonical NaN rule.
pub fn kernel_f32(rti: &Rti<Ieee<F32Native>>) -> Kernel {
    best_kernel(eligible(&rti.fmt) && rti.det_thr >= 0.0, WIDEST_F32)
}

/// The kernel `rti_batch_f16` uses for this unit on this machine (and this thread's cap):
/// IEEE subnormals or FTZ (flushed in the lanes), the canonical NaN rule.
pub fn kernel_f16(rti: &Rti<Ieee<F16Half>>) -> Kernel {
    best_kernel(eligible(&rti.fmt) && rti.det_thr.to_f32() >= 0.0, WIDEST_F16)
}

/// [`Rti::batch`] for binary32 on the fastest kernel available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn rti_batch_f32(
    rti: &Rti<Ieee<F32Native>>,
    rays: &RaysSoa<f32>,
    tris: &TrisSoa<f32>,
    out: &mut HitsSoa<f32>,
) -> Kernel {
    let which = kernel_f32(rti);
    rti_dispatch(
        rti,
        rays,
        tris,
        out,
        which,
        #[cfg(target_arch = "x86_64")]
        (kernels::v8::rti_f32, kernels::v16::rti_f32, None),
    )
}

/// [`Rti::batch`] for binary16 on the fastest kernel available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn rti_batch_f16(
    rti: &Rti<Ieee<F16Half>>,
    rays: &RaysSoa<f16>,
    tris: &TrisSoa<f16>,
    out: &mut HitsSoa<f16>,
) -> Kernel {
    let which = kernel_f16(rti);
    rti_dispatch(
        rti,
        rays,
        tris,
        out,
        which,
        #[cfg(target_arch = "x86_64")]
        (kernels::v8::rti_f16, kernels::v16::rti_f16, Some(kernels::v32h::rti_f16)),
    )
}

/// The widest kernel of bf16 and the narrow `eEmM` formats (AVX-512F: 16 binary32 / 8 binary64 lanes).
pub const WIDEST_NARROW: Kernel = Kernel::Avx512;

/// The kernel `rti_batch_bf16` / `rti_batch_soft` use for this unit on this machine: bf16 on
/// binary32 lanes, `eEmM` with M ≤ 24, E ≤ 10 on binary64 lanes; the canonical NaN rule.
pub fn kernel_narrow<B: IeeeBackend>(rti: &Rti<Ieee<B>>) -> Kernel {
    best_kernel(narrow_of(&rti.fmt).is_some() && rti.fmt.to_f64(rti.det_thr) >= 0.0, WIDEST_NARROW)
}

/// [`Rti::batch`] for bf16 on the fastest kernel available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn rti_batch_bf16(
    rti: &Rti<Ieee<Bf16>>,
    rays: &RaysSoa<u16>,
    tris: &TrisSoa<u16>,
    out: &mut HitsSoa<u16>,
) -> Kernel {
    let which = kernel_narrow(rti);
    rti_dispatch(
        rti,
        rays,
        tris,
        out,
        which,
        #[cfg(target_arch = "x86_64")]
        (kernels::b8::rti_bf16, kernels::b16::rti_bf16, None),
    )
}

/// The kernel `rti_batch_soft` uses for this unit on this machine: [`kernel_narrow`], whose
/// 8-lane kernel also needs AVX-512DQ (the range filter's `vrangepd`).
pub fn kernel_soft(rti: &Rti<Ieee<Soft>>) -> Kernel {
    let k = kernel_narrow(rti);
    #[cfg(target_arch = "x86_64")]
    if k == Kernel::Avx512 && !std::arch::is_x86_feature_detected!("avx512dq") {
        return Kernel::Avx2;
    }
    k
}

/// [`Rti::batch`] for a custom `eEmM` layout on the fastest kernel available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn rti_batch_soft(
    rti: &Rti<Ieee<Soft>>,
    rays: &RaysSoa<u64>,
    tris: &TrisSoa<u64>,
    out: &mut HitsSoa<u64>,
) -> Kernel {
    let which = kernel_soft(rti);
    rti_dispatch(
        rti,
        rays,
        tris,
        out,
        which,
        #[cfg(target_arch = "x86_64")]
        (kernels::v4d::rti_soft, kernels::v8d::rti_soft, None),
    )
}

/// The kernel `op_batch_soft` uses for this format (the narrow path's eligibility).
pub fn op_kernel_soft(f: &Ieee<Soft>) -> Kernel {
    best_kernel(narrow_of(f).is_some(), WIDEST_NARROW)
}

/// One operation (`Add`, `Sub`, `Mul` or `Div` in the format's division mode) of an `eEmM`
/// format on whole columns, `out[i] = a[i] op b[i]`, on the fastest kernel available: the
/// format's own `add` … `div` bits (FTZ and NaN rules included).
///
/// # Panics
/// If the slice lengths differ or `op` is `Logic`.
pub fn op_batch_soft(f: &Ieee<Soft>, op: crate::stage::Op, a: &[u64], b: &[u64], out: &mut [u64]) -> Kernel {
    use crate::stage::Op;
    assert!(a.len() == b.len() && b.len() == out.len(), "batch lengths differ");
    assert!(op != Op::Logic, "op_batch_soft computes arithmetic only");
    let which = op_kernel_soft(f);
    // binary64 lanes per vector: 4 on AVX2, 8 on AVX-512F; none on the scalar model
    let full = match which {
        Kernel::Scalar => 0,
        Kernel::Avx2 => a.len() / 4 * 4,
        _ => a.len() / 8 * 8,
    };
    let scalar = |i: usize| match op {
        Op::Add => f.add(a[i], b[i]),
        Op::Sub => f.sub(a[i], b[i]),
        Op::Mul => f.mul(a[i], b[i]),
        _ => f.div(a[i], b[i]),
    };
    #[cfg(target_arch = "x86_64")]
    match which {
        // SAFETY: `which` names a kernel only after run-time feature detection; every slice
        // holds the same n >= full slots (checked above).
        Kernel::Avx2 => unsafe { kernels::v4d::op_soft(f, op, a, b, out, full) },
        Kernel::Scalar => {}
        _ => unsafe { kernels::v8d::op_soft(f, op, a, b, out, full) },
    }
    for (i, o) in out.iter_mut().enumerate().skip(full) {
        *o = scalar(i);
    }
    which
}

/// The kernel `slab_batch_f32` / `slab_ray_f32` use for this unit on this machine (the
/// round-to-nearest variants; the directed one runs the scalar model).
pub fn slab_kernel_f32(s: &Slab<Ieee<F32Native>>) -> Kernel {
    best_kernel(eligible(&s.fmt) && !s.cfg.directed, WIDEST_F32)
}

/// The kernel `slab_batch_f16` / `slab_ray_f16` use for this unit on this machine.
pub fn slab_kernel_f16(s: &Slab<Ieee<F16Half>>) -> Kernel {
    best_kernel(eligible(&s.fmt) && !s.cfg.directed, WIDEST_F16)
}

/// The directed variant's kernel applies to one-ray batches (its interval ends are the ray's,
/// so every lane shares the choices the scalar model branches on) without widening or guard.
pub(super) fn directed_one_ok(c: &crate::slab::SlabConfig) -> bool {
    c.directed && c.widen_ulps == 0 && !c.guard
}

/// The kernel `slab_ray_f32` (one ray, many boxes) uses: every variant, the directed one included.
pub fn slab_ray_kernel_f32(s: &Slab<Ieee<F32Native>>) -> Kernel {
    best_kernel(eligible(&s.fmt) && (!s.cfg.directed || directed_one_ok(&s.cfg)), WIDEST_F32)
}

/// The kernel `slab_ray_f16` uses: every variant, the directed one included.
pub fn slab_ray_kernel_f16(s: &Slab<Ieee<F16Half>>) -> Kernel {
    best_kernel(eligible(&s.fmt) && (!s.cfg.directed || directed_one_ok(&s.cfg)), WIDEST_F16)
}

/// A typed slab entry point: the unit's kernel choice, then [`slab_dispatch`].
macro_rules! slab_entry {
    ($(#[$doc:meta])* $name:ident, $fmt:ty, $v:ty, $rays:ty, $shape:ident, $which:ident, $m8:ident, $m16:ident, $kernel:ident, $fp16:expr) => {
        $(#[$doc])*
        ///
        /// # Panics
        /// If the column lengths differ.
        pub fn $name(s: &Slab<$fmt>, rays: &$rays, boxes: &BoxesSoa<$v>, out: &mut SlabOutSoa<$v>) -> Kernel {
            let which = $which(s);
            slab_dispatch(
                s,
                SlabRays::$shape(rays),
                boxes,
                out,
                which,
                #[cfg(target_arch = "x86_64")]
                (kernels::$m8::$kernel, kernels::$m16::$kernel, $fp16),
            )
        }
    };
}

slab_entry!(
    /// [`Slab::batch`] for binary32 on the fastest kernel available; the same bits.
    slab_batch_f32, Ieee<F32Native>, f32, SlabRaysSoa<f32>, Pairs, slab_kernel_f32, v8, v16, slab_f32, None
);
slab_entry!(
    /// [`Slab::batch_ray`] (one ray, many boxes) for binary32 on the fastest kernel available; the same bits.
    slab_ray_f32, Ieee<F32Native>, f32, SlabRay<f32>, One, slab_ray_kernel_f32, v8, v16, slab_f32, None
);
slab_entry!(
    /// [`Slab::batch`] for binary16 on the fastest kernel available; the same bits.
    slab_batch_f16, Ieee<F16Half>, f16, SlabRaysSoa<f16>, Pairs, slab_kernel_f16, v8, v16, slab_f16, Some(kernels::v32h::slab_f16)
);
slab_entry!(
    /// [`Slab::batch_ray`] (one ray, many boxes) for binary16 on the fastest kernel available; the same bits.
    slab_ray_f16, Ieee<F16Half>, f16, SlabRay<f16>, One, slab_ray_kernel_f16, v8, v16, slab_f16, Some(kernels::v32h::slab_f16)
);

/// The kernel `slab_batch_bf16` uses for this unit on this machine (the canonical NaN rule;
/// every variant but the directed one).
pub fn slab_kernel_bf16(s: &Slab<Ieee<Bf16>>) -> Kernel {
    best_kernel(eligible(&s.fmt) && !s.cfg.directed, WIDEST_NARROW)
}

/// The kernel `slab_ray_bf16` (one ray, many boxes) uses: every variant, the directed one included.
pub fn slab_ray_kernel_bf16(s: &Slab<Ieee<Bf16>>) -> Kernel {
    best_kernel(eligible(&s.fmt) && (!s.cfg.directed || directed_one_ok(&s.cfg)), WIDEST_NARROW)
}

/// Whether the `eEmM` slab kernels take this unit (pairs, or one ray when `one`): M ≤ 24,
/// E ≤ 10, the canonical NaN rule, either subnormal mode, every variant but the directed one
/// on pairs.
pub(super) fn soft_slab_ok(s: &Slab<Ieee<Soft>>, one: bool) -> bool {
    let c = &s.cfg;
    match narrow_of(&s.fmt) {
        Some(_) => !c.directed || (one && directed_one_ok(c)),
        None => false,
    }
}

/// The kernel `slab_batch_soft` uses for this unit on this machine (see `soft_slab_ok`).
pub fn slab_kernel_soft(s: &Slab<Ieee<Soft>>) -> Kernel {
    best_kernel(soft_slab_ok(s, false), WIDEST_NARROW)
}

/// The kernel `slab_ray_soft` (one ray, many boxes) uses for this unit on this machine.
pub fn slab_ray_kernel_soft(s: &Slab<Ieee<Soft>>) -> Kernel {
    best_kernel(soft_slab_ok(s, true), WIDEST_NARROW)
}

slab_entry!(
    /// [`Slab::batch`] for an `eEmM` format on the fastest kernel available; the same bits.
    slab_batch_soft, Ieee<Soft>, u64, SlabRaysSoa<u64>, Pairs, slab_kernel_soft, v4d, v8d, slab_soft, None
);
slab_entry!(
    /// [`Slab::batch_ray`] (one ray, many boxes) for an `eEmM` format on the fastest kernel available; the same bits.
    slab_ray_soft, Ieee<Soft>, u64, SlabRay<u64>, One, slab_ray_kernel_soft, v4d, v8d, slab_soft, None
);

/// A typed shared slab entry point ([`super::slab_ray_shared`]): [`shared_dispatch`] with the
/// format's one-ray kernel choice and eligibility (IEEE subnormals: the shared loops do not
/// flush).
macro_rules! shared_entry {
    ($(#[$doc:meta])* $name:ident, $fmt:ty, $v:ty, $which:ident, $eligible:expr, $m8:ident, $m16:ident, $kernel:ident, $fp16:expr) => {
        $(#[$doc])*
        pub fn $name(
            group: &[&Slab<$fmt>],
            rays: &[&SlabRay<$v>],
            boxes: &BoxesSoa<$v>,
            outs: &mut [SlabOutSoa<$v>],
        ) -> Option<Kernel> {
            let eligible: fn(&Slab<$fmt>) -> bool = $eligible;
            shared_dispatch(
                group,
                rays,
                boxes,
                outs,
                |s| s.fmt.opts.subnormals != Subnormals::Ftz && eligible(s),
                $which,
                #[cfg(target_arch = "x86_64")]
                (kernels::$m8::$kernel, kernels::$m16::$kernel, $fp16),
            )
        }
    };
}

shared_entry!(
    /// [`slab_ray_f32`] of each `(group[j], rays[j])` into `outs[j]`, their planes computed once
    /// ([`super::slab_ray_shared`]); `None`, nothing written, when the group does not qualify.
    slab_ray_shared_f32, Ieee<F32Native>, f32, slab_ray_kernel_f32, |_| true, v8, v16, slab_f32_shared, None
);
shared_entry!(
    /// [`slab_ray_f16`] of each `(group[j], rays[j])` into `outs[j]`, their planes computed once
    /// ([`super::slab_ray_shared`]); `None`, nothing written, when the group does not qualify.
    slab_ray_shared_f16, Ieee<F16Half>, f16, slab_ray_kernel_f16, |_| true, v8, v16, slab_f16_shared,
    Some(kernels::v32h::slab_f16_shared)
);
shared_entry!(
    /// [`slab_ray_bf16`] of each `(group[j], rays[j])` into `outs[j]`, their planes computed once
    /// ([`super::slab_ray_shared`]); `None`, nothing written, when the group does not qualify.
    slab_ray_shared_bf16, Ieee<Bf16>, u16, slab_ray_kernel_bf16, |_| true, b8, b16, slab_bf16_shared, None
);
shared_entry!(
    /// [`slab_ray_soft`] of each `(group[j], rays[j])` into `outs[j]`, their planes computed once
    /// ([`super::slab_ray_shared`]); `None`, nothing written, when the group does not qualify
    /// (also: a layout the `eEmM` kernels do not take).
    slab_ray_shared_soft, Ieee<Soft>, u64, slab_ray_kernel_soft, |s| soft_slab_ok(s, true), v4d, v8d, slab_soft_shared, None
);

slab_entry!(
    /// [`Slab::batch`] for bf16 on the fastest kernel available; the same bits.
    slab_batch_bf16, Ieee<Bf16>, u16, SlabRaysSoa<u16>, Pairs, slab_kernel_bf16, b8, b16, slab_bf16, None
);
slab_entry!(
    /// [`Slab::batch_ray`] (one ray, many boxes) for bf16 on the fastest kernel available; the same bits.
    slab_ray_bf16, Ieee<Bf16>, u16, SlabRay<u16>, One, slab_ray_kernel_bf16, b8, b16, slab_bf16, None
);

/// [`rti_batch_f16`] on the AVX2 kernel whose binary16 rounding stays in binary32 lanes
/// (`isa::v8r`: no F16C round trip per operation), or the scalar model where that kernel does
/// not apply (no AVX2 + F16C, a cap below AVX2, a unit the binary16 kernels do not take); the
/// same bits. Measured beside the dispatched kernel by `raypipe speed` (docs/speed.md).
///
/// # Panics
/// If the column lengths differ.
pub fn rti_batch_f16_lanes(
    rti: &Rti<Ieee<F16Half>>,
    rays: &RaysSoa<f16>,
    tris: &TrisSoa<f16>,
    out: &mut HitsSoa<f16>,
) -> Kernel {
    let which = kernel_f16(rti).min(Kernel::Avx2);
    rti_dispatch(
        rti,
        rays,
        tris,
        out,
        which,
        #[cfg(target_arch = "x86_64")]
        (kernels::v8r::rti_f16, kernels::v8r::rti_f16, None),
    )
}

/// [`slab_batch_f16`] on the AVX2 kernel whose binary16 rounding stays in binary32 lanes, as
/// [`rti_batch_f16_lanes`]; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn slab_batch_f16_lanes(
    s: &Slab<Ieee<F16Half>>,
    rays: &SlabRaysSoa<f16>,
    boxes: &BoxesSoa<f16>,
    out: &mut SlabOutSoa<f16>,
) -> Kernel {
    let which = slab_kernel_f16(s).min(Kernel::Avx2);
    slab_dispatch(
        s,
        SlabRays::Pairs(rays),
        boxes,
        out,
        which,
        #[cfg(target_arch = "x86_64")]
        (kernels::v8r::slab_f16, kernels::v8r::slab_f16, None),
    )
}
