//! AVX-512F + DQ lanes: 8 raw values in a zmm register, masks in `__mmask8`.

use super::lanes::*;

use std::arch::x86_64::*;

/// The format's constants, broadcast. A value of this type exists only where AVX-512F
/// and AVX-512DQ were detected ([`Z::new`] is unsafe), which is what makes the
/// intrinsics in its methods sound.
#[derive(Clone, Copy)]
pub(super) struct Z {
    c: Lanes,
    min: __m512i,
    max: __m512i,
    low: __m512i,
    unit: __m512i,
    one: __m512i,
    f: __m128i,
    sh: __m128i,
}

/// `_mm512_cvt_roundpd_epi64` toward −∞: the floor of each lane as an integer.
const FLOOR_CVT: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;

impl Z {
    /// The broadcast constants of `c`.
    ///
    /// # Safety
    /// The CPU has AVX-512F and AVX-512DQ.
    #[inline(always)]
    pub(super) unsafe fn new(c: Lanes) -> Self {
        // SAFETY: the caller's promise
        unsafe {
            Self {
                c,
                min: _mm512_set1_epi64(c.min),
                max: _mm512_set1_epi64(c.max),
                low: _mm512_set1_epi64(c.low),
                unit: _mm512_set1_epi64(c.low + 1),
                one: _mm512_set1_epi64(1),
                f: _mm_cvtsi64_si128(c.f as i64),
                sh: _mm_cvtsi64_si128(c.sh as i64),
            }
        }
    }
    /// [`fit`].
    #[inline(always)]
    fn fit<const WRAP: bool>(&self, x: __m512i) -> __m512i {
        // SAFETY (every method): `self` exists, so the features do (see the type)
        unsafe {
            if WRAP {
                _mm512_sra_epi64(_mm512_sll_epi64(x, self.sh), self.sh)
            } else {
                _mm512_min_epi64(_mm512_max_epi64(x, self.min), self.max)
            }
        }
    }
    /// `q` + [`bump`] (remainder `r` of `d`, exact value negative in `neg`).
    #[inline(always)]
    fn bump<const R: u8>(&self, q: __m512i, r: __m512i, d: __m512i, neg: __mmask8) -> __m512i {
        unsafe {
            let inexact = _mm512_test_epi64_mask(r, r);
            let m = match R {
                FLOOR => 0,
                CEIL => inexact,
                TRUNC => inexact & neg,
                _ => {
                    let twice = _mm512_add_epi64(r, r);
                    _mm512_cmpgt_epi64_mask(twice, d)
                        | (_mm512_cmpeq_epi64_mask(twice, d) & _mm512_test_epi64_mask(q, self.one))
                }
            };
            _mm512_mask_add_epi64(q, m, q, self.one)
        }
    }
}

