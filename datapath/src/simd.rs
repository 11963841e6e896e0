//! SIMD batch kernels of the RTI model, bit-identical to the scalar model, with runtime dispatch.
//!
//! One kernel body (the `rti_kernel!` macro) is instantiated for binary32 and binary16 on
//! AVX2 (+ F16C for binary16), eight tests per vector, in the stage table's exact operation
//! order with separate multiplies and adds (no FMA). binary16 computes every operation in
//! binary32 and rounds it to binary16 at once (`vcvtps2ph` nearest-even, then back): binary32's
//! 24 bits are at least 2·11 + 2, so this double rounding is innocuous for + − × ÷ and the
//! result is the correctly rounded binary16 operation, subnormals and overflow included.
//! NaN payloads never influence a non-NaN result or a compare, so the kernels canonicalise NaN
//! only where a value leaves them (t, u, v). Eligible formats: IEEE subnormals and canonical
//! NaN (either division mode, either culling); others, and machines without AVX2, run the
//! scalar model, as does a det threshold that is negative or NaN (the kernels' sign-flip side
//! tests need det_ok to exclude det = ±0). Columns are processed 8 lanes at a time straight
//! from the SoA inputs.

use crate::format::{DivMode, F16Half, F32Native, Ieee, NanMode, Subnormals};
use crate::rti::{Cull, HitsSoa, RaysSoa, Rti, TrisSoa};
use crate::slab::{BoxesSoa, Slab, SlabNan, SlabOutSoa, SlabRaysSoa};
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

/// The kernel `slab_batch_f32` uses for this unit on this machine (the round-to-nearest
/// variants; the directed one runs the scalar model).
pub fn slab_kernel_f32(s: &Slab<Ieee<F32Native>>) -> Kernel {
    #[cfg(target_arch = "x86_64")]
    if eligible(&s.fmt) && !s.cfg.directed && std::arch::is_x86_feature_detected!("avx2") {
        return Kernel::Avx2;
    }
    let _ = s;
    Kernel::Scalar
}

/// [`Slab::batch`] for binary32 on the fastest kernel available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn slab_batch_f32(
    s: &Slab<Ieee<F32Native>>,
    rays: &SlabRaysSoa<f32>,
    boxes: &BoxesSoa<f32>,
    out: &mut SlabOutSoa<f32>,
) -> Kernel {
    let n = rays.tmin.len();
    assert!(boxes.min[0].len() == n && out.hit.len() == n, "batch lengths differ");
    let cols_ok = rays.o.iter().chain(&rays.inv_d).all(|c| c.len() == n)
        && rays.tmax.len() == n
        && boxes.min.iter().chain(&boxes.max).all(|c| c.len() == n)
        && out.t_near.len() == n
        && out.t_far.len() == n;
    match slab_kernel_f32(s) {
        #[cfg(target_arch = "x86_64")]
        Kernel::Avx2 if cols_ok => {
            let full = n / 8 * 8;
            // SAFETY: AVX2 was detected; every column holds n >= full lanes (checked above).
            unsafe { avx2::slab_f32(s, rays, boxes, out, full) };
            s.batch_from(rays, boxes, out, full);
            Kernel::Avx2
        }
        _ => {
            s.batch(rays, boxes, out);
            Kernel::Scalar
        }
    }
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

    #[target_feature(enable = "avx2")]
    pub(super) fn slab_f32(
        s: &Slab<Ieee<F32Native>>,
        rays: &SlabRaysSoa<f32>,
        boxes: &BoxesSoa<f32>,
        out: &mut SlabOutSoa<f32>,
        full: usize,
    ) {
        let nan = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fc0_0000));
        // SAFETY: the caller checked that every column holds at least `full` lanes.
        let load = |c: &Vec<f32>, i: usize| unsafe { _mm256_loadu_ps(c.as_ptr().add(i)) };
        let take_on_false = s.cfg.nan == SlabNan::TakeOnFalse;
        // near chain: acc replaced by x when x is farther in; far chain: when x is nearer
        let near_sel = |acc: __m256, x: __m256| {
            if take_on_false {
                _mm256_blendv_ps(x, acc, _mm256_cmp_ps::<_CMP_LE_OQ>(x, acc))
            } else {
                _mm256_blendv_ps(acc, x, _mm256_cmp_ps::<_CMP_LT_OQ>(acc, x))
            }
        };
        let far_sel = |acc: __m256, x: __m256| {
            if take_on_false {
                _mm256_blendv_ps(x, acc, _mm256_cmp_ps::<_CMP_LE_OQ>(acc, x))
            } else {
                _mm256_blendv_ps(acc, x, _mm256_cmp_ps::<_CMP_LT_OQ>(x, acc))
            }
        };
        let mut i = 0;
        while i < full {
            let mut tn = load(&rays.tmin, i);
            let mut tf = load(&rays.tmax, i);
            let mut near = [tn; 3];
            let mut far = [tf; 3];
            for a in 0..3 {
                let (o, inv) = (load(&rays.o[a], i), load(&rays.inv_d[a], i));
                let tlo = _mm256_mul_ps(_mm256_sub_ps(load(&boxes.min[a], i), o), inv);
                let thi = _mm256_mul_ps(_mm256_sub_ps(load(&boxes.max[a], i), o), inv);
                // the sign bit of 1/d picks the near plane (blendv reads the sign bit)
                near[a] = _mm256_blendv_ps(tlo, thi, inv);
                far[a] = _mm256_blendv_ps(thi, tlo, inv);
            }
            for a in 0..3 {
                tn = near_sel(tn, near[a]);
                tf = far_sel(tf, far[a]);
            }
            for _ in 0..s.cfg.widen_ulps.unsigned_abs() {
                if s.cfg.widen_ulps > 0 {
                    tn = next_down(tn);
                    tf = next_up(tf);
                } else {
                    tn = next_up(tn);
                    tf = next_down(tf);
                }
            }
            let hit = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tn, tf)) as usize;
            // SAFETY: lanes i..i + 8 are in bounds; the bytes written are 0 or 1.
            unsafe {
                (out.hit.as_mut_ptr().add(i) as *mut u64).write_unaligned(SPREAD[hit]);
                _mm256_storeu_ps(out.t_near.as_mut_ptr().add(i), canon(tn, nan));
                _mm256_storeu_ps(out.t_far.as_mut_ptr().add(i), canon(tf, nan));
            }
            i += 8;
        }
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
