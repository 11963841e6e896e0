//! The staggering allocator as a program's global allocator: the columns of an SoA batch start
//! in distinct cache sets (the system allocator puts large blocks at one page offset).

use datapath::alloc::{is_global, page_offset, with_placement, Placement, Staggered, LINE};
use datapath::rti::{RaysSoa, TrisSoa};
use datapath::slab::BoxesSoa;

#[global_allocator]
static ALLOC: Staggered = Staggered;

/// The cache lines within a page at which the columns start, deduplicated.
fn lines<'a>(cols: impl Iterator<Item = &'a Vec<f32>>) -> (usize, usize) {
    let offs: Vec<usize> = cols.map(|c| page_offset(c.as_ptr()) / LINE).collect();
    let mut d = offs.clone();
    d.sort_unstable();
    d.dedup();
    (offs.len(), d.len())
}

#[test]
fn is_the_global_allocator() {
    assert!(is_global());
}

#[test]
fn batch_columns_start_in_distinct_cache_sets() {
    // 256 KiB columns: glibc would mmap each and start all of them at page offset 16
    let n = 1 << 16;
    let (rays, tris) = (RaysSoa::<f32>::with_capacity(n), TrisSoa::<f32>::with_capacity(n));
    let cols = rays.o.iter().chain(&rays.d).chain([&rays.tmin, &rays.tmax]).chain(tris.v.iter().flatten());
    let (all, distinct) = lines(cols);
    assert_eq!((all, distinct), (17, 17));
    // grown by pushes (reallocations), too
    let mut b = BoxesSoa::<f32>::default();
    for c in b.min.iter_mut().chain(&mut b.max) {
        c.extend(std::iter::repeat_n(0.0, n));
    }
    assert_eq!(lines(b.min.iter().chain(&b.max)), (6, 6));
}

#[test]
fn same_page_offset_is_the_aliased_worst_case() {
    let rays = with_placement(Placement::SamePageOffset, || RaysSoa::<f32>::with_capacity(1 << 16));
    let cols = rays.o.iter().chain(&rays.d).chain([&rays.tmin, &rays.tmax]);
    assert!(cols.clone().all(|c| page_offset(c.as_ptr()) == 0));
    // a small batch's columns are the system's, whatever the placement
    let small = with_placement(Placement::SamePageOffset, || RaysSoa::<f32>::with_capacity(16));
    assert!(small.o.iter().all(|c| c.capacity() >= 16));
}
