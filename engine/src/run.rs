//! Running a chunk space: chunks in parallel on a pool of `threads`, each chunk's accumulator
//! merged into the run's one accumulator as the chunk completes (so at most `threads` chunk
//! accumulators and the run's are alive at once, whatever the number of chunks). The merge
//! order is the completion order; `Merge` is commutative and associative, so the result does
//! not depend on it.

use crate::{Merge, Progress};
use rayon::prelude::*;
use std::ops::Range;

/// One shard of a chunk space: shard `k` of `n` runs the chunks whose index c has
/// c mod n = k, so the n shards together run every chunk exactly once.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    /// This shard, 0..n.
    pub k: u64,
    /// Shards in all (at least 1).
    pub n: u64,
}

impl Shard {
    /// The whole space.
    pub const ALL: Shard = Shard { k: 0, n: 1 };

    /// `K/N` (0 <= K < N), or `slurm`: the shard of a Slurm array task, from
    /// `SLURM_ARRAY_TASK_ID` and `SLURM_ARRAY_TASK_COUNT` (read through `env`).
    pub fn parse(s: &str, env: impl Fn(&str) -> Option<String>) -> Result<Shard, String> {
        let (k, n) = if s == "slurm" {
            let get = |v: &str| {
                env(v).ok_or_else(|| format!("--shard slurm: {v} is not set (not inside a Slurm array task)"))
            };
            (get("SLURM_ARRAY_TASK_ID")?, get("SLURM_ARRAY_TASK_COUNT")?)
        } else {
            let (k, n) = s.split_once('/').ok_or_else(|| format!("--shard must be K/N or slurm, got '{s}'"))?;
            (k.to_string(), n.to_string())
        };
        let num = |x: &str| x.trim().parse::<u64>().map_err(|_| format!("--shard: '{x}' is not a shard number"));
        let (k, n) = (num(&k)?, num(&n)?);
        if n == 0 {
            return Err("--shard: N must be at least 1".into());
        }
        if k >= n {
            return Err(format!("--shard: K must be below N (shards are 0..{n}), got {k}"));
        }
        Ok(Shard { k, n })
    }

