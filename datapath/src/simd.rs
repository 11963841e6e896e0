//! SIMD batch kernels of the RTI and slab models, bit-identical to the scalar models, with
//! runtime dispatch.
//!
//! One kernel body per unit (the `rti_kernel!` and `slab_kernel!` macros), written in the
//! operations of an `isa` module, is instantiated for binary32 and binary16 on AVX2 (+ F16C
//! for binary16; 8 tests per vector) and on AVX-512F (16 tests per vector), and for binary16
//! on AVX512-FP16 (32 tests per vector), in the stage table's exact operation order with
//! separate multiplies and adds (no FMA). On AVX2 and AVX-512F, binary16 computes every
//! operation in binary32 and rounds it to binary16 at once (`vcvtps2ph` nearest-even, then
//! back): binary32's 24 bits are at least 2·11 + 2, so this double rounding is innocuous for
//! the four operations (+ − × ÷) and the result is the correctly rounded binary16 operation,
//! subnormals and overflow included; compares and min/max of binary16 values held in binary32
//! are exact. On AVX512-FP16 the operations are binary16's own (`vaddph` … `vdivph`, correctly
//! rounded, subnormals always kept).
//! NaN payloads never influence a non-NaN result or a compare, so the RTI kernels canonicalise
//! NaN only where a value leaves them (every RTI output is arithmetic), and only when a mask
//! shows a NaN lane. A slab output NaN may be arithmetic (canonical in the model) or a NaN t
//! interval passed through the comparators with its payload, so the scalar model redoes a
//! slab batch's NaN lanes after the loop; a one-ray batch with the plain comparator and a
//! number interval cannot make one and skips the check.
//!
//! The slab kernels take either pairs (ray i against box i) or one ray against every box (a
//! node's children, a level): the second reads only the six box columns and picks each axis's
//! near plane once per batch. The plain comparator `t = (x > t) ? x : t` is exactly `vmaxps(x,
//! t)` (the second operand on NaN or equality, ±0 included), so it costs one instruction.
//!
//! RTI also has kernels for bf16 (the scalar model's binary32 arithmetic on binary32 lanes,
//! each result rounded to bf16 in the integer lanes, FTZ flushes in the lanes) and for custom
//! `eEmM` layouts with M ≤ 24 and E ≤ 10 (binary64 lanes behind a filter that sends a lane
//! with a subnormal, overflowing or infinite intermediate to the scalar model; the argument is
//! in [`crate::format::narrow`]), IEEE or FTZ, canonical NaN, either division mode.
//!
//! Eligible formats (binary32 / binary16): the canonical NaN rule, IEEE subnormals or FTZ
//! (flushed in the lanes), either division mode, either culling; every slab variant (the
//! directed one on one-ray batches); others, and machines
//! without AVX2, run the scalar model, as does a det threshold that is negative or NaN (the RTI kernels' sign-flip
//! side tests need det_ok to exclude det = ±0). Columns are processed a vector at a time
//! straight from the SoA inputs; a batch's last `n mod lanes` slots run the scalar model.
//!
//! The dispatch takes the widest kernel the machine has ([`kernels_here`]), within this
//! thread's cap ([`with_kernel_cap`]), so every kernel can be tested and timed on one machine.
//! The AVX-512F and AVX512-FP16 kernels are tested by the same property tests as the AVX2
//! ones, on an emulated machine with both (`emu/avx512`, Bochs 3.0) when the host has neither.

pub use crate::fixed_lanes::{rti_batch_fixed, slab_batch_fixed, slab_ray_fixed};
use crate::format::narrow::Narrow;
use crate::format::{Bf16, DivMode, F16Half, F32Native, Ieee, IeeeBackend, NanMode, Soft, Subnormals};
use crate::rti::{Cull, HitsSoa, RaysSoa, Rti, TrisSoa};
use crate::slab::{BoxesSoa, Slab, SlabNan, SlabOutSoa, SlabRay, SlabRaysSoa};
use crate::Format as _;
use half::f16;

/// Which implementation ran (ordered: a cap of `Avx2` allows `Scalar` and `Avx2`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kernel {
    /// The scalar model.
    Scalar,
    /// AVX2 (binary32) or AVX2 + F16C (binary16), 8 lanes; detected with FMA (the `eEmM`
    /// kernels' exact product split uses it).
    Avx2,
    /// AVX-512F (binary32 and binary16, the latter through its conversions), 16 lanes.
    Avx512,
    /// AVX512-FP16: binary16 arithmetic natively, 32 lanes (binary32 runs its AVX-512F kernel).
    Avx512Fp16,
}

thread_local! {
    /// The widest kernel this thread's dispatch may choose.
    static CAP: std::cell::Cell<Kernel> = const { std::cell::Cell::new(Kernel::Avx512Fp16) };
}

/// Runs `f` with this thread's dispatch limited to kernels no wider than `cap` (to test or
/// time a narrower kernel on a wider machine); the previous cap is restored afterwards.
pub fn with_kernel_cap<R>(cap: Kernel, f: impl FnOnce() -> R) -> R {
    crate::scoped(&CAP, cap, f)
}

/// The process-wide cap ([`cap_process`]), as `Kernel as u8`.
static PROCESS_CAP: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(Kernel::Avx512Fp16 as u8);

/// Limits the dispatch of every thread, from now on, to kernels no wider than `cap`, as if the
/// machine had none wider ([`kernels_here`] included): `raypipe speed --cap avx2` measures an
/// AVX2 machine's kernels on an AVX-512 one.
pub fn cap_process(cap: Kernel) {
    PROCESS_CAP.store(cap as u8, std::sync::atomic::Ordering::Relaxed);
}

/// The kernels this machine can run, narrowest first (`Scalar` always).
pub fn kernels_here() -> Vec<Kernel> {
    [Kernel::Scalar, Kernel::Avx2, Kernel::Avx512, Kernel::Avx512Fp16]
        .into_iter()
        .filter(|&k| k <= widest_here())
        .collect()
}

/// The widest kernel this machine can run (detected once) within the process cap.
fn widest_here() -> Kernel {
    let all = [Kernel::Scalar, Kernel::Avx2, Kernel::Avx512, Kernel::Avx512Fp16];
    let cap = all[PROCESS_CAP.load(std::sync::atomic::Ordering::Relaxed) as usize];
    detected().min(cap)
}

/// The widest kernel this machine's features allow, detected once.
fn detected() -> Kernel {
    static WIDEST: std::sync::OnceLock<Kernel> = std::sync::OnceLock::new();
    *WIDEST.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx2") && has!("f16c") && has!("fma") {
                // the AVX-512 kernels use AVX2 for the binary16 step
                return match (has!("avx512f"), has!("avx512bw") && has!("avx512fp16")) {
                    (true, true) => Kernel::Avx512Fp16,
                    (true, false) => Kernel::Avx512,
                    _ => Kernel::Avx2,
                };
            }
        }
        Kernel::Scalar
    })
}

/// The kernels model this binary32 / binary16 / bf16 format: the canonical NaN rule, IEEE
/// subnormals or FTZ (flushed in the lanes).
fn eligible<B: crate::format::IeeeBackend>(f: &Ieee<B>) -> bool {
    f.opts.nan == NanMode::Canonical
}

/// The widest kernel this machine has within this thread's cap and `useful` (the widest
/// kernel the format has), if `eligible`.
pub(crate) fn best_kernel(eligible: bool, useful: Kernel) -> Kernel {
    match eligible {
        true => widest_here().min(CAP.with(|c| c.get())).min(useful),
        false => Kernel::Scalar,
    }
}

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

/// The signature of an RTI kernel: lanes `0..full` of every column.
#[cfg(target_arch = "x86_64")]
pub(crate) type RtiKernelFn<F> = unsafe fn(
    &Rti<F>,
    &RaysSoa<<F as crate::Format>::V>,
    &TrisSoa<<F as crate::Format>::V>,
    &mut HitsSoa<<F as crate::Format>::V>,
    usize,
);

/// Every column of an RTI batch holds `n` slots.
pub(crate) fn rti_columns_ok<V>(rays: &RaysSoa<V>, tris: &TrisSoa<V>, out: &HitsSoa<V>, n: usize) -> bool {
    rays.o.iter().chain(&rays.d).all(|c| c.len() == n)
        && rays.tmax.len() == n
        && tris.v.iter().flatten().all(|c| c.len() == n)
        && out.valid.len() == n
        && [&out.t, &out.u, &out.v].iter().all(|c| c.len() == n)
}

/// A format's kernels: AVX2, AVX-512F and, for binary16, AVX512-FP16.
#[cfg(target_arch = "x86_64")]
pub(crate) type Table<K> = (K, K, Option<K>);

/// The kernel of `table` that `which` names, and its lanes per vector.
#[cfg(target_arch = "x86_64")]
fn pick<K>(which: Kernel, table: Table<K>) -> Option<(K, usize)> {
    let (v8, v16, v32h) = table;
    match which {
        Kernel::Scalar => None,
        Kernel::Avx2 => Some((v8, isa::v8::LANES)),
        Kernel::Avx512 => Some((v16, isa::v16::LANES)),
        Kernel::Avx512Fp16 => v32h.map(|k| (k, isa::v32h::LANES)),
    }
}

