//! Narrow IEEE-like floats held exactly in binary64 lanes: the constants of the SIMD batch
//! path for custom `eEmM` layouts with precision p = M + 1 ≤ 25 and E ≤ 10 (bf16, whose scalar
//! model computes in binary32, has its own kernel on binary32 lanes, `datapath::simd`).
//!
//! Every operation (+ − × ÷) is computed in binary64 (rounded to nearest-even) and the result
//! rounded once more to the target, nearest-even (subnormals on the target's subnormal grid,
//! overflow to ±∞, under FTZ a subnormal result flushed to zero of its sign). This equals the
//! target's correctly rounded operation:
//!
//! * **Double rounding is innocuous** for + − × ÷ when the wide precision is at least 2p + 2
//!   (Figueroa, "When is double rounding innocuous?", SIGNUM 1995): binary64 has 53 ≥ 2·25 + 2
//!   bits, so rounding the exact result to binary64 and then to p bits gives the same value as
//!   rounding the exact result to p bits. The theorem needs the binary64 result to carry its
//!   full 53 bits wherever the target can round to a nonzero value.
//! * **Range**: with E ≤ 10 the target's magnitudes lie in [2^(emin − M), 2^(emax + 1)) with
//!   emin ≥ −510 and emax ≤ 511. Any exact result whose target rounding is nonzero and finite
//!   is ≥ 2^(emin − M − 1) ≥ 2^−535, far above binary64's smallest normal 2^−1022, so binary64
//!   holds it with 53 bits (the theorem applies; in the target's subnormal range its precision
//!   is smaller than p, which only helps). An exact result below 2^−1022 rounds to ±0 in the
//!   target whatever binary64 makes of it (binary64 rounding cannot lift it above 2^−1022,
//!   still far below half the target's least subnormal), with the sign of the exact result.
//!   A binary64 overflow (|result| ≥ 2^1024) happens only where the target overflows too
//!   (its largest finite value is below 2^512), and both give ±∞.
//! * E = 11 layouts share binary64's exponent range, where binary64's own subnormals lose
//!   bits: they keep the scalar model.
//!
//! **Rounding in the lanes** (`round_full` in `datapath::simd`): each binary64 result x is
//! rounded to the target, nearest-even, with its whole range:
//! * 2^emin ≤ |x| < max + ulp(max)/2: two fused operations, with S = 53 − p:
//!   g = RN(x·(2^S − 1) + 0), then r = RN(x·2^S − g) (each a single-rounding multiply-add,
//!   its product exact). r is x rounded to p bits, ties to even. Proof, for x > 0 in
//!   [2^e, 2^(e+1)) with 53-bit integer significand X (x = X·2^(e−52)), u = 2^(e−p+1) its
//!   p-bit spacing: x·2^S = X·u, and (2^S − 1)·x < 2^(e+S+1), so g is a multiple of u (or of
//!   u/2, below), r = X·u − g is exact in binary64 (a multiple of u/2 near x), and
//!   r − x = −(g − (2^S − 1)x), minus g's rounding error. (a) When (2^S − 1)x ≥ 2^(e+S), g's
//!   spacing is u, so |r − x| ≤ u/2 and r is a multiple of u: a nearest p-bit value. At a
//!   tie, x = (k + ½)u, X = (2k + 1)·2^(52−p) is even, g's nearest-even choice between
//!   (X − k − 1)u and (X − k)u takes the even one, so r = k′u with k′ even: ties to even.
//!   (b) When (2^S − 1)x < 2^(e+S), i.e. x < 2^e·(1 + 1/(2^S − 1)), g's spacing is u/2 and r
//!   is the multiple of u/2 nearest x, which is 2^e (x − 2^e < 2^e/(2^S − 1) ≤ u/4 when
//!   S ≥ p + 2, i.e. p ≤ 25): x's p-bit rounding too. Negative x by symmetry. Zeros: x = ±0
//!   gives g = +0 (the exact sum ±0 + +0 is +0 under nearest-even) and r = ±0 − +0 = ±0, the
//!   sign kept (the "+ 0" is there for −0: without it g = −0 and r = +0). Below the overflow
//!   threshold the p-bit rounding never exceeds max (a value in [max, max + ulp/2) rounds
//!   to max). (Veltkamp's splitting, g = x·(2^S + 1), r = g − (g − x), gives the same value
//!   in three operations; its fused form r = g − 2^S·x fails just below a power of two,
//!   where x·(2^S + 1) crosses into the next binade.)
//! * |x| < 2^emin: the subnormal grid, `(|x| + C) − C` with C = 2^(emin − M + 52) (the sum lies
//!   in [C, 2C), where binary64's spacing is the target's subnormal step 2^(emin − M), so
//!   binary64's nearest-even addition is the target's rounding, 2^emin included; the
//!   subtraction is exact), then the sign of x; under FTZ a result below 2^emin (subnormal
//!   after rounding) becomes zero of x's sign, the model's rule;
//! * |x| ≥ max + ulp(max)/2 (= 2^(emax+1)·(1 − 2^−(p+1)), exact in binary64; infinities
//!   included): ±∞ (the tie rounds to even, i.e. up);
//! * a NaN stays a NaN and is stored as the canonical NaN (the canonical rule: a NaN result is
//!   the canonical NaN whatever its operands).
//!
//! Under FTZ the operand read flushes in the lanes too (a subnormal operand reads as zero of
//! its sign). No lane falls back to the scalar model. `narrow_ops_in_binary64_lanes_equal_the_
//! soft_float_model_exhaustively` checks every operand pair of e5m4, e4m3, e3m2 and e2m1 (each
//! subnormal and division mode), where subnormals, overflow and ties are dense.
//!
//! **The range filter** (a cheaper filter first, CGAL-style, per vector of lanes): the RTI
//! kernel rounds stage 1 without the per-result check and then looks at the twelve values
//! every product of stages 2 and 4 takes an operand from (e1, e2, s and d). Let L be the
//! smallest nonzero magnitude among them and H the largest, and ℓ = 2^⌊log2 L⌋. Every target
//! value x ≠ 0 is a multiple of its quantum q(x) = 2^(max(⌊log2 |x|⌋, emin) − M), so a
//! nonzero exact sum or difference of two target values is at least the smaller quantum, and
//! a value ≥ 2^j has quantum ≥ 2^(j − M) when 2^j ≥ 2^emin. Hence the nonzero results are
//! at least: stage 2 (d × e2, s × e1) ℓ²; stage 3 (differences) ℓ²·2^−M; stage 4 (products
//! with one of the twelve) ℓ³·2^−M; stages 5, 6 and u + v (sums) ℓ³·2^−2M, ℓ³·2^−3M,
//! ℓ³·2^−4M; and, with u = 2^−p the unit roundoff, at most H², 2H²(1+u)², 2H³(1+u)³, 4H³(1+u)⁴,
//! 6H³(1+u)⁵ and 12H³(1+u)⁶ ≤ 64H³ (u ≤ 1/4). If every lane has L ≥ `fast_lo` =
//! 2^⌈(emin + 4M)/3⌉ (which implies the stage-2 and stage-3 bounds ℓ ≥ 2^⌈(emin + M)/2⌉, since
//! (emin + M)/2 ≤ (emin + 4M)/3 ⟺ emin ≤ 5M, and emin ≤ 0) and H ≤ `fast_hi` =
//! 2^⌊(emax − 6)/3⌋, every result of
//! stages 2–7 is ±0 or in [2^emin, max], where the split is the target rounding: the vector
//! computes stages 2–7 without the check (for e8m16: nonzero stage-1 results and direction
//! components in [2^−20, 2^40]). Otherwise stages 1–6 are recomputed with the full
//! rounding. A NaN or an infinity among the twelve fails the filter (the unfiltered stage 1
//! turns an infinite difference into a NaN, so both must take the full road). The reciprocal
//! or division and the three final multiplies always round in full. (The AVX2 filter checks
//! the rounded sum of the twelve magnitudes against `fast_hi` instead of each: the sum is at
//! least H, so it passes fewer vectors, never more; AVX-512 checks H itself.)
//!
//! **Products on the filtered path** (`split_mul` in `datapath::simd`): a product a·b of two
//! target values is exact in binary64 (2p ≤ 50 bits), and so are b·(2^S − 1) and b·2^S (b's
//! p bits times an S-bit constant span at most 53 bits). So RN(a·(b·(2^S − 1)) + 0) is the
//! rounding's g for x = a·b and RN(a·(b·2^S) − g) its r: the same two values, the same bits,
//! without forming a·b, with the two factors of b formed once for the products that share b
//! (the 18 products of stages 2–5 with a factor of d or s). The fused operations fuse none of
//! the modelled datapath's roundings (their products are exact).
//!
//! **e8mM loads** (E = 8, M ≤ 23, binary32's exponent field and bias): an encoding shifted
//! left by 23 − M is the binary32 encoding of the same value (subnormals, ±∞ and NaNs
//! included), which widens to binary64 exactly; a stored lane (a target value, or binary64's
//! canonical NaN) narrows to binary32 exactly and shifts back.
//!
//! Eligible formats: bf16 and `eEmM` with M ≤ 24 and E ≤ 10, either subnormal mode, either
//! division mode, and the canonical NaN rule (a NaN result is the canonical NaN, so payloads
//! never matter); the propagate NaN rule keeps the scalar model.