    /// The shard runs chunk `c`.
    pub fn has(&self, c: u64) -> bool {
        c % self.n == self.k
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

/// How a run is executed; the result does not depend on `threads` or `chunk` (a shard's
/// result is its share of the whole, merged with the other shards' by [`crate::Merge`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Engine {
    /// Worker threads (at least 1).
    pub threads: usize,
    /// Items per chunk (at least 1).
    pub chunk: u64,
    /// The chunks this run takes (default: all).
    pub shard: Shard,
}

impl Engine {
    /// Every core, with chunks of `chunk` items.
    pub fn new(chunk: u64) -> Self {
        Engine { threads: std::thread::available_parallelism().map_or(1, |n| n.get()), chunk, shard: Shard::ALL }
    }
    /// The same engine on one shard of the chunk space.
    pub fn with_shard(mut self, shard: Shard) -> Self {
        self.shard = shard;
        self
    }
    /// Items this engine's shard runs out of `items`.
    pub fn shard_items(&self, items: u64) -> u64 {
        let chunk = self.chunk.max(1);
        (0..items.div_ceil(chunk))
            .filter(|&c| self.shard.has(c))
            .map(|c| ((c + 1) * chunk).min(items) - c * chunk)
            .sum()
    }
    /// The same engine on `threads` threads (`None`: unchanged).
    pub fn with_threads(mut self, threads: Option<usize>) -> Self {
        if let Some(t) = threads {
            self.threads = t.max(1);
        }
        self
    }
}

/// Runs `work(scratch, items)` over every chunk of `0..items` in the engine's shard and merges
/// the accumulators.
/// `init` makes a worker's scratch space (reusable buffers); a worker may make more than one.
/// `progress` advances by each chunk's item count as it completes.
pub fn run<S, A: Merge>(
    engine: &Engine,
    items: u64,
    progress: &Progress,
    init: impl Fn() -> S + Sync + Send,
    work: impl Fn(&mut S, Range<u64>) -> A + Sync + Send,
) -> A {
    let chunk = engine.chunk.max(1);
    let chunks = items.div_ceil(chunk);
    let shard = engine.shard;
    let mine = chunks.saturating_sub(shard.k).div_ceil(shard.n.max(1));
    let total = std::sync::Mutex::new(A::default());
    let body = || {
        // one task per chunk (rayon's adaptive splitting alone leaves a run of slow chunks on
        // one thread); the shard's chunks are k, k + n, k + 2n, …
        (0..usize::try_from(mine).expect("the chunk count fits in usize"))
            .into_par_iter()
            .with_max_len(1)
            .for_each_init(&init, |s, j| {
                let c = shard.k + j as u64 * shard.n;
                let r = c * chunk..((c + 1) * chunk).min(items);
                let n = r.end - r.start;
                let a = work(s, r);
                // a poisoned lock only means another chunk panicked (the run then panics too)
                total.lock().unwrap_or_else(|e| e.into_inner()).merge(a);
                progress.inc(n);
            })
    };
    match rayon::ThreadPoolBuilder::new().num_threads(engine.threads.max(1)).build() {
        Ok(pool) => pool.install(body),
        // no pool could be made (thread limit): run on the caller's pool
        Err(_) => body(),
    }
    total.into_inner().unwrap_or_else(|e| e.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Counts, First, Hist};

    /// A shard prints as `K/N` (the form `--shard` takes and `merge` names missing ones in).
    #[test]
    fn a_shard_prints_as_k_slash_n() {
        assert_eq!(Shard { k: 2, n: 3 }.to_string(), "2/3");
        assert_eq!(Shard::ALL.to_string(), "0/1");
    }

    /// A toy workload: item i contributes i mod 7 to a counter, a histogram value and a
    /// "violation" when i mod 97 == 13.
    fn toy(engine: &Engine, n: u64) -> (Counts<2>, Hist, First<u64, String>) {
        run(
            engine,
            n,
            &Progress::off(),
            || Vec::<u64>::with_capacity(16),
            |buf, r| {
                buf.clear();
                buf.extend(r.clone());
                let mut acc = (Counts::<2>::default(), Hist::default(), First::default());
                for &i in buf.iter() {
                    acc.0 .0[0] += 1;
                    acc.0 .0[1] += i % 7;
                    acc.1.add((i % 1000) as f64 / 3.0);
                    if i % 97 == 13 {
                        acc.2.offer(i, || format!("item {i}"));
                    }
                }
                acc
            },
        )
    }

    #[test]
    fn shards_merged_equal_the_whole_in_any_order() {
        let n = 10_007;
        let whole = toy(&Engine { threads: 2, chunk: 64, shard: Shard::ALL }, n);
        for shards in [1, 2, 3, 7, 200] {
            let parts: Vec<_> =
                (0..shards).map(|k| toy(&Engine { threads: 2, chunk: 64, shard: Shard { k, n: shards } }, n)).collect();
            let e = Engine::new(64);
            let total: u64 = (0..shards).map(|k| e.with_shard(Shard { k, n: shards }).shard_items(n)).sum();
            assert_eq!(total, n);
            // forward and backward merge orders
            for order in [(0..shards as usize).collect::<Vec<_>>(), (0..shards as usize).rev().collect()] {
                let mut m = (Counts::<2>::default(), Hist::default(), First::default());
                for &i in &order {
                    m.merge(parts[i].clone());
                }
                assert_eq!(m, whole, "{shards} shards");
            }
        }
        // the shard of a Slurm array task, and the refusals
        let env = |k: &'static str, n: &'static str| {
            move |v: &str| match v {
                "SLURM_ARRAY_TASK_ID" => Some(k.to_string()),
                "SLURM_ARRAY_TASK_COUNT" => Some(n.to_string()),
                _ => None,
            }
        };
        assert_eq!(Shard::parse("slurm", env("2", "4")), Ok(Shard { k: 2, n: 4 }));
        assert_eq!(Shard::parse("1/3", |_| None), Ok(Shard { k: 1, n: 3 }));
        for bad in ["3/3", "0/0", "x/2", "2", "-1/2"] {
            assert!(Shard::parse(bad, |_| None).unwrap_err().contains("--shard"), "{bad}");
        }
        assert!(Shard::parse("slurm", |_| None).unwrap_err().contains("SLURM_ARRAY_TASK_ID"));
        assert!(Shard::parse("slurm", env("4", "4")).unwrap_err().contains("below N"));
    }

    #[test]
    fn accumulators_survive_json() {
        let a = toy(&Engine::new(100), 5000);
        let mut h = a.1.clone();
        h.add(f64::INFINITY);
        let back: (Counts<2>, Hist, First<u64, String>) =
            serde_json::from_str(&serde_json::to_string(&(a.0, &h, &a.2)).unwrap()).unwrap();
        assert_eq!(back, (a.0, h, a.2));
        assert!(serde_json::from_str::<Counts<3>>("[1, 2]").unwrap_err().to_string().contains("expected 3 counts"));
    }

    #[test]
    fn results_do_not_depend_on_threads_or_chunks() {
        let n = 20_011;
        let base = toy(&Engine { threads: 1, chunk: n, shard: Shard::ALL }, n);
        assert_eq!(base.0 .0[0], n);
        assert_eq!(base.2.get().map(String::as_str), Some("item 13"));
        for threads in [1, 2, 3, 8] {
            for chunk in [1, 7, 256, 4096, 1 << 20] {
                let r = toy(&Engine { threads, chunk, shard: Shard::ALL }, n);
                assert_eq!(r.0, base.0, "threads {threads} chunk {chunk}");
                assert_eq!(r.1, base.1, "threads {threads} chunk {chunk}");
                assert_eq!(r.2, base.2, "threads {threads} chunk {chunk}");
            }
        }
        // an empty space is the identity
        let e = toy(&Engine { threads: 2, chunk: 3, shard: Shard::ALL }, 0);
        assert_eq!((e.0 .0, e.1.count(), e.2.get().is_none()), ([0, 0], 0, true));
    }
}
