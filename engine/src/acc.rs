//! Mergeable accumulators: what a chunk folds its results into, and how two chunks' results
//! combine. Every accumulator here is an exact commutative monoid (`merge` is associative and
//! commutative, `Default` is its identity, no floating-point sum anywhere), so a run's result
//! does not depend on how its items were chunked, scheduled or merged.

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::collections::BTreeMap;

/// An accumulator: `Default` is the empty result, `merge` adds another chunk's result. `merge`
/// must be associative and commutative: a run merges chunks in the order they complete.
pub trait Merge: Default + Send {
    /// Adds `other`'s results to `self`.
    fn merge(&mut self, other: Self);
}

/// `N` integer counters, merged by addition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Counts<const N: usize>(pub [u64; N]);

impl<const N: usize> Default for Counts<N> {
    fn default() -> Self {
        Counts([0; N])
    }
}

// serde's arrays stop at 32: a sequence of exactly N numbers
impl<const N: usize> Serialize for Counts<N> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.as_slice().serialize(s)
    }
}

impl<'de, const N: usize> Deserialize<'de> for Counts<N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = Vec::<u64>::deserialize(d)?;
        let n = v.len();
        v.try_into().map(Counts).map_err(|_| serde::de::Error::custom(format!("expected {N} counts, found {n}")))
    }
}

impl<const N: usize> Merge for Counts<N> {
    fn merge(&mut self, other: Self) {
        for (a, b) in self.0.iter_mut().zip(other.0) {
            *a += b;
        }
    }
}

/// The record with the smallest key (e.g. the first violation by item index), merged by taking
/// the smaller key; equal keys keep `self`'s record (keys are unique per item in practice).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct First<K, T>(pub Option<(K, T)>);

impl<K, T> Default for First<K, T> {
    fn default() -> Self {
        First(None)
    }
}

impl<K: Ord + Send, T: Send> First<K, T> {
    /// Offers a record; it is kept when its key is smaller than the held one's.
    pub fn offer(&mut self, key: K, make: impl FnOnce() -> T) {
        if self.0.as_ref().is_none_or(|(k, _)| key < *k) {
            self.0 = Some((key, make()));
        }
    }
    /// The held record.
    pub fn get(&self) -> Option<&T> {
        self.0.as_ref().map(|(_, t)| t)
    }
    /// The held record, owned.
    pub fn into_inner(self) -> Option<T> {
        self.0.map(|(_, t)| t)
    }
}

impl<K: Ord + Send, T: Send> Merge for First<K, T> {
    fn merge(&mut self, other: Self) {
        if let Some((k, t)) = other.0 {
            self.offer(k, || t);
        }
    }
}

/// Fraction bits of a [`Hist`] bucket: values sharing an exponent and their top 10 fraction
/// bits share a bucket, so a bucket spans a relative width of at most 2⁻¹⁰.
pub const HIST_FRACTION_BITS: u32 = 10;
const HIST_SHIFT: u32 = 52 - HIST_FRACTION_BITS;

/// A histogram of non-negative values with exact integer counts per bucket and the exact
/// maximum. Bucket of a value `x >= 0` (finite or +∞): the binary64 encoding of `x` shifted
/// right by 42 bits (sign 0, exponent, top 10 fraction bits), so bucket `b` holds
/// `[from_bits(b << 42), from_bits((b + 1) << 42))` and every bucket is narrower than 2⁻¹⁰ of
/// its lower edge; 0 and subnormals below 2⁻¹⁰²² · 2⁻⁴² share bucket 0's range as the encoding
/// says. A NaN or negative value is counted in `invalid`, not in a bucket.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Hist {
    buckets: BTreeMap<u32, u64>,
    count: u64,
    invalid: u64,
    /// Serialised as its binary64 encoding (JSON has no +∞).
    #[serde(with = "f64_bits")]
    max: f64,
}

/// An f64 as its encoding.
mod f64_bits {
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_u64(x.to_bits())
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        u64::deserialize(d).map(f64::from_bits)
    }
}

