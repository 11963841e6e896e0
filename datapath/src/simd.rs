//! SIMD batch kernels of the RTI and slab models, bit-identical to the scalar models, with
//! runtime dispatch.
//!
//! One kernel body per unit (the `rti_kernel!` and `slab_kernel!` macros) is instantiated for
//! binary32 and binary16 on AVX2 (+ F16C for binary16), eight tests per vector, in the stage
//! table's exact operation order with separate multiplies and adds (no FMA). binary16 computes
//! every operation in binary32 and rounds it to binary16 at once (`vcvtps2ph` nearest-even,
//! then back): binary32's 24 bits are at least 2·11 + 2, so this double rounding is innocuous
//! for + − × ÷ and the result is the correctly rounded binary16 operation, subnormals and
//! overflow included; compares and min/max of binary16 values held in binary32 are exact.
//! NaN payloads never influence a non-NaN result or a compare, so the kernels canonicalise NaN
//! only where a value leaves them, and only when a movemask shows a NaN lane.
//!
//! The slab kernels take either pairs (ray i against box i) or one ray against every box (a
//! node's children, a level): the second reads only the six box columns and picks each axis's
//! near plane once per batch. The plain comparator `t = (x > t) ? x : t` is exactly `vmaxps(x,
//! t)` (the second operand on NaN or equality, ±0 included), so it costs one instruction.
//!
//! Eligible formats: IEEE subnormals and canonical NaN (either division mode, either culling;
//! every slab variant but the directed one); others, and machines without AVX2, run the
//! scalar model, as does a det threshold that is negative or NaN (the RTI kernels' sign-flip
//! side tests need det_ok to exclude det = ±0). Columns are processed 8 lanes at a time
//! straight from the SoA inputs; a batch's last `n mod 8` slots run the scalar model.
//!
//! No AVX-512 kernels: the machines this suite is developed and tested on have none, and a
//! kernel that no test has run is not offered.

use crate::format::{DivMode, F16Half, F32Native, Ieee, NanMode, Subnormals};
use crate::rti::{Cull, HitsSoa, RaysSoa, Rti, TrisSoa};
use crate::slab::{BoxesSoa, Slab, SlabNan, SlabOutSoa, SlabRay, SlabRaysSoa};
use half::f16;

/// Which implementation ran.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// AVX2 (binary32) or AVX2 + F16C (binary16), 8 lanes.
    Avx2,
    /// The scalar model.
    Scalar,
}

fn eligible<B: crate::format::IeeeBackend>(f: &Ieee<B>) -> bool {
    f.opts.subnormals == Subnormals::Ieee && f.opts.nan == NanMode::Canonical
}

/// The kernel `rti_batch_f32` uses for this unit on this machine.
pub fn kernel_f32(rti: &Rti<Ieee<F32Native>>) -> Kernel {
    #[cfg(target_arch = "x86_64")]
    if eligible(&rti.fmt) && rti.det_thr >= 0.0 && std::arch::is_x86_feature_detected!("avx2") {
        return Kernel::Avx2;
    }
    let _ = rti;
    Kernel::Scalar
}

/// The kernel `rti_batch_f16` uses for this unit on this machine.
pub fn kernel_f16(rti: &Rti<Ieee<F16Half>>) -> Kernel {
    #[cfg(target_arch = "x86_64")]
    if eligible(&rti.fmt)
        && rti.det_thr.to_f32() >= 0.0
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("f16c")
    {
        return Kernel::Avx2;
    }
    let _ = rti;
    Kernel::Scalar
}

/// The signature of an RTI kernel: lanes `0..full` of every column.
#[cfg(target_arch = "x86_64")]
type RtiKernelFn<F> = unsafe fn(
    &Rti<F>,
    &RaysSoa<<F as crate::Format>::V>,
    &TrisSoa<<F as crate::Format>::V>,
    &mut HitsSoa<<F as crate::Format>::V>,
    usize,
);