/// Runs the kernel of `table` that `which` names (when every column has the batch's length)
/// on the full vectors and the scalar model on the rest; otherwise the scalar model throughout.
pub(crate) fn rti_dispatch<F: crate::Format>(
    rti: &Rti<F>,
    rays: &RaysSoa<F::V>,
    tris: &TrisSoa<F::V>,
    out: &mut HitsSoa<F::V>,
    which: Kernel,
    #[cfg(target_arch = "x86_64")] table: Table<RtiKernelFn<F>>,
) -> Kernel {
    let n = rays.len();
    assert!(tris.len() == n && out.len() == n, "batch lengths differ");
    #[cfg(target_arch = "x86_64")]
    if let Some((kernel, lanes)) = pick(which, table).filter(|_| rti_columns_ok(rays, tris, out, n)) {
        let full = n / lanes * lanes;
        // SAFETY: `which` names a kernel only after run-time feature detection; every column
        // holds n >= full slots (checked above).
        unsafe { kernel(rti, rays, tris, out, full) };
        rti.batch_from(rays, tris, out, full);
        return which;
    }
    let _ = which;
    rti.batch(rays, tris, out);
    Kernel::Scalar
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

/// The binary64-lane constants of a float format, when its narrow batch path applies.
fn narrow_of<B: IeeeBackend>(f: &Ieee<B>) -> Option<Narrow> {
    Narrow::of(f.backend.layout(), f.opts)
}

/// The det threshold as the narrow kernels' lanes hold it (read-flushed under FTZ).
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
fn narrow_thr<B: IeeeBackend>(rti: &Rti<Ieee<B>>, n: &Narrow) -> f64 {
    let t = rti.fmt.to_f64(rti.det_thr);
    if n.ftz && t.abs() < n.min_normal {
        0.0
    } else {
        t
    }
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
pub fn op_batch_soft(f: &Ieee<Soft>, op: crate::rti::Op, a: &[u64], b: &[u64], out: &mut [u64]) -> Kernel {
    use crate::rti::Op;
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
fn directed_one_ok(c: &crate::slab::SlabConfig) -> bool {
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

/// Every box and output column holds `n` slots.
fn slab_columns_ok<V>(boxes: &BoxesSoa<V>, out: &SlabOutSoa<V>, n: usize) -> bool {
    boxes.min.iter().chain(&boxes.max).all(|c| c.len() == n)
        && out.hit.len() == n
        && out.t_near.len() == n
        && out.t_far.len() == n
}

/// Every ray column holds `n` slots.
fn slab_rays_ok<V>(rays: &SlabRaysSoa<V>, n: usize) -> bool {
    rays.o.iter().chain(&rays.inv_d).all(|c| c.len() == n) && rays.tmin.len() == n && rays.tmax.len() == n
}

/// What a slab batch tests: ray i against box i, or one ray against every box.
#[derive(Clone, Copy)]
pub(crate) enum SlabRays<'a, V> {
    /// Ray i against box i.
    Pairs(&'a SlabRaysSoa<V>),
    /// One ray against every box.
    One(&'a SlabRay<V>),
}

/// The signature of a slab kernel: lanes `0..full` of every column.
#[cfg(target_arch = "x86_64")]
pub(crate) type SlabKernelFn<F> = unsafe fn(
    &Slab<F>,
    SlabRays<<F as crate::Format>::V>,
    &BoxesSoa<<F as crate::Format>::V>,
    &mut SlabOutSoa<<F as crate::Format>::V>,
    usize,
);

/// Runs the kernel of `table` that `which` names (when every column has the batch's length)
/// on the full vectors and the scalar model on the rest; otherwise the scalar model throughout.
pub(crate) fn slab_dispatch<F: crate::Format>(
    s: &Slab<F>,
    rays: SlabRays<F::V>,
    boxes: &BoxesSoa<F::V>,
    out: &mut SlabOutSoa<F::V>,
    which: Kernel,
    #[cfg(target_arch = "x86_64")] table: Table<SlabKernelFn<F>>,
) -> Kernel {
    let n = out.hit.len();
    let rays_ok = match rays {
        SlabRays::Pairs(r) => {
            assert!(r.tmin.len() == n && boxes.min[0].len() == n, "batch lengths differ");
            slab_rays_ok(r, n)
        }
        SlabRays::One(_) => {
            assert!(boxes.min[0].len() == n, "batch lengths differ");
            true
        }
    };
    #[cfg(target_arch = "x86_64")]
    if let Some((kernel, lanes)) = pick(which, table).filter(|_| rays_ok && slab_columns_ok(boxes, out, n)) {
        let full = n / lanes * lanes;
        // SAFETY: `which` names a kernel only after run-time feature detection; every column
        // holds n >= full slots (checked above).
        unsafe { kernel(s, rays, boxes, out, full) };
        match rays {
            SlabRays::Pairs(r) => s.batch_from(r, boxes, out, full),
            SlabRays::One(r) => s.batch_ray_from(r, boxes, out, full),
        }
        return which;
    }
    let _ = (which, rays_ok);
    match rays {
        SlabRays::Pairs(r) => s.batch(r, boxes, out),
        SlabRays::One(r) => s.batch_ray(r, boxes, out),
    }
    Kernel::Scalar
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
fn soft_slab_ok(s: &Slab<Ieee<Soft>>, one: bool) -> bool {
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

slab_entry!(
    /// [`Slab::batch`] for bf16 on the fastest kernel available; the same bits.
    slab_batch_bf16, Ieee<Bf16>, u16, SlabRaysSoa<u16>, Pairs, slab_kernel_bf16, b8, b16, slab_bf16, None
);
slab_entry!(
    /// [`Slab::batch_ray`] (one ray, many boxes) for bf16 on the fastest kernel available; the same bits.
    slab_ray_bf16, Ieee<Bf16>, u16, SlabRay<u16>, One, slab_ray_kernel_bf16, b8, b16, slab_bf16, None
);

/// The body of a format-generic dispatch: calls the first of the `typed` entry points whose
/// unit and column types are the arguments', the scalar model `$scalar` when none is.
macro_rules! by_format {
    ($unit:expr, $a:expr, $b:expr, $out:expr, [$($typed:ident),+], $scalar:expr) => {{
        use std::any::Any;
        let (unit, a, b) = ($unit as &dyn Any, $a as &dyn Any, $b as &dyn Any);
        $(
            if let (Some(unit), Some(a), Some(b)) = (unit.downcast_ref(), a.downcast_ref(), b.downcast_ref()) {
                return $typed(
                    unit,
                    a,
                    b,
                    ($out as &mut dyn Any).downcast_mut().expect("the output type follows the format"),
                );
            }
        )+
        $scalar;
        Kernel::Scalar
    }};
}

/// [`Rti::batch`] for any format on the fastest bit-identical implementation: the SIMD kernels
/// for binary32 and binary16 where they apply, the scalar model otherwise.
///
/// # Panics
/// If the column lengths differ.
pub fn rti_batch<F: crate::Format + 'static>(
    rti: &Rti<F>,
    rays: &RaysSoa<F::V>,
    tris: &TrisSoa<F::V>,
    out: &mut HitsSoa<F::V>,
) -> Kernel
where
    F::V: 'static,
{
    by_format!(
        rti,
        rays,
        tris,
        out,
        [rti_batch_f32, rti_batch_f16, rti_batch_bf16, rti_batch_soft, rti_batch_fixed],
        rti.batch(rays, tris, out)
    )
}

/// [`Slab::batch`] for any format on the fastest bit-identical implementation.
///
/// # Panics
/// If the column lengths differ.
pub fn slab_batch<F: crate::Format + 'static>(
    s: &Slab<F>,
    rays: &SlabRaysSoa<F::V>,
    boxes: &BoxesSoa<F::V>,
    out: &mut SlabOutSoa<F::V>,
) -> Kernel
where
    F::V: 'static,
{
    by_format!(
        s,
        rays,
        boxes,
        out,
        [slab_batch_f32, slab_batch_f16, slab_batch_bf16, slab_batch_soft, slab_batch_fixed],
        s.batch(rays, boxes, out)
    )
}

/// [`Slab::batch_ray`] (one ray, many boxes) for any format on the fastest bit-identical
/// implementation.
///
/// # Panics
/// If the column lengths differ.
pub fn slab_ray<F: crate::Format + 'static>(
    s: &Slab<F>,
    ray: &SlabRay<F::V>,
    boxes: &BoxesSoa<F::V>,
    out: &mut SlabOutSoa<F::V>,
) -> Kernel
where
    F::V: 'static,
{
    by_format!(
        s,
        ray,
        boxes,
        out,
        [slab_ray_f32, slab_ray_f16, slab_ray_bf16, slab_ray_soft, slab_ray_fixed],
        s.batch_ray(ray, boxes, out)
    )
}

/// Pairs per chunk of [`rti_stream`]: 256 pairs × (15 input + 3 output columns) × 4 bytes plus
/// two flag columns is 19 KiB, inside a 32 KiB L1 data cache.
pub const CHUNK: usize = 256;

/// Streams `n` RTI tests through L1-sized chunks on the fastest kernel (see [`rti_batch`]):
/// for each chunk `start..end` of at most [`CHUNK`] pairs, the columns are sized to
/// `end - start` slots, `fill(start..end, rays, tris)` writes every slot (slot k holds pair
/// `start + k`, e.g. with [`RaysSoa::set`]), the kernel runs, and `consume(start..end, rays,
/// tris, out)` reads the results. The columns are allocated once, side by side, so a pass over
/// millions of pairs keeps its working set in L1 (one pass over columns of 1 M pairs is
/// DRAM-bound, and equal-offset page-aligned columns contend for the same L1 sets).
pub fn rti_stream<F: crate::Format + 'static>(
    rti: &Rti<F>,
    n: usize,
    mut fill: impl FnMut(std::ops::Range<usize>, &mut RaysSoa<F::V>, &mut TrisSoa<F::V>),
    mut consume: impl FnMut(std::ops::Range<usize>, &RaysSoa<F::V>, &TrisSoa<F::V>, &HitsSoa<F::V>),
) -> Kernel
where
    F::V: 'static + Default,
{
    let (mut rays, mut tris) = (RaysSoa::default(), TrisSoa::default());
    let mut out = HitsSoa::default();
    let mut kernel = Kernel::Scalar;
    for start in (0..n).step_by(CHUNK) {
        let end = (start + CHUNK).min(n);
        rays.resize(end - start, F::V::default());
        tris.resize(end - start, F::V::default());
        out.resize(end - start);
        fill(start..end, &mut rays, &mut tris);
        kernel = rti_batch(rti, &rays, &tris, &mut out);
        consume(start..end, &rays, &tris, &out);
    }
    kernel
}

/// The vector operations the kernel bodies use, one module per instruction set with the same
/// names: `v8` (AVX2, 8 binary32 lanes, masks as vectors) and `v16` (AVX-512F, 16 lanes, masks
/// as `__mmask16`). Each function is one or two instructions; binary16 columns are widened to
/// binary32 on load (`vcvtph2ps`, exact) and narrowed on store (`vcvtps2ph`, nearest-even).
#[cfg(target_arch = "x86_64")]
mod isa {
    /// An 8-bit lane mask spread to 8 bytes of 0 / 1 (lane k in byte k).
    pub(super) const SPREAD: [u64; 256] = {
        let mut t = [0u64; 256];
        let mut m = 0;
        while m < 256 {
            let mut k = 0;
            while k < 8 {
                if m >> k & 1 == 1 {
                    t[m] |= 1 << (8 * k);
                }
                k += 1;
            }
            m += 1;
        }
        t
    };

    /// The binary16 next-up step on 16 binary16 encodings (NaN and +inf unchanged, ±0 to the
    /// smallest subnormal), as the scalar model's `next_up` with IEEE subnormals.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn step_up16(b: std::arch::x86_64::__m256i) -> std::arch::x86_64::__m256i {
        use std::arch::x86_64::*;
        let mag = _mm256_and_si256(b, _mm256_set1_epi16(0x7fff));
        let keep = _mm256_or_si256(
            _mm256_cmpgt_epi16(mag, _mm256_set1_epi16(0x7c00)), // NaN
            _mm256_cmpeq_epi16(b, _mm256_set1_epi16(0x7c00)),   // +inf
        );
        let zero = _mm256_cmpeq_epi16(mag, _mm256_setzero_si256());
        // negative: bits - 1, positive: bits + 1
        let step = _mm256_or_si256(_mm256_srai_epi16::<15>(b), _mm256_set1_epi16(1));
        let r = _mm256_add_epi16(b, step);
        let r = _mm256_blendv_epi8(r, _mm256_set1_epi16(1), zero);
        _mm256_blendv_epi8(r, b, keep)
    }

    /// The binary operations and compares of an ISA table, each a one-instruction function:
    /// `$prec` names the arithmetic's rounding, `cmp` is the compare taking a predicate.
    macro_rules! table_ops {
        ($feat:literal, $v:ty, $m:ty, $prec:literal;
         add = $add:ident, sub = $sub:ident, mul = $mul:ident, div = $div:ident,
         max = $max:ident, min = $min:ident, cmp = $cmp:ident) => {
            table_ops!(@op $feat, $v, add, $add, concat!("a + b, rounded to ", $prec, "."));
            table_ops!(@op $feat, $v, sub, $sub, concat!("a − b, rounded to ", $prec, "."));
            table_ops!(@op $feat, $v, mul, $mul, concat!("a × b, rounded to ", $prec, "."));
            table_ops!(@op $feat, $v, div, $div, concat!("a ÷ b, rounded to ", $prec, "."));
            table_ops!(@op $feat, $v, max, $max, "`a > b ? a : b` (the second operand on NaN or equality, ±0 included).");
            table_ops!(@op $feat, $v, min, $min, "`a < b ? a : b` (the second operand on NaN or equality, ±0 included).");
            table_ops!(@cmp $feat, $v, $m, le, $cmp, _CMP_LE_OQ, "Lanes where a ≤ b (false on NaN).");
            table_ops!(@cmp $feat, $v, $m, lt, $cmp, _CMP_LT_OQ, "Lanes where a < b (false on NaN).");
            table_ops!(@cmp $feat, $v, $m, unord, $cmp, _CMP_UNORD_Q, "Lanes where a or b is NaN.");
        };
        (@op $feat:literal, $v:ty, $name:ident, $intr:ident, $doc:expr) => {
            #[doc = $doc]
            #[inline]
            #[target_feature(enable = $feat)]
            pub fn $name(a: $v, b: $v) -> $v {
                $intr(a, b)
            }
        };
        (@cmp $feat:literal, $v:ty, $m:ty, $name:ident, $cmp:ident, $pred:ident, $doc:expr) => {
            #[doc = $doc]
            #[inline]
            #[target_feature(enable = $feat)]
            pub fn $name(a: $v, b: $v) -> $m {
                $cmp::<$pred>(a, b)
            }
        };
    }

    /// AVX2 (+ F16C for binary16): 8 lanes, a mask is a vector of all-ones / all-zeros lanes.
    pub(super) mod v8 {
        use half::f16;
        use std::arch::x86_64::*;
        /// Lanes per vector.
        pub const LANES: usize = 8;
        /// A mask.
        pub type M = __m256;
        table_ops!("avx2", __m256, M, "binary32";
            add = _mm256_add_ps, sub = _mm256_sub_ps, mul = _mm256_mul_ps, div = _mm256_div_ps,
            max = _mm256_max_ps, min = _mm256_min_ps, cmp = _mm256_cmp_ps);
        /// Every lane x.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn splat(x: f32) -> __m256 {
            _mm256_set1_ps(x)
        }
        /// Every lane binary32's canonical NaN (`vcvtps2ph` makes it binary16's 0x7e00).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn canonical_nan() -> __m256 {
            splat_bits(0x7fc0_0000)
        }
        /// Every lane the binary16 value x, held in binary32 (exact).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn splat16(x: f16) -> __m256 {
            splat(x.to_f32())
        }
        /// Every lane the binary32 with these bits.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn splat_bits(x: u32) -> __m256 {
            _mm256_castsi256_ps(_mm256_set1_epi32(x as i32))
        }
        /// Both masks.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn and_m(a: M, b: M) -> M {
            _mm256_and_ps(a, b)
        }
        /// The mask as lane bits (lane k in bit k).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn bits(m: M) -> u32 {
            _mm256_movemask_ps(m) as u32
        }
        /// `m ? b : a` per lane.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn blend(a: __m256, b: __m256, m: M) -> __m256 {
            _mm256_blendv_ps(a, b, m)
        }
        /// `sign(x) ? b : a` per lane (the sign bit of x, as vblendvps reads it).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn blend_sign(a: __m256, b: __m256, x: __m256) -> __m256 {
            _mm256_blendv_ps(a, b, x)
        }
        /// The sign bits of x (everything else cleared).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn sign(x: __m256) -> __m256 {
            _mm256_and_ps(x, _mm256_set1_ps(-0.0))
        }
        /// |x| by clearing the sign bit.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn abs(x: __m256) -> __m256 {
            _mm256_andnot_ps(_mm256_set1_ps(-0.0), x)
        }
        /// a ⊕ b, bitwise.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn xor(a: __m256, b: __m256) -> __m256 {
            _mm256_xor_ps(a, b)
        }
        /// Either mask.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn or_m(a: M, b: M) -> M {
            _mm256_or_ps(a, b)
        }
        /// The mask's complement.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn not_m(a: M) -> M {
            _mm256_xor_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(-1)))
        }
        /// `sel ? b : a` per lane, on masks.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn blend_m(a: M, b: M, sel: M) -> M {
            _mm256_blendv_ps(a, b, sel)
        }
        /// Lanes whose sign bit is set.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn sign_m(x: __m256) -> M {
            _mm256_castsi256_ps(_mm256_srai_epi32::<31>(_mm256_castps_si256(x)))
        }
        /// Writes the mask's lanes as bools 0 / 1 to `p[i..i + 8]`.
        ///
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub unsafe fn flags(p: *mut bool, i: usize, m: M) {
            // SAFETY: in bounds (the caller); every byte written is 0 or 1, a valid bool.
            unsafe { (p.add(i) as *mut u64).write_unaligned(super::SPREAD[bits(m) as usize]) }
        }
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub unsafe fn load32(p: *const f32, i: usize) -> __m256 {
            unsafe { _mm256_loadu_ps(p.add(i)) }
        }
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub unsafe fn store32(p: *mut f32, i: usize, x: __m256) {
            unsafe { _mm256_storeu_ps(p.add(i), x) }
        }
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2,f16c")]
        pub unsafe fn load16(p: *const f16, i: usize) -> __m256 {
            unsafe { _mm256_cvtph_ps(_mm_loadu_si128(p.add(i) as *const __m128i)) }
        }
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2,f16c")]
        pub unsafe fn store16(p: *mut f16, i: usize, x: __m256) {
            unsafe { _mm_storeu_si128(p.add(i) as *mut __m128i, _mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(x)) }
        }
        /// Loads 8 bf16 encodings as binary32 (exact: bf16 is binary32's top half).
        ///
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub unsafe fn load_bf16(p: *const u16, i: usize) -> __m256 {
            let h = unsafe { _mm_loadu_si128(p.add(i) as *const __m128i) };
            _mm256_castsi256_ps(_mm256_slli_epi32::<16>(_mm256_cvtepu16_epi32(h)))
        }
        /// Stores 8 lanes holding bf16 values as bf16 encodings (their top halves).
        ///
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub unsafe fn store_bf16(p: *mut u16, i: usize, x: __m256) {
            let w = _mm256_srli_epi32::<16>(_mm256_castps_si256(x));
            // packing works per 128-bit half: take quadwords 0 and 2
            let packed = _mm256_permute4x64_epi64::<0b1000>(_mm256_packus_epi32(w, w));
            unsafe { _mm_storeu_si128(p.add(i) as *mut __m128i, _mm256_castsi256_si128(packed)) }
        }
        /// Rounds binary32 lanes to bf16, nearest-even, as the scalar model's `Bf16::round_f32`:
        /// `(b + 0x7fff + ((b >> 16) & 1))` with the low 16 bits cleared (a carry steps the
        /// exponent; past the largest finite value it reaches infinity).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn round_bf16(x: __m256) -> __m256 {
            let b = _mm256_castps_si256(x);
            let lsb = _mm256_and_si256(_mm256_srli_epi32::<16>(b), _mm256_set1_epi32(1));
            let r = _mm256_add_epi32(_mm256_add_epi32(b, _mm256_set1_epi32(0x7fff)), lsb);
            _mm256_castsi256_ps(_mm256_and_si256(r, _mm256_set1_epi32(0xffff_0000_u32 as i32)))
        }
        /// Under FTZ, lanes below binary32's (and bf16's) smallest normal become zeros of the same sign.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn flush_bf16(x: __m256, ftz: bool) -> __m256 {
            match ftz {
                true => blend(x, sign(x), lt(abs(x), splat(f32::MIN_POSITIVE))),
                false => x,
            }
        }
        /// Rounds binary32 lanes to binary16 (nearest-even), held in binary32.
        #[inline]
        #[target_feature(enable = "avx2,f16c")]
        pub fn round16(x: __m256) -> __m256 {
            _mm256_cvtph_ps(_mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(x))
        }
        /// The next binary32 encoding above each lane (NaN and +inf unchanged, ±0 to the
        /// smallest subnormal), as the scalar model's `next_up` with IEEE subnormals.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn next_up(v: __m256) -> __m256 {
            next_up_by(v, 1)
        }
        /// The step up by `unit` encodings of binary32 (1: binary32's grid, 2^16: bf16's): NaN
        /// and +inf unchanged, ±0 to `unit`, negative values `unit` encodings toward zero.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub(in crate::simd) fn next_up_by(v: __m256, unit: i32) -> __m256 {
            let b = _mm256_castps_si256(v);
            let keep = _mm256_or_si256(
                _mm256_castps_si256(_mm256_cmp_ps::<_CMP_UNORD_Q>(v, v)),
                _mm256_cmpeq_epi32(b, _mm256_set1_epi32(0x7f80_0000)),
            );
            let zero = _mm256_cmpeq_epi32(_mm256_and_si256(b, _mm256_set1_epi32(0x7fff_ffff)), _mm256_setzero_si256());
            // negative: bits - unit, positive: bits + unit
            let step = _mm256_add_epi32(
                _mm256_and_si256(_mm256_srai_epi32::<31>(b), _mm256_set1_epi32(-2 * unit)),
                _mm256_set1_epi32(unit),
            );
            let r = _mm256_add_epi32(b, step);
            let r = _mm256_blendv_epi8(r, _mm256_set1_epi32(unit), zero);
            _mm256_castsi256_ps(_mm256_blendv_epi8(r, b, keep))
        }
        /// [`next_up`] on the bf16 grid, for lanes that hold bf16 values (a step of 2^16 in the
        /// binary32 encoding; NaN and +inf unchanged, ±0 to the least bf16 subnormal).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn next_up_bf16(v: __m256) -> __m256 {
            next_up_by(v, 0x1_0000)
        }
        /// [`next_up`] on the binary16 grid, for lanes that hold binary16 values.
        #[inline]
        #[target_feature(enable = "avx2,f16c")]
        pub fn next_up16(v: __m256) -> __m256 {
            // exact: every lane is a binary16 value (a NaN stays a NaN and is kept); the upper
            // 8 halves of the 256-bit step are don't-care
            let b = _mm256_castsi128_si256(_mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(v));
            _mm256_cvtph_ps(_mm256_castsi256_si128(super::step_up16(b)))
        }
    }

    /// AVX-512F: 16 lanes, a mask is a `__mmask16` (binary16 via the AVX-512F conversions,
    /// the binary16 step on 256-bit AVX2 integer lanes).
    pub(super) mod v16 {
        use half::f16;
        use std::arch::x86_64::*;
        /// Lanes per vector.
        pub const LANES: usize = 16;
        /// A mask.
        pub type M = __mmask16;
        table_ops!("avx512f", __m512, M, "binary32";
            add = _mm512_add_ps, sub = _mm512_sub_ps, mul = _mm512_mul_ps, div = _mm512_div_ps,
            max = _mm512_max_ps, min = _mm512_min_ps, cmp = _mm512_cmp_ps_mask);
        /// vcvtps2ph: round to nearest even, exceptions suppressed (flags are not modelled).
        const NEAREST: i32 = _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC;
        /// Loads 16 bf16 encodings as binary32 (exact: bf16 is binary32's top half).
        ///
        /// # Safety
        /// `p[i..i + 16]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn load_bf16(p: *const u16, i: usize) -> __m512 {
            let h = unsafe { _mm256_loadu_si256(p.add(i) as *const __m256i) };
            _mm512_castsi512_ps(_mm512_slli_epi32::<16>(_mm512_cvtepu16_epi32(h)))
        }
        /// Stores 16 lanes holding bf16 values as bf16 encodings (their top halves).
        ///
        /// # Safety
        /// `p[i..i + 16]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn store_bf16(p: *mut u16, i: usize, x: __m512) {
            let w = _mm512_srli_epi32::<16>(_mm512_castps_si512(x));
            unsafe { _mm256_storeu_si256(p.add(i) as *mut __m256i, _mm512_cvtepi32_epi16(w)) }
        }
        /// Rounds binary32 lanes to bf16, nearest-even, as the scalar model's `Bf16::round_f32`.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn round_bf16(x: __m512) -> __m512 {
            let b = _mm512_castps_si512(x);
            let lsb = _mm512_and_si512(_mm512_srli_epi32::<16>(b), _mm512_set1_epi32(1));
            let r = _mm512_add_epi32(_mm512_add_epi32(b, _mm512_set1_epi32(0x7fff)), lsb);
            _mm512_castsi512_ps(_mm512_and_si512(r, _mm512_set1_epi32(0xffff_0000_u32 as i32)))
        }
        /// Under FTZ, lanes below binary32's (and bf16's) smallest normal become zeros of the same sign.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn flush_bf16(x: __m512, ftz: bool) -> __m512 {
            match ftz {
                true => blend(x, sign(x), lt(abs(x), splat(f32::MIN_POSITIVE))),
                false => x,
            }
        }
        /// Every lane x.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn splat(x: f32) -> __m512 {
            _mm512_set1_ps(x)
        }
        /// Every lane binary32's canonical NaN (`vcvtps2ph` makes it binary16's 0x7e00).
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn canonical_nan() -> __m512 {
            splat_bits(0x7fc0_0000)
        }
        /// Every lane the binary16 value x, held in binary32 (exact).
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn splat16(x: f16) -> __m512 {
            splat(x.to_f32())
        }
        /// Every lane the binary32 with these bits.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn splat_bits(x: u32) -> __m512 {
            _mm512_castsi512_ps(_mm512_set1_epi32(x as i32))
        }
        /// Both masks.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn and_m(a: M, b: M) -> M {
            a & b
        }
        /// The mask as lane bits (lane k in bit k).
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn bits(m: M) -> u32 {
            m as u32
        }
        /// `m ? b : a` per lane.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn blend(a: __m512, b: __m512, m: M) -> __m512 {
            _mm512_mask_blend_ps(m, a, b)
        }
        /// `sign(x) ? b : a` per lane.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn blend_sign(a: __m512, b: __m512, x: __m512) -> __m512 {
            let m = _mm512_test_epi32_mask(_mm512_castps_si512(x), _mm512_set1_epi32(i32::MIN));
            _mm512_mask_blend_ps(m, a, b)
        }
        /// The sign bits of x (everything else cleared).
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn sign(x: __m512) -> __m512 {
            _mm512_castsi512_ps(_mm512_and_si512(_mm512_castps_si512(x), _mm512_set1_epi32(i32::MIN)))
        }
        /// |x| by clearing the sign bit.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn abs(x: __m512) -> __m512 {
            _mm512_castsi512_ps(_mm512_and_si512(_mm512_castps_si512(x), _mm512_set1_epi32(i32::MAX)))
        }
        /// a ⊕ b, bitwise.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn xor(a: __m512, b: __m512) -> __m512 {
            _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(a), _mm512_castps_si512(b)))
        }
        /// Either mask.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn or_m(a: M, b: M) -> M {
            a | b
        }
        /// The mask's complement.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn not_m(a: M) -> M {
            !a
        }
        /// `sel ? b : a` per lane, on masks.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn blend_m(a: M, b: M, sel: M) -> M {
            (a & !sel) | (b & sel)
        }
        /// Lanes whose sign bit is set.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn sign_m(x: __m512) -> M {
            _mm512_test_epi32_mask(_mm512_castps_si512(x), _mm512_set1_epi32(i32::MIN))
        }
        /// Writes the mask's lanes as bools 0 / 1 to `p[i..i + 16]`.
        ///
        /// # Safety
        /// `p[i..i + 16]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn flags(p: *mut bool, i: usize, m: M) {
            // SAFETY: in bounds (the caller); every byte written is 0 or 1, a valid bool.
            unsafe {
                (p.add(i) as *mut u64).write_unaligned(super::SPREAD[(m & 0xff) as usize]);
                (p.add(i + 8) as *mut u64).write_unaligned(super::SPREAD[(m >> 8) as usize]);
            }
        }
        /// # Safety
        /// `p[i..i + 16]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn load32(p: *const f32, i: usize) -> __m512 {
            unsafe { _mm512_loadu_ps(p.add(i)) }
        }
        /// # Safety
        /// `p[i..i + 16]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn store32(p: *mut f32, i: usize, x: __m512) {
            unsafe { _mm512_storeu_ps(p.add(i), x) }
        }
        /// # Safety
        /// `p[i..i + 16]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn load16(p: *const f16, i: usize) -> __m512 {
            unsafe { _mm512_cvtph_ps(_mm256_loadu_si256(p.add(i) as *const __m256i)) }
        }
        /// # Safety
        /// `p[i..i + 16]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn store16(p: *mut f16, i: usize, x: __m512) {
            unsafe { _mm256_storeu_si256(p.add(i) as *mut __m256i, _mm512_cvtps_ph::<NEAREST>(x)) }
        }
        /// Rounds binary32 lanes to binary16 (nearest-even), held in binary32.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn round16(x: __m512) -> __m512 {
            _mm512_cvtph_ps(_mm512_cvtps_ph::<NEAREST>(x))
        }
        /// The next binary32 encoding above each lane, as [`super::v8::next_up`].
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn next_up(v: __m512) -> __m512 {
            next_up_by(v, 1)
        }
        /// The step up by `unit` encodings of binary32 (1: binary32's grid, 2^16: bf16's): NaN
        /// and +inf unchanged, ±0 to `unit`, negative values `unit` encodings toward zero.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn next_up_by(v: __m512, unit: i32) -> __m512 {
            let b = _mm512_castps_si512(v);
            let keep =
                _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(v, v) | _mm512_cmpeq_epi32_mask(b, _mm512_set1_epi32(0x7f80_0000));
            let zero = _mm512_testn_epi32_mask(b, _mm512_set1_epi32(0x7fff_ffff));
            // negative: bits - unit, positive: bits + unit
            let step = _mm512_add_epi32(
                _mm512_and_si512(_mm512_srai_epi32::<31>(b), _mm512_set1_epi32(-2 * unit)),
                _mm512_set1_epi32(unit),
            );
            let r = _mm512_add_epi32(b, step);
            let r = _mm512_mask_blend_epi32(zero, r, _mm512_set1_epi32(unit));
            _mm512_castsi512_ps(_mm512_mask_blend_epi32(keep, r, b))
        }
        /// [`next_up`] on the bf16 grid, for lanes that hold bf16 values (a step of 2^16 in the
        /// binary32 encoding; NaN and +inf unchanged, ±0 to the least bf16 subnormal).
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn next_up_bf16(v: __m512) -> __m512 {
            next_up_by(v, 0x1_0000)
        }
        /// [`next_up`] on the binary16 grid, for lanes that hold binary16 values.
        #[inline]
        #[target_feature(enable = "avx512f,avx2")]
        pub fn next_up16(v: __m512) -> __m512 {
            // exact: every lane is a binary16 value (a NaN stays a NaN and is kept)
            _mm512_cvtph_ps(super::step_up16(_mm512_cvtps_ph::<NEAREST>(v)))
        }
    }
    /// The binary16 next-up step on 32 binary16 encodings, as [`step_up16`] (AVX512BW).
    #[inline]
    #[target_feature(enable = "avx512bw,avx512f")]
    pub(super) fn step_up16x32(b: std::arch::x86_64::__m512i) -> std::arch::x86_64::__m512i {
        use std::arch::x86_64::*;
        let mag = _mm512_and_si512(b, _mm512_set1_epi16(0x7fff));
        let keep = _mm512_cmpgt_epi16_mask(mag, _mm512_set1_epi16(0x7c00)) // NaN
            | _mm512_cmpeq_epi16_mask(b, _mm512_set1_epi16(0x7c00)); // +inf
        let zero = _mm512_cmpeq_epi16_mask(mag, _mm512_setzero_si512());
        // negative: bits - 1, positive: bits + 1
        let step = _mm512_or_si512(_mm512_srai_epi16::<15>(b), _mm512_set1_epi16(1));
        let r = _mm512_add_epi16(b, step);
        let r = _mm512_mask_blend_epi16(zero, r, _mm512_set1_epi16(1));
        _mm512_mask_blend_epi16(keep, r, b)
    }

    /// The narrow formats' rounding, filter and flush, in the ops of the ISA module that
    /// invokes it (`v4d`, `v8d`: binary64 lanes).
    macro_rules! narrow_ops {
        ($feat:literal, $fmafeat:literal, $v:ty, $fnmadd:ident) => {
            /// Every lane rounded to the format's precision p, nearest-even, by Veltkamp's
            /// splitting (g = x·(2^S + 1), then g − (g − x)); correct for |x| in [2^emin, max]
            /// and for zeros ([`round_full`] handles the rest of the range).
            #[inline]
            #[target_feature(enable = $feat)]
            pub fn split(x: $v, n: &Narrow) -> $v {
                let g = mul(x, splat(n.split));
                // g − (g − x) is g + (x − g) (nearest-even rounding is symmetric) with -0 kept
                sub(g, sub(g, x))
            }
            /// b·(2^S + 1), exact in every lane holding a format value (its p significant bits
            /// and their copy S = 53 − p places up span at most 53 bits): the factor
            /// [`split_mul`] takes for b.
            #[inline]
            #[target_feature(enable = $feat)]
            pub fn split_k(b: $v, n: &Narrow) -> $v {
                mul(b, splat(n.split))
            }
            /// [`split`] of the product a·b of two format values, with bk = [`split_k`]`(b)`:
            /// the same three values without forming a·b first. a·b is exact in binary64
            /// (2p ≤ 53 bits), so g = RN(a·bk) is RN(a·b·(2^S + 1)), split's g; the negative
            /// multiply-add RN(g − a·b) is split's RN(g − x) (its product is exact: no rounding
            /// of the modelled datapath is fused away); g minus it is split's result, bit for bit.
            #[inline]
            #[target_feature(enable = $fmafeat)]
            pub fn split_mul(a: $v, b: $v, bk: $v) -> $v {
                let g = mul(a, bk);
                sub(g, $fnmadd(a, b, g))
            }
            /// Every lane rounded to the format, nearest-even, with its range (see "Rounding in
            /// the lanes" in [`crate::format::narrow`]): [`split`] where |x| ≥ 2^emin; the
            /// subnormal grid where |x| < 2^emin (`(|x| + C) − C`, C = 2^(emin − M + 52), sign
            /// restored), then under FTZ a subnormal result flushed to zero of its sign; ±∞ where
            /// |x| ≥ max + ulp(max)/2 (infinities included). A NaN stays a NaN.
            #[inline]
            #[target_feature(enable = $feat)]
            pub fn round_full(x: $v, n: &Narrow) -> $v {
                let a = abs(x);
                // the common vector: every lane ±0 or normal-range (the binary64 just below
                // |x| is below 2^emin only for a nonzero |x| < 2^emin; for ±0 it is a NaN),
                // where the split is the rounding
                let odd = or_m(le(splat(n.overflow_at), a), lt(pred(a), splat(n.min_normal)));
                if bits(odd) == 0 {
                    return split(x, n);
                }
                let sgn = sign(x);
                let mut tiny = sub(add(a, splat(n.sub_grid)), splat(n.sub_grid));
                if n.ftz {
                    tiny = blend(tiny, splat(0.0), lt(tiny, splat(n.min_normal)));
                }
                let r = blend(split(x, n), xor(tiny, sgn), lt(a, splat(n.min_normal)));
                blend(r, xor(splat(f64::INFINITY), sgn), le(splat(n.overflow_at), a))
            }
            /// The next value above each lane on the format's grid, the model's `next_up` for
            /// lanes holding format values:
            /// a lane x ≥ +0 (−0 included) steps away from zero by its quantum
            /// q(x) = max(2^⌊log2 x⌋ · 2^−M, 2^(emin − M)), a lane x < 0 toward zero by the
            /// quantum of the magnitude just below |x| (the binade below at a power of two);
            /// the step past max is +∞, −∞ steps to −max, NaN and +∞ stay. IEEE subnormals:
            /// under FTZ, `slab_ftz!` moves a step that lands among the subnormals on, as it
            /// does for every format.
            #[inline]
            #[target_feature(enable = $feat)]
            pub fn next_up_soft(x: $v, n: &Narrow) -> $v {
                let zero = splat(0.0);
                let a = abs(x);
                let toward = lt(x, zero);
                let q = max(mul(exponent(blend(a, pred(a), toward)), splat(n.quantum)), splat(n.step));
                let r = blend(add(a, q), xor(sub(a, q), splat(-0.0)), toward);
                let r = blend(r, splat(-n.max_finite), lt(x, splat(-n.max_finite)));
                blend(r, splat(f64::INFINITY), lt(splat(n.max_finite), r))
            }
            /// Under FTZ, subnormal lanes read as zeros of the same sign (the operand read).
            #[inline]
            #[target_feature(enable = $feat)]
            pub fn flush(x: $v, n: &Narrow) -> $v {
                match n.ftz {
                    true => blend(x, sign(x), lt(abs(x), splat(n.min_normal))),
                    false => x,
                }
            }
        };
    }

    /// AVX2, 4 binary64 lanes holding a narrow format's values exactly (see
    /// [`crate::format::narrow`]); a mask is a vector of all-ones / all-zeros lanes.
    #[allow(dead_code)] // max and min: no slab kernel runs on binary64 lanes
    pub(super) mod v4d {
        use crate::format::narrow::Narrow;
        use std::arch::x86_64::*;
        /// Lanes per vector.
        pub const LANES: usize = 4;
        /// A mask.
        pub type M = __m256d;
        table_ops!("avx2", __m256d, M, "binary64";
            add = _mm256_add_pd, sub = _mm256_sub_pd, mul = _mm256_mul_pd, div = _mm256_div_pd,
            max = _mm256_max_pd, min = _mm256_min_pd, cmp = _mm256_cmp_pd);
        /// Every lane x.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn splat(x: f64) -> __m256d {
            _mm256_set1_pd(x)
        }
        /// Every lane the integer x.
        #[inline]
        #[target_feature(enable = "avx2")]
        fn int(x: u64) -> __m256i {
            _mm256_set1_epi64x(x as i64)
        }
        /// A shift count for the `sll` / `srl` forms.
        #[inline]
        #[target_feature(enable = "avx2")]
        fn count(n: u32) -> __m128i {
            _mm_cvtsi64_si128(n as i64)
        }
        /// Every lane binary64's canonical NaN (stored as the format's canonical NaN).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn canonical_nan() -> __m256d {
            _mm256_castsi256_pd(int(0x7ff8_0000_0000_0000))
        }
        /// Both masks.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn and_m(a: M, b: M) -> M {
            _mm256_and_pd(a, b)
        }
        /// Either mask.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn or_m(a: M, b: M) -> M {
            _mm256_or_pd(a, b)
        }
        /// The mask as lane bits (lane k in bit k).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn bits(m: M) -> u32 {
            _mm256_movemask_pd(m) as u32
        }
        /// `m ? b : a` per lane.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn blend(a: __m256d, b: __m256d, m: M) -> __m256d {
            _mm256_blendv_pd(a, b, m)
        }
        /// `sign(x) ? b : a` per lane.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn blend_sign(a: __m256d, b: __m256d, x: __m256d) -> __m256d {
            _mm256_blendv_pd(a, b, x)
        }
        /// The mask's complement.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn not_m(a: M) -> M {
            _mm256_xor_pd(a, _mm256_castsi256_pd(int(u64::MAX)))
        }
        /// `sel ? b : a` per lane, on masks.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn blend_m(a: M, b: M, sel: M) -> M {
            _mm256_blendv_pd(a, b, sel)
        }
        /// Lanes whose sign bit is set.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn sign_m(x: __m256d) -> M {
            _mm256_castsi256_pd(_mm256_cmpgt_epi64(_mm256_setzero_si256(), _mm256_castpd_si256(x)))
        }
        /// The sign bits of x (everything else cleared).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn sign(x: __m256d) -> __m256d {
            _mm256_and_pd(x, _mm256_set1_pd(-0.0))
        }
        /// |x| by clearing the sign bit.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn abs(x: __m256d) -> __m256d {
            _mm256_andnot_pd(_mm256_set1_pd(-0.0), x)
        }
        /// a ⊕ b, bitwise.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn xor(a: __m256d, b: __m256d) -> __m256d {
            _mm256_xor_pd(a, b)
        }
        /// Writes the mask's lanes as bools 0 / 1 to `p[i..i + 4]`.
        ///
        /// # Safety
        /// `p[i..i + 4]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub unsafe fn flags(p: *mut bool, i: usize, m: M) {
            // SAFETY: in bounds (the caller); every byte written is 0 or 1, a valid bool.
            unsafe { (p.add(i) as *mut u32).write_unaligned(super::SPREAD[bits(m) as usize] as u32) }
        }
        /// The binary64 just below each lane of a magnitude `a` (a NaN for +0).
        #[inline]
        #[target_feature(enable = "avx2")]
        fn pred(a: __m256d) -> __m256d {
            _mm256_castsi256_pd(_mm256_sub_epi64(_mm256_castpd_si256(a), int(1)))
        }
        /// Each lane's binary64 exponent field alone: 2^⌊log2 |x|⌋ for a normal x, 0 for ±0
        /// (and binary64 subnormals), +∞ for ±∞ and NaN.
        #[inline]
        #[target_feature(enable = "avx2")]
        fn exponent(x: __m256d) -> __m256d {
            _mm256_and_pd(x, _mm256_castsi256_pd(int(0x7ff0_0000_0000_0000)))
        }
        /// The range filter (see [`crate::format::narrow`]): true when on every lane the
        /// nonzero magnitudes among `v` (the stage-1 results and the direction) are at least
        /// `n.fast_lo` and all magnitudes at most `n.fast_hi`, so that no result of stages 2-7
        /// leaves {±0} ∪ [2^emin, max]. A NaN fails (the unfiltered stage 1 turns an infinite
        /// difference into a NaN, which must take the filtered road).
        ///
        /// Five operations a value, on a = |x|: the upper limit on a's encoding as a signed
        /// integer (a NaN's is above +∞'s, so it fails there); the lower limit on the binary64
        /// just below a (encoding − 1: order kept for a > 0, and ±0 becomes the all-ones NaN,
        /// which `vminpd` skips, returning its second operand, the running minimum).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn fast_ok(v: &[__m256d; 12], n: &Narrow) -> bool {
            let top = _mm256_set1_epi64x(n.fast_hi.to_bits() as i64);
            let mut over = _mm256_setzero_si256();
            let mut lo = splat(f64::INFINITY);
            for &x in v {
                let a = _mm256_castpd_si256(abs(x));
                over = _mm256_or_si256(over, _mm256_cmpgt_epi64(a, top));
                lo = _mm256_min_pd(_mm256_castsi256_pd(_mm256_sub_epi64(a, int(1))), lo);
            }
            _mm256_testz_si256(over, over) == 1 && bits(le(pred(splat(n.fast_lo)), lo)) == (1 << LANES) - 1
        }
        narrow_ops!("avx2", "avx2,fma", __m256d, _mm256_fnmadd_pd);
        /// Loads 4 `eEmM` encodings as binary64 (exact).
        ///
        /// # Safety
        /// `p[i..i + 4]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub unsafe fn load_soft(p: *const u64, i: usize, n: &Narrow) -> __m256d {
            let (l, m) = (n.lay, n.lay.man_bits);
            let b = unsafe { _mm256_loadu_si256(p.add(i) as *const __m256i) };
            if n.e8 {
                return unsafe { load_e8(p, i, n) };
            }
            let emax = (1u64 << l.exp_bits) - 1;
            let e = _mm256_and_si256(_mm256_srl_epi64(b, count(m)), int(emax));
            let f = _mm256_and_si256(b, int((1u64 << m) - 1));
            let s = _mm256_slli_epi64::<63>(_mm256_srl_epi64(b, count(l.width() - 1)));
            let frac = _mm256_sll_epi64(f, count(52 - m));
            let bexp = _mm256_sll_epi64(_mm256_add_epi64(e, int((1023 - l.bias()) as u64)), count(52));
            let normal = _mm256_or_si256(_mm256_or_si256(s, bexp), frac);
            let special = _mm256_or_si256(_mm256_or_si256(s, int(0x7ff0_0000_0000_0000)), frac);
            // a subnormal: fraction × 2^(emin − M), the fraction converted exactly via 2^52
            let two52 = splat(4503599627370496.0);
            let fv = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(f, int(0x4330_0000_0000_0000))), two52);
            let sub = _mm256_or_pd(_mm256_mul_pd(fv, splat(n.step)), _mm256_castsi256_pd(s));
            let r = blend(_mm256_castsi256_pd(normal), sub, _mm256_castsi256_pd(_mm256_cmpeq_epi64(e, int(0))));
            blend(r, _mm256_castsi256_pd(special), _mm256_castsi256_pd(_mm256_cmpeq_epi64(e, int(emax))))
        }
        /// [`load_soft`] for `e8mM` with M ≤ 23 (`n.e8`), as `v8d::load_e8`.
        ///
        /// # Safety
        /// `p[i..i + 4]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub unsafe fn load_e8(p: *const u64, i: usize, n: &Narrow) -> __m256d {
            let b = unsafe { _mm256_loadu_si256(p.add(i) as *const __m256i) };
            // the low 32 bits of each lane
            let lo = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(b, _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
            _mm256_cvtps_pd(_mm_castsi128_ps(_mm_sll_epi32(lo, count(n.e8_shift))))
        }
        /// [`store_soft`] for `e8mM` with M ≤ 23 (`n.e8`), as `v8d::store_e8`.
        ///
        /// # Safety
        /// `p[i..i + 4]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub unsafe fn store_e8(p: *mut u64, i: usize, x: __m256d, n: &Narrow) {
            let b32 = _mm_srl_epi32(_mm_castps_si128(_mm256_cvtpd_ps(x)), count(n.e8_shift));
            unsafe { _mm256_storeu_si256(p.add(i) as *mut __m256i, _mm256_cvtepu32_epi64(b32)) }
        }
        /// Stores 4 lanes holding `eEmM` values (or a NaN, stored as the canonical NaN) as
        /// encodings.
        ///
        /// # Safety
        /// `p[i..i + 4]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub unsafe fn store_soft(p: *mut u64, i: usize, x: __m256d, n: &Narrow) {
            let (l, m) = (n.lay, n.lay.man_bits);
            if n.e8 {
                return unsafe { store_e8(p, i, blend(x, canonical_nan(), unord(x, x)), n) };
            }
            let b = _mm256_castpd_si256(x);
            let s = _mm256_sll_epi64(_mm256_srli_epi64::<63>(b), count(l.width() - 1));
            let a = abs(x);
            let bexp = _mm256_srli_epi64::<52>(_mm256_castpd_si256(a));
            let e = _mm256_sub_epi64(bexp, int((1023 - l.bias()) as u64));
            let frac = _mm256_srl_epi64(_mm256_and_si256(b, int((1u64 << 52) - 1)), count(52 - m));
            let normal = _mm256_or_si256(s, _mm256_or_si256(_mm256_sll_epi64(e, count(m)), frac));
            // a subnormal: |x| / 2^(emin − M) is an integer < 2^52, read off 2^52 + it
            let two52 = splat(4503599627370496.0);
            let q = _mm256_castpd_si256(_mm256_add_pd(_mm256_mul_pd(a, splat(n.inv_step)), two52));
            let sub = _mm256_or_si256(s, _mm256_and_si256(q, int((1u64 << 52) - 1)));
            let inf = _mm256_or_si256(s, int(l.exp_mask()));
            let r = blend(_mm256_castsi256_pd(normal), _mm256_castsi256_pd(sub), lt(a, splat(n.min_normal)));
            let r = blend(r, _mm256_castsi256_pd(inf), _mm256_cmp_pd::<_CMP_EQ_OQ>(a, splat(f64::INFINITY)));
            let r = blend(r, _mm256_castsi256_pd(int(l.canonical_nan())), unord(x, x));
            unsafe { _mm256_storeu_si256(p.add(i) as *mut __m256i, _mm256_castpd_si256(r)) }
        }
    }

    /// AVX-512F, 8 binary64 lanes holding a narrow format's values exactly; masks as `__mmask8`.
    #[allow(dead_code)] // max and min: no slab kernel runs on binary64 lanes
    pub(super) mod v8d {
        use crate::format::narrow::Narrow;
        use std::arch::x86_64::*;
        /// Lanes per vector.
        pub const LANES: usize = 8;
        /// A mask.
        pub type M = __mmask8;
        table_ops!("avx512f", __m512d, M, "binary64";
            add = _mm512_add_pd, sub = _mm512_sub_pd, mul = _mm512_mul_pd, div = _mm512_div_pd,
            max = _mm512_max_pd, min = _mm512_min_pd, cmp = _mm512_cmp_pd_mask);
        /// Every lane x.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn splat(x: f64) -> __m512d {
            _mm512_set1_pd(x)
        }
        /// Every lane the integer x.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn int(x: u64) -> __m512i {
            _mm512_set1_epi64(x as i64)
        }
        /// A shift count for the `sll` / `srl` forms.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn count(n: u32) -> __m128i {
            _mm_cvtsi64_si128(n as i64)
        }
        /// The lanes as integers.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn ib(x: __m512d) -> __m512i {
            _mm512_castpd_si512(x)
        }
        /// The integers as lanes.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn fb(x: __m512i) -> __m512d {
            _mm512_castsi512_pd(x)
        }
        /// Every lane binary64's canonical NaN (stored as the format's canonical NaN).
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn canonical_nan() -> __m512d {
            fb(int(0x7ff8_0000_0000_0000))
        }
        /// Both masks.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn and_m(a: M, b: M) -> M {
            a & b
        }
        /// Either mask.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn or_m(a: M, b: M) -> M {
            a | b
        }
        /// The mask as lane bits (lane k in bit k).
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn bits(m: M) -> u32 {
            m as u32
        }
        /// `m ? b : a` per lane.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn blend(a: __m512d, b: __m512d, m: M) -> __m512d {
            _mm512_mask_blend_pd(m, a, b)
        }
        /// `sign(x) ? b : a` per lane.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn blend_sign(a: __m512d, b: __m512d, x: __m512d) -> __m512d {
            _mm512_mask_blend_pd(sign_m(x), a, b)
        }
        /// The mask's complement.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn not_m(a: M) -> M {
            !a
        }
        /// `sel ? b : a` per lane, on masks.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn blend_m(a: M, b: M, sel: M) -> M {
            (a & !sel) | (b & sel)
        }
        /// Lanes whose sign bit is set.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn sign_m(x: __m512d) -> M {
            _mm512_test_epi64_mask(ib(x), int(1 << 63))
        }
        /// The sign bits of x (everything else cleared).
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn sign(x: __m512d) -> __m512d {
            fb(_mm512_and_si512(ib(x), int(1 << 63)))
        }
        /// |x| by clearing the sign bit.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn abs(x: __m512d) -> __m512d {
            fb(_mm512_and_si512(ib(x), int(!(1 << 63))))
        }
        /// a ⊕ b, bitwise.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub fn xor(a: __m512d, b: __m512d) -> __m512d {
            fb(_mm512_xor_si512(ib(a), ib(b)))
        }
        /// Writes the mask's lanes as bools 0 / 1 to `p[i..i + 8]`.
        ///
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn flags(p: *mut bool, i: usize, m: M) {
            // SAFETY: in bounds (the caller); every byte written is 0 or 1, a valid bool.
            unsafe { (p.add(i) as *mut u64).write_unaligned(super::SPREAD[m as usize]) }
        }
        /// The binary64 just below each lane of a magnitude `a` (a NaN for +0).
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn pred(a: __m512d) -> __m512d {
            fb(_mm512_sub_epi64(ib(a), int(1)))
        }
        /// [`super::v4d::exponent`] on 8 lanes.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn exponent(x: __m512d) -> __m512d {
            fb(_mm512_and_si512(ib(x), int(0x7ff0_0000_0000_0000)))
        }
        /// [`super::v4d::fast_ok`] on 8 lanes, in three AVX-512 operations a value: the largest
        /// magnitude by `vrangepd` (max-abs, sign cleared), and the smallest nonzero magnitude
        /// by `vfixupimmpd` (±0 becomes +∞, a NaN becomes +0, every other class stays itself)
        /// and `vrangepd` (min-abs, sign cleared), each over a balanced tree of the twelve.
        /// `vrangepd` returns the other operand when one is a quiet NaN (as `maxNum` does), so
        /// the NaN is caught by the lower limit: it reads as +0 there, below `fast_lo` (> 0);
        /// an infinity fails the upper limit.
        #[inline]
        #[target_feature(enable = "avx512f,avx512dq")]
        pub fn fast_ok(v: &[__m512d; 12], n: &Narrow) -> bool {
            // vfixupimmpd's table: a 4-bit response per input class, class j in bits 4j..4j+3
            // (QNaN, SNaN, ±0, +1, −∞, +∞, negative, positive); 1 = the input itself, 5 = +∞,
            // 8 = +0
            let table = int(0x1111_1588);
            let nz = |x: __m512d| _mm512_fixupimm_pd::<0>(x, x, table);
            // imm bits 1:0 = 11 max-abs / 10 min-abs; bits 3:2 = 10 sign cleared
            let hi = |a, b| _mm512_range_pd::<0b1011>(a, b);
            let lo = |a, b| _mm512_range_pd::<0b1010>(a, b);
            let z: [__m512d; 12] = std::array::from_fn(|k| nz(v[k]));
            let h = |k: usize| hi(hi(v[k], v[k + 1]), hi(v[k + 2], v[k + 3]));
            let l = |k: usize| lo(lo(z[k], z[k + 1]), lo(z[k + 2], z[k + 3]));
            let (h, l) = (hi(hi(h(0), h(4)), h(8)), lo(lo(l(0), l(4)), l(8)));
            let ok = _mm512_cmp_pd_mask::<_CMP_LE_OQ>(h, splat(n.fast_hi))
                & _mm512_cmp_pd_mask::<_CMP_GE_OQ>(l, splat(n.fast_lo));
            ok == u8::MAX
        }
        narrow_ops!("avx512f", "avx512f", __m512d, _mm512_fnmadd_pd);
        /// Loads 8 `eEmM` encodings as binary64 (exact).
        ///
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn load_soft(p: *const u64, i: usize, n: &Narrow) -> __m512d {
            let (l, m) = (n.lay, n.lay.man_bits);
            let b = unsafe { _mm512_loadu_si512(p.add(i) as *const __m512i) };
            if n.e8 {
                return unsafe { load_e8(p, i, n) };
            }
            let emax = (1u64 << l.exp_bits) - 1;
            let e = _mm512_and_si512(_mm512_srl_epi64(b, count(m)), int(emax));
            let f = _mm512_and_si512(b, int((1u64 << m) - 1));
            let s = _mm512_slli_epi64::<63>(_mm512_srl_epi64(b, count(l.width() - 1)));
            let frac = _mm512_sll_epi64(f, count(52 - m));
            let bexp = _mm512_sll_epi64(_mm512_add_epi64(e, int((1023 - l.bias()) as u64)), count(52));
            let normal = fb(_mm512_or_si512(_mm512_or_si512(s, bexp), frac));
            let special = fb(_mm512_or_si512(_mm512_or_si512(s, int(0x7ff0_0000_0000_0000)), frac));
            // a subnormal: fraction × 2^(emin − M), the fraction converted exactly via 2^52
            let two52 = splat(4503599627370496.0);
            let fv = _mm512_sub_pd(fb(_mm512_or_si512(f, int(0x4330_0000_0000_0000))), two52);
            let sub = fb(_mm512_or_si512(ib(_mm512_mul_pd(fv, splat(n.step))), s));
            let r = blend(normal, sub, _mm512_cmpeq_epi64_mask(e, int(0)));
            blend(r, special, _mm512_cmpeq_epi64_mask(e, int(emax)))
        }
        /// [`load_soft`] for `e8mM` with M ≤ 23 (`n.e8`): binary32's exponent, so the
        /// encoding shifted to binary32's fraction width is the same value in binary32
        /// (subnormals, infinities and NaNs included), widened exactly to binary64.
        ///
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn load_e8(p: *const u64, i: usize, n: &Narrow) -> __m512d {
            // the low halves of the 8 lanes to the low 256 bits (the encodings fit 32 bits):
            // one `vpermd` from memory, written out because LLVM turns the permute intrinsic
            // into a `vpmovqd` (two shuffle uops and a separate load)
            let idx = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 0, 0, 0, 0, 0, 0, 0, 0);
            let low: __m512i;
            // SAFETY: `p[i..i + 8]` is in bounds (the caller): the 64 bytes read; the asm
            // writes only its output register.
            unsafe {
                std::arch::asm!(
                    "vpermd {o}, {x}, zmmword ptr [{p}]",
                    o = lateout(zmm_reg) low,
                    x = in(zmm_reg) idx,
                    p = in(reg) p.add(i),
                    options(pure, readonly, nostack, preserves_flags)
                );
            }
            let low = _mm512_castsi512_si256(low);
            _mm512_cvtps_pd(_mm256_castsi256_ps(_mm256_sll_epi32(low, count(n.e8_shift))))
        }
        /// [`store_soft`] for `e8mM` with M ≤ 23 (`n.e8`): the lanes hold target values, which
        /// binary32 holds exactly, so narrowing is exact and the binary32 encoding shifted
        /// right is the target's. A NaN lane must be binary64's canonical NaN, which narrows
        /// to binary32's, whose shift is the target's canonical NaN.
        ///
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn store_e8(p: *mut u64, i: usize, x: __m512d, n: &Narrow) {
            let b32 = _mm256_srl_epi32(_mm256_castps_si256(_mm512_cvtpd_ps(x)), count(n.e8_shift));
            unsafe { _mm512_storeu_si512(p.add(i) as *mut __m512i, _mm512_cvtepu32_epi64(b32)) }
        }
        /// Stores 8 lanes holding `eEmM` values (or a NaN, stored as the canonical NaN) as
        /// encodings.
        ///
        /// # Safety
        /// `p[i..i + 8]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub unsafe fn store_soft(p: *mut u64, i: usize, x: __m512d, n: &Narrow) {
            let (l, m) = (n.lay, n.lay.man_bits);
            if n.e8 {
                return unsafe { store_e8(p, i, blend(x, canonical_nan(), unord(x, x)), n) };
            }
            let b = ib(x);
            let s = _mm512_sll_epi64(_mm512_srli_epi64::<63>(b), count(l.width() - 1));
            let a = abs(x);
            let bexp = _mm512_srli_epi64::<52>(ib(a));
            let e = _mm512_sub_epi64(bexp, int((1023 - l.bias()) as u64));
            let frac = _mm512_srl_epi64(_mm512_and_si512(b, int((1u64 << 52) - 1)), count(52 - m));
            let normal = fb(_mm512_or_si512(s, _mm512_or_si512(_mm512_sll_epi64(e, count(m)), frac)));
            // a subnormal: |x| / 2^(emin − M) is an integer < 2^52, read off 2^52 + it
            let two52 = splat(4503599627370496.0);
            let q = ib(_mm512_add_pd(_mm512_mul_pd(a, splat(n.inv_step)), two52));
            let sub = fb(_mm512_or_si512(s, _mm512_and_si512(q, int((1u64 << 52) - 1))));
            let inf = fb(_mm512_or_si512(s, int(l.exp_mask())));
            let r = blend(normal, sub, lt(a, splat(n.min_normal)));
            let r = blend(r, inf, _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(a, splat(f64::INFINITY)));
            let r = blend(r, fb(int(l.canonical_nan())), unord(x, x));
            unsafe { _mm512_storeu_si512(p.add(i) as *mut __m512i, ib(r)) }
        }
    }

    /// AVX512-FP16: 32 binary16 lanes computed natively (`vaddph` … `vdivph`, each correctly
    /// rounded to binary16, round to nearest even from MXCSR's default, subnormals always kept:
    /// the FP16 instructions ignore MXCSR.DAZ / FTZ), a mask is a `__mmask32`. Only the binary16
    /// kernels use it: loads, stores and the rounding step are identities.
    pub(super) mod v32h {
        use half::f16;
        use std::arch::x86_64::*;
        /// Lanes per vector.
        pub const LANES: usize = 32;
        /// A mask.
        pub type M = __mmask32;
        table_ops!("avx512fp16,avx512bw,avx512f", __m512h, M, "binary16";
            add = _mm512_add_ph, sub = _mm512_sub_ph, mul = _mm512_mul_ph, div = _mm512_div_ph,
            max = _mm512_max_ph, min = _mm512_min_ph, cmp = _mm512_cmp_ph_mask);
        /// Every lane the binary16 with these bits.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        fn splat_bits(x: u16) -> __m512h {
            _mm512_castsi512_ph(_mm512_set1_epi16(x as i16))
        }
        /// Every lane x, a binary16 value (0, ±1, −0, a det threshold read from binary16).
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn splat(x: f32) -> __m512h {
            let h = f16::from_f32(x);
            debug_assert!(h.to_f32().to_bits() == x.to_bits(), "{x} is not a binary16 value");
            splat_bits(h.to_bits())
        }
        /// Every lane the binary16 x, bits and all.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn splat16(x: f16) -> __m512h {
            splat_bits(x.to_bits())
        }
        /// Every lane binary16's canonical NaN, 0x7e00.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn canonical_nan() -> __m512h {
            splat_bits(0x7e00)
        }
        /// Both masks.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn and_m(a: M, b: M) -> M {
            a & b
        }
        /// The mask as lane bits (lane k in bit k).
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn bits(m: M) -> u32 {
            m
        }
        /// `m ? b : a` per lane.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn blend(a: __m512h, b: __m512h, m: M) -> __m512h {
            _mm512_mask_blend_ph(m, a, b)
        }
        /// `sign(x) ? b : a` per lane.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn blend_sign(a: __m512h, b: __m512h, x: __m512h) -> __m512h {
            _mm512_mask_blend_ph(_mm512_movepi16_mask(_mm512_castph_si512(x)), a, b)
        }
        /// The bits of `a` and `b` combined by a 512-bit logic instruction.
        macro_rules! bits_op {
            ($op:ident, $a:expr, $b:expr) => {
                _mm512_castsi512_ph($op(_mm512_castph_si512($a), $b))
            };
        }
        /// The sign bits of x (everything else cleared).
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn sign(x: __m512h) -> __m512h {
            bits_op!(_mm512_and_si512, x, _mm512_set1_epi16(i16::MIN))
        }
        /// |x| by clearing the sign bit.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn abs(x: __m512h) -> __m512h {
            bits_op!(_mm512_and_si512, x, _mm512_set1_epi16(i16::MAX))
        }
        /// a ⊕ b, bitwise.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn xor(a: __m512h, b: __m512h) -> __m512h {
            bits_op!(_mm512_xor_si512, a, _mm512_castph_si512(b))
        }
        /// Either mask.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn or_m(a: M, b: M) -> M {
            a | b
        }
        /// The mask's complement.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn not_m(a: M) -> M {
            !a
        }
        /// `sel ? b : a` per lane, on masks.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn blend_m(a: M, b: M, sel: M) -> M {
            (a & !sel) | (b & sel)
        }
        /// Lanes whose sign bit is set.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn sign_m(x: __m512h) -> M {
            _mm512_movepi16_mask(_mm512_castph_si512(x))
        }
        /// Writes the mask's lanes as bools 0 / 1 to `p[i..i + 32]`.
        ///
        /// # Safety
        /// `p[i..i + 32]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub unsafe fn flags(p: *mut bool, i: usize, m: M) {
            for k in 0..4 {
                // SAFETY: in bounds (the caller); every byte written is 0 or 1, a valid bool.
                unsafe {
                    (p.add(i + 8 * k) as *mut u64).write_unaligned(super::SPREAD[(m >> (8 * k) & 0xff) as usize])
                };
            }
        }
        /// # Safety
        /// `p[i..i + 32]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub unsafe fn load16(p: *const f16, i: usize) -> __m512h {
            unsafe { _mm512_castsi512_ph(_mm512_loadu_si512(p.add(i) as *const __m512i)) }
        }
        /// # Safety
        /// `p[i..i + 32]` must be in bounds.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub unsafe fn store16(p: *mut f16, i: usize, x: __m512h) {
            unsafe { _mm512_storeu_si512(p.add(i) as *mut __m512i, _mm512_castph_si512(x)) }
        }
        /// The lanes are binary16 already: nothing to round.
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn round16(x: __m512h) -> __m512h {
            x
        }
        /// The next binary16 encoding above each lane, as [`super::v8::next_up16`].
        #[inline]
        #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
        pub fn next_up16(v: __m512h) -> __m512h {
            _mm512_castsi512_ph(super::step_up16x32(_mm512_castph_si512(v)))
        }
    }
}