impl Ops for Z {
    const L: usize = 8;
    type V = __m512i;
    #[inline(always)]
    fn c(&self) -> &Lanes {
        &self.c
    }
    #[inline(always)]
    fn load(&self, col: &[i64], i: usize) -> __m512i {
        let s = &col[i..i + 8];
        unsafe { _mm512_loadu_si512(s.as_ptr().cast()) }
    }
    #[inline(always)]
    fn store(&self, col: &mut [i64], i: usize, v: __m512i) {
        let s = &mut col[i..i + 8];
        unsafe { _mm512_storeu_si512(s.as_mut_ptr().cast(), v) }
    }
    #[inline(always)]
    fn splat(&self, x: i64) -> __m512i {
        unsafe { _mm512_set1_epi64(x) }
    }
    #[inline(always)]
    fn add<const WRAP: bool>(&self, a: __m512i, b: __m512i) -> __m512i {
        self.fit::<WRAP>(unsafe { _mm512_add_epi64(a, b) })
    }
    #[inline(always)]
    fn sub<const WRAP: bool>(&self, a: __m512i, b: __m512i) -> __m512i {
        self.fit::<WRAP>(unsafe { _mm512_sub_epi64(a, b) })
    }
    #[inline(always)]
    fn mul<const R: u8, const WRAP: bool>(&self, a: __m512i, b: __m512i) -> __m512i {
        unsafe {
            // the raw values are 32-bit: vpmuldq is the exact product
            let p = _mm512_mul_epi32(a, b);
            let q = _mm512_sra_epi64(p, self.f);
            let r = _mm512_and_si512(p, self.low);
            // to nearest: 2r against 2^F is r against 2^(F-1)
            self.fit::<WRAP>(self.bump::<R>(q, r, self.unit, _mm512_movepi64_mask(p)))
        }
    }
    #[inline(always)]
    fn div<const R: u8, const WRAP: bool, const TWO: bool>(&self, a: __m512i, b: __m512i) -> __m512i {
        unsafe {
            let zero = _mm512_setzero_si512();
            let n0 = _mm512_sll_epi64(a, self.f);
            let n = _mm512_mask_sub_epi64(n0, _mm512_movepi64_mask(b), zero, n0);
            let d0 = _mm512_abs_epi64(b);
            let by0 = _mm512_testn_epi64_mask(d0, d0);
            let d = _mm512_mask_mov_epi64(d0, by0, self.one);
            let df = _mm512_cvtepi64_pd(d);
            let mut q = _mm512_cvt_roundpd_epi64::<FLOOR_CVT>(_mm512_div_pd(_mm512_cvtepi64_pd(n), df));
            let mut r = _mm512_sub_epi64(n, _mm512_mullo_epi64(q, d));
            if TWO {
                let step = _mm512_cvt_roundpd_epi64::<FLOOR_CVT>(_mm512_div_pd(_mm512_cvtepi64_pd(r), df));
                q = _mm512_add_epi64(q, step);
                r = _mm512_sub_epi64(n, _mm512_mullo_epi64(q, d));
            }
            let below = _mm512_movepi64_mask(r);
            q = _mm512_mask_sub_epi64(q, below, q, self.one);
            r = _mm512_mask_add_epi64(r, below, r, d);
            let res = self.fit::<WRAP>(self.bump::<R>(q, r, d, _mm512_movepi64_mask(n)));
            let pos = _mm512_mask_mov_epi64(zero, _mm512_cmpgt_epi64_mask(a, zero), self.max);
            let by_zero = _mm512_mask_mov_epi64(pos, _mm512_movepi64_mask(a), self.min);
            _mm512_mask_mov_epi64(res, by0, by_zero)
        }
    }
    #[inline(always)]
    fn abs<const WRAP: bool>(&self, a: __m512i) -> __m512i {
        self.fit::<WRAP>(unsafe { _mm512_abs_epi64(a) })
    }
    #[inline(always)]
    fn lt(&self, a: __m512i, b: __m512i) -> u8 {
        unsafe { _mm512_cmplt_epi64_mask(a, b) }
    }
    #[inline(always)]
    fn le(&self, a: __m512i, b: __m512i) -> u8 {
        unsafe { _mm512_cmple_epi64_mask(a, b) }
    }
    #[inline(always)]
    fn eq(&self, a: __m512i, b: __m512i) -> u8 {
        unsafe { _mm512_cmpeq_epi64_mask(a, b) }
    }
    #[inline(always)]
    fn sel(&self, m: u8, a: __m512i, b: __m512i) -> __m512i {
        unsafe { _mm512_mask_blend_epi64(m, b, a) }
    }
    #[inline(always)]
    fn max(&self, a: __m512i, b: __m512i) -> __m512i {
        unsafe { _mm512_max_epi64(a, b) }
    }
    #[inline(always)]
    fn min(&self, a: __m512i, b: __m512i) -> __m512i {
        unsafe { _mm512_min_epi64(a, b) }
    }
    #[inline(always)]
    fn step(&self, a: __m512i, k: i64) -> __m512i {
        unsafe { _mm512_add_epi64(a, _mm512_set1_epi64(k)) }
    }
}