use super::{FloatLayout, FpOpts, NanMode, Subnormals};

/// The constants of one narrow format's binary64-lane arithmetic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Narrow {
    /// The layout.
    pub lay: FloatLayout,
    /// Under FTZ: subnormal operands read as zero, subnormal results become zero.
    pub ftz: bool,
    /// 2^emin, the smallest normal magnitude.
    pub min_normal: f64,
    /// The largest finite magnitude.
    pub max_finite: f64,
    /// 2^(emin − M), the subnormal step (decode: fraction × step).
    pub step: f64,
    /// 2^−M: a normal value's quantum over its power of two.
    pub quantum: f64,
    /// 2^(M − emin), the inverse of the step (encode).
    pub inv_step: f64,
    /// 2^S − 1 with S = 52 − M: the multiplier of the rounding to p = 53 − S bits.
    pub split_lo: f64,
    /// 2^S: the rounding's scale.
    pub split_hi: f64,
    /// C = 2^(emin − M + 52): `(|x| + C) − C` is |x| < 2^emin rounded to the subnormal grid.
    pub sub_grid: f64,
    /// max + ulp(max)/2: the magnitude from which a result rounds to ±∞.
    pub overflow_at: f64,
    /// The range filter's lower limit: a power of two ℓ_min (see "The range filter").
    pub fast_lo: f64,
    /// The range filter's upper limit: a power of two h_max (see "The range filter").
    pub fast_hi: f64,
    /// E = 8 and M ≤ 23: the encodings convert through binary32 (shifted by 23 − M).
    pub e8: bool,
    /// 23 − M, the shift between the encoding and binary32's (meaningful when `e8`).
    pub e8_shift: u32,
}

