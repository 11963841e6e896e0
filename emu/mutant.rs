
/// `emu/avx512 --mutant` appends this to a copy of `datapath/src/simd.rs`: vmaxps / vmaxph
/// with their operands swapped (a wrong NaN / ±0 rule), which the ISA tables then use.
#[cfg(target_arch = "x86_64")]
#[allow(dead_code)]
mod mutant {
    use std::arch::x86_64::*;
    #[target_feature(enable = "avx512f")]
    pub fn _mm512_max_ps_swapped(a: __m512, b: __m512) -> __m512 {
        _mm512_max_ps(b, a)
    }
    #[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
    pub fn _mm512_max_ph_swapped(a: __m512h, b: __m512h) -> __m512h {
        _mm512_max_ph(b, a)
    }
}
