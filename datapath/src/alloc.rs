//! A global allocator that staggers the page offsets of large allocations, so that the columns
//! of a structure-of-arrays batch do not all start at the same offset within a page.
//!
//! Every SoA column is its own `Vec`. glibc hands out large blocks (from 128 KiB, by `mmap`)
//! at one and the same page offset, and equal-size heap blocks of a whole number of pages at
//! offsets 16 bytes apart, so lane i of the 14 to 20 columns a kernel streams falls in one or
//! a few L1 sets (more lines than the cache has ways), and loads look 4 KiB-aliased to the
//! stores before them. Measured here (Zen 3, AVX2 kernels, best of 100 × 3 ms): 128 Ki pairs,
//! slab pairs 3.9 → 1.3 ns per test and RTI 4.8 → 2.4 ns with staggered columns; 1 Ki pairs
//! (4 KiB columns), slab pairs 1.5 → 0.75 ns; 512 pairs, 1.0 → 0.75 ns. `raypipe speed`
//! measures both placements at 128 Ki pairs.
//!
//! [`Staggered`] gives a thread's k-th allocation of at least [`MIN_SIZE`] bytes the page offset
//! `k · STRIDE mod 4096` ([`STRIDE`] is 9 cache lines, so 64 consecutive columns start in 64
//! different L1 sets); smaller blocks, and blocks aligned to more than a cache line, go to the
//! system allocator unchanged. A staggered block takes 4 KiB + 64 bytes more from the system
//! (the `raypipe` default run: 98 → 110 MB peak resident). Programs opt in with
//! `#[global_allocator] static A: datapath::alloc::Staggered = datapath::alloc::Staggered;`
//! (the `raypipe` CLI and the benches do).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// Blocks at least this large (a 512-lane binary32 column) are placed at a staggered page offset.
pub const MIN_SIZE: usize = 2048;
/// The page-offset step between consecutive large blocks: 9 cache lines (coprime with the 64
/// lines of a page).
pub const STRIDE: usize = 9 * LINE;
/// A cache line; staggered blocks are aligned to it.
pub const LINE: usize = 64;
/// A page.
pub const PAGE: usize = 4096;
/// Extra bytes a staggered block takes from the system allocator.
const SLACK: usize = PAGE + LINE;

/// Where large blocks start within a page.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// A thread's k-th large block at page offset `k · STRIDE mod 4096` (the default).
    Staggered,
    /// Every large block at page offset 0: the worst case, as the system allocator's large
    /// blocks all share one offset (kept for measuring what staggering gains).
    SamePageOffset,
}

thread_local! {
    static PLACEMENT: Cell<Placement> = const { Cell::new(Placement::Staggered) };
    /// Large blocks this thread has placed: its next block's stagger index (per thread, so a
    /// thread's consecutive columns get consecutive offsets whatever other threads allocate).
    static NEXT: Cell<usize> = const { Cell::new(0) };
}

/// This thread's stagger index.
fn placed() -> usize {
    NEXT.try_with(Cell::get).unwrap_or(0)
}

/// Runs `f` with large blocks this thread allocates placed by `p`, then restores the
/// previous placement (also if `f` panics).
pub fn with_placement<R>(p: Placement, f: impl FnOnce() -> R) -> R {
    crate::scoped(&PLACEMENT, p, f)
}

/// Whether [`Staggered`] is this program's global allocator (a large block allocated by
/// `Vec` went through it).
pub fn is_global() -> bool {
    let before = placed();
    let probe: Vec<u8> = Vec::with_capacity(MIN_SIZE);
    let after = placed();
    drop(std::hint::black_box(probe));
    after != before
}

/// The offset of `p` within its page.
pub fn page_offset<T>(p: *const T) -> usize {
    p as usize % PAGE
}

/// The global allocator that staggers large blocks (see the module documentation).
#[derive(Clone, Copy, Debug, Default)]
pub struct Staggered;

/// Whether a block of this layout is staggered.
fn staggers(size: usize, align: usize) -> bool {
    size >= MIN_SIZE && align <= LINE
}

