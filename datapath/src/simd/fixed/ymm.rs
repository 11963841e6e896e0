//! AVX2 lanes: 4 raw values in a ymm register, each held **biased**: the 64-bit pattern of
//! `v + M` with `M = 0x4338_0000_0000_0000` (the binary64 `1.5 · 2^52`), which for
//! |v| < 2^51 is also the binary64 encoding of the number `1.5 · 2^52 + v`. The one pattern
//! serves three instruction families that AVX2 lacks in 64-bit integer form:
//!
//! * **order** (`vcmppd`, `vmaxpd`, `vminpd`): biased values compare as binary64 numbers in
//!   the order of `v`, so compares, min, max and saturation are one floating-point op each
//!   (AVX2 has no 64-bit integer min / max, and its one signed 64-bit compare runs on one port);
//! * **products** (`vpmuldq`): `M`'s low 32 bits are zero, so the low half of a biased raw
//!   value is the raw value's own 32 bits, the operand `vpmuldq` reads;
//! * **conversion**: `v` as binary64 is `bits(v + M) − 1.5 · 2^52` (one subtraction, no
//!   `vcvtqq2pd`), and a binary64 `x` with |x| ≤ 2^51 rounded to an integer *and* biased is
//!   `x + 1.5 · 2^52` (one addition, no `vcvtpd2qq`).
//!
//! `M`'s low 51 bits are zero too, so the low w bits of a biased value are those of `v`
//! (wrapping is mask, sign flip, subtract, whatever the magnitude), and adding an integer to
//! a biased value is adding it to `v`. The bias is added at every load and removed at every
//! store. The lanes are exact while every value the saturating arithmetic orders stays below
//! 2^51 in magnitude: raw values and their sums (< 2^33), quotients clamped to the range,
//! and products after the shift, |a·b / 2^F| ≤ 2^(2w − 2 − F); [`Y::fits`] admits the
//! saturating formats with 2w − 2 − F ≤ 50 (`q16.16`, `q8.24`, `q1.31`, every format of at
//! most 26 bits) and every wrapping one. Others take the portable lanes.
//!
//! Division under saturation: the quotient `Q = a·2^F / b` is estimated as
//! `x = RN(a · RN(2^F / b))` (the reciprocal shared by the divisions of one divisor, as in
//! RTI's three), clamped to [min, max] and rounded to the nearest integer `q0`. For
//! min ≤ Q < max + 1 the estimate is within 2^−20 of Q (two roundings of relative error
//! 2^−53 on |Q| < 2^31), so `q0` is ⌊Q⌋ or ⌊Q⌋ + 1 and the remainder step of the module
//! documentation gives the floor. For Q ≥ max + 1 the clamp gives q0 = max with a remainder
//! ≥ d (no step), for Q < min it gives q0 = min with a negative remainder (the step makes
//! min − 1): both then saturate as the exact quotient would. The remainder is
//! `±(a·2^F − q0·b)` with both 32-bit factors of `vpmuldq`. Division under wrapping needs
//! the exact quotient up to 2^62 and runs the scalar function per lane.

use super::lanes::*;

use std::arch::x86_64::*;

/// The bias: binary64 `1.5 · 2^52`.
const M: i64 = 0x4338_0000_0000_0000;

/// `sel`'s masks: entry m has lane j all ones when bit j of m is set.
static EXPAND: [[i64; 4]; 16] = {
    let mut t = [[0i64; 4]; 16];
    let mut m = 0;
    while m < 16 {
        let mut j = 0;
        while j < 4 {
            t[m][j] = -(((m >> j) & 1) as i64);
            j += 1;
        }
        m += 1;
    }
    t
};

