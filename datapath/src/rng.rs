//! SplitMix64: the small seeded generator every random stream of raypipe uses, so that a seed
//! reproduces a run exactly on any machine.

/// What the state advances by per draw (SplitMix64's golden-ratio increment).
pub const GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// SplitMix64's output function of a state.
#[inline(always)]
pub const fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// SplitMix64 (Steele, Lea, Flood 2014).
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    /// The generator of item `index` of stream `stream` under `seed`: seeded with the first
    /// output of `SplitMix64::new(seed ^ stream)` plus `index`, then one output is discarded
    /// (so neighbouring items start far apart). An item's numbers depend on (seed, stream,
    /// index) alone, never on how items are chunked or scheduled.
    pub fn for_item(seed: u64, stream: u64, index: u64) -> Self {
        let base = SplitMix64::new(seed ^ stream).next_u64();
        let mut r = SplitMix64::new(base.wrapping_add(index));
        r.next_u64();
        r
    }
    /// Next 64 random bits: the state advanced by [`GAMMA`], then [`mix`]ed.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(GAMMA);
        mix(self.0)
    }
    /// The state: draw k from here (k = 1, 2, …) is `mix(state + k · GAMMA)`.
    pub fn state(&self) -> u64 {
        self.0
    }
    /// Moves on as `k` draws would.
    pub fn skip(&mut self, k: u64) {
        self.0 = self.0.wrapping_add(k.wrapping_mul(GAMMA));
    }
    /// Uniform in [0, 1) with 53 random bits.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    /// Uniform integer in 0..n (n > 0).
    pub fn below(&mut self, n: u64) -> u64 {
        ((self.next_u64() as u128 * n as u128) >> 64) as u64
    }
}

#[cfg(test)]
mod tests {
    use super::SplitMix64;

    #[test]
    fn reference_sequence() {
        // first outputs for seed 1234567 from the published reference implementation
        let mut r = SplitMix64::new(1234567);
        assert_eq!(r.next_u64(), 6457827717110365317);
        assert_eq!(r.next_u64(), 3203168211198807973);
    }

    #[test]
    fn unit_range_and_below_are_the_documented_maps_of_the_bits() {
        // the reference outputs above, mapped by hand: unit = (x >> 11) · 2^−53 (53 bits,
        // exact), range(lo, hi) = lo + (hi − lo) · unit, below(n) = ⌊x · n / 2^64⌋
        let u: f64 = 3153236189995295.0 / 9007199254740992.0;
        assert_eq!(SplitMix64::new(1234567).unit().to_bits(), u.to_bits());
        assert_eq!(SplitMix64::new(1234567).range(-2.0, 4.0).to_bits(), (-2.0 + 6.0 * u).to_bits());
        assert_eq!(SplitMix64::new(1234567).below(1000), 350);
        let mut r = SplitMix64::new(1234567);
        r.next_u64();
        assert_eq!(r.below(10), 1);
        // every unit is in [0, 1) and every below(n) in 0..n
        let mut r = SplitMix64::new(7);
        for _ in 0..1000 {
            let x = r.unit();
            assert!((0.0..1.0).contains(&x));
            assert!(r.below(3) < 3);
        }
    }

    #[test]
    fn item_streams_follow_their_definition() {
        let base = SplitMix64::new(5 ^ 9).next_u64();
        let mut want = SplitMix64::new(base.wrapping_add(3));
        want.next_u64();
        assert_eq!(SplitMix64::for_item(5, 9, 3).next_u64(), want.next_u64());
        assert_ne!(SplitMix64::for_item(5, 9, 3).next_u64(), SplitMix64::for_item(5, 9, 4).next_u64());
    }
}