/// The kernel bodies, instantiated for each instruction set in [`isa`].
#[cfg(target_arch = "x86_64")]
mod kernels {
    use super::*;

    /// The RTI stage table on one vector per step, in the ops of `$x` (an [`isa`] module).
    /// `$load(column, i)` gives the lanes as binary32, `$round(x)` rounds a binary32 result to
    /// the format, `$store(column, i, x)` writes results, `$thr` is the det threshold as binary32.
    macro_rules! rti_kernel {
        ($x:ident, $rti:expr, $rays:expr, $tris:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $thr:expr, $start:expr, $end:expr) => {{
            let round = $round;
            rti_kernel!($x, $rti, $rays, $tris, $out, $full, $load, round, round, |b| b, |a, b, _| round($x::mul(a, b)), |_: &[_; 12]| true, $store, $thr, $start, $end)
        }};
        // `$fast` rounds without the filter; `$fmulk(a, b, $k(b))` is `$fast` of the product
        // a·b (`$k(b)` formed once for the products that share b); `$ok(v)` (v: the stage-1
        // results and the direction) says that `$fast` gives `$round`'s results at stages 2-6
        // on every lane
        ($x:ident, $rti:expr, $rays:expr, $tris:expr, $out:expr, $full:expr, $load:expr, $round:expr, $fast:expr, $k:expr, $fmulk:expr, $ok:expr, $store:expr, $thr:expr, $start:expr, $end:expr) => {{
            // one loop per (culling, division mode), so that neither is decided per vector
            let backface = $rti.cull == Cull::Backface;
            match ($rti.fmt.opts.div, backface) {
                (DivMode::RecipMul, false) => rti_kernel!(@loop $x, $rti, $rays, $tris, $out, $full, $load, $round, $fast, $k, $fmulk, $ok, $store, $thr, $start, $end, false, true),
                (DivMode::RecipMul, true) => rti_kernel!(@loop $x, $rti, $rays, $tris, $out, $full, $load, $round, $fast, $k, $fmulk, $ok, $store, $thr, $start, $end, true, true),
                (DivMode::Divide, false) => rti_kernel!(@loop $x, $rti, $rays, $tris, $out, $full, $load, $round, $fast, $k, $fmulk, $ok, $store, $thr, $start, $end, false, false),
                (DivMode::Divide, true) => rti_kernel!(@loop $x, $rti, $rays, $tris, $out, $full, $load, $round, $fast, $k, $fmulk, $ok, $store, $thr, $start, $end, true, false),
            }
        }};
        // stage 1 in `$sub`: (e1, e2, s)
        (@stage1 $sub:ident, $v:ident, $ox:ident, $oy:ident, $oz:ident) => {{
            let (v0x, v0y, v0z) = ($v(0, 0), $v(0, 1), $v(0, 2));
            (
                ($sub($v(1, 0), v0x), $sub($v(1, 1), v0y), $sub($v(1, 2), v0z)),
                ($sub($v(2, 0), v0x), $sub($v(2, 1), v0y), $sub($v(2, 2), v0z)),
                ($sub($ox, v0x), $sub($oy, v0y), $sub($oz, v0z)),
            )
        }};
        // stages 2-6 in `$sub`, `$add`, `$mul`: [det, u', v', t']. The 18 products with a
        // factor of d or s go through `$mulk(a, b, $k(b))` with b that factor (multiplication
        // commutes: `$mulk(e2z, dy, ..)` is the product dy·e2z of the table)
        (@stages26 $sub:ident, $add:ident, $mul:ident, $k:ident, $mulk:ident, $e1:expr, $e2:expr, $s:expr, $d:expr) => {{
            let ((e1x, e1y, e1z), (e2x, e2y, e2z), (sx, sy, sz), (dx, dy, dz)) = ($e1, $e2, $s, $d);
            let (kdx, kdy, kdz) = ($k(dx), $k(dy), $k(dz));
            let (ksx, ksy, ksz) = ($k(sx), $k(sy), $k(sz));
            // stages 2, 3: p = d x e2, q = s x e1
            let px = $sub($mulk(e2z, dy, kdy), $mulk(e2y, dz, kdz));
            let py = $sub($mulk(e2x, dz, kdz), $mulk(e2z, dx, kdx));
            let pz = $sub($mulk(e2y, dx, kdx), $mulk(e2x, dy, kdy));
            let qx = $sub($mulk(e1z, sy, ksy), $mulk(e1y, sz, ksz));
            let qy = $sub($mulk(e1x, sz, ksz), $mulk(e1z, sx, ksx));
            let qz = $sub($mulk(e1y, sx, ksx), $mulk(e1x, sy, ksy));
            // stages 4-6: (x + y) + z
            let det = $add($add($mul(e1x, px), $mul(e1y, py)), $mul(e1z, pz));
            let up = $add($add($mulk(px, sx, ksx), $mulk(py, sy, ksy)), $mulk(pz, sz, ksz));
            let vp = $add($add($mulk(qx, dx, kdx), $mulk(qy, dy, kdy)), $mulk(qz, dz, kdz));
            let tp = $add($add($mul(e2x, qx), $mul(e2y, qy)), $mul(e2z, qz));
            [det, up, vp, tp]
        }};
        (@loop $x:ident, $rti:expr, $rays:expr, $tris:expr, $out:expr, $full:expr, $load:expr, $round:expr, $fast:expr, $k:expr, $fmulk:expr, $ok:expr, $store:expr, $thr:expr, $start:expr, $end:expr, $backface:expr, $recip:expr) => {{
            let (rays, tris, out) = ($rays, $tris, $out);
            let load = $load;
            let rd = $round;
            let fast = $fast;
            let ok = $ok;
            let fsub = |a, b| fast($x::sub(a, b));
            let fadd = |a, b| fast($x::add(a, b));
            let fmul = |a, b| fast($x::mul(a, b));
            let (fk, fmulk) = ($k, $fmulk);
            // the filtered path's products as the table's: no factor formed ahead
            let (nok, mulk) = (|b| b, |a, b, _| rd($x::mul(a, b)));
            let store = $store;
            // called before and after each block of vectors (the narrow formats' filter)
            let (start, end) = ($start, $end);
            let sub = |a, b| rd($x::sub(a, b));
            let add = |a, b| rd($x::add(a, b));
            let mul = |a, b| rd($x::mul(a, b));
            let div = |a, b| rd($x::div(a, b));
            let thr = $x::splat($thr);
            let zero = $x::splat(0.0);
            let one = $x::splat(1.0);
            // the canonical NaN of the lanes' encoding (stored as the format's canonical NaN)
            let nan = $x::canonical_nan();
            const L: usize = $x::LANES;
            // Two passes over blocks of BLOCK vectors (software pipelining): the first runs
            // stages 1-6 and keeps det, u', v' and t'; the second runs stage 7, divides and
            // stores.
            // The divide's latency then overlaps the next block's arithmetic instead of
            // filling the scheduler with instructions that wait for it.
            const BLOCK: usize = 8;
            let mut keep = [[zero; 4]; BLOCK];
            // which vectors of the block took the unfiltered stages 2-6 (and so stage 7's u + v)
            let mut unfiltered = [false; BLOCK];
            // the NaN lanes of each vector of the block (bit j: lane j), for `end`
            let mut nan_bits = [0u32; BLOCK];
            let mut base = 0;
            while base < $full {
                let nv = (($full - base) / L).min(BLOCK);
                start();
                for (k, slot) in keep.iter_mut().enumerate().take(nv) {
                    let i = base + L * k;
                    // (direct calls: a closure mapped over an array may stay out of line)
                    let (ox, oy, oz) = (load(&rays.o[0], i), load(&rays.o[1], i), load(&rays.o[2], i));
                    let (dx, dy, dz) = (load(&rays.d[0], i), load(&rays.d[1], i), load(&rays.d[2], i));
                    let v = |k: usize, a: usize| load(&tris.v[k][a], i);
                    let d = (dx, dy, dz);
                    // stage 1 unfiltered; when `ok` clears every lane, stages 2-6 unfiltered
                    // too, else all of stages 1-6 again behind the filter
                    let (e1, e2, s) = rti_kernel!(@stage1 fsub, v, ox, oy, oz);
                    let all = [e1.0, e1.1, e1.2, e2.0, e2.1, e2.2, s.0, s.1, s.2, dx, dy, dz];
                    unfiltered[k] = ok(&all);
                    *slot = if unfiltered[k] {
                        rti_kernel!(@stages26 fsub, fadd, fmul, fk, fmulk, e1, e2, s, d)
                    } else {
                        let (e1, e2, s) = rti_kernel!(@stage1 sub, v, ox, oy, oz);
                        rti_kernel!(@stages26 sub, add, mul, nok, mulk, e1, e2, s, d)
                    };
                }
                for (k, &[det, up, vp, tp]) in keep.iter().enumerate().take(nv) {
                    let i = base + L * k;
                    // stage 7
                    let uv = if unfiltered[k] { fadd(up, vp) } else { add(up, vp) };
                    // The compares of stage 7, with the det-sign select done by a sign flip:
                    // when `det_ok` holds, det is neither ±0 nor NaN (threshold >= 0, checked
                    // by the dispatch), so `det > 0 ? a <= b : b <= a` equals `a^s <= b^s`
                    // with s = det's sign bit (negation is exact): `valid` is the same bit.
                    let abs_det = $x::abs(det);
                    let det_ok = if $backface { $x::lt(thr, det) } else { $x::lt(thr, abs_det) };
                    let s = $x::sign(det);
                    let nonneg = |x| $x::le(zero, $x::xor(x, s));
                    let valid = $x::and_m(
                        $x::and_m(det_ok, nonneg(up)),
                        $x::and_m($x::and_m(nonneg(vp), $x::le($x::xor(uv, s), abs_det)), nonneg(tp)),
                    );
                    // the division last
                    let (t, u, w) = if $recip {
                        let inv = div(one, det);
                        (mul(tp, inv), mul(up, inv), mul(vp, inv))
                    } else {
                        (div(tp, det), div(up, det), div(vp, det))
                    };
                    let tmin = load(&rays.tmin, i);
                    let tmax = load(&rays.tmax, i);
                    let hit = $x::and_m(valid, $x::and_m($x::le(tmin, t), $x::le(t, tmax)));
                    // SAFETY: lanes i..i + L are in bounds (checked by the caller).
                    unsafe {
                        $x::flags(out.hit.as_mut_ptr(), i, hit);
                        $x::flags(out.valid.as_mut_ptr(), i, valid);
                    }
                    // NaN lanes are rare: canonicalise only when one of the results is NaN
                    let canon = |x| $x::blend(x, nan, $x::unord(x, x));
                    let nan_lanes = $x::bits($x::or_m($x::unord(t, u), $x::unord(w, w)));
                    nan_bits[k] = nan_lanes;
                    let (t, u, w) = if nan_lanes == 0 { (t, u, w) } else { (canon(t), canon(u), canon(w)) };
                    store(&mut out.t, i, t);
                    store(&mut out.u, i, u);
                    store(&mut out.v, i, w);
                }
                end(base, nv, &nan_bits, &mut *out);
                base += L * nv;
            }
        }};
    }