/// The format's constants, broadcast and biased. A value of this type exists only where
/// AVX2 was detected ([`Y::new`] is unsafe), which is what makes the intrinsics in its
/// methods sound.
#[derive(Clone, Copy)]
pub(super) struct Y {
    c: Lanes,
    /// M as an integer.
    m: __m256i,
    /// M as a binary64.
    md: __m256d,
    /// 2M as a binary64 (|v| is max(M + v, 2M − (M + v))).
    m2d: __m256d,
    /// Biased min and max, as binary64.
    bmin: __m256d,
    bmax: __m256d,
    /// min and max as binary64.
    fmin: __m256d,
    fmax: __m256d,
    /// The product shift's constants: 2^63 (floor), 2^63 + 2^F − 1 (toward +∞),
    /// 2^63 + 2^(F−1) − 1 (to nearest), and M − 2^(63−F) (unbias the shift, bias the
    /// result).
    k_floor: __m256i,
    k_ceil: __m256i,
    k_near: __m256i,
    unshift: __m256i,
    /// 1 when F ≥ 1 (the quotient's last bit breaks a tie), else 0.
    tie_bit: __m256i,
    low: __m256i,
    one: __m256i,
    /// 2^F as binary64.
    scale: __m256d,
    /// Wrap: the low w bits, 2^(w−1), and M − 2^(w−1).
    wmask: __m256i,
    wsign: __m256i,
    wunsign: __m256i,
    f: __m128i,
}

impl Y {
    /// Whether the biased lanes compute format `c` exactly (see the type).
    pub(super) fn fits(c: &Lanes, wrap: bool) -> bool {
        let w = 64 - c.sh;
        wrap || 2 * w - 2 - c.f.min(2 * w - 2) <= 50
    }

    /// The broadcast constants of `c`.
    ///
    /// # Safety
    /// The CPU has AVX2.
    #[inline(always)]
    pub(super) unsafe fn new(c: Lanes) -> Self {
        let w = 64 - c.sh;
        let f = c.f;
        let b = |v: i64| f64::from_bits(M.wrapping_add(v) as u64);
        let near = if f == 0 { 0 } else { (1i64 << (f - 1)) - 1 };
        // SAFETY: the caller's promise
        unsafe {
            let i = _mm256_set1_epi64x;
            let d = _mm256_set1_pd;
            Self {
                c,
                m: i(M),
                md: d(f64::from_bits(M as u64)),
                m2d: d(2.0 * f64::from_bits(M as u64)),
                bmin: d(b(c.min)),
                bmax: d(b(c.max)),
                fmin: d(c.min as f64),
                fmax: d(c.max as f64),
                k_floor: i(i64::MIN),
                k_ceil: i(i64::MIN.wrapping_add(c.low)),
                k_near: i(i64::MIN.wrapping_add(near)),
                unshift: i(M.wrapping_sub((1u64 << (63 - f)) as i64)),
                tie_bit: i((f > 0) as i64),
                low: i(c.low),
                one: i(1),
                scale: d((1u64 << f) as f64),
                wmask: i(((1u64 << w) - 1) as i64),
                wsign: i(1i64 << (w - 1)),
                wunsign: i(M.wrapping_sub(1i64 << (w - 1))),
                f: _mm_cvtsi64_si128(f as i64),
            }
        }
    }
    /// [`fit`] of a biased value.
    #[inline(always)]
    fn fit<const WRAP: bool>(&self, x: __m256i) -> __m256i {
        // SAFETY (every method): `self` exists, so AVX2 does (see the type)
        unsafe {
            if WRAP {
                // the low w bits, sign-extended, biased: ((x & mask) ^ 2^(w-1)) + M - 2^(w-1)
                _mm256_add_epi64(_mm256_xor_si256(_mm256_and_si256(x, self.wmask), self.wsign), self.wunsign)
            } else {
                let x = _mm256_castsi256_pd(x);
                _mm256_castpd_si256(_mm256_min_pd(_mm256_max_pd(x, self.bmin), self.bmax))
            }
        }
    }
    /// The unbiased value.
    #[inline(always)]
    fn plain(&self, x: __m256i) -> __m256i {
        unsafe { _mm256_sub_epi64(x, self.m) }
    }
    /// The value as binary64 (exact).
    #[inline(always)]
    fn float(&self, x: __m256i) -> __m256d {
        unsafe { _mm256_sub_pd(_mm256_castsi256_pd(x), self.md) }
    }
    /// Lanes where `x` (plain) is negative, all ones.
    #[inline(always)]
    fn negative(&self, x: __m256i) -> __m256i {
        unsafe { _mm256_cmpgt_epi64(_mm256_setzero_si256(), x) }
    }
    /// A 4-bit compare mask of two biased vectors.
    #[inline(always)]
    fn cmp<const P: i32>(&self, a: __m256i, b: __m256i) -> u8 {
        unsafe { _mm256_movemask_pd(_mm256_cmp_pd::<P>(_mm256_castsi256_pd(a), _mm256_castsi256_pd(b))) as u8 }
    }
}

