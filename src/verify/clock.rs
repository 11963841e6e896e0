//! The clock of verify's model timings, read around every batch call of the timed rays (a dozen
//! short intervals per block; every 8th ray, `chunk::TIME_EVERY`). On x86-64 with an invariant
//! time-stamp counter (CPUID leaf 0x8000_0007, EDX bit 8) a reading is the counter (a few
//! cycles, where the OS clock costs tens of nanoseconds), and ticks become nanoseconds at the
//! rate measured against the OS's monotonic clock over the same pass; elsewhere a reading is
//! the OS clock in nanoseconds. Timings only: no count, verdict or report field other than a
//! rate depends on it.

use std::time::Instant;

/// A pass's clock: readings in ticks, converted to nanoseconds by [`Clock::to_ns`].
#[derive(Clone, Copy, Debug)]
pub struct Clock {
    tsc: bool,
    t0: Instant,
    c0: u64,
}

impl Clock {
    /// A clock started now.
    pub fn start() -> Self {
        let tsc = invariant_tsc();
        let t0 = Instant::now();
        let mut c = Clock { tsc, t0, c0: 0 };
        c.c0 = c.now();
        c
    }

    /// A reading, in ticks.
    #[inline(always)]
    pub fn now(&self) -> u64 {
        #[cfg(target_arch = "x86_64")]
        if self.tsc {
            // SAFETY: RDTSC exists on every x86-64 processor and reads a register
            return unsafe { std::arch::x86_64::_rdtsc() };
        }
        self.t0.elapsed().as_nanos() as u64
    }

    /// Ticks from the reading `t0` to now (zero if the counter reads lower, as it may after the
    /// thread moved to a core whose counter lags).
    #[inline(always)]
    pub fn since(&self, t0: u64) -> u64 {
        self.now().saturating_sub(t0)
    }

    /// `ticks` (a sum of reading differences) in nanoseconds: at the rate ticks advanced
    /// against the OS clock since the start (one tick per nanosecond without the counter).
    pub fn to_ns(&self, ticks: u64) -> u64 {
        if !self.tsc {
            return ticks;
        }
        let (ns, t) = (self.t0.elapsed().as_nanos() as f64, self.now().wrapping_sub(self.c0) as f64);
        if t > 0.0 {
            (ticks as f64 * (ns / t)).round() as u64
        } else {
            0
        }
    }
}

/// The processor's time-stamp counter runs at a constant rate in every power state.
fn invariant_tsc() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::__cpuid;
        // leaf 0x8000_0007 exists when the largest extended leaf reaches it
        let max = __cpuid(0x8000_0000).eax;
        max >= 0x8000_0007 && __cpuid(0x8000_0007).edx & (1 << 8) != 0
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Readings do not go back, and a measured sleep converts to about its length (the
    /// conversion's rate comes from the OS clock, so it holds whichever reading is used).
    #[test]
    fn intervals_convert_to_nanoseconds() {
        let c = Clock::start();
        let a = c.now();
        std::thread::sleep(std::time::Duration::from_millis(30));
        let b = c.now();
        assert!(b >= a);
        let ns = c.to_ns(b - a);
        assert!((25_000_000..2_000_000_000).contains(&ns), "30 ms measured as {ns} ns");
    }
}