impl Hist {
    /// Adds one value.
    pub fn add(&mut self, x: f64) {
        if x.is_nan() || x < 0.0 {
            self.invalid += 1;
            return;
        }
        // -0.0 counts as 0
        let x = x + 0.0;
        *self.buckets.entry((x.to_bits() >> HIST_SHIFT) as u32).or_insert(0) += 1;
        self.count += 1;
        if x > self.max {
            self.max = x;
        }
    }
    /// Values added (NaN and negative ones excluded).
    pub fn count(&self) -> u64 {
        self.count
    }
    /// NaN or negative values offered.
    pub fn invalid(&self) -> u64 {
        self.invalid
    }
    /// The exact largest value (0 when empty).
    pub fn max(&self) -> f64 {
        self.max
    }
    /// The bucket `[lo, hi)` holding the value of rank `rank` (0-based, in increasing order),
    /// or `None` when `rank >= count`. The top bucket's `hi` is clipped to the exact maximum
    /// (then the interval is closed: `lo <= x <= max`).
    pub fn rank_bucket(&self, rank: u64) -> Option<(f64, f64)> {
        if rank >= self.count {
            return None;
        }
        let mut seen = 0;
        for (&b, &n) in &self.buckets {
            seen += n;
            if seen > rank {
                let lo = f64::from_bits((b as u64) << HIST_SHIFT);
                let hi = f64::from_bits((b as u64 + 1) << HIST_SHIFT).min(self.max);
                return Some((lo, hi.max(lo)));
            }
        }
        None
    }
    /// The median as the lower edge of the bucket holding the value of rank `count / 2` (the
    /// upper median): within 2⁻¹⁰ relative below the exact upper median; 0 when empty.
    pub fn median(&self) -> f64 {
        self.rank_bucket(self.count / 2).map_or(0.0, |(lo, _)| lo)
    }
    /// Distinct buckets in use (memory is proportional to this, at most 2²¹).
    pub fn buckets(&self) -> usize {
        self.buckets.len()
    }

    /// Checks a histogram read from a file: its buckets add up to its count, and its maximum
    /// lies in its highest bucket (0 when it is empty).
    pub fn check(&self) -> Result<(), String> {
        let total: u64 = self.buckets.values().sum();
        if total != self.count {
            return Err(format!("a histogram's buckets hold {total} values, its count says {}", self.count));
        }
        let top = self.buckets.iter().next_back().filter(|(_, &n)| n > 0).map(|(&b, _)| b);
        let max_ok = match top {
            None => self.max.to_bits() == 0,
            Some(b) => self.max >= 0.0 && (self.max.to_bits() >> HIST_SHIFT) as u32 == b,
        };
        if !max_ok {
            return Err(format!("a histogram's maximum {:e} is not in its highest bucket", self.max));
        }
        Ok(())
    }
}

impl Merge for Hist {
    fn merge(&mut self, other: Self) {
        for (b, n) in other.buckets {
            *self.buckets.entry(b).or_insert(0) += n;
        }
        self.count += other.count;
        self.invalid += other.invalid;
        if other.max > self.max {
            self.max = other.max;
        }
    }
}

/// A set of small indices as a bitmap, merged by union.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Bits(Vec<u64>);

impl Bits {
    /// Adds index `i`.
    pub fn insert(&mut self, i: usize) {
        let w = i / 64;
        if w >= self.0.len() {
            self.0.resize(w + 1, 0);
        }
        self.0[w] |= 1 << (i % 64);
    }
    /// Indices in the set.
    pub fn count(&self) -> u64 {
        self.0.iter().map(|w| w.count_ones() as u64).sum()
    }
}

impl Merge for Bits {
    fn merge(&mut self, other: Self) {
        if other.0.len() > self.0.len() {
            self.0.resize(other.0.len(), 0);
        }
        for (a, b) in self.0.iter_mut().zip(other.0) {
            *a |= b;
        }
    }
}

/// Integer counters of a length known only at run time (e.g. one per tree level), merged by
/// element-wise addition; a shorter operand counts as zeros.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tally(pub Vec<u64>);

impl Tally {
    /// Adds `n` at index `i`.
    pub fn add(&mut self, i: usize, n: u64) {
        if i >= self.0.len() {
            self.0.resize(i + 1, 0);
        }
        self.0[i] += n;
    }
}

