//! Gathers: fields of records picked by index copied into columns (`cols[c][k] =
//! pick(recs[idx[k]])[c]`), the step that turns a block of test indices into the kernels' SoA
//! columns. Scalar; or with AVX-512F gather instructions for 4- and 8-byte values (16 lanes a
//! step), 2-byte values two columns at a time by 4-byte gathers (each lane's pair of
//! neighbouring fields, split into the two columns); or with AVX2 by plain loads of each
//! record's field and shuffles that transpose the rows into columns (8 lanes a step, 16 for
//! 2-byte values); the same values either way: a gather only copies bits.

use super::select::best_kernel;
use super::Kernel;
use std::any::TypeId;

/// Records this many lanes ahead of the copy are prefetched when the caller asks
/// (random records come from L2).
pub const AHEAD: usize = 16;

/// Column by column, `cols[c][k] = pick(&recs[idx[k]])[c]` for every lane `k` of `idx`. With
/// `fetch` each record [`AHEAD`] lanes on is prefetched, all its lines (a hint). The widest
/// copy `cap`, the thread's cap and the machine allow: AVX-512F gathers, else AVX2 loads and
/// transposes, when `T` is a 4- or 8-byte number (`f32`, `u32`, `i32`, `f64`, `u64`, `i64`) or
/// a 2-byte one (`u16`, `i16`, `half::f16`, `half::bf16`: 4-byte reads of neighbouring pairs,
/// every byte read within its record), else scalar.
///
/// # Panics
/// If a column is shorter than `idx`, or an index is out of range.
#[inline(always)]
pub fn gather<R, T: Copy + 'static, const C: usize>(
    cap: Kernel,
    recs: &[R],
    idx: &[u32],
    fetch: bool,
    pick: impl Fn(&R) -> &[T; C],
    mut cols: [&mut [T]; C],
) {
    assert!(cols.iter().all(|c| c.len() >= idx.len()), "gather: a column is shorter than the block");
    let mut done = 0;
    #[cfg(target_arch = "x86_64")]
    if idx.len() >= 16 && best_kernel(true, cap) >= Kernel::Avx2 && fits_i32::<R>(recs.len()) {
        // the field's byte offset in its record (the same in every record)
        let off = (pick(&recs[0]) as *const [T; C] as usize) - (&recs[0] as *const R as usize);
        let wide = if is::<T, f32>() || is::<T, u32>() || is::<T, i32>() {
            Some(4)
        } else if is::<T, f64>() || is::<T, u64>() || is::<T, i64>() {
            Some(8)
        } else if (is::<T, u16>() || is::<T, i16>() || is::<T, half::f16>() || is::<T, half::bf16>())
            && pair_reads_fit::<R>(off, C)
        {
            Some(2)
        } else {
            None
        };
        if let Some(w) = wide {
            let ptrs: [*mut T; C] = std::array::from_fn(|c| cols[c].as_mut_ptr());
            // SAFETY: AVX-512F or AVX2 is present (best_kernel checks the machine); every column holds
            // idx.len() values; the byte offsets fit in i32 (fits_i32) and every index is
            // checked against recs.len() before its records are read; T is a plain number of
            // w bytes, so copying its bits copies it
            done = if best_kernel(true, cap) >= Kernel::Avx512 {
                unsafe { avx512(recs, idx, fetch, off, w, ptrs) }
            } else if w == 2 {
                unsafe { avx2_rows16(recs, idx, fetch, off, ptrs) }
            } else {
                unsafe { avx2_rows(recs, idx, fetch, off, w, ptrs) }
            };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = cap;
    for k in done..idx.len() {
        if fetch {
            if let Some(&j) = idx.get(k + AHEAD) {
                prefetch(&recs[j as usize]);
            }
        }
        let r = pick(&recs[idx[k] as usize]);
        for (col, &x) in cols.iter_mut().zip(r) {
            // SAFETY: k < idx.len() <= col.len() (asserted above)
            unsafe { *col.get_unchecked_mut(k) = x };
        }
    }
}

/// `T` is `U`.
#[inline(always)]
fn is<T: 'static, U: 'static>() -> bool {
    TypeId::of::<T>() == TypeId::of::<U>()
}

/// Every byte offset `index · size_of::<R>()` of `n` records (and the field within) fits in an
/// i32, the gather instructions' offsets.
#[inline(always)]
fn fits_i32<R>(n: usize) -> bool {
    n.checked_add(1).and_then(|m| m.checked_mul(std::mem::size_of::<R>())).is_some_and(|b| b <= i32::MAX as usize)
}

/// Whether the 4-byte reads of a 2-byte field of `c` columns at byte offset `off` ([`pair_read`])
/// stay within the record: always for `c` ≥ 2 (every read covers two of the field's columns);
/// for `c` = 1 the 2 bytes after the field must lie in the record.
#[inline(always)]
fn pair_reads_fit<R>(off: usize, c: usize) -> bool {
    c >= 2 || off + 4 <= std::mem::size_of::<R>()
}

/// The byte offsets (from the field) of the 4-byte reads of a 2-byte field of `c` columns, and
/// which half of each read a column takes: column `k` reads at `2·(k − k % 2)` (its pair's
/// first), taking the low half when k is even, the high half when odd; an odd last column
/// (`c` odd, ≥ 3) reads with its left neighbour at `2·(k − 1)`, high half; `c` = 1 reads at 0,
/// low half.
#[inline(always)]
fn pair_read(k: usize, c: usize) -> (usize, bool) {
    if k % 2 == 1 {
        (2 * (k - 1), true)
    } else if k + 1 < c || c == 1 {
        (2 * k, false)
    } else {
        (2 * (k - 1), true)
    }
}

/// Asks the cache for every line of `*r` (a hint: no effect on results).
#[inline(always)]
pub fn prefetch<R>(r: &R) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let p = (r as *const R).cast::<i8>();
        let mut off = 0;
        while off < std::mem::size_of::<R>() {
            // SAFETY: a prefetch never faults; p + off lies within *r
            unsafe { _mm_prefetch::<_MM_HINT_T0>(p.add(off)) };
            off += 64;
        }
        // the record's last line when it straddles one more
        // SAFETY: as above
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p.add(std::mem::size_of::<R>().saturating_sub(1))) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = r;
}

