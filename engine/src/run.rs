//! Running a chunk space: chunks in parallel on a pool of `threads`, each chunk's accumulator
//! merged into the run's one accumulator as the chunk completes (so at most `threads` chunk
//! accumulators and the run's are alive at once, whatever the number of chunks). The merge
//! order is the completion order; `Merge` is commutative and associative, so the result does
//! not depend on it.

use crate::{Merge, Progress};
use rayon::prelude::*;
use std::ops::Range;

/// How a run is executed; the result does not depend on either field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Engine {
    /// Worker threads (at least 1).
    pub threads: usize,
    /// Items per chunk (at least 1).
    pub chunk: u64,
}

impl Engine {
    /// Every core, with chunks of `chunk` items.
    pub fn new(chunk: u64) -> Self {
        Engine { threads: std::thread::available_parallelism().map_or(1, |n| n.get()), chunk }
    }
    /// The same engine on `threads` threads (`None`: unchanged).
    pub fn with_threads(mut self, threads: Option<usize>) -> Self {
        if let Some(t) = threads {
            self.threads = t.max(1);
        }
        self
    }
}

/// Runs `work(scratch, items)` over every chunk of `0..items` and merges the accumulators.
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
    let total = std::sync::Mutex::new(A::default());
    let body = || {
        // one task per chunk (rayon's adaptive splitting alone leaves a run of slow chunks on
        // one thread)
        (0..usize::try_from(chunks).expect("the chunk count fits in usize"))
            .into_par_iter()
            .with_max_len(1)
            .for_each_init(&init, |s, c| {
                let c = c as u64;
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
    fn results_do_not_depend_on_threads_or_chunks() {
        let n = 20_011;
        let base = toy(&Engine { threads: 1, chunk: n }, n);
        assert_eq!(base.0 .0[0], n);
        assert_eq!(base.2.get().map(String::as_str), Some("item 13"));
        for threads in [1, 2, 3, 8] {
            for chunk in [1, 7, 256, 4096, 1 << 20] {
                let r = toy(&Engine { threads, chunk }, n);
                assert_eq!(r.0, base.0, "threads {threads} chunk {chunk}");
                assert_eq!(r.1, base.1, "threads {threads} chunk {chunk}");
                assert_eq!(r.2, base.2, "threads {threads} chunk {chunk}");
            }
        }
        // an empty space is the identity
        let e = toy(&Engine { threads: 2, chunk: 3 }, 0);
        assert_eq!((e.0 .0, e.1.count(), e.2.get().is_none()), ([0, 0], 0, true));
    }
}
