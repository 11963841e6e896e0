//! The instruction-set tables the kernels are written in: one module per vector type, each
//! operation one instruction; helpers shared by the tables.

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

pub(super) mod v8;

pub(super) mod v8r;

pub(super) mod v16;
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
    ($feat:literal, $fmafeat:literal, $v:ty, $fmadd:ident, $fmsub:ident) => {
        /// Every lane rounded to the format's precision p, nearest-even, in two fused
        /// operations (see "Rounding in the lanes" in [`crate::format::narrow`]):
        /// g = RN(x·(2^S − 1) + 0), then r = RN(x·2^S − g), S = 53 − p; correct for |x| in
        /// [2^emin, max] and for zeros (−0 kept: g is +0, and −0 − +0 is −0; [`round_full`]
        /// handles the rest of the range).
        #[inline]
        #[target_feature(enable = $fmafeat)]
        pub fn split(x: $v, n: &Narrow) -> $v {
            let g = $fmadd(x, splat(n.split_lo), splat(0.0));
            $fmsub(x, splat(n.split_hi), g)
        }
        /// (b·(2^S − 1), b·2^S), both exact in every lane holding a format value (b's p
        /// significant bits times an S-bit constant span at most 53 bits): the factors
        /// [`split_mul`] takes for b.
        #[inline]
        #[target_feature(enable = $feat)]
        pub fn split_k(b: $v, n: &Narrow) -> ($v, $v) {
            (mul(b, splat(n.split_lo)), mul(b, splat(n.split_hi)))
        }
        /// [`split`] of the product a·b of two format values, with bk = [`split_k`]`(b)`:
        /// a·b is exact in binary64 (2p ≤ 53 bits), so RN(a·(b·(2^S − 1)) + 0) is split's g
        /// for x = a·b and RN(a·(b·2^S) − g) its result, bit for bit, without forming a·b
        /// (the fused products are exact: no rounding of the modelled datapath is fused away).
        #[inline]
        #[target_feature(enable = $fmafeat)]
        pub fn split_mul(a: $v, _b: $v, bk: ($v, $v)) -> $v {
            let g = $fmadd(a, bk.0, splat(0.0));
            $fmsub(a, bk.1, g)
        }
        /// Every lane rounded to the format, nearest-even, with its range (see "Rounding in
        /// the lanes" in [`crate::format::narrow`]): [`split`] where |x| ≥ 2^emin; the
        /// subnormal grid where |x| < 2^emin (`(|x| + C) − C`, C = 2^(emin − M + 52), sign
        /// restored), then under FTZ a subnormal result flushed to zero of its sign; ±∞ where
        /// |x| ≥ max + ulp(max)/2 (infinities included). A NaN stays a NaN.
        #[inline]
        #[target_feature(enable = $fmafeat)]
        pub fn round_full(x: $v, n: &Narrow) -> $v {
            let a = abs(x);
            // the common vector: every lane in the normal range, where the split is the
            // rounding (±0 and NaN lanes take the road below, which keeps them)
            if !any_outside_normal(a, n) {
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
        /// [`split`], the lanes where it need not be the format's rounding — those
        /// [`round_full`] takes the full road for: |x| outside [2^emin, max + ulp(max)/2), ±0
        /// and NaN included — or'ed into `pending` (a caller redoes them).
        #[inline]
        #[target_feature(enable = $fmafeat)]
        pub fn split_noting(x: $v, n: &Narrow, pending: &std::cell::Cell<M>) -> $v {
            pending.set(or_m(pending.get(), outside_normal(abs(x), n)));
            split(x, n)
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
            if let Some(r) = step_inside(x, n) {
                return r;
            }
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

#[allow(dead_code)] // max and min: no slab kernel runs on binary64 lanes
pub(super) mod v4d;

#[allow(dead_code)] // max and min: no slab kernel runs on binary64 lanes
pub(super) mod v8d;

pub(super) mod v32h;