/// The whole `lanes`-lane steps of `idx`, in order: `step(k)` checks and copies lanes
/// k .. k + lanes, then, with `fetch`, the records [`AHEAD`] lanes on are prefetched; returns
/// the lanes done (a multiple of `lanes`; the rest are the caller's).
#[inline(always)]
fn steps<R>(recs: &[R], idx: &[u32], fetch: bool, lanes: usize, mut step: impl FnMut(usize)) -> usize {
    let whole = idx.len() - idx.len() % lanes;
    let mut k = 0;
    while k < whole {
        step(k);
        if fetch {
            for &j in idx.get(k + AHEAD..(k + AHEAD + lanes).min(idx.len())).unwrap_or(&[]) {
                prefetch(&recs[j as usize]);
            }
        }
        k += lanes;
    }
    whole
}

/// The whole 16-lane steps of [`gather`] with AVX-512F gathers of `w`-byte values (4 or 8; 2:
/// 4-byte gathers of pairs, [`pair_read`]) at byte offset `off` of each record; returns the
/// lanes done (the rest are the caller's).
///
/// # Safety
/// AVX-512F present; `cols[c]` valid for `idx.len()` writes of `T`; `T` a plain `w`-byte
/// number; `(recs.len() + 1) · size_of::<R>()` at most `i32::MAX`; `off + C·w` within a record; for `w` = 2, [`pair_reads_fit`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn avx512<R, T, const C: usize>(
    recs: &[R],
    idx: &[u32],
    fetch: bool,
    off: usize,
    w: usize,
    cols: [*mut T; C],
) -> usize {
    use std::arch::x86_64::*;
    let base = recs.as_ptr().cast::<u8>();
    let stride = _mm512_set1_epi32(std::mem::size_of::<R>() as i32);
    let len = _mm512_set1_epi32(recs.len() as i32);
    steps(recs, idx, fetch, 16, |k| {
        // SAFETY: k + 16 <= idx.len()
        let ix = unsafe { _mm512_loadu_si512(idx.as_ptr().add(k).cast()) };
        assert!(_mm512_cmpge_epu32_mask(ix, len) == 0, "gather: index out of range");
        let offs = _mm512_mullo_epi32(ix, stride);
        if w == 2 {
            let mut c = 0;
            while c < C {
                // SAFETY: each 4-byte read lies within its record (pair_read, pair_reads_fit:
                // the caller); cols[c] + k .. + 16 is within the column (the caller)
                unsafe {
                    let (o, high) = pair_read(c, C);
                    let v = _mm512_i32gather_epi32::<1>(offs, base.add(off + o).cast());
                    let lo = _mm512_cvtepi32_epi16(v);
                    let hi = _mm512_cvtepi32_epi16(_mm512_srli_epi32::<16>(v));
                    if c + 1 < C {
                        _mm256_storeu_si256(cols[c].add(k).cast(), lo);
                        _mm256_storeu_si256(cols[c + 1].add(k).cast(), hi);
                        c += 2;
                    } else {
                        _mm256_storeu_si256(cols[c].add(k).cast(), if high { hi } else { lo });
                        c += 1;
                    }
                }
            }
            return;
        }
        for (c, &col) in cols.iter().enumerate() {
            // SAFETY: every offset + off + c·w + w lies within recs (indices checked, field
            // within its record); col + k .. col + k + 16 is within the column (the caller)
            unsafe {
                let p = base.add(off + c * w);
                if w == 4 {
                    let v = _mm512_i32gather_epi32::<1>(offs, p.cast());
                    _mm512_storeu_si512(col.add(k).cast(), v);
                } else {
                    let lo = _mm512_i32gather_epi64::<1>(_mm512_castsi512_si256(offs), p.cast());
                    let hi = _mm512_i32gather_epi64::<1>(_mm512_extracti64x4_epi64::<1>(offs), p.cast());
                    _mm512_storeu_si512(col.add(k).cast(), lo);
                    _mm512_storeu_si512(col.add(k + 8).cast(), hi);
                }
            }
        }
    })
}

