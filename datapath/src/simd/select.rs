//! Kernel selection: the instruction sets ([`Kernel`]), what this machine and thread may use,
//! and the generic dispatch that runs a kernel over a batch's full vectors and the scalar model
//! over the rest (for RTI and slab batches, of any format with lanes).

use crate::format::narrow::Narrow;
use crate::format::{Ieee, IeeeBackend, NanMode};
use crate::rti::{HitsSoa, RaysSoa, Rti, TrisSoa};
use crate::slab::{BoxesSoa, Slab, SlabOutSoa, SlabRay, SlabRaysSoa};
use crate::Format as _;

use super::isa;

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
pub(super) static PROCESS_CAP: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(Kernel::Avx512Fp16 as u8);

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
pub(super) fn widest_here() -> Kernel {
    let all = [Kernel::Scalar, Kernel::Avx2, Kernel::Avx512, Kernel::Avx512Fp16];
    let cap = all[PROCESS_CAP.load(std::sync::atomic::Ordering::Relaxed) as usize];
    detected().min(cap)
}

/// The widest kernel this machine's features allow, detected once.
pub(super) fn detected() -> Kernel {
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
pub(super) fn eligible<B: crate::format::IeeeBackend>(f: &Ieee<B>) -> bool {
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

/// The lanes a binary64 block body (the error bound, the static filter, its block maxima)
/// runs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum F64Lanes {
    /// Eight lanes of AVX-512F.
    Avx512,
    /// Four lanes of AVX2.
    Avx2,
    /// The baseline loop (the compiler's choice of instructions).
    Baseline,
}

/// The widest binary64 lanes the machine has (AVX-512F or AVX2, detected) within `cap` and
/// this thread's and the process's caps: a body for [`F64Lanes::Avx512`] or
/// [`F64Lanes::Avx2`] may be called with that feature enabled.
pub(crate) fn f64_lanes(cap: Kernel) -> F64Lanes {
    let cap = best_kernel(true, cap);
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        if cap >= Kernel::Avx512 && has!("avx512f") {
            return F64Lanes::Avx512;
        }
        if cap >= Kernel::Avx2 && has!("avx2") {
            return F64Lanes::Avx2;
        }
    }
    let _ = cap;
    F64Lanes::Baseline
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
pub(super) fn pick<K>(which: Kernel, table: Table<K>) -> Option<(K, usize)> {
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

/// The binary64-lane constants of a float format, when its narrow batch path applies.
pub(super) fn narrow_of<B: IeeeBackend>(f: &Ieee<B>) -> Option<Narrow> {
    Narrow::of(f.backend.layout(), f.opts)
}

/// The det threshold as the narrow kernels' lanes hold it (read-flushed under FTZ).
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(super) fn narrow_thr<B: IeeeBackend>(rti: &Rti<Ieee<B>>, n: &Narrow) -> f64 {
    let t = rti.fmt.to_f64(rti.det_thr);
    if n.ftz && t.abs() < n.min_normal {
        0.0
    } else {
        t
    }
}

/// Every box and output column holds `n` slots.
pub(super) fn slab_columns_ok<V>(boxes: &BoxesSoa<V>, out: &SlabOutSoa<V>, n: usize) -> bool {
    boxes.min.iter().chain(&boxes.max).all(|c| c.len() == n)
        && out.hit.len() == n
        && out.t_near.len() == n
        && out.t_far.len() == n
}

/// Every ray column holds `n` slots.
pub(super) fn slab_rays_ok<V>(rays: &SlabRaysSoa<V>, n: usize) -> bool {
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

/// Variants at most in one shared slab batch (`slab_kernel!`'s `@mloop`, the fixed-point
/// `slab_shared_loop`).
pub(crate) const MAX_SHARED: usize = 8;

/// The signature of a shared slab kernel: several round-to-nearest variants of one format on
/// one ray and the same boxes, lanes `0..full` of every column, `outs[j]` for `group[j]`.
#[cfg(target_arch = "x86_64")]
pub(crate) type SharedSlabFn<F> = unsafe fn(
    &[&Slab<F>],
    &SlabRay<<F as crate::Format>::V>,
    &BoxesSoa<<F as crate::Format>::V>,
    &mut [SlabOutSoa<<F as crate::Format>::V>],
    usize,
);

/// Runs the shared slab kernel of `table` that `which(group[0])` names on the full vectors
/// and each variant's scalar model on the rest, when the group qualifies: one to
/// [`MAX_SHARED`] variants, as many rays and outputs; every variant of the first's format,
/// not directed, and `eligible`; every prepared ray's origin, 1/d and t interval the first's
/// bit for bit (the loops read nothing else of a ray); every column the boxes' length; a
/// kernel for it on this machine. Returns that kernel, or `None`, nothing written, otherwise.
pub(crate) fn shared_dispatch<F: crate::Format + PartialEq>(
    group: &[&Slab<F>],
    rays: &[&SlabRay<F::V>],
    boxes: &BoxesSoa<F::V>,
    outs: &mut [SlabOutSoa<F::V>],
    eligible: impl Fn(&Slab<F>) -> bool,
    which: impl Fn(&Slab<F>) -> Kernel,
    #[cfg(target_arch = "x86_64")] table: Table<SharedSlabFn<F>>,
) -> Option<Kernel> {
    let (s0, r0) = (group.first()?, rays.first()?);
    let f = &s0.fmt;
    let same = |a: &[F::V], b: &[F::V]| a.iter().zip(b).all(|(&x, &y)| f.to_bits(x) == f.to_bits(y));
    let same_ray = |r: &&SlabRay<F::V>| {
        same(&r.o, &r0.o) && same(&r.inv_d, &r0.inv_d) && same(&[r.tmin, r.tmax], &[r0.tmin, r0.tmax])
    };
    let n = boxes.min[0].len();
    let ok = group.len() == rays.len()
        && group.len() == outs.len()
        && group.len() <= MAX_SHARED
        && group.iter().all(|s| s.fmt == s0.fmt && !s.cfg.directed && eligible(s))
        && rays.iter().all(same_ray)
        && outs.iter().all(|o| slab_columns_ok(boxes, o, n));
    if !ok {
        return None;
    }
    let which = which(s0);
    #[cfg(target_arch = "x86_64")]
    if let Some((kernel, lanes)) = pick(which, table) {
        let full = n / lanes * lanes;
        // SAFETY: `which` names a kernel only after run-time feature detection; every column
        // holds n >= full slots (checked above); the variants qualify (checked)
        unsafe { kernel(group, r0, boxes, outs, full) };
        for ((s, r), o) in group.iter().zip(rays).zip(outs.iter_mut()) {
            s.batch_ray_from(r, boxes, o, full);
        }
        return Some(which);
    }
    let _ = which;
    None
}
