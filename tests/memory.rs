//! The streaming engine's memory does not grow with the number of rays: the peak heap of a
//! `verify` run is measured by a counting allocator at 64 and at 4096 rays (64× the work).

use raypipe::scene::Scene;
use raypipe::verify::{verify, VerifyConfig};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

struct Counting;
static NOW: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator; only counts bytes
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            let now = NOW.fetch_add(l.size(), Relaxed) + l.size();
            PEAK.fetch_max(now, Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        NOW.fetch_sub(l.size(), Relaxed);
    }
}

#[global_allocator]
static A: Counting = Counting;

/// Heap bytes above the level before the run, at the run's peak.
fn peak_of(rays: usize) -> usize {
    let scene = Scene::builtin();
    let cfg =
        VerifyConfig::new(vec!["f32".parse().unwrap(), "bf16".parse().unwrap()], rays, 3, Default::default(), 512);
    let before = NOW.load(Relaxed);
    PEAK.store(before, Relaxed);
    let rep = verify(&cfg, &scene);
    assert!(rep.formats.iter().all(|f| f.tests == rays as u64 * 368));
    PEAK.load(Relaxed) - before
}

#[test]
fn peak_memory_is_flat_in_rays() {
    let small = peak_of(64);
    let large = peak_of(4096);
    // the materialising engine held ~160 bytes per test: 4096 rays x 368 tests would be ~240 MB
    assert!(large <= small + small / 2 + (256 << 10), "peak heap {small} B at 64 rays, {large} B at 4096 rays");
    assert!(large < 16 << 20, "peak heap {large} B");
}