/// [`avx512`] with AVX2, for 4- and 8-byte values, 8 lanes a step, without gather
/// instructions (AVX2's gathers load lane by lane: on AMD's Zen 3 `verify --format f32` took
/// 0.85 of the wall time with these copies): each record's field read with 16-byte loads (4
/// or 2 values; the last few of a field by masked or 8-byte loads, which read only the field's
/// bytes) and the rows of 8 records transposed into columns by shuffles; returns the lanes done
/// (a multiple of 8).
///
/// # Safety
/// As [`avx512`], with AVX2 present and `w` 4 or 8.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn avx2_rows<R, T, const C: usize>(
    recs: &[R],
    idx: &[u32],
    fetch: bool,
    off: usize,
    w: usize,
    cols: [*mut T; C],
) -> usize {
    use std::arch::x86_64::*;
    let base = recs.as_ptr().cast::<u8>();
    let size = std::mem::size_of::<R>();
    steps(recs, idx, fetch, 8, |k| {
        let ix = &idx[k..k + 8];
        assert!(ix.iter().all(|&i| (i as usize) < recs.len()), "gather: index out of range");
        // SAFETY: every index is below recs.len() (asserted): each field lies within its record
        let p: [*const u8; 8] = std::array::from_fn(|j| unsafe { base.add(ix[j] as usize * size + off) });
        if w == 4 {
            let mut c = 0;
            while c < C {
                let r = (C - c).min(4);
                let m = _mm_setr_epi32(-1, -((r > 1) as i32), -((r > 2) as i32), -((r > 3) as i32));
                // SAFETY: values c .. c + r of each field lie within its record (a masked load
                // reads only its lanes' bytes); cols[c..c + r] + k .. + 8 lie within the
                // columns (the caller)
                unsafe {
                    let row = |j: usize| {
                        let q = p[j].add(4 * c).cast::<f32>();
                        if r == 4 {
                            _mm_loadu_ps(q)
                        } else {
                            _mm_maskload_ps(q, m)
                        }
                    };
                    // rows j | j + 4, then 4 × 4 transposes in each 128-bit half
                    let [r0, r1, r2, r3] = std::array::from_fn(|j| _mm256_set_m128(row(j + 4), row(j)));
                    let (t0, t1) = (_mm256_unpacklo_ps(r0, r1), _mm256_unpackhi_ps(r0, r1));
                    let (t2, t3) = (_mm256_unpacklo_ps(r2, r3), _mm256_unpackhi_ps(r2, r3));
                    let out = [
                        _mm256_shuffle_ps::<0x44>(t0, t2),
                        _mm256_shuffle_ps::<0xee>(t0, t2),
                        _mm256_shuffle_ps::<0x44>(t1, t3),
                        _mm256_shuffle_ps::<0xee>(t1, t3),
                    ];
                    for (i, v) in out.into_iter().take(r).enumerate() {
                        _mm256_storeu_ps(cols[c + i].add(k).cast(), v);
                    }
                }
                c += 4;
            }
        } else {
            let mut c = 0;
            while c < C {
                let r = (C - c).min(2);
                for h in [0, 4] {
                    // SAFETY: as above, for values c .. c + r (a one-value load reads 8 bytes)
                    unsafe {
                        let row = |j: usize| {
                            let q = p[h + j].add(8 * c).cast::<f64>();
                            if r == 2 {
                                _mm_loadu_pd(q)
                            } else {
                                _mm_load_sd(q)
                            }
                        };
                        // records 0 | 2 and 1 | 3 of the half: their first and second values
                        let (a, b) = (_mm256_set_m128d(row(2), row(0)), _mm256_set_m128d(row(3), row(1)));
                        _mm256_storeu_pd(cols[c].add(k + h).cast(), _mm256_unpacklo_pd(a, b));
                        if r == 2 {
                            _mm256_storeu_pd(cols[c + 1].add(k + h).cast(), _mm256_unpackhi_pd(a, b));
                        }
                    }
                }
                c += 2;
            }
        }
    })
}

