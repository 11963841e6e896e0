//! Lane flags as bit masks: a column of up to 64 `bool`s as the bits of a `u64` (SSE2 on
//! x86-64 for a whole word), a block cut into words, the set bits of a word.

/// A bit mask of at most 64 lanes: bit k is `b[k]`.
#[inline(always)]
pub fn bits(b: &[bool]) -> u64 {
    debug_assert!(b.len() <= 64);
    #[cfg(target_arch = "x86_64")]
    if let Ok(b) = <&[bool; 64]>::try_from(b) {
        use std::arch::x86_64::*;
        // SSE2 (every x86-64): a 0/1 byte compared above zero is all ones, movemask takes
        // each byte's top bit
        let p = b.as_ptr().cast::<__m128i>();
        let mut m = 0u64;
        for q in 0..4 {
            // SAFETY: 64 bools are 4 × 16 readable bytes; SSE2 is part of x86-64
            let k = unsafe { _mm_movemask_epi8(_mm_cmpgt_epi8(_mm_loadu_si128(p.add(q)), _mm_setzero_si128())) };
            m |= (k as u32 as u64) << (16 * q);
        }
        return m;
    }
    let (bytes, rest) = b.as_chunks::<8>();
    let mut m = 0u64;
    for (j, c) in bytes.iter().enumerate() {
        // eight 0/1 bytes to eight bits: byte i lands on bit 56 + i, no carries between them
        let x = u64::from_le_bytes(c.map(u8::from));
        m |= (x.wrapping_mul(0x0102_0408_1020_4080) >> 56) << (8 * j);
    }
    for (j, &v) in rest.iter().enumerate() {
        m |= u64::from(v) << (8 * bytes.len() + j);
    }
    m
}

/// A block of `n` lanes in words of 64: (first lane, lane count) per word.
pub fn words(n: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..n).step_by(64).map(move |w| (w, (n - w).min(64)))
}

/// The set bits of `m`, lowest first.
pub fn ones(mut m: u64) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let j = m.trailing_zeros() as usize;
            m &= m - 1;
            j
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// `bits` puts lane k on bit k for every pattern of a byte and for every length up to 64
    /// (random lanes); `ones` lists the set bits lowest first; `words` covers a block exactly.
    #[test]
    fn masks() {
        let naive = |b: &[bool]| b.iter().enumerate().fold(0u64, |m, (k, &x)| m | (u64::from(x) << k));
        for p in 0..256u32 {
            let b: Vec<bool> = (0..8).map(|k| p >> k & 1 == 1).collect();
            assert_eq!(bits(&b), u64::from(p));
        }
        let mut r = SplitMix64::new(3);
        for len in 0..=64 {
            for _ in 0..50 {
                let b: Vec<bool> = (0..len).map(|_| r.below(2) == 1).collect();
                let m = bits(&b);
                assert_eq!(m, naive(&b), "{b:?}");
                let set: Vec<usize> = (0..len).filter(|&k| b[k]).collect();
                assert_eq!(ones(m).collect::<Vec<_>>(), set);
            }
        }
        // a whole word (the SSE2 path on x86-64): each lane alone, and all
        for k in 0..64 {
            let b: Vec<bool> = (0..64).map(|j| j == k).collect();
            assert_eq!(bits(&b), 1u64 << k);
        }
        assert_eq!(bits(&[true; 64]), u64::MAX);
        assert_eq!(words(0).count(), 0);
        assert_eq!(words(64).collect::<Vec<_>>(), [(0, 64)]);
        assert_eq!(words(200).collect::<Vec<_>>(), [(0, 64), (64, 64), (128, 64), (192, 8)]);
    }
}
