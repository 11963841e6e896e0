//! The counters a `verify` pass accumulates per format, by name (a partial file's
//! `rti.counts` and each slab variant's `counts` carry these names; docs/cluster.md).

use engine::Merge;
use serde::{Deserialize, Serialize};

/// One format's RTI counters.
#[derive(Default, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RtiCounts {
    /// Ray–triangle tests.
    pub tests: u64,
    /// Tests whose error bound is clear of every threshold (the model must agree).
    pub decisive: u64,
    /// Reference hits (the exact decision on the quantised inputs).
    pub reference_hits: u64,
    /// Model hits.
    pub model_hits: u64,
    /// Reference hit, model miss.
    pub false_misses: u64,
    /// Reference miss, model hit.
    pub false_hits: u64,
    /// Property failures ([`crate::judge::violation`]).
    pub violations: u64,
    /// Both hit.
    pub shared_hits: u64,
    /// Rays whose min-capture result names another triangle (or hit/miss) than the golden
    /// closest hit.
    pub closest_disagreements: u64,
    /// Tests whose valid bit cleared at stage 7 (a valid-gated divide skips them).
    pub divide_skipped: u64,
    /// Tests the f64 filter could not decide, decided by exact rational arithmetic.
    pub exact: u64,
}

impl Merge for RtiCounts {
    fn merge(&mut self, o: Self) {
        self.tests += o.tests;
        self.decisive += o.decisive;
        self.reference_hits += o.reference_hits;
        self.model_hits += o.model_hits;
        self.false_misses += o.false_misses;
        self.false_hits += o.false_hits;
        self.violations += o.violations;
        self.shared_hits += o.shared_hits;
        self.closest_disagreements += o.closest_disagreements;
        self.divide_skipped += o.divide_skipped;
        self.exact += o.exact;
    }
}

/// One slab variant's counters.
#[derive(Default, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlabCounts {
    /// Ray–box tests.
    pub tests: u64,
    /// Exact hits (rational decision on the quantised ray and the original box).
    pub exact_hits: u64,
    /// Exact hit, model miss.
    pub false_misses: u64,
    /// Exact miss, model hit.
    pub false_hits: u64,
    /// Tests settled by the exact rational decision.
    pub exact_calls: u64,
}

impl Merge for SlabCounts {
    fn merge(&mut self, o: Self) {
        self.tests += o.tests;
        self.exact_hits += o.exact_hits;
        self.false_misses += o.false_misses;
        self.false_hits += o.false_hits;
        self.exact_calls += o.exact_calls;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Merging adds every counter to its own (distinct values, so a swapped or dropped field
    /// shows).
    #[test]
    fn merging_adds_each_counter_to_itself() {
        let a = RtiCounts {
            tests: 1,
            decisive: 2,
            reference_hits: 3,
            model_hits: 4,
            false_misses: 5,
            false_hits: 6,
            violations: 7,
            shared_hits: 8,
            closest_disagreements: 9,
            divide_skipped: 10,
            exact: 11,
        };
        let mut b = a;
        b.merge(a);
        assert_eq!(
            b,
            RtiCounts {
                tests: 2,
                decisive: 4,
                reference_hits: 6,
                model_hits: 8,
                false_misses: 10,
                false_hits: 12,
                violations: 14,
                shared_hits: 16,
                closest_disagreements: 18,
                divide_skipped: 20,
                exact: 22,
            }
        );
        let s = SlabCounts { tests: 1, exact_hits: 2, false_misses: 3, false_hits: 4, exact_calls: 5 };
        let mut t = s;
        t.merge(s);
        assert_eq!(t, SlabCounts { tests: 2, exact_hits: 4, false_misses: 6, false_hits: 8, exact_calls: 10 });
    }
}