    /// The slab stage table on one vector per step, for either batch shape, in the ops of `$x`.
    /// `$load(column, i)` gives the lanes as binary32, `$round(x)` rounds a binary32 result to
    /// the format, `$store(column, i, x)` writes results, `$up` steps up on the format's grid,
    /// `$bcast` broadcasts a ray value.
    macro_rules! slab_kernel {
        ($x:ident, $s:expr, $rays:expr, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $bcast:expr) => {{
            // one loop per comparator and batch shape, so that neither is decided per vector
            let tof = $s.cfg.nan == SlabNan::TakeOnFalse;
            if $s.cfg.directed {
                match $rays {
                    SlabRays::One(r) if tof => slab_kernel!(@dloop $x, $s, r, $boxes, $out, $full, $load, $round, $store, $up, $bcast, true),
                    SlabRays::One(r) => slab_kernel!(@dloop $x, $s, r, $boxes, $out, $full, $load, $round, $store, $up, $bcast, false),
                    // pairs of the directed variant are not eligible (see `slab_kernel_ray_*`)
                    SlabRays::Pairs(r) => {
                        for k in 0..$full {
                            $out.set(k, $s.test(&r.get(k), &$boxes.get(k)));
                        }
                    }
                }
                return;
            }
            match ($rays, tof) {
                (SlabRays::Pairs(r), false) => slab_kernel!(@loop $x, $s, pairs r, $boxes, $out, $full, $load, $round, $store, $up, $bcast, false),
                (SlabRays::Pairs(r), true) => slab_kernel!(@loop $x, $s, pairs r, $boxes, $out, $full, $load, $round, $store, $up, $bcast, true),
                (SlabRays::One(r), false) => slab_kernel!(@loop $x, $s, one r, $boxes, $out, $full, $load, $round, $store, $up, $bcast, false),
                (SlabRays::One(r), true) => slab_kernel!(@loop $x, $s, one r, $boxes, $out, $full, $load, $round, $store, $up, $bcast, true),
            }
        }};
        // per-batch preparation, hoisted out of the loop: column pointers; for one ray, each
        // axis's near and far plane columns (picked by the sign bit of 1/d) and the broadcast
        // origin, 1/d and t interval
        (@prep $x:ident, pairs $r:ident, $bmin:ident, $bmax:ident, $bcast:ident) => {
            (
                $r.o.each_ref().map(|c| c.as_ptr()),
                $r.inv_d.each_ref().map(|c| c.as_ptr()),
                $r.tmin.as_ptr(),
                $r.tmax.as_ptr(),
                true, // a lane's t interval may be NaN
            )
        };
        (@prep $x:ident, one $r:ident, $bmin:ident, $bmax:ident, $bcast:ident) => {{
            let neg = $r.inv_d.map(|v| $x::bits($x::sign_m($bcast(v))) != 0);
            let is_nan = |v| { let b = $bcast(v); $x::bits($x::unord(b, b)) != 0 };
            (
                std::array::from_fn::<_, 3, _>(|a| if neg[a] { $bmax[a] } else { $bmin[a] }),
                std::array::from_fn::<_, 3, _>(|a| if neg[a] { $bmin[a] } else { $bmax[a] }),
                ($r.o.map($bcast), $r.inv_d.map($bcast)),
                ($bcast($r.tmin), $bcast($r.tmax)),
                is_nan($r.tmin) || is_nan($r.tmax),
            )
        }};
        // axis a of lanes i..i + L: (near-plane t, far-plane t)
        (@plane $x:ident, pairs $prep:ident, $bmin:ident, $bmax:ident, $load:ident, $rd:ident, $a:expr, $i:ident) => {{
            let (o, inv) = ($load($prep.0[$a], $i), $load($prep.1[$a], $i));
            let tlo = $rd($x::mul($rd($x::sub($load($bmin[$a], $i), o)), inv));
            let thi = $rd($x::mul($rd($x::sub($load($bmax[$a], $i), o)), inv));
            // the sign bit of 1/d picks the near plane
            ($x::blend_sign(tlo, thi, inv), $x::blend_sign(thi, tlo, inv))
        }};
        (@plane $x:ident, one $prep:ident, $bmin:ident, $bmax:ident, $load:ident, $rd:ident, $a:expr, $i:ident) => {{
            let (o, inv) = ($prep.2 .0[$a], $prep.2 .1[$a]);
            (
                $rd($x::mul($rd($x::sub($load($prep.0[$a], $i), o)), inv)),
                $rd($x::mul($rd($x::sub($load($prep.1[$a], $i), o)), inv)),
            )
        }};
        // the batch's rays again, for the scalar model
        (@rays pairs $r:ident) => {
            SlabRays::Pairs($r)
        };
        (@rays one $r:ident) => {
            SlabRays::One($r)
        };
        // the t interval the chains start from
        (@limits pairs $prep:ident, $load:ident, $i:ident) => {
            ($load($prep.2, $i), $load($prep.3, $i))
        };
        (@limits one $prep:ident, $load:ident, $i:ident) => {
            $prep.3
        };
        // the directed variant, one ray against every box (see `Slab::trace_directed`, step for
        // step): the entry plane's difference rounded to nearest and stepped outward to a
        // bracket, the bracket end and the 1/d end chosen by their signs (the first by the ray's
        // direction, uniform; the second per lane), ends standing for ±∞ giving the unbounded
        // bound, the product stepped outward once. A parallel axis (uniform) tests the origin
        // against the slab. Lanes whose plane difference is NaN (its sign would pick an end) are
        // marked NaN and redone by the model, as are NaN outputs.
        (@dloop $x:ident, $s:expr, $r:ident, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $bcast:expr, $tof:expr) => {{
            let (s, boxes, out) = ($s, $boxes, $out);
            let (load, rd, store, up, bcast) = ($load, $round, $store, $up, $bcast);
            let neg = |v| $x::xor(v, $x::splat(-0.0));
            let down = |v| neg(up(neg(v)));
            let bmin = boxes.min.each_ref().map(|c| c.as_ptr());
            let bmax = boxes.max.each_ref().map(|c| c.as_ptr());
            let r = $r;
            use crate::Format as _;
            let f = &s.fmt;
            let prep = slab_kernel!(@prep $x, one r, bmin, bmax, bcast);
            let (top, bottom) = (f.from_f64(f64::INFINITY), f.from_f64(f64::NEG_INFINITY));
            let (vtop, vbottom) = (bcast(top), bcast(bottom));
            let is_top = |v| f.to_bits(v) == f.to_bits(top);
            let is_bottom = |v| f.to_bits(v) == f.to_bits(bottom);
            // per axis, uniform: direction sign, 1/d ends and whether each stands for ±∞
            let dneg: [bool; 3] = std::array::from_fn(|a| f.sign_bit(r.inv_d[a]));
            let inv_lo = r.inv_lo.map(bcast);
            let inv_hi = r.inv_hi.map(bcast);
            let lo_inf: [bool; 3] = std::array::from_fn(|a| is_bottom(r.inv_lo[a]));
            let hi_inf: [bool; 3] = std::array::from_fn(|a| is_top(r.inv_hi[a]));
            let all = $x::le($x::splat(0.0), $x::splat(0.0));
            let none = $x::lt($x::splat(0.0), $x::splat(0.0));
            let m = |b: bool| if b { all } else { none };
            let (o_hit, o_near, o_far) = (out.hit.as_mut_ptr(), out.t_near.as_mut_ptr(), out.t_far.as_mut_ptr());
            let mut nan_seen = 0;
            let mut i = 0;
            while i < $full {
                let (mut tn, mut tf) = prep.3;
                let mut outside = none;
                let mut bad = none;
                for a in 0..3 {
                    let o = prep.2 .0[a];
                    if r.parallel[a] {
                        let inside = $x::and_m($x::le(load(bmin[a], i), o), $x::le(o, load(bmax[a], i)));
                        outside = $x::or_m(outside, $x::not_m(inside));
                        continue;
                    }
                    let de = rd($x::sub(load(prep.0[a], i), o));
                    let dx = rd($x::sub(load(prep.1[a], i), o));
                    bad = $x::or_m(bad, $x::unord(de, dx));
                    // bracket end of the entry difference: d < 0 → its upper end, else its lower
                    let (x_e, x_e_inf) = if dneg[a] {
                        let v = up(de);
                        (v, $x::le(vtop, v))
                    } else {
                        let v = down(de);
                        (v, $x::le(v, vbottom))
                    };
                    let (x_x, x_x_inf) = if dneg[a] {
                        let v = down(dx);
                        (v, $x::le(v, vbottom))
                    } else {
                        let v = up(dx);
                        (v, $x::le(vtop, v))
                    };
                    // the 1/d end by the bracket end's sign: negative → inv_hi (entry) / inv_lo (exit)
                    let inv_e = $x::blend_sign(inv_lo[a], inv_hi[a], x_e);
                    let inv_e_inf = $x::blend_m(m(lo_inf[a]), m(hi_inf[a]), $x::sign_m(x_e));
                    let inv_x = $x::blend_sign(inv_hi[a], inv_lo[a], x_x);
                    let inv_x_inf = $x::blend_m(m(hi_inf[a]), m(lo_inf[a]), $x::sign_m(x_x));
                    let t_entry = $x::blend(down(rd($x::mul(x_e, inv_e))), vbottom, $x::or_m(x_e_inf, inv_e_inf));
                    let t_exit = $x::blend(up(rd($x::mul(x_x, inv_x))), vtop, $x::or_m(x_x_inf, inv_x_inf));
                    if $tof {
                        tn = $x::blend(t_entry, tn, $x::le(t_entry, tn));
                        tf = $x::blend(t_exit, tf, $x::le(tf, t_exit));
                    } else {
                        tn = $x::max(t_entry, tn);
                        tf = $x::min(t_exit, tf);
                    }
                }
                tn = $x::blend(tn, $x::canonical_nan(), bad);
                let hit = $x::and_m($x::not_m(outside), $x::le(tn, tf));
                // SAFETY: lanes i..i + L are in bounds.
                unsafe { $x::flags(o_hit, i, hit) };
                store(o_near, i, tn);
                store(o_far, i, tf);
                nan_seen |= $x::bits($x::unord(tn, tf));
                i += $x::LANES;
            }
            if nan_seen != 0 {
                // SAFETY: lanes 0..full are in bounds (as above).
                unsafe { slab_redo(s, SlabRays::One(r), boxes, (o_hit, o_near, o_far), $full) };
            }
        }};
        (@loop $x:ident, $s:expr, $shape:ident $r:ident, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $bcast:expr, $tof:expr) => {{
            let (s, boxes, out) = ($s, $boxes, $out);
            let (load, rd, store, up, bcast) = ($load, $round, $store, $up, $bcast);
            // next-down is next-up mirrored through the sign (negation is exact)
            let neg = |v| $x::xor(v, $x::splat(-0.0));
            let down = |v| neg(up(neg(v)));
            let bmin = boxes.min.each_ref().map(|c| c.as_ptr());
            let bmax = boxes.max.each_ref().map(|c| c.as_ptr());
            let prep = slab_kernel!(@prep $x, $shape $r, bmin, bmax, bcast);
            let _ = bcast; // the pairs shape broadcasts nothing
            let (o_hit, o_near, o_far) = (out.hit.as_mut_ptr(), out.t_near.as_mut_ptr(), out.t_far.as_mut_ptr());
            let widen = s.cfg.widen_ulps;
            // vmaxps / vminps return their second operand (the running t) when either is NaN,
            // and the widening steps keep a number a number, so the plain comparator's chains
            // end in NaN only if they start from a NaN t interval: a one-ray batch with a
            // number interval needs no NaN check per vector (take-on-false chains can take a
            // NaN plane and always check)
            // the conservative variant's guard: a stage-1 subtract that overflowed is NaN in the
            // model, and the plane it feeds is dropped; the kernel leaves it ±∞, which differs
            // from dropping it only when it leaves t_near = +∞ or t_far = −∞. Lanes with a
            // non-finite chain end (before widening) are marked NaN and redone by the model
            // (the reciprocal's guard is applied when the ray is prepared)
            let guard = s.cfg.guard;
            let zero = $x::splat(0.0);
            let check_nan = $tof || prep.4 || guard;
            let (r, model) = ($r, s);
            let mut nan_seen = 0;
            let mut i = 0;
            while i < $full {
                let (mut tn, mut tf) = slab_kernel!(@limits $shape prep, load, i);
                let p = [
                    slab_kernel!(@plane $x, $shape prep, bmin, bmax, load, rd, 0, i),
                    slab_kernel!(@plane $x, $shape prep, bmin, bmax, load, rd, 1, i),
                    slab_kernel!(@plane $x, $shape prep, bmin, bmax, load, rd, 2, i),
                ];
                for (near, far) in p {
                    if $tof {
                        // t = (x <= t) ? t : x (near), (t <= x) ? t : x (far)
                        tn = $x::blend(near, tn, $x::le(near, tn));
                        tf = $x::blend(far, tf, $x::le(tf, far));
                    } else {
                        // t = (x > t) ? x : t (near), (x < t) ? x : t (far): exactly vmaxps(x, t)
                        // and vminps(x, t), which return the second operand on NaN or equality
                        tn = $x::max(near, tn);
                        tf = $x::min(far, tf);
                    }
                }
                let ends = (tn, tf);
                for _ in 0..widen.unsigned_abs() {
                    if widen > 0 {
                        tn = down(tn);
                        tf = up(tf);
                    } else {
                        tn = up(tn);
                        tf = down(tf);
                    }
                }
                if guard {
                    let unbounded = $x::unord($x::mul(ends.0, zero), $x::mul(ends.1, zero));
                    tn = $x::blend(tn, $x::canonical_nan(), unbounded);
                }
                // SAFETY: lanes i..i + L are in bounds.
                unsafe { $x::flags(o_hit, i, $x::le(tn, tf)) };
                store(o_near, i, tn);
                store(o_far, i, tf);
                // NaN lanes are rare, and their bits depend on where the NaN came from (the
                // model canonicalises an arithmetic NaN but passes a NaN t interval through a
                // comparator as it is, payload and all, which binary16's widening would quiet):
                // noted here, done again by the scalar model after the loop
                if check_nan {
                    nan_seen |= $x::bits($x::unord(tn, tf));
                }
                i += $x::LANES;
            }
            if nan_seen != 0 {
                // SAFETY: lanes 0..full are in bounds (as above).
                unsafe { slab_redo(model, slab_kernel!(@rays $shape r), boxes, (o_hit, o_near, o_far), $full) };
            }
        }};
    }