impl Merge for Tally {
    fn merge(&mut self, other: Self) {
        if other.0.len() > self.0.len() {
            self.0.resize(other.0.len(), 0);
        }
        for (a, b) in self.0.iter_mut().zip(other.0) {
            *a += b;
        }
    }
}

impl<T: Merge> Merge for Vec<T> {
    /// Element-wise; an empty vector is the identity.
    fn merge(&mut self, other: Self) {
        if self.is_empty() {
            *self = other;
            return;
        }
        assert!(other.is_empty() || other.len() == self.len(), "merging accumulators of different shapes");
        for (a, b) in self.iter_mut().zip(other) {
            a.merge(b);
        }
    }
}

impl<T: Merge> Merge for Option<T> {
    fn merge(&mut self, other: Self) {
        match (self.as_mut(), other) {
            (_, None) => {}
            (None, o) => *self = o,
            (Some(a), Some(b)) => a.merge(b),
        }
    }
}

macro_rules! tuple_merge {
    ($($t:ident $i:tt),+) => {
        impl<$($t: Merge),+> Merge for ($($t,)+) {
            fn merge(&mut self, other: Self) {
                $(self.$i.merge(other.$i);)+
            }
        }
    };
}
tuple_merge!(A 0, B 1);
tuple_merge!(A 0, B 1, C 2);
tuple_merge!(A 0, B 1, C 2, D 3);

#[cfg(test)]
mod tests {
    use super::*;

    /// A histogram's check: a merged one passes; a count unequal to its buckets, or a maximum
    /// outside its highest bucket, fails.
    #[test]
    fn a_histogram_checks_its_count_and_maximum() {
        let mut h = Hist::default();
        assert!(h.check().is_ok());
        for x in [0.5, 3.0, 3.0, 1e9] {
            h.add(x);
        }
        h.add(f64::NAN);
        assert!(h.check().is_ok());
        let mut c = h.clone();
        c.count += 1;
        assert!(c.check().unwrap_err().contains("hold 4 values, its count says 5"));
        let mut m = h.clone();
        m.max = 3.0;
        assert!(m.check().is_err());
        let z = Hist { max: 1.0, ..Default::default() };
        assert!(z.check().is_err());
    }
    use proptest::prelude::*;

    fn hist(xs: &[f64]) -> Hist {
        let mut h = Hist::default();
        xs.iter().for_each(|&x| h.add(x));
        h
    }

    /// −0 counts as +0: one bucket, the one of +0, and the maximum +0.
    #[test]
    fn negative_zero_is_zero() {
        let h = hist(&[-0.0, 0.0, -0.0]);
        assert_eq!((h.count(), h.invalid(), h.buckets()), (3, 0, 1));
        assert_eq!(h.rank_bucket(0), Some((0.0, 0.0)));
        assert_eq!(h.max().to_bits(), 0f64.to_bits());
        assert_eq!(h.median().to_bits(), 0f64.to_bits());
        assert_eq!(hist(&[1.0, 2.0, 2.0, 1e300]).buckets(), 3);
        assert_eq!(Hist::default().buckets(), 0);
    }

    /// Merging adds the counts of buckets both sides hold; a bitmap keeps one bit per index
    /// in word i / 64; options merge their contents.
    #[test]
    fn merges_add_overlapping_buckets_and_contents() {
        let mut a = hist(&[1.0, 2.0, 2.0]);
        a.merge(hist(&[2.0, 2.0, 2.0, 3.0]));
        assert_eq!((a.count(), a.buckets()), (7, 3));
        let mut bad = hist(&[f64::NAN, -1.0, 1.0]);
        bad.merge(hist(&[f64::NAN, 0.5]));
        assert_eq!((bad.count(), bad.invalid()), (2, 3));
        // ranks 0 = 1.0, 1..=5 = 2.0, 6 = 3.0
        assert_eq!(a.rank_bucket(0).map(|b| b.0), Some(1.0));
        assert_eq!(a.rank_bucket(5).map(|b| b.0), Some(2.0));
        assert_eq!(a.rank_bucket(6).map(|b| b.0), Some(3.0));
        let mut b = Bits::default();
        for i in [0, 63, 64, 130] {
            b.insert(i);
        }
        assert_eq!(b.0, [1 | 1 << 63, 1, 1 << 2]);
        let mut o = Some(Counts([1u64, 2]));
        o.merge(Some(Counts([10, 20])));
        assert_eq!(o, Some(Counts([11, 22])));
        o.merge(None);
        assert_eq!(o, Some(Counts([11, 22])));
        let mut n: Option<Counts<2>> = None;
        n.merge(Some(Counts([5, 6])));
        assert_eq!(n, Some(Counts([5, 6])));
    }