/// The system allocator's layout behind a staggered block of `size` bytes.
fn outer(size: usize) -> Option<Layout> {
    Layout::from_size_align(size.checked_add(SLACK)?, LINE).ok()
}

impl Staggered {
    /// Places a block inside `base` (from the system allocator, `outer(size)`, or null) and
    /// records `base` in the 8 bytes before it.
    ///
    /// # Safety
    /// `base` is null or a live block of `outer(size)`.
    unsafe fn place(base: *mut u8) -> *mut u8 {
        if base.is_null() {
            return base;
        }
        let k = placed();
        let _ = NEXT.try_with(|c| c.set(k.wrapping_add(1)));
        let target = match PLACEMENT.try_with(Cell::get).unwrap_or(Placement::Staggered) {
            Placement::Staggered => k.wrapping_mul(STRIDE) % PAGE,
            Placement::SamePageOffset => 0,
        };
        // base is line-aligned, so delta is a multiple of a line in LINE..=PAGE: the block
        // and the word before it are inside the outer block
        let mut delta = (target + PAGE - page_offset(base)) % PAGE;
        if delta < LINE {
            delta += PAGE;
        }
        // SAFETY: delta + size <= SLACK + size (the caller's outer block); the word before
        // the block is inside it and aligned (delta is a multiple of 64).
        unsafe {
            let p = base.add(delta);
            (p as *mut *mut u8).sub(1).write(base);
            p
        }
    }

    /// The system block behind a staggered block.
    ///
    /// # Safety
    /// `p` came from [`Staggered::place`].
    unsafe fn base(p: *mut u8) -> *mut u8 {
        // SAFETY: `place` wrote it there.
        unsafe { (p as *mut *mut u8).sub(1).read() }
    }
}