    /// [`slab_kernel!`] with the format's subnormal rule: as it is under IEEE subnormals; under
    /// FTZ every operand read (columns and broadcast ray values) and every rounded result
    /// flushed in the lanes (a lane below `$min`, the smallest normal, becomes zero of its
    /// sign), and a grid step that lands strictly between 0 and `$min` goes on to `$min` (up
    /// from ±0) or to −0 (up from −`$min`), the model's `next_up`. The model's comparators read a
    /// t limit flushed but pass it on as it is, so a limit that is a nonzero subnormal encoding
    /// (`$raw_sub`) sends its lane, or the whole one-ray batch, to the scalar model.
    macro_rules! slab_ftz {
        ($x:ident, $s:expr, $rays:expr, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $bcast:expr, $min:expr, $raw_sub:expr) => {{
            let (s, rays, boxes, out, full) = ($s, $rays, $boxes, $out, $full);
            if s.fmt.opts.subnormals != Subnormals::Ftz {
                slab_kernel!($x, s, rays, boxes, out, full, $load, $round, $store, $up, $bcast);
            } else {
                let raw_sub = $raw_sub;
                if let SlabRays::One(r) = rays {
                    if raw_sub(r.tmin) || raw_sub(r.tmax) {
                        return s.batch_ray(r, boxes, out);
                    }
                }
                let (load, round, up, bcast) = ($load, $round, $up, $bcast);
                let (min, zero) = ($x::splat($min), $x::splat(0.0));
                let flush = move |x| $x::blend(x, $x::sign(x), $x::lt($x::abs(x), min));
                let up_ftz = move |v| {
                    let r = up(v);
                    let a = $x::abs(r);
                    let tiny = $x::and_m($x::lt(zero, a), $x::lt(a, min));
                    $x::blend(r, $x::blend(min, $x::splat(-0.0), $x::lt(v, zero)), tiny)
                };
                slab_kernel!(
                    $x,
                    s,
                    rays,
                    boxes,
                    &mut *out,
                    full,
                    |c, i| flush(load(c, i)),
                    |x| flush(round(x)),
                    $store,
                    up_ftz,
                    |v| flush(bcast(v))
                );
                if let SlabRays::Pairs(r) = rays {
                    for k in 0..full {
                        if raw_sub(r.tmin[k]) || raw_sub(r.tmax[k]) {
                            out.set(k, s.test(&r.get(k), &boxes.get(k)));
                        }
                    }
                }
            }
        }};
    }