impl Narrow {
    /// The constants of this layout and options, when the binary64-lane path models it.
    pub fn of(lay: FloatLayout, opts: FpOpts) -> Option<Self> {
        if lay.exp_bits > 10 || lay.man_bits > 24 || opts.nan != NanMode::Canonical {
            return None;
        }
        let m = lay.man_bits as i32;
        Some(Self {
            lay,
            ftz: opts.subnormals == Subnormals::Ftz,
            min_normal: lay.min_normal(),
            max_finite: lay.max_finite(),
            step: super::layout::pow2(lay.emin() - m),
            quantum: super::layout::pow2(-m),
            inv_step: super::layout::pow2(m - lay.emin()),
            split_lo: super::layout::pow2(52 - m) - 1.0,
            split_hi: super::layout::pow2(52 - m),
            sub_grid: super::layout::pow2(lay.emin() - m + 52),
            overflow_at: lay.max_finite() + super::layout::pow2(lay.emax() - m - 1),
            fast_lo: super::layout::pow2(((lay.emin() + 4 * m) as f64 / 3.0).ceil() as i32),
            fast_hi: super::layout::pow2((lay.emax() - 6).div_euclid(3)),
            e8: lay.exp_bits == 8 && m <= 23,
            e8_shift: (23 - m).max(0) as u32,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::Narrow;
    use crate::format::{FloatLayout, FpOpts};

    fn of(e: u32, m: u32) -> Narrow {
        Narrow::of(FloatLayout::validate(e, m).unwrap(), FpOpts::default()).expect("a narrow layout")
    }

    /// The constants are the documented ones, worked by hand from the formulas in the module
    /// docs: split_lo 2^(52 − M) − 1 and split_hi 2^(52 − M), fast_lo 2^⌈(emin + 4M)/3⌉,
    /// fast_hi 2^⌊(emax − 6)/3⌋, e8 for E = 8 and M ≤ 23 with shift 23 − M.
    #[test]
    fn the_constants_are_the_documented_ones() {
        let x = |v: f64, k: i32| assert_eq!(v, (k as f64).exp2(), "2^{k}");
        // e8m16: emin −126, emax 127: ⌈−62/3⌉ = −20, ⌊121/3⌋ = 40
        let n = of(8, 16);
        assert_eq!((n.split_lo, n.split_hi), (68_719_476_735.0, 68_719_476_736.0)); // 2^36 − 1, 2^36
        x(n.fast_lo, -20);
        x(n.fast_hi, 40);
        assert!(n.e8 && n.e8_shift == 7);
        // e10m24: emin −510, emax 511: ⌈−414/3⌉ = −138, ⌊505/3⌋ = 168
        let n = of(10, 24);
        assert_eq!((n.split_lo, n.split_hi), (268_435_455.0, 268_435_456.0)); // 2^28 − 1, 2^28
        x(n.fast_lo, -138);
        x(n.fast_hi, 168);
        assert!(!n.e8);
        // e5m10: emin −14, emax 15: ⌈26/3⌉ = 9, ⌊9/3⌋ = 3 (the filter never passes: full road)
        let n = of(5, 10);
        x(n.fast_lo, 9);
        x(n.fast_hi, 3);
        // binary32's own width is e8's limit; one bit more is not e8
        assert!(of(8, 23).e8 && of(8, 23).e8_shift == 0);
        assert!(!of(8, 24).e8);
    }
}