/// [`avx512`] with AVX2, for 2-byte values, 16 lanes a step: each record's field read with
/// 16-byte loads (8 values; a chunk of fewer by masked loads of whole pairs, which read only
/// the field's bytes) and the rows of 16 records transposed into columns by shuffles; an odd
/// last column (or a one-column field) by AVX2's 4-byte gathers of pairs ([`pair_read`]);
/// returns the lanes done (a multiple of 16).
///
/// # Safety
/// As [`avx512`], with AVX2 present and `w` = 2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn avx2_rows16<R, T, const C: usize>(
    recs: &[R],
    idx: &[u32],
    fetch: bool,
    off: usize,
    cols: [*mut T; C],
) -> usize {
    use std::arch::x86_64::*;
    let base = recs.as_ptr().cast::<u8>();
    let size = std::mem::size_of::<R>();
    let stride = _mm256_set1_epi32(size as i32);
    // the columns in pairs by rows, the odd last one (if any) by pair gathers
    let even = C - C % 2;
    steps(recs, idx, fetch, 16, |k| {
        let ix = &idx[k..k + 16];
        assert!(ix.iter().all(|&i| (i as usize) < recs.len()), "gather: index out of range");
        // SAFETY: every index is below recs.len() (asserted): each field lies within its record
        let p: [*const u8; 16] = std::array::from_fn(|j| unsafe { base.add(ix[j] as usize * size + off) });
        let mut c = 0;
        while c < even {
            let r = (even - c).min(8);
            let m = _mm_setr_epi32(-1, -((r > 2) as i32), -((r > 4) as i32), -((r > 6) as i32));
            // SAFETY: values c .. c + r (r even) of each field lie within its record (a masked
            // load reads only its lanes' bytes); cols[c..c + r] + k .. + 16 lie within the
            // columns (the caller)
            unsafe {
                let row = |j: usize| {
                    let q = p[j].add(2 * c);
                    if r == 8 {
                        _mm_loadu_si128(q.cast())
                    } else {
                        _mm_maskload_epi32(q.cast(), m)
                    }
                };
                // rows j | j + 8, then 8 × 8 transposes of 2-byte values in each 128-bit half
                let rw: [__m256i; 8] = std::array::from_fn(|j| _mm256_set_m128i(row(j + 8), row(j)));
                let s: [__m256i; 8] = std::array::from_fn(|i| {
                    let (a, b) = (rw[2 * (i / 2)], rw[2 * (i / 2) + 1]);
                    if i % 2 == 0 {
                        _mm256_unpacklo_epi16(a, b)
                    } else {
                        _mm256_unpackhi_epi16(a, b)
                    }
                });
                // u[4h + i]: rows 4h .. 4h + 4, values 2i, 2i + 1 of (i even: low, odd: high)
                let u: [__m256i; 8] = std::array::from_fn(|x| {
                    let (h, i) = (x / 4, x % 4);
                    let (a, b) = (s[4 * h + i / 2], s[4 * h + 2 + i / 2]);
                    if i % 2 == 0 {
                        _mm256_unpacklo_epi32(a, b)
                    } else {
                        _mm256_unpackhi_epi32(a, b)
                    }
                });
                for v in 0..r {
                    let (a, b) = (u[v / 2], u[4 + v / 2]);
                    let col = if v % 2 == 0 { _mm256_unpacklo_epi64(a, b) } else { _mm256_unpackhi_epi64(a, b) };
                    _mm256_storeu_si256(cols[c + v].add(k).cast(), col);
                }
            }
            c += 8;
        }
        if even < C {
            // SAFETY: k + 16 <= idx.len(); the pair read lies within the field, or for a
            // one-column field within the record (pair_read, pair_reads_fit: the caller); the
            // indices are checked above
            unsafe {
                let (o, high) = pair_read(C - 1, C);
                for h in [0, 8] {
                    let offs = _mm256_mullo_epi32(_mm256_loadu_si256(idx.as_ptr().add(k + h).cast()), stride);
                    let v = _mm256_i32gather_epi32::<1>(base.add(off + o).cast(), offs);
                    let v = if high { _mm256_srli_epi32::<16>(v) } else { v };
                    // the low 2 bytes of each 4-byte lane, in lane order
                    let v = _mm256_packus_epi32(_mm256_and_si256(v, _mm256_set1_epi32(0xffff)), v);
                    let v = _mm256_permute4x64_epi64::<0b10_00>(v);
                    _mm_storeu_si128(cols[C - 1].add(k + h).cast(), _mm256_castsi256_si128(v));
                }
            }
        }
    })
}