    /// The lanes of `0..full` with a NaN output, again by the scalar model (the slab kernels'
    /// rare NaN path, kept out of their loops).
    ///
    /// # Safety
    /// The output pointers must be valid for lanes `0..full`.
    #[cold]
    #[inline(never)]
    pub(super) unsafe fn slab_redo<F: crate::Format>(
        s: &Slab<F>,
        rays: SlabRays<F::V>,
        boxes: &BoxesSoa<F::V>,
        (hit, near, far): (*mut bool, *mut F::V, *mut F::V),
        full: usize,
    ) {
        for k in 0..full {
            // SAFETY: k is in bounds (the caller).
            let nan = unsafe { s.fmt.is_nan(*near.add(k)) || s.fmt.is_nan(*far.add(k)) };
            if nan {
                let ray = match rays {
                    SlabRays::Pairs(r) => r.get(k),
                    SlabRays::One(r) => *r,
                };
                let o = s.test(&ray, &boxes.get(k));
                // SAFETY: as above.
                unsafe {
                    *hit.add(k) = o.hit;
                    *near.add(k) = o.t_near;
                    *far.add(k) = o.t_far;
                }
            }
        }
    }

    /// The kernels (RTI and slab) of one instruction set: binary32 and binary16, or binary16 only.
    macro_rules! kernels_for {
        ($x:ident, $f32feat:literal, $f16feat:literal) => {
            pub(in crate::simd) mod $x {
                use super::super::isa::$x;
                use super::*;
                kernels_for!(@f32 $x, $f32feat);
                kernels_for!(@f16 $x, $f16feat);
            }
        };
        ($x:ident, binary16 $f16feat:literal) => {
            pub(in crate::simd) mod $x {
                use super::super::isa::$x;
                use super::*;
                kernels_for!(@f16 $x, $f16feat);
            }
        };
        (@f32 $x:ident, $f32feat:literal) => {
            kernels_for!(@format $x, $f32feat, rti_f32, slab_f32, Ieee<F32Native>, f32, load32, store32,
                |x| x, |v| $x::next_up(v), |x: f32| $x::splat(x), |r: &Rti<Ieee<F32Native>>| r.det_thr,
                f32::MIN_POSITIVE, |v: f32| v != 0.0 && v.abs() < f32::MIN_POSITIVE);
        };
        (@f16 $x:ident, $f16feat:literal) => {
            kernels_for!(@format $x, $f16feat, rti_f16, slab_f16, Ieee<F16Half>, f16, load16, store16,
                |v| $x::round16(v), |v| $x::next_up16(v), |x: f16| $x::splat16(x),
                |r: &Rti<Ieee<F16Half>>| r.det_thr.to_f32(), f16::MIN_POSITIVE.to_f32(), |v: f16| v.to_bits() & 0x7c00 == 0 && v.to_bits() & 0x3ff != 0);
        };
        // one format's RTI and slab kernels: its column type, loads and stores, rounding, grid
        // step, ray broadcast, det threshold (as the lanes hold it), and smallest normal (the RTI
        // kernel under FTZ flushes every operand read and every rounded result in the lanes: a
        // lane below it becomes zero of its sign)
        (@format $x:ident, $feat:literal, $rti:ident, $slab:ident, $fmt:ty, $v:ty, $load:ident, $store:ident,
         $round:expr, $up:expr, $bcast:expr, $thr:expr, $min_normal:expr, $raw_sub:expr) => {
            #[target_feature(enable = $feat)]
            pub fn $rti(rti: &Rti<$fmt>, rays: &RaysSoa<$v>, tris: &TrisSoa<$v>, out: &mut HitsSoa<$v>, full: usize) {
                // SAFETY (loads and stores): the caller checked that every column holds
                // `full` lanes; the column types are plain values.
                macro_rules! run {
                    ($ld:expr, $rd:expr) => {
                        rti_kernel!(
                            $x,
                            rti,
                            rays,
                            tris,
                            out,
                            full,
                            $ld,
                            $rd,
                            |c: &mut Vec<$v>, i: usize, x| unsafe { $x::$store(c.as_mut_ptr(), i, x) },
                            ($thr)(rti),
                            || {},
                            |_: usize, _: usize, _: &[u32; 8], _: &mut HitsSoa<$v>| {}
                        )
                    };
                }
                let load = |c: &Vec<$v>, i: usize| unsafe { $x::$load(c.as_ptr(), i) };
                if rti.fmt.opts.subnormals == Subnormals::Ftz {
                    // (the comparator reads the threshold flushed, but det is ±0 or normal
                    // here, so a subnormal threshold decides as zero does)
                    let flush = |x| $x::blend(x, $x::sign(x), $x::lt($x::abs(x), $x::splat($min_normal)));
                    let round = $round;
                    run!(|c: &Vec<$v>, i: usize| flush(load(c, i)), |x| flush(round(x)));
                } else {
                    run!(load, $round);
                }
            }

            #[target_feature(enable = $feat)]
            pub fn $slab(s: &Slab<$fmt>, rays: SlabRays<$v>, boxes: &BoxesSoa<$v>, out: &mut SlabOutSoa<$v>, full: usize) {
                // SAFETY (loads and stores): as above.
                slab_ftz!(
                    $x,
                    s,
                    rays,
                    boxes,
                    out,
                    full,
                    |c: *const $v, i: usize| unsafe { $x::$load(c, i) },
                    $round,
                    |c: *mut $v, i: usize, x| unsafe { $x::$store(c, i, x) },
                    $up,
                    $bcast,
                    $min_normal,
                    $raw_sub
                );
            }
        };
    }