    #[test]
    fn median_is_the_bucket_below_the_exact_upper_median() {
        let xs = [3.0, 0.5, 1.0, 1.0009765625, 7.25, 0.0, 2.0];
        let h = hist(&xs);
        let mut s = xs.to_vec();
        s.sort_by(f64::total_cmp);
        let exact = s[s.len() / 2];
        assert_eq!(exact, 1.0009765625);
        // 1 + 2^-10 starts its own bucket
        assert_eq!(h.median().to_bits(), exact.to_bits());
        assert_eq!(h.max().to_bits(), 7.25f64.to_bits());
        assert_eq!(h.rank_bucket(0), Some((0.0, f64::from_bits(1 << HIST_SHIFT))));
        // a value just below the next bucket edge reports the edge below it
        let h = hist(&[1.0 + 2f64.powi(-11)]);
        assert_eq!(h.median(), 1.0);
        assert_eq!(h.rank_bucket(0), Some((1.0, 1.0 + 2f64.powi(-11))));
        assert_eq!(hist(&[f64::NAN, -1.0]).invalid(), 2);
        assert_eq!(Hist::default().median(), 0.0);
    }

    proptest! {
        #[test]
        fn sets_and_tallies_merge_to_one_pass(xs in prop::collection::vec(0usize..500, 0..100), cut in 0usize..100) {
            let cut = cut.min(xs.len());
            let make = |v: &[usize]| {
                let (mut b, mut t) = (Bits::default(), Tally::default());
                v.iter().for_each(|&i| { b.insert(i); t.add(i % 37, 1); });
                (b, t)
            };
            let one = make(&xs);
            let (mut a, b) = (make(&xs[..cut]), make(&xs[cut..]));
            a.merge(b);
            prop_assert_eq!(a.0.count(), one.0.count());
            prop_assert_eq!(&a.1 .0.iter().sum::<u64>(), &(xs.len() as u64));
            let mut distinct = xs.clone();
            distinct.sort();
            distinct.dedup();
            prop_assert_eq!(one.0.count(), distinct.len() as u64);
            // the trailing-zero shape may differ; the counts per index may not
            for i in 0..37 {
                prop_assert_eq!(a.1 .0.get(i).copied().unwrap_or(0), one.1 .0.get(i).copied().unwrap_or(0));
            }
        }

        #[test]
        fn merging_in_any_split_equals_one_pass(xs in prop::collection::vec(0.0f64..1e6, 0..200), cut in 0usize..200, key in 0u64..300) {
            let cut = cut.min(xs.len());
            let one = hist(&xs);
            let (mut a, b) = (hist(&xs[..cut]), hist(&xs[cut..]));
            let mut b2 = b.clone();
            a.merge(b);
            b2.merge(hist(&xs[..cut]));
            prop_assert_eq!(&a, &one);
            prop_assert_eq!(&b2, &one);
            // the median bucket really holds the exact upper median
            if !xs.is_empty() {
                let mut s = xs.clone();
                s.sort_by(f64::total_cmp);
                let (lo, hi) = one.rank_bucket(one.count() / 2).unwrap();
                let m = s[s.len() / 2];
                prop_assert!(lo <= m && (m < hi || m == one.max()));
                prop_assert!(hi - lo <= lo * 2f64.powi(-10) || lo == 0.0);
            }
            // First keeps the smallest key in either order
            let (mut f, mut g) = (First::default(), First::default());
            let key = 2 * key + 1; // unique keys: never 150
            f.offer(key, || "a");
            g.offer(150, || "b");
            let mut f2 = f.clone();
            f.merge(g.clone());
            g.merge(f2.clone());
            f2.merge(First::default());
            prop_assert_eq!(f.get(), g.get());
            prop_assert_eq!(f.get(), Some(if key < 150 { &"a" } else { &"b" }));
            prop_assert_eq!(f2.get(), Some(&"a"));
        }
    }
}
