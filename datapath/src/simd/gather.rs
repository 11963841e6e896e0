//! Gathers: fields of records picked by index copied into columns (`cols[c][k] =
//! pick(recs[idx[k]])[c]`), the step that turns a block of test indices into the kernels' SoA
//! columns. Scalar, or with AVX-512F gather instructions for 4- and 8-byte values (16 lanes a
//! step), or AVX2's (8 lanes a step); 2-byte values two columns at a time by 4-byte gathers
//! (each lane's pair of neighbouring fields, split into the two columns); the same values
//! either way: a gather only copies bits.

use super::select::best_kernel;
use super::Kernel;
use std::any::TypeId;

/// Records this many lanes ahead of the copy are prefetched when the caller asks
/// (random records come from L2).
pub const AHEAD: usize = 16;

/// Column by column, `cols[c][k] = pick(&recs[idx[k]])[c]` for every lane `k` of `idx`. With
/// `fetch` each record [`AHEAD`] lanes on is prefetched, all its lines (a hint). The widest
/// copy `cap`, the thread's cap and the machine allow: AVX-512F, else AVX2 gathers when `T` is
/// a 4- or 8-byte number (`f32`, `u32`, `i32`, `f64`, `u64`, `i64`) or a 2-byte one (`u16`,
/// `i16`, `half::f16`, `half::bf16`: 4-byte gathers of neighbouring pairs, every byte read
/// within its record), else scalar.
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
            // SAFETY: AVX-512F is present (best_kernel checks the machine); every column holds
            // idx.len() values; the byte offsets fit in i32 (fits_i32) and every index is
            // checked against recs.len() before its records are read; T is a plain number of
            // w bytes, so copying its bits copies it
            done = if best_kernel(true, cap) >= Kernel::Avx512 {
                unsafe { avx512(recs, idx, fetch, off, w, ptrs) }
            } else {
                unsafe { avx2(recs, idx, fetch, off, w, ptrs) }
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

/// [`avx512`] with AVX2 gathers: 8 lanes a step (4-byte values in one gather, 8-byte values in
/// two of 4); returns the lanes done (a multiple of 8).
///
/// # Safety
/// As [`avx512`], with AVX2 present.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn avx2<R, T, const C: usize>(
    recs: &[R],
    idx: &[u32],
    fetch: bool,
    off: usize,
    w: usize,
    cols: [*mut T; C],
) -> usize {
    use std::arch::x86_64::*;
    let base = recs.as_ptr().cast::<u8>();
    let stride = _mm256_set1_epi32(std::mem::size_of::<R>() as i32);
    // every index below recs.len() (not empty: the caller read recs[0]): unsigned,
    // max(ix, len − 1) == len − 1 on every lane
    let top = _mm256_set1_epi32((recs.len() as u32).wrapping_sub(1) as i32);
    steps(recs, idx, fetch, 8, |k| {
        // SAFETY: k + 8 <= idx.len()
        let ix = unsafe { _mm256_loadu_si256(idx.as_ptr().add(k).cast()) };
        let fits = _mm256_movemask_epi8(_mm256_cmpeq_epi32(_mm256_max_epu32(ix, top), top)) == -1;
        assert!(fits, "gather: index out of range");
        let offs = _mm256_mullo_epi32(ix, stride);
        if w == 2 {
            // the low halves of 8 lanes, then the high halves, as 16-bit lanes (values below
            // 2^16: the unsigned saturating pack keeps them), in lane order
            let mask = _mm256_set1_epi32(0xffff);
            let mut c = 0;
            while c < C {
                // SAFETY: as in `avx512`, for 8 lanes
                unsafe {
                    let (o, high) = pair_read(c, C);
                    let v = _mm256_i32gather_epi32::<1>(base.add(off + o).cast(), offs);
                    let lh = _mm256_packus_epi32(_mm256_and_si256(v, mask), _mm256_srli_epi32::<16>(v));
                    // per 128-bit half: 4 low, 4 high; reordered to 8 low, 8 high
                    let lh = _mm256_permute4x64_epi64::<0b11_01_10_00>(lh);
                    let (lo, hi) = (_mm256_castsi256_si128(lh), _mm256_extracti128_si256::<1>(lh));
                    if c + 1 < C {
                        _mm_storeu_si128(cols[c].add(k).cast(), lo);
                        _mm_storeu_si128(cols[c + 1].add(k).cast(), hi);
                        c += 2;
                    } else {
                        _mm_storeu_si128(cols[c].add(k).cast(), if high { hi } else { lo });
                        c += 1;
                    }
                }
            }
            return;
        }
        for (c, &col) in cols.iter().enumerate() {
            // SAFETY: as in `avx512`, for 8 lanes
            unsafe {
                let p = base.add(off + c * w);
                if w == 4 {
                    let v = _mm256_i32gather_epi32::<1>(p.cast(), offs);
                    _mm256_storeu_si256(col.add(k).cast(), v);
                } else {
                    let lo = _mm256_i32gather_epi64::<1>(p.cast(), _mm256_castsi256_si128(offs));
                    let hi = _mm256_i32gather_epi64::<1>(p.cast(), _mm256_extracti128_si256::<1>(offs));
                    _mm256_storeu_si256(col.add(k).cast(), lo);
                    _mm256_storeu_si256(col.add(k + 4).cast(), hi);
                }
            }
        }
    })
}