    kernels_for!(v8, "avx2", "avx2,f16c");
    kernels_for!(v16, "avx512f", "avx512f,avx2");
    kernels_for!(v32h, binary16 "avx512fp16,avx512bw,avx512f");

    /// The RTI kernels of the narrow `eEmM` formats (M ≤ 24 and E ≤ 10) on the binary64 lanes
    /// of one instruction set (`v4d`, `v8d`): the same stage table, every operation in
    /// binary64 then rounded to the format in the lanes, its whole range included
    /// ([`isa::v4d::round_full`]), and stages 2-7 by the split alone when the range filter
    /// ([`isa::v4d::fast_ok`]) proves them in range (see [`crate::format::narrow`]).
    macro_rules! narrow_for {
        ($x:ident, $feat:literal, $rtifeat:literal) => {
            pub(in crate::simd) mod $x {
                use super::super::isa::$x;
                use super::*;
                use crate::format::narrow::Narrow;
                use crate::format::Soft;

                /// One format's RTI kernel on lanes `0..full`: its column loads and stores.
                macro_rules! narrow_rti {
                    ($rti:expr, $rays:expr, $tris:expr, $out:expr, $full:expr, $v:ty, $load:expr, $store:expr) => {{
                        let (rti, rays, tris) = ($rti, $rays, $tris);
                        let n: &Narrow = &super::super::narrow_of(&rti.fmt).expect("the dispatch checked the format");
                        let load = $load;
                        rti_kernel!(
                            $x,
                            rti,
                            rays,
                            tris,
                            $out,
                            $full,
                            |c: &Vec<$v>, i: usize| $x::flush(load(c, i), n),
                            |x| $x::round_full(x, n),
                            |x| $x::split(x, n),
                            |b| $x::split_k(b, n),
                            |a, b, bk| $x::split_mul(a, b, bk),
                            |v: &[_; 12]| $x::fast_ok(v, n),
                            $store,
                            super::super::narrow_thr(rti, n),
                            || {},
                            |_: usize, _: usize, _: &[u32; 8], _: &mut HitsSoa<$v>| {}
                        )
                    }};
                }

                /// The `eEmM` RTI kernel on lanes `0..full`.
                #[target_feature(enable = $rtifeat)]
                pub fn rti_soft(
                    rti: &Rti<Ieee<Soft>>,
                    rays: &RaysSoa<u64>,
                    tris: &TrisSoa<u64>,
                    out: &mut HitsSoa<u64>,
                    full: usize,
                ) {
                    let n: &Narrow = &super::super::narrow_of(&rti.fmt).expect("the dispatch checked the format");
                    // SAFETY (loads and stores): as above. One loop per encoding shape, so that
                    // neither is decided per load.
                    if n.e8 {
                        narrow_rti!(
                            rti,
                            rays,
                            tris,
                            out,
                            full,
                            u64,
                            |c: &Vec<u64>, i: usize| unsafe { $x::load_e8(c.as_ptr(), i, n) },
                            |c: &mut Vec<u64>, i: usize, x| unsafe { $x::store_e8(c.as_mut_ptr(), i, x, n) }
                        );
                    } else {
                        narrow_rti!(
                            rti,
                            rays,
                            tris,
                            out,
                            full,
                            u64,
                            |c: &Vec<u64>, i: usize| unsafe { $x::load_soft(c.as_ptr(), i, n) },
                            |c: &mut Vec<u64>, i: usize, x| unsafe { $x::store_soft(c.as_mut_ptr(), i, x, n) }
                        );
                    }
                }

                /// The `eEmM` slab kernel (pairs, or one ray against every box) on lanes
                /// `0..full`, every variant (the directed one on one-ray batches), either
                /// subnormal mode (`slab_kernel_soft`, `slab_ray_kernel_soft`). Under FTZ the
                /// operands read flushed; a t limit that is a nonzero subnormal encoding (the
                /// model's comparators read it as zero but pass it on as it is) sends its lanes
                /// (one ray: the batch) to the scalar model.
                #[target_feature(enable = $feat)]
                pub fn slab_soft(
                    s: &Slab<Ieee<Soft>>,
                    rays: SlabRays<u64>,
                    boxes: &BoxesSoa<u64>,
                    out: &mut SlabOutSoa<u64>,
                    full: usize,
                ) {
                    let n: &Narrow = &super::super::narrow_of(&s.fmt).expect("the dispatch checked the format");
                    let f = s.fmt;
                    // SAFETY (loads and stores): the caller checked that every column holds
                    // `full` lanes.
                    slab_ftz!(
                        $x,
                        s,
                        rays,
                        boxes,
                        out,
                        full,
                        |c: *const u64, i: usize| unsafe { $x::load_soft(c, i, n) },
                        |x| $x::round_full(x, n),
                        |c: *mut u64, i: usize, x| unsafe { $x::store_soft(c, i, x, n) },
                        |v| $x::next_up_soft(v, n),
                        |v: u64| $x::splat(f.to_f64(v)),
                        n.min_normal,
                        |v: u64| n.lay.is_subnormal(v)
                    );
                }

                /// One operation of an `eEmM` format on lanes `0..full`: `out[i] = a[i] op b[i]`,
                /// each result rounded by [`isa::v4d::round_full`] (the RTI kernel's rounding).
                #[target_feature(enable = $feat)]
                pub fn op_soft(f: &Ieee<Soft>, op: crate::rti::Op, a: &[u64], b: &[u64], out: &mut [u64], full: usize) {
                    use crate::rti::Op;
                    let n = &super::super::narrow_of(f).expect("the dispatch checked the format");
                    let mut i = 0;
                    while i < full {
                        // SAFETY: the caller checked that every slice holds `full` lanes.
                        let (x, y) = unsafe { ($x::load_soft(a.as_ptr(), i, n), $x::load_soft(b.as_ptr(), i, n)) };
                        let (x, y) = ($x::flush(x, n), $x::flush(y, n));
                        let rd = |v| $x::round_full(v, n);
                        let r = match (op, f.opts.div) {
                            (Op::Add, _) => rd($x::add(x, y)),
                            (Op::Sub, _) => rd($x::sub(x, y)),
                            (Op::Mul, _) => rd($x::mul(x, y)),
                            (Op::Div, DivMode::Divide) => rd($x::div(x, y)),
                            (Op::Div, DivMode::RecipMul) => {
                                let inv = rd($x::div($x::splat(1.0), y));
                                rd($x::mul(x, inv))
                            }
                            (Op::Logic, _) => unreachable!("the dispatch refuses Logic"),
                        };
                        // SAFETY: as above; a NaN lane is stored as the canonical NaN.
                        unsafe { $x::store_soft(out.as_mut_ptr(), i, r, n) };
                        i += $x::LANES;
                    }
                }
            }
        };
    }