// SAFETY: every block is either the system allocator's own (small or over-aligned layouts,
// decided by the layout alone, so alloc and dealloc agree) or lies inside a system block of
// `outer(size)` that is freed with that layout; blocks are line-aligned (>= the layout's
// alignment) and never overlap.
unsafe impl GlobalAlloc for Staggered {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if !staggers(l.size(), l.align()) {
            // SAFETY: the caller's layout contract.
            return unsafe { System.alloc(l) };
        }
        let Some(o) = outer(l.size()) else { return std::ptr::null_mut() };
        // SAFETY: o has a nonzero size; the block is `outer(size)`.
        unsafe { Self::place(System.alloc(o)) }
    }

    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        if !staggers(l.size(), l.align()) {
            // SAFETY: as in `alloc`.
            return unsafe { System.alloc_zeroed(l) };
        }
        let Some(o) = outer(l.size()) else { return std::ptr::null_mut() };
        // SAFETY: as in `alloc` (the whole outer block is zero, so the placed block is).
        unsafe { Self::place(System.alloc_zeroed(o)) }
    }

    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        if !staggers(l.size(), l.align()) {
            // SAFETY: allocated by the system with this layout.
            return unsafe { System.dealloc(p, l) };
        }
        // SAFETY: placed by `place` inside a system block of `outer(size)` (which exists:
        // the allocation succeeded with it).
        unsafe { System.dealloc(Self::base(p), outer(l.size()).unwrap_unchecked()) }
    }

    unsafe fn realloc(&self, p: *mut u8, l: Layout, new_size: usize) -> *mut u8 {
        if !staggers(l.size(), l.align()) && !staggers(new_size, l.align()) {
            // SAFETY: both the old and the new block are the system's own.
            return unsafe { System.realloc(p, l, new_size) };
        }
        // SAFETY: the caller guarantees that new_size, rounded up to the alignment, fits isize.
        let nl = unsafe { Layout::from_size_align_unchecked(new_size, l.align()) };
        // SAFETY: nl has a nonzero size (the caller's contract).
        let q = unsafe { self.alloc(nl) };
        if !q.is_null() {
            // SAFETY: both blocks are live, distinct and at least this long.
            unsafe {
                std::ptr::copy_nonoverlapping(p, q, l.size().min(new_size));
                self.dealloc(p, l);
            }
        }
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Allocates `n` blocks of `size` bytes aligned to `align` with placement `p`, checks that
    /// each is writable over its whole length and frees them: their page offsets.
    fn offsets(p: Placement, n: usize, size: usize, align: usize) -> Vec<usize> {
        let l = Layout::from_size_align(size, align).unwrap();
        with_placement(p, || {
            let blocks: Vec<*mut u8> = (0..n).map(|_| unsafe { Staggered.alloc(l) }).collect();
            let offs = blocks
                .iter()
                .map(|&b| {
                    assert!(!b.is_null());
                    assert_eq!(b as usize % align, 0, "alignment {align}");
                    unsafe { std::ptr::write_bytes(b, 0xa5, size) };
                    page_offset(b)
                })
                .collect();
            for b in blocks {
                unsafe { Staggered.dealloc(b, l) };
            }
            offs
        })
    }

    #[test]
    fn consecutive_large_blocks_start_in_distinct_cache_sets() {
        for (size, align) in [(MIN_SIZE, 4), (1 << 20, 8), (100_003, 16), (70_000, 64)] {
            let offs = offsets(Placement::Staggered, 64, size, align);
            let mut lines: Vec<usize> = offs.iter().map(|o| o / LINE).collect();
            assert!(offs.iter().all(|o| o % LINE == 0), "{offs:?}");
            lines.sort_unstable();
            lines.dedup();
            assert_eq!(lines.len(), 64, "size {size}: {offs:?}");
        }
    }

    #[test]
    fn same_page_offset_places_every_large_block_at_offset_zero() {
        assert!(offsets(Placement::SamePageOffset, 20, 1 << 18, 8).iter().all(|&o| o == 0));
        // and the placement is restored afterwards
        let offs = offsets(Placement::Staggered, 2, 1 << 18, 8);
        assert_ne!(offs[0], offs[1]);
    }

    #[test]
    fn small_and_over_aligned_blocks_are_the_systems() {
        // small: usable as asked (the system's block, no slack)
        offsets(Placement::Staggered, 8, MIN_SIZE - 1, 8);
        // over-aligned: page-aligned as asked, not staggered
        assert!(offsets(Placement::Staggered, 4, 1 << 16, PAGE).iter().all(|&o| o == 0));
    }

    #[test]
    fn zeroed_blocks_are_zero() {
        let l = Layout::from_size_align(1 << 17, 8).unwrap();
        unsafe {
            let p = Staggered.alloc_zeroed(l);
            assert!(std::slice::from_raw_parts(p, l.size()).iter().all(|&b| b == 0));
            Staggered.dealloc(p, l);
        }
    }

    #[test]
    fn realloc_keeps_the_contents_across_the_threshold() {
        // small → large → larger → small, checking the common prefix each time
        let sizes = [100, MIN_SIZE + 8, 300_000, MIN_SIZE - 8, 64];
        let mut l = Layout::from_size_align(sizes[0], 8).unwrap();
        unsafe {
            let mut p = Staggered.alloc(l);
            for k in 0..l.size() {
                *p.add(k) = k as u8;
            }
            for &n in &sizes[1..] {
                let keep = l.size().min(n);
                p = Staggered.realloc(p, l, n);
                assert!(!p.is_null());
                for k in 0..keep {
                    assert_eq!(*p.add(k), k as u8, "byte {k} after realloc to {n}");
                }
                for k in keep..n {
                    *p.add(k) = k as u8;
                }
                l = Layout::from_size_align(n, 8).unwrap();
            }
            Staggered.dealloc(p, l);
        }
    }

    #[test]
    fn placement_is_restored_after_a_panic() {
        let r = std::panic::catch_unwind(|| with_placement(Placement::SamePageOffset, || panic!("inside")));
        assert!(r.is_err());
        assert_eq!(PLACEMENT.with(Cell::get), Placement::Staggered);
    }

    /// The library's own test binary keeps the system allocator: `is_global` must say so (the
    /// CLI's and `datapath/tests/alloc.rs`'s binaries install `Staggered` and see `true`).
    #[test]
    fn is_global_is_false_under_the_system_allocator() {
        assert!(!super::is_global());
    }
}
