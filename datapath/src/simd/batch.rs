//! The front doors: one batch call per unit for any format, sent to its format's entry point
//! (or the fixed-point lanes, or the scalar model), and the streaming form of the RTI batch.

use super::entries::*;
use super::fixed::{rti_batch_fixed, slab_batch_fixed, slab_ray_fixed, slab_ray_shared_fixed};
use super::select::*;
use crate::rti::{HitsSoa, RaysSoa, Rti, TrisSoa};
use crate::slab::{BoxesSoa, Slab, SlabOutSoa, SlabRay, SlabRaysSoa};

/// The body of a format-generic dispatch: calls the first of the `typed` entry points whose
/// unit and column types are the arguments', the scalar model `$scalar` when none is.
macro_rules! by_format {
    ($unit:expr, $a:expr, $b:expr, $out:expr, [$($typed:ident),+], $scalar:expr) => {{
        use std::any::Any;
        let (unit, a, b) = ($unit as &dyn Any, $a as &dyn Any, $b as &dyn Any);
        $(
            if let (Some(unit), Some(a), Some(b)) = (unit.downcast_ref(), a.downcast_ref(), b.downcast_ref()) {
                return $typed(
                    unit,
                    a,
                    b,
                    ($out as &mut dyn Any).downcast_mut().expect("the output type follows the format"),
                );
            }
        )+
        $scalar;
        Kernel::Scalar
    }};
}

/// [`Rti::batch`] for any format on the fastest bit-identical implementation: the SIMD kernels
/// for binary32 and binary16 where they apply, the scalar model otherwise.
///
/// # Panics
/// If the column lengths differ.
pub fn rti_batch<F: crate::Format + 'static>(
    rti: &Rti<F>,
    rays: &RaysSoa<F::V>,
    tris: &TrisSoa<F::V>,
    out: &mut HitsSoa<F::V>,
) -> Kernel
where
    F::V: 'static,
{
    by_format!(
        rti,
        rays,
        tris,
        out,
        [rti_batch_f32, rti_batch_f16, rti_batch_bf16, rti_batch_soft, rti_batch_fixed],
        rti.batch(rays, tris, out)
    )
}

/// [`Slab::batch`] for any format on the fastest bit-identical implementation.
///
/// # Panics
/// If the column lengths differ.
pub fn slab_batch<F: crate::Format + 'static>(
    s: &Slab<F>,
    rays: &SlabRaysSoa<F::V>,
    boxes: &BoxesSoa<F::V>,
    out: &mut SlabOutSoa<F::V>,
) -> Kernel
where
    F::V: 'static,
{
    by_format!(
        s,
        rays,
        boxes,
        out,
        [slab_batch_f32, slab_batch_f16, slab_batch_bf16, slab_batch_soft, slab_batch_fixed],
        s.batch(rays, boxes, out)
    )
}

/// [`Slab::batch_ray`] (one ray, many boxes) for any format on the fastest bit-identical
/// implementation.
///
/// # Panics
/// If the column lengths differ.
pub fn slab_ray<F: crate::Format + 'static>(
    s: &Slab<F>,
    ray: &SlabRay<F::V>,
    boxes: &BoxesSoa<F::V>,
    out: &mut SlabOutSoa<F::V>,
) -> Kernel
where
    F::V: 'static,
{
    by_format!(
        s,
        ray,
        boxes,
        out,
        [slab_ray_f32, slab_ray_f16, slab_ray_bf16, slab_ray_soft, slab_ray_fixed],
        s.batch_ray(ray, boxes, out)
    )
}