impl Ops for Y {
    const L: usize = 4;
    type V = __m256i;
    #[inline(always)]
    fn c(&self) -> &Lanes {
        &self.c
    }
    #[inline(always)]
    fn load(&self, col: &[i64], i: usize) -> __m256i {
        let s = &col[i..i + 4];
        unsafe { _mm256_add_epi64(_mm256_loadu_si256(s.as_ptr().cast()), self.m) }
    }
    #[inline(always)]
    fn store(&self, col: &mut [i64], i: usize, v: __m256i) {
        let s = &mut col[i..i + 4];
        unsafe { _mm256_storeu_si256(s.as_mut_ptr().cast(), self.plain(v)) }
    }
    #[inline(always)]
    fn splat(&self, x: i64) -> __m256i {
        unsafe { _mm256_set1_epi64x(x.wrapping_add(M)) }
    }
    #[inline(always)]
    fn add<const WRAP: bool>(&self, a: __m256i, b: __m256i) -> __m256i {
        self.fit::<WRAP>(unsafe { _mm256_add_epi64(a, self.plain(b)) })
    }
    #[inline(always)]
    fn sub<const WRAP: bool>(&self, a: __m256i, b: __m256i) -> __m256i {
        self.fit::<WRAP>(unsafe { _mm256_add_epi64(_mm256_sub_epi64(a, b), self.m) })
    }
    #[inline(always)]
    fn mul<const R: u8, const WRAP: bool>(&self, a: __m256i, b: __m256i) -> __m256i {
        unsafe {
            // the low halves are the 32-bit raw values: vpmuldq is the exact product
            let p = _mm256_mul_epi32(a, b);
            // the rounded quotient by 2^F as a floor: (p + k) >> F with the arithmetic
            // shift made logical by 2^63 (p + 2^63 >= 0 as |p| <= 2^62)
            let biased = match R {
                FLOOR => _mm256_add_epi64(p, self.k_floor),
                CEIL => _mm256_add_epi64(p, self.k_ceil),
                TRUNC => {
                    _mm256_add_epi64(_mm256_add_epi64(p, self.k_floor), _mm256_and_si256(self.negative(p), self.low))
                }
                // ties to even: + 2^(F-1) - 1 + (bit F of p)
                _ => {
                    let bit = _mm256_and_si256(_mm256_srl_epi64(p, self.f), self.tie_bit);
                    _mm256_add_epi64(_mm256_add_epi64(p, self.k_near), bit)
                }
            };
            self.fit::<WRAP>(_mm256_add_epi64(_mm256_srl_epi64(biased, self.f), self.unshift))
        }
    }
    #[inline(always)]
    fn div<const R: u8, const WRAP: bool, const TWO: bool>(&self, a: __m256i, b: __m256i) -> __m256i {
        if WRAP {
            // the exact quotient can reach 2^62: the scalar function, lane by lane
            let (mut pa, mut pb) = ([0i64; 4], [0i64; 4]);
            self.store(&mut pa, 0, a);
            self.store(&mut pb, 0, b);
            let q: [i64; 4] = std::array::from_fn(|j| div::<R, WRAP, TWO>(&self.c, pa[j], pb[j]));
            return self.load(&q, 0);
        }
        unsafe {
            let zero = _mm256_setzero_si256();
            let (pa, pb) = (self.plain(a), self.plain(b));
            let sb = self.negative(pb);
            let by0 = _mm256_cmpeq_epi64(pb, zero);
            // d = |b| (2^31 at the most negative b), 1 for b = 0
            let d = _mm256_sub_epi64(_mm256_sub_epi64(_mm256_xor_si256(pb, sb), sb), by0);
            // the estimate, clamped, rounded to an integer and biased in one addition
            let recip = _mm256_div_pd(self.scale, self.float(b));
            let x = _mm256_mul_pd(self.float(a), recip);
            let x = _mm256_min_pd(_mm256_max_pd(x, self.fmin), self.fmax);
            let q0 = _mm256_castpd_si256(_mm256_add_pd(x, self.md));
            // r = n - q0 d with n = a 2^F sign(b), d = |b|: the sign of b moved from d to n
            let n0 = _mm256_sll_epi64(pa, self.f);
            let rs = _mm256_sub_epi64(n0, _mm256_mul_epi32(q0, b));
            let r = _mm256_sub_epi64(_mm256_xor_si256(rs, sb), sb);
            // one step to the floor: r < 0 gives q0 - 1, r + d
            let below = self.negative(r);
            let q = _mm256_add_epi64(q0, below);
            let r = _mm256_add_epi64(r, _mm256_and_si256(below, d));
            let q = match R {
                FLOOR => q,
                CEIL => _mm256_sub_epi64(q, _mm256_andnot_si256(_mm256_cmpeq_epi64(r, zero), _mm256_set1_epi64x(-1))),
                TRUNC => {
                    let n = _mm256_sub_epi64(_mm256_xor_si256(n0, sb), sb);
                    _mm256_sub_epi64(q, _mm256_andnot_si256(_mm256_cmpeq_epi64(r, zero), self.negative(n)))
                }
                _ => {
                    let twice = _mm256_add_epi64(r, r);
                    let odd = _mm256_sub_epi64(zero, _mm256_and_si256(q, self.one));
                    let up = _mm256_or_si256(
                        _mm256_cmpgt_epi64(twice, d),
                        _mm256_and_si256(_mm256_cmpeq_epi64(twice, d), odd),
                    );
                    _mm256_sub_epi64(q, up)
                }
            };
            let res = self.fit::<WRAP>(q);
            // b = 0: the most positive value for a > 0, the most negative for a < 0, 0 for 0
            let pos = _mm256_and_si256(_mm256_cmpgt_epi64(pa, zero), _mm256_set1_epi64x(self.c.max));
            let neg = _mm256_and_si256(self.negative(pa), _mm256_set1_epi64x(self.c.min));
            let by_zero = _mm256_add_epi64(_mm256_or_si256(pos, neg), self.m);
            _mm256_blendv_epi8(res, by_zero, by0)
        }
    }
    #[inline(always)]
    fn abs<const WRAP: bool>(&self, a: __m256i) -> __m256i {
        unsafe {
            let x = _mm256_castsi256_pd(a);
            self.fit::<WRAP>(_mm256_castpd_si256(_mm256_max_pd(x, _mm256_sub_pd(self.m2d, x))))
        }
    }
    #[inline(always)]
    fn lt(&self, a: __m256i, b: __m256i) -> u8 {
        self.cmp::<_CMP_LT_OQ>(a, b)
    }
    #[inline(always)]
    fn le(&self, a: __m256i, b: __m256i) -> u8 {
        self.cmp::<_CMP_LE_OQ>(a, b)
    }
    #[inline(always)]
    fn eq(&self, a: __m256i, b: __m256i) -> u8 {
        self.cmp::<_CMP_EQ_OQ>(a, b)
    }
    #[inline(always)]
    fn sel(&self, m: u8, a: __m256i, b: __m256i) -> __m256i {
        unsafe {
            let mask = _mm256_loadu_si256(EXPAND[(m & 15) as usize].as_ptr().cast());
            _mm256_blendv_epi8(b, a, mask)
        }
    }
    #[inline(always)]
    fn max(&self, a: __m256i, b: __m256i) -> __m256i {
        unsafe { _mm256_castpd_si256(_mm256_max_pd(_mm256_castsi256_pd(a), _mm256_castsi256_pd(b))) }
    }
    #[inline(always)]
    fn min(&self, a: __m256i, b: __m256i) -> __m256i {
        unsafe { _mm256_castpd_si256(_mm256_min_pd(_mm256_castsi256_pd(a), _mm256_castsi256_pd(b))) }
    }
    #[inline(always)]
    fn step(&self, a: __m256i, k: i64) -> __m256i {
        unsafe { _mm256_add_epi64(a, _mm256_set1_epi64x(k)) }
    }
}
