//! Bit-accurate models of ray-tracing hardware datapaths: number formats ([`format`](mod@format)), the
//! latency-reordered Möller–Trumbore ray–triangle pipeline ([`rti`]) with per-stage probes
//! ([`probe`]), and its error bounds ([`bound`]).
#![warn(missing_docs)]

pub mod alloc;
pub mod bound;
pub mod bound_filter;
pub mod box_memo;
pub mod bvh;
pub mod fault;
pub mod format;
pub mod lanes;
#[cfg(target_arch = "x86_64")]
pub mod lanes_x86;
pub mod probe;
pub mod rng;
pub mod rti;
pub mod simd;
pub mod slab;
pub mod stage;

pub use format::{AnyFormat, Format};

/// Runs `f` with this thread's `key` set to `v`, then restores the previous value (also if
/// `f` panics): the per-thread settings (kernel cap, column placement).
pub(crate) fn scoped<T: Copy + 'static, R>(
    key: &'static std::thread::LocalKey<std::cell::Cell<T>>,
    v: T,
    f: impl FnOnce() -> R,
) -> R {
    struct Restore<T: Copy + 'static>(&'static std::thread::LocalKey<std::cell::Cell<T>>, T);
    impl<T: Copy + 'static> Drop for Restore<T> {
        fn drop(&mut self) {
            self.0.with(|c| c.set(self.1));
        }
    }
    let _restore = Restore(key, key.with(|c| c.replace(v)));
    f()
}