/// [`slab_ray`] of each `(group[j], rays[j])` into `outs[j]` — the same bits — with the work
/// the variants do alike done once: the round-to-nearest variants (plain, conservative,
/// take-on-false, embree) of one format with IEEE subnormals (binary32, binary16, bf16, an
/// `eEmM` layout the kernels take) or of one fixed-point format, whose prepared rays have the
/// same origin, 1/d and t interval, bit for bit, compute the planes `(box − o) ⊗ 1/d` once,
/// then each its comparator chains, widening and guard (fixed point: the chains once too; it
/// has no NaN, so its variants differ only in the widening). Returns the kernel used, or
/// `None`, nothing written, when the group does not qualify (another format, FTZ, a directed
/// variant, rays that differ, columns of another length, a machine without the kernel): the
/// caller runs [`slab_ray`] per variant.
pub fn slab_ray_shared<F: crate::Format + 'static>(
    group: &[&Slab<F>],
    rays: &[&SlabRay<F::V>],
    boxes: &BoxesSoa<F::V>,
    outs: &mut [SlabOutSoa<F::V>],
) -> Option<Kernel>
where
    F::V: 'static,
{
    use crate::format::{Bf16, F16Half, F32Native, Fixed, Ieee, Soft};
    use std::any::TypeId;
    // the typed entry of F's format, if it has one
    macro_rules! typed {
        ($fmt:ty, $v:ty, $entry:ident) => {
            if TypeId::of::<F>() == TypeId::of::<$fmt>() {
                // SAFETY: F is $fmt (the same type, checked above), so F::V is $v and each
                // slice has the element type it is cast to
                let (group, rays, boxes, outs) = unsafe {
                    (
                        &*(group as *const [&Slab<F>] as *const [&Slab<$fmt>]),
                        &*(rays as *const [&SlabRay<F::V>] as *const [&SlabRay<$v>]),
                        &*(boxes as *const BoxesSoa<F::V>).cast::<BoxesSoa<$v>>(),
                        &mut *(outs as *mut [SlabOutSoa<F::V>] as *mut [SlabOutSoa<$v>]),
                    )
                };
                return $entry(group, rays, boxes, outs);
            }
        };
    }
    typed!(Ieee<F32Native>, f32, slab_ray_shared_f32);
    typed!(Ieee<F16Half>, half::f16, slab_ray_shared_f16);
    typed!(Ieee<Bf16>, u16, slab_ray_shared_bf16);
    typed!(Ieee<Soft>, u64, slab_ray_shared_soft);
    typed!(Fixed, i64, slab_ray_shared_fixed);
    None
}

/// Pairs per chunk of [`rti_stream`]: 256 pairs × (15 input + 3 output columns) × 4 bytes plus
/// two flag columns is 19 KiB, inside a 32 KiB L1 data cache.
pub const CHUNK: usize = 256;

/// Streams `n` RTI tests through L1-sized chunks on the fastest kernel (see [`rti_batch`]):
/// for each chunk `start..end` of at most [`CHUNK`] pairs, the columns are sized to
/// `end - start` slots, `fill(start..end, rays, tris)` writes every slot (slot k holds pair
/// `start + k`, e.g. with [`RaysSoa::set`]), the kernel runs, and `consume(start..end, rays,
/// tris, out)` reads the results. The columns are allocated once, side by side, so a pass over
/// millions of pairs keeps its working set in L1 (one pass over columns of 1 M pairs is
/// DRAM-bound, and equal-offset page-aligned columns contend for the same L1 sets).
pub fn rti_stream<F: crate::Format + 'static>(
    rti: &Rti<F>,
    n: usize,
    mut fill: impl FnMut(std::ops::Range<usize>, &mut RaysSoa<F::V>, &mut TrisSoa<F::V>),
    mut consume: impl FnMut(std::ops::Range<usize>, &RaysSoa<F::V>, &TrisSoa<F::V>, &HitsSoa<F::V>),
) -> Kernel
where
    F::V: 'static + Default,
{
    let (mut rays, mut tris) = (RaysSoa::default(), TrisSoa::default());
    let mut out = HitsSoa::default();
    let mut kernel = Kernel::Scalar;
    for start in (0..n).step_by(CHUNK) {
        let end = (start + CHUNK).min(n);
        rays.resize(end - start, F::V::default());
        tris.resize(end - start, F::V::default());
        out.resize(end - start);
        fill(start..end, &mut rays, &mut tris);
        kernel = rti_batch(rti, &rays, &tris, &mut out);
        consume(start..end, &rays, &tris, &out);
    }
    kernel
}