/// Every column of an RTI batch holds `n` slots.
fn rti_columns_ok<V>(rays: &RaysSoa<V>, tris: &TrisSoa<V>, out: &HitsSoa<V>, n: usize) -> bool {
    rays.o.iter().chain(&rays.d).all(|c| c.len() == n)
        && rays.tmax.len() == n
        && tris.v.iter().flatten().all(|c| c.len() == n)
        && out.valid.len() == n
        && [&out.t, &out.u, &out.v].iter().all(|c| c.len() == n)
}

/// Runs `kernel` (when `which` is AVX2 and every column has the batch's length) on the full
/// 8-lane vectors and the scalar model on the rest; otherwise the scalar model throughout.
fn rti_dispatch<F: crate::Format>(
    rti: &Rti<F>,
    rays: &RaysSoa<F::V>,
    tris: &TrisSoa<F::V>,
    out: &mut HitsSoa<F::V>,
    which: Kernel,
    #[cfg(target_arch = "x86_64")] kernel: RtiKernelFn<F>,
) -> Kernel {
    let n = rays.len();
    assert!(tris.len() == n && out.len() == n, "batch lengths differ");
    #[cfg(target_arch = "x86_64")]
    if which == Kernel::Avx2 && rti_columns_ok(rays, tris, out, n) {
        let full = n / 8 * 8;
        // SAFETY: `which` is AVX2 only after run-time feature detection; every column holds
        // n >= full slots (checked above).
        unsafe { kernel(rti, rays, tris, out, full) };
        rti.batch_from(rays, tris, out, full);
        return Kernel::Avx2;
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
        avx2::rti_f32,
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
        avx2::rti_f16,
    )
}

/// The kernel `slab_batch_f32` / `slab_ray_f32` use for this unit on this machine (the
/// round-to-nearest variants; the directed one runs the scalar model).
pub fn slab_kernel_f32(s: &Slab<Ieee<F32Native>>) -> Kernel {
    #[cfg(target_arch = "x86_64")]
    if eligible(&s.fmt) && !s.cfg.directed && std::arch::is_x86_feature_detected!("avx2") {
        return Kernel::Avx2;
    }
    let _ = s;
    Kernel::Scalar
}