    /// The bf16 RTI kernel on binary32 lanes of one instruction set (`v8`, `v16`): the scalar
    /// model's own arithmetic (each operation in binary32, then rounded to bf16 in the
    /// integer lanes), the operand read and the result write flushed under FTZ.
    macro_rules! bf16_for {
        ($m:ident, $x:ident, $feat:literal) => {
            pub(in crate::simd) mod $m {
                use super::super::isa::$x;
                use super::*;
                use crate::format::Bf16;

                /// The bf16 RTI kernel on lanes `0..full`.
                #[target_feature(enable = $feat)]
                pub fn rti_bf16(
                    rti: &Rti<Ieee<Bf16>>,
                    rays: &RaysSoa<u16>,
                    tris: &TrisSoa<u16>,
                    out: &mut HitsSoa<u16>,
                    full: usize,
                ) {
                    let ftz = rti.fmt.opts.subnormals == Subnormals::Ftz;
                    let thr = rti.fmt.to_f64(rti.det_thr) as f32;
                    let thr = if ftz && thr.abs() < f32::MIN_POSITIVE { 0.0 } else { thr };
                    // SAFETY (loads and stores): the caller checked that every column holds
                    // `full` lanes; the column types are plain values.
                    rti_kernel!(
                        $x,
                        rti,
                        rays,
                        tris,
                        out,
                        full,
                        |c: &Vec<u16>, i: usize| $x::flush_bf16(unsafe { $x::load_bf16(c.as_ptr(), i) }, ftz),
                        |x| $x::flush_bf16($x::round_bf16(x), ftz),
                        |c: &mut Vec<u16>, i: usize, x| unsafe { $x::store_bf16(c.as_mut_ptr(), i, x) },
                        thr,
                        || {},
                        |_: usize, _: usize, _: &[u32; 8], _: &mut HitsSoa<u16>| {}
                    );
                }

                /// The bf16 slab kernel on lanes `0..full`, IEEE subnormals or FTZ ([`slab_ftz!`]).
                #[target_feature(enable = $feat)]
                pub fn slab_bf16(
                    s: &Slab<Ieee<Bf16>>,
                    rays: SlabRays<u16>,
                    boxes: &BoxesSoa<u16>,
                    out: &mut SlabOutSoa<u16>,
                    full: usize,
                ) {
                    // SAFETY (loads and stores): the caller checked that every column holds
                    // `full` lanes; the column types are plain values.
                    slab_ftz!(
                        $x,
                        s,
                        rays,
                        boxes,
                        out,
                        full,
                        |c: *const u16, i: usize| unsafe { $x::load_bf16(c, i) },
                        |x| $x::round_bf16(x),
                        |c: *mut u16, i: usize, x| unsafe { $x::store_bf16(c, i, x) },
                        |v| $x::next_up_bf16(v),
                        |x: u16| $x::splat(f32::from_bits((x as u32) << 16)),
                        f32::MIN_POSITIVE,
                        |v: u16| v & 0x7f80 == 0 && v & 0x7f != 0
                    );
                }
            }
        };
    }

    bf16_for!(b8, v8, "avx2");
    bf16_for!(b16, v16, "avx512f,avx2");

    narrow_for!(v4d, "avx2,fma", "avx2,fma");
    // the RTI kernel's range filter uses AVX-512DQ's `vrangepd` ([`isa::v8d::fast_ok`])
    narrow_for!(v8d, "avx512f,avx2", "avx512f,avx512dq,avx2");
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::isa::{v4d, v8d};
    use crate::format::{Ieee, Soft};
    use crate::Format;

    /// The range filter of both binary64-lane ISAs passes a vector exactly when, on every lane,
    /// every one of the twelve values is ±0 or a magnitude in [`fast_lo`, `fast_hi`] (the
    /// predicate of `datapath::format::narrow`, written here per value): NaNs, infinities,
    /// zeros, the limits and their neighbours, one odd value in one lane among ordinary ones.
    #[test]
    fn the_range_filter_is_the_documented_predicate() {
        use crate::rng::SplitMix64;
        use std::arch::is_x86_feature_detected as has;
        for name in ["e8m16", "e10m24", "e8m7", "e6m9"] {
            let crate::AnyFormat::Soft(f) = name.parse::<crate::AnyFormat>().unwrap() else { unreachable!() };
            let n = super::narrow_of(&f).unwrap();
            let (lo, hi) = (n.fast_lo, n.fast_hi);
            let odd = [
                f64::NAN,
                -f64::NAN,
                f64::INFINITY,
                f64::NEG_INFINITY,
                0.0,
                -0.0,
                lo,
                -lo,
                hi,
                -hi,
                lo * (1.0 - f64::EPSILON / 2.0),
                -lo * (1.0 - f64::EPSILON / 2.0),
                hi * (1.0 + f64::EPSILON),
                -hi * (1.0 + f64::EPSILON),
                lo / 2.0,
                hi * 2.0,
                f64::MIN_POSITIVE,
                f64::MAX,
            ];
            let ordinary = (lo * hi).sqrt();
            let pass = |x: f64| !x.is_nan() && x.abs() <= hi && (x == 0.0 || x.abs() >= lo);
            let mut r = SplitMix64::new(0xf11);
            for round in 0..4000 {
                // every value ordinary, then one to three odd values at random places
                let mut v = [[ordinary; 8]; 12];
                for _ in 0..round % 4 {
                    v[r.below(12) as usize][r.below(8) as usize] = odd[r.below(odd.len() as u64) as usize];
                }
                let want = v.iter().flatten().all(|&x| pass(x));
                if has!("avx2") && has!("fma") {
                    for half in 0..2 {
                        let w: [std::arch::x86_64::__m256d; 12] = std::array::from_fn(|k| {
                            let l = &v[k][4 * half..4 * half + 4];
                            // SAFETY: the features were detected.
                            unsafe { std::mem::transmute::<[f64; 4], _>([l[0], l[1], l[2], l[3]]) }
                        });
                        let want = v.iter().all(|l| l[4 * half..4 * half + 4].iter().all(|&x| pass(x)));
                        // SAFETY: the features were detected.
                        assert_eq!(unsafe { v4d::fast_ok(&w, &n) }, want, "{name} v4d {v:?}");
                    }
                }
                if has!("avx512f") && has!("avx512dq") {
                    // SAFETY: the features were detected.
                    let w: [std::arch::x86_64::__m512d; 12] =
                        std::array::from_fn(|k| unsafe { std::mem::transmute::<[f64; 8], _>(v[k]) });
                    // SAFETY: the features were detected.
                    assert_eq!(unsafe { v8d::fast_ok(&w, &n) }, want, "{name} v8d {v:?}");
                }
            }
        }
    }

    /// The lanes' grid step equals the model's `next_up` on every encoding of small formats
    /// (subnormals, ±0, ±max, ±∞ dense), on every binary64-lane ISA here. (Under FTZ the step
    /// goes through `slab_ftz!`, held to the model by the slab proptests in `:ftz`.)
    #[test]
    fn next_up_in_binary64_lanes_equals_the_model_on_every_encoding() {
        use std::arch::is_x86_feature_detected as has;
        for name in ["e5m4", "e4m3", "e3m2", "e2m1", "e8m7", "e5m10", "e6m9"] {
            let crate::AnyFormat::Soft(f) = name.parse::<crate::AnyFormat>().unwrap() else { unreachable!() };
            let f: Ieee<Soft> = f;
            let n = super::narrow_of(&f).unwrap();
            let lay = n.lay;
            let vals: Vec<u64> = (0..1u64 << lay.width()).filter(|&b| !lay.is_nan(b)).collect();
            for &b in &vals {
                let want = f.to_f64(f.next_up(f.from_bits(b)));
                let x = f.to_f64(f.from_bits(b));
                let mut got = Vec::new();
                if has!("avx2") && has!("fma") {
                    // SAFETY: the features were detected.
                    let v = unsafe {
                        std::mem::transmute::<std::arch::x86_64::__m256d, [f64; 4]>(v4d::next_up_soft(
                            v4d::splat(x),
                            &n,
                        ))
                    };
                    got.push(v[0]);
                }
                if has!("avx512f") {
                    // SAFETY: the feature was detected.
                    let v = unsafe {
                        std::mem::transmute::<std::arch::x86_64::__m512d, [f64; 8]>(v8d::next_up_soft(
                            v8d::splat(x),
                            &n,
                        ))
                    };
                    got.push(v[0]);
                }
                for g in got {
                    assert_eq!(g.to_bits(), want.to_bits(), "{name}: next_up({x:e}) = {g:e}, the model {want:e}");
                }
            }
        }
    }
}