/// The kernel `slab_batch_f16` / `slab_ray_f16` use for this unit on this machine.
pub fn slab_kernel_f16(s: &Slab<Ieee<F16Half>>) -> Kernel {
    #[cfg(target_arch = "x86_64")]
    if eligible(&s.fmt)
        && !s.cfg.directed
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("f16c")
    {
        return Kernel::Avx2;
    }
    let _ = s;
    Kernel::Scalar
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
enum SlabRays<'a, V> {
    Pairs(&'a SlabRaysSoa<V>),
    One(&'a SlabRay<V>),
}

/// The signature of a slab kernel: lanes `0..full` of every column.
#[cfg(target_arch = "x86_64")]
type SlabKernelFn<F> = unsafe fn(
    &Slab<F>,
    SlabRays<<F as crate::Format>::V>,
    &BoxesSoa<<F as crate::Format>::V>,
    &mut SlabOutSoa<<F as crate::Format>::V>,
    usize,
);

/// Runs `kernel` (when `which` is AVX2 and every column has the batch's length) on the full
/// 8-lane vectors and the scalar model on the rest; otherwise the scalar model throughout.
fn slab_dispatch<F: crate::Format>(
    s: &Slab<F>,
    rays: SlabRays<F::V>,
    boxes: &BoxesSoa<F::V>,
    out: &mut SlabOutSoa<F::V>,
    which: Kernel,
    #[cfg(target_arch = "x86_64")] kernel: SlabKernelFn<F>,
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
    if which == Kernel::Avx2 && rays_ok && slab_columns_ok(boxes, out, n) {
        let full = n / 8 * 8;
        // SAFETY: `which` is AVX2 only after run-time feature detection; every column holds
        // n >= full slots (checked above).
        unsafe { kernel(s, rays, boxes, out, full) };
        match rays {
            SlabRays::Pairs(r) => s.batch_from(r, boxes, out, full),
            SlabRays::One(r) => s.batch_ray_from(r, boxes, out, full),
        }
        return Kernel::Avx2;
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
    ($(#[$doc:meta])* $name:ident, $fmt:ty, $v:ty, $rays:ty, $shape:ident, $which:ident, $kernel:ident) => {
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
                avx2::$kernel,
            )
        }
    };
}

slab_entry!(
    /// [`Slab::batch`] for binary32 on the fastest kernel available; the same bits.
    slab_batch_f32, Ieee<F32Native>, f32, SlabRaysSoa<f32>, Pairs, slab_kernel_f32, slab_f32
);
slab_entry!(
    /// [`Slab::batch_ray`] (one ray, many boxes) for binary32 on the fastest kernel available; the same bits.
    slab_ray_f32, Ieee<F32Native>, f32, SlabRay<f32>, One, slab_kernel_f32, slab_f32
);
slab_entry!(
    /// [`Slab::batch`] for binary16 on the fastest kernel available; the same bits.
    slab_batch_f16, Ieee<F16Half>, f16, SlabRaysSoa<f16>, Pairs, slab_kernel_f16, slab_f16
);
slab_entry!(
    /// [`Slab::batch_ray`] (one ray, many boxes) for binary16 on the fastest kernel available; the same bits.
    slab_ray_f16, Ieee<F16Half>, f16, SlabRay<f16>, One, slab_kernel_f16, slab_f16
);

/// The body of a format-generic dispatch: calls `$f32` (or `$f16`) when the unit and its
/// columns are the binary32 (binary16) types, the scalar model `$scalar` otherwise.
macro_rules! by_format {
    ($unit:expr, $a:expr, $b:expr, $out:expr, $f32:ident, $f16:ident, $scalar:expr) => {{
        use std::any::Any;
        let (unit, a, b) = ($unit as &dyn Any, $a as &dyn Any, $b as &dyn Any);
        if let (Some(unit), Some(a), Some(b)) = (unit.downcast_ref(), a.downcast_ref(), b.downcast_ref()) {
            return $f32(
                unit,
                a,
                b,
                ($out as &mut dyn Any).downcast_mut().expect("the output type follows the format"),
            );
        }
        if let (Some(unit), Some(a), Some(b)) = (unit.downcast_ref(), a.downcast_ref(), b.downcast_ref()) {
            return $f16(
                unit,
                a,
                b,
                ($out as &mut dyn Any).downcast_mut().expect("the output type follows the format"),
            );
        }
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
    by_format!(rti, rays, tris, out, rti_batch_f32, rti_batch_f16, rti.batch(rays, tris, out))
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
    by_format!(s, rays, boxes, out, slab_batch_f32, slab_batch_f16, s.batch(rays, boxes, out))
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
    by_format!(s, ray, boxes, out, slab_ray_f32, slab_ray_f16, s.batch_ray(ray, boxes, out))
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

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::*;
    use std::arch::x86_64::*;

    /// The RTI stage table on 8 lanes. `$load(column, i)` gives 8 binary32 lanes,
    /// `$round(x)` rounds a binary32 result to the format, `$store(column, i, x)` writes 8
    /// results, `$thr` is the det threshold as binary32, `$nan` the canonical NaN as binary32.
    macro_rules! rti_kernel {
        ($rti:expr, $rays:expr, $tris:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $thr:expr, $nan:expr) => {{
            // one loop per (culling, division mode), so that neither is decided per vector
            let backface = $rti.cull == Cull::Backface;
            match ($rti.fmt.opts.div, backface) {
                (DivMode::RecipMul, false) => rti_kernel!(@loop $rti, $rays, $tris, $out, $full, $load, $round, $store, $thr, $nan, false, true),
                (DivMode::RecipMul, true) => rti_kernel!(@loop $rti, $rays, $tris, $out, $full, $load, $round, $store, $thr, $nan, true, true),
                (DivMode::Divide, false) => rti_kernel!(@loop $rti, $rays, $tris, $out, $full, $load, $round, $store, $thr, $nan, false, false),
                (DivMode::Divide, true) => rti_kernel!(@loop $rti, $rays, $tris, $out, $full, $load, $round, $store, $thr, $nan, true, false),
            }
        }};
        (@loop $rti:expr, $rays:expr, $tris:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $thr:expr, $nan:expr, $backface:expr, $recip:expr) => {{
            let (rays, tris, out) = ($rays, $tris, $out);
            let load = $load;
            let rd = $round;
            let store = $store;
            let sub = |a, b| rd(_mm256_sub_ps(a, b));
            let add = |a, b| rd(_mm256_add_ps(a, b));
            let mul = |a, b| rd(_mm256_mul_ps(a, b));
            let div = |a, b| rd(_mm256_div_ps(a, b));
            let le = |a, b| _mm256_cmp_ps::<_CMP_LE_OQ>(a, b);
            let lt = |a, b| _mm256_cmp_ps::<_CMP_LT_OQ>(a, b);
            let thr = _mm256_set1_ps($thr);
            let zero = _mm256_setzero_ps();
            let one = _mm256_set1_ps(1.0);
            let sign = _mm256_set1_ps(-0.0);
            let nan = $nan;
            // Two passes over blocks of BLOCK vectors (software pipelining): the first runs
            // stages 1-6 and keeps det, u', v' and t'; the second runs stage 7, divides and
            // stores.
            // The divide's latency then overlaps the next block's arithmetic instead of
            // filling the scheduler with instructions that wait for it.
            const BLOCK: usize = 8;
            let mut keep = [[zero; 4]; BLOCK];
            let mut base = 0;
            while base < $full {
                let nv = (($full - base) / 8).min(BLOCK);
                for (k, slot) in keep.iter_mut().enumerate().take(nv) {
                    let i = base + 8 * k;
                    let [ox, oy, oz] = [0, 1, 2].map(|a| load(&rays.o[a], i));
                    let [dx, dy, dz] = [0, 1, 2].map(|a| load(&rays.d[a], i));
                    let v = |k: usize, a: usize| load(&tris.v[k][a], i);
                    let (v0x, v0y, v0z) = (v(0, 0), v(0, 1), v(0, 2));
                    // stage 1
                    let (e1x, e1y, e1z) = (sub(v(1, 0), v0x), sub(v(1, 1), v0y), sub(v(1, 2), v0z));
                    let (e2x, e2y, e2z) = (sub(v(2, 0), v0x), sub(v(2, 1), v0y), sub(v(2, 2), v0z));
                    let (sx, sy, sz) = (sub(ox, v0x), sub(oy, v0y), sub(oz, v0z));
                    // stages 2, 3: p = d x e2, q = s x e1
                    let px = sub(mul(dy, e2z), mul(dz, e2y));
                    let py = sub(mul(dz, e2x), mul(dx, e2z));
                    let pz = sub(mul(dx, e2y), mul(dy, e2x));
                    let qx = sub(mul(sy, e1z), mul(sz, e1y));
                    let qy = sub(mul(sz, e1x), mul(sx, e1z));
                    let qz = sub(mul(sx, e1y), mul(sy, e1x));
                    // stages 4-6: (x + y) + z
                    let det = add(add(mul(e1x, px), mul(e1y, py)), mul(e1z, pz));
                    let up = add(add(mul(sx, px), mul(sy, py)), mul(sz, pz));
                    let vp = add(add(mul(dx, qx), mul(dy, qy)), mul(dz, qz));
                    let tp = add(add(mul(e2x, qx), mul(e2y, qy)), mul(e2z, qz));
                    *slot = [det, up, vp, tp];
                }
                for (k, &[det, up, vp, tp]) in keep.iter().enumerate().take(nv) {
                    let i = base + 8 * k;
                    // stage 7
                    let uv = add(up, vp);
                    // The compares of stage 7, with the det-sign select done by a sign flip:
                    // when `det_ok` holds, det is neither ±0 nor NaN (threshold >= 0, checked
                    // by the dispatch), so `det > 0 ? a <= b : b <= a` equals `a^s <= b^s`
                    // with s = det's sign bit (negation is exact): `valid` is the same bit.
                    let abs_det = _mm256_andnot_ps(sign, det);
                    let det_ok = if $backface { lt(thr, det) } else { lt(thr, abs_det) };
                    let s = _mm256_and_ps(sign, det);
                    let nonneg = |x| le(zero, _mm256_xor_ps(x, s));
                    let valid = _mm256_and_ps(
                        _mm256_and_ps(det_ok, nonneg(up)),
                        _mm256_and_ps(_mm256_and_ps(nonneg(vp), le(_mm256_xor_ps(uv, s), abs_det)), nonneg(tp)),
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
                    let hit = _mm256_and_ps(valid, _mm256_and_ps(le(tmin, t), le(t, tmax)));
                    let (hm, vm) = (_mm256_movemask_ps(hit) as usize, _mm256_movemask_ps(valid) as usize);
                    // SAFETY: lanes i..i + 8 are in bounds (checked by the caller); every
                    // byte written is 0 or 1, a valid bool.
                    unsafe {
                        (out.hit.as_mut_ptr().add(i) as *mut u64).write_unaligned(SPREAD[hm]);
                        (out.valid.as_mut_ptr().add(i) as *mut u64).write_unaligned(SPREAD[vm]);
                    }
                    // NaN lanes are rare: canonicalise only when one of the 24 results is NaN
                    let any_nan =
                        _mm256_or_ps(_mm256_cmp_ps::<_CMP_UNORD_Q>(t, u), _mm256_cmp_ps::<_CMP_UNORD_Q>(w, w));
                    let (t, u, w) = if _mm256_movemask_ps(any_nan) == 0 {
                        (t, u, w)
                    } else {
                        (canon(t, nan), canon(u, nan), canon(w, nan))
                    };
                    store(&mut out.t, i, t);
                    store(&mut out.u, i, u);
                    store(&mut out.v, i, w);
                }
                base += 8 * nv;
            }
        }};
    }

    /// An 8-bit lane mask spread to 8 bytes of 0 / 1 (lane k in byte k).
    const SPREAD: [u64; 256] = {
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

    /// The next binary32 encoding above each lane (NaN and +inf unchanged, ±0 to the
    /// smallest subnormal), as the scalar model's `next_up` with IEEE subnormals.
    #[target_feature(enable = "avx2")]
    fn next_up(v: __m256) -> __m256 {
        let b = _mm256_castps_si256(v);
        let keep = _mm256_or_si256(
            _mm256_castps_si256(_mm256_cmp_ps::<_CMP_UNORD_Q>(v, v)),
            _mm256_cmpeq_epi32(b, _mm256_set1_epi32(0x7f80_0000)),
        );
        let zero = _mm256_cmpeq_epi32(_mm256_and_si256(b, _mm256_set1_epi32(0x7fff_ffff)), _mm256_setzero_si256());
        // negative: bits - 1, positive: bits + 1
        let step = _mm256_or_si256(_mm256_srai_epi32::<31>(b), _mm256_set1_epi32(1));
        let r = _mm256_add_epi32(b, step);
        let r = _mm256_blendv_epi8(r, _mm256_set1_epi32(1), zero);
        _mm256_castsi256_ps(_mm256_blendv_epi8(r, b, keep))
    }

    /// The next encoding below: next_up mirrored through the sign (NaN unchanged).
    #[target_feature(enable = "avx2")]
    fn next_down(v: __m256) -> __m256 {
        let sign = _mm256_set1_ps(-0.0);
        _mm256_xor_ps(next_up(_mm256_xor_ps(v, sign)), sign)
    }

    /// [`next_up`] on the binary16 grid, for lanes that hold binary16 values widened to binary32.
    #[target_feature(enable = "avx2,f16c")]
    fn next_up16(v: __m256) -> __m256 {
        // exact: every lane is a binary16 value (a NaN stays a NaN and is kept)
        let b = _mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(v);
        let mag = _mm_and_si128(b, _mm_set1_epi16(0x7fff));
        let keep = _mm_or_si128(
            _mm_cmpgt_epi16(mag, _mm_set1_epi16(0x7c00)), // NaN
            _mm_cmpeq_epi16(b, _mm_set1_epi16(0x7c00)),   // +inf
        );
        let zero = _mm_cmpeq_epi16(mag, _mm_setzero_si128());
        let step = _mm_or_si128(_mm_srai_epi16::<15>(b), _mm_set1_epi16(1));
        let r = _mm_add_epi16(b, step);
        let r = _mm_blendv_epi8(r, _mm_set1_epi16(1), zero);
        _mm256_cvtph_ps(_mm_blendv_epi8(r, b, keep))
    }

    /// [`next_down`] on the binary16 grid.
    #[target_feature(enable = "avx2,f16c")]
    fn next_down16(v: __m256) -> __m256 {
        let sign = _mm256_set1_ps(-0.0);
        _mm256_xor_ps(next_up16(_mm256_xor_ps(v, sign)), sign)
    }

    /// The slab stage table on 8 lanes, for either batch shape. `$load(column, i)` gives 8
    /// binary32 lanes, `$round(x)` rounds a binary32 result to the format, `$store(column, i,
    /// x)` writes 8 results, `$up` / `$down` step on the format's grid, `$nan` is the canonical
    /// NaN as binary32.
    macro_rules! slab_kernel {
        ($s:expr, $rays:expr, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $down:expr, $nan:expr, $bcast:expr) => {{
            // one loop per comparator and batch shape, so that neither is decided per vector
            let tof = $s.cfg.nan == SlabNan::TakeOnFalse;
            match ($rays, tof) {
                (SlabRays::Pairs(r), false) => slab_kernel!(@loop $s, pairs r, $boxes, $out, $full, $load, $round, $store, $up, $down, $nan, $bcast, false),
                (SlabRays::Pairs(r), true) => slab_kernel!(@loop $s, pairs r, $boxes, $out, $full, $load, $round, $store, $up, $down, $nan, $bcast, true),
                (SlabRays::One(r), false) => slab_kernel!(@loop $s, one r, $boxes, $out, $full, $load, $round, $store, $up, $down, $nan, $bcast, false),
                (SlabRays::One(r), true) => slab_kernel!(@loop $s, one r, $boxes, $out, $full, $load, $round, $store, $up, $down, $nan, $bcast, true),
            }
        }};
        // per-batch preparation, hoisted out of the loop: column pointers; for one ray, each
        // axis's near and far plane columns (picked by the sign bit of 1/d) and the broadcast
        // origin, 1/d and t interval
        (@prep pairs $r:ident, $bmin:ident, $bmax:ident, $bcast:ident) => {
            (
                $r.o.each_ref().map(|c| c.as_ptr()),
                $r.inv_d.each_ref().map(|c| c.as_ptr()),
                $r.tmin.as_ptr(),
                $r.tmax.as_ptr(),
            )
        };
        (@prep one $r:ident, $bmin:ident, $bmax:ident, $bcast:ident) => {{
            let neg = $r.inv_d.map(|x| x.to_bits() >> (8 * std::mem::size_of_val(&x) - 1) == 1);
            (
                std::array::from_fn::<_, 3, _>(|a| if neg[a] { $bmax[a] } else { $bmin[a] }),
                std::array::from_fn::<_, 3, _>(|a| if neg[a] { $bmin[a] } else { $bmax[a] }),
                ($r.o.map($bcast), $r.inv_d.map($bcast)),
                ($bcast($r.tmin), $bcast($r.tmax)),
            )
        }};
        // axis a of lanes i..i + 8: (near-plane t, far-plane t)
        (@plane pairs $prep:ident, $bmin:ident, $bmax:ident, $load:ident, $rd:ident, $a:expr, $i:ident) => {{
            let (o, inv) = ($load($prep.0[$a], $i), $load($prep.1[$a], $i));
            let tlo = $rd(_mm256_mul_ps($rd(_mm256_sub_ps($load($bmin[$a], $i), o)), inv));
            let thi = $rd(_mm256_mul_ps($rd(_mm256_sub_ps($load($bmax[$a], $i), o)), inv));
            // the sign bit of 1/d picks the near plane (blendv reads the sign bit)
            (_mm256_blendv_ps(tlo, thi, inv), _mm256_blendv_ps(thi, tlo, inv))
        }};
        (@plane one $prep:ident, $bmin:ident, $bmax:ident, $load:ident, $rd:ident, $a:expr, $i:ident) => {{
            let (o, inv) = ($prep.2 .0[$a], $prep.2 .1[$a]);
            (
                $rd(_mm256_mul_ps($rd(_mm256_sub_ps($load($prep.0[$a], $i), o)), inv)),
                $rd(_mm256_mul_ps($rd(_mm256_sub_ps($load($prep.1[$a], $i), o)), inv)),
            )
        }};
        // the t interval the chains start from
        (@limits pairs $prep:ident, $load:ident, $i:ident) => {
            ($load($prep.2, $i), $load($prep.3, $i))
        };
        (@limits one $prep:ident, $load:ident, $i:ident) => {
            $prep.3
        };
        (@loop $s:expr, $shape:ident $r:ident, $boxes:expr, $out:expr, $full:expr, $load:expr, $round:expr, $store:expr, $up:expr, $down:expr, $nan:expr, $bcast:expr, $tof:expr) => {{
            let (s, boxes, out) = ($s, $boxes, $out);
            let (load, rd, store, up, down, nan, bcast) = ($load, $round, $store, $up, $down, $nan, $bcast);
            let bmin = boxes.min.each_ref().map(|c| c.as_ptr());
            let bmax = boxes.max.each_ref().map(|c| c.as_ptr());
            let prep = slab_kernel!(@prep $shape $r, bmin, bmax, bcast);
            let _ = bcast; // the pairs shape broadcasts nothing
            let (o_hit, o_near, o_far) = (out.hit.as_mut_ptr(), out.t_near.as_mut_ptr(), out.t_far.as_mut_ptr());
            let widen = s.cfg.widen_ulps;
            let mut i = 0;
            while i < $full {
                let (mut tn, mut tf) = slab_kernel!(@limits $shape prep, load, i);
                let p = [
                    slab_kernel!(@plane $shape prep, bmin, bmax, load, rd, 0, i),
                    slab_kernel!(@plane $shape prep, bmin, bmax, load, rd, 1, i),
                    slab_kernel!(@plane $shape prep, bmin, bmax, load, rd, 2, i),
                ];
                for (near, far) in p {
                    if $tof {
                        // t = (x <= t) ? t : x (near), (t <= x) ? t : x (far)
                        tn = _mm256_blendv_ps(near, tn, _mm256_cmp_ps::<_CMP_LE_OQ>(near, tn));
                        tf = _mm256_blendv_ps(far, tf, _mm256_cmp_ps::<_CMP_LE_OQ>(tf, far));
                    } else {
                        // t = (x > t) ? x : t (near), (x < t) ? x : t (far): exactly vmaxps(x, t)
                        // and vminps(x, t), which return the second operand on NaN or equality
                        tn = _mm256_max_ps(near, tn);
                        tf = _mm256_min_ps(far, tf);
                    }
                }
                for _ in 0..widen.unsigned_abs() {
                    if widen > 0 {
                        tn = down(tn);
                        tf = up(tf);
                    } else {
                        tn = up(tn);
                        tf = down(tf);
                    }
                }
                let hit = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tn, tf)) as usize;
                // SAFETY: lanes i..i + 8 are in bounds; the bytes written are 0 or 1.
                unsafe { (o_hit.add(i) as *mut u64).write_unaligned(SPREAD[hit]) };
                // NaN lanes are rare: canonicalise only when a movemask shows one
                let (tn, tf) = if _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_UNORD_Q>(tn, tf)) == 0 {
                    (tn, tf)
                } else {
                    (canon(tn, nan), canon(tf, nan))
                };
                store(o_near, i, tn);
                store(o_far, i, tf);
                i += 8;
            }
        }};
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn slab_f32(
        s: &Slab<Ieee<F32Native>>,
        rays: SlabRays<f32>,
        boxes: &BoxesSoa<f32>,
        out: &mut SlabOutSoa<f32>,
        full: usize,
    ) {
        // SAFETY (loads and stores): the caller checked that every column holds `full` lanes.
        slab_kernel!(
            s,
            rays,
            boxes,
            out,
            full,
            |c: *const f32, i: usize| unsafe { _mm256_loadu_ps(c.add(i)) },
            |x: __m256| x,
            |c: *mut f32, i: usize, x: __m256| unsafe { _mm256_storeu_ps(c.add(i), x) },
            next_up,
            next_down,
            _mm256_castsi256_ps(_mm256_set1_epi32(0x7fc0_0000)),
            |x: f32| _mm256_set1_ps(x)
        );
    }

    #[target_feature(enable = "avx2,f16c")]
    pub(super) fn slab_f16(
        s: &Slab<Ieee<F16Half>>,
        rays: SlabRays<f16>,
        boxes: &BoxesSoa<f16>,
        out: &mut SlabOutSoa<f16>,
        full: usize,
    ) {
        // SAFETY (loads and stores): the caller checked that every column holds `full` lanes;
        // f16 is a 2-byte plain value.
        slab_kernel!(
            s,
            rays,
            boxes,
            out,
            full,
            |c: *const f16, i: usize| unsafe { _mm256_cvtph_ps(_mm_loadu_si128(c.add(i) as *const __m128i)) },
            |x: __m256| _mm256_cvtph_ps(_mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(x)),
            |c: *mut f16, i: usize, x: __m256| unsafe {
                _mm_storeu_si128(c.add(i) as *mut __m128i, _mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(x))
            },
            next_up16,
            next_down16,
            _mm256_castsi256_ps(_mm256_set1_epi32(0x7fc0_0000)), // becomes 0x7e00 in binary16
            |x: f16| _mm256_set1_ps(x.to_f32())
        );
    }

    /// Replaces NaN lanes by `canonical`.
    #[target_feature(enable = "avx2")]
    fn canon(x: __m256, canonical: __m256) -> __m256 {
        _mm256_blendv_ps(x, canonical, _mm256_cmp_ps::<_CMP_UNORD_Q>(x, x))
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn rti_f32(
        rti: &Rti<Ieee<F32Native>>,
        rays: &RaysSoa<f32>,
        tris: &TrisSoa<f32>,
        out: &mut HitsSoa<f32>,
        full: usize,
    ) {
        let nan = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fc0_0000));
        // SAFETY (loads and stores): the caller checked that every column holds `full` lanes.
        rti_kernel!(
            rti,
            rays,
            tris,
            out,
            full,
            |c: &Vec<f32>, i: usize| unsafe { _mm256_loadu_ps(c.as_ptr().add(i)) },
            |x: __m256| x,
            |c: &mut Vec<f32>, i: usize, x: __m256| unsafe { _mm256_storeu_ps(c.as_mut_ptr().add(i), x) },
            rti.det_thr,
            nan
        );
    }

    #[target_feature(enable = "avx2,f16c")]
    pub(super) fn rti_f16(
        rti: &Rti<Ieee<F16Half>>,
        rays: &RaysSoa<f16>,
        tris: &TrisSoa<f16>,
        out: &mut HitsSoa<f16>,
        full: usize,
    ) {
        let nan = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fc0_0000)); // becomes 0x7e00 in binary16
                                                                       // SAFETY (loads and stores): the caller checked that every column holds `full` lanes;
                                                                       // f16 is a 2-byte plain value.
        rti_kernel!(
            rti,
            rays,
            tris,
            out,
            full,
            |c: &Vec<f16>, i: usize| unsafe { _mm256_cvtph_ps(_mm_loadu_si128(c.as_ptr().add(i) as *const __m128i)) },
            |x: __m256| _mm256_cvtph_ps(_mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(x)),
            |c: &mut Vec<f16>, i: usize, x: __m256| unsafe {
                _mm_storeu_si128(c.as_mut_ptr().add(i) as *mut __m128i, _mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(x))
            },
            rti.det_thr.to_f32(),
            nan
        );
    }
}
