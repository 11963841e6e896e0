//! SIMD batch kernels of the RTI and slab models, bit-identical to the scalar models, with
//! runtime dispatch.
//!
//! One kernel body per unit (the `rti_kernel!` and `slab_kernel!` macros), written in the
//! operations of an `isa` module, is instantiated for binary32 and binary16 on AVX2 (+ F16C
//! for binary16; 8 tests per vector) and on AVX-512F (16 tests per vector), and for binary16
//! on AVX512-FP16 (32 tests per vector), in the stage table's exact operation order with
//! separate multiplies and adds (no FMA). On AVX2 and AVX-512F, binary16 computes every
//! operation in binary32 and rounds it to binary16 at once (`vcvtps2ph` nearest-even, then
//! back): binary32's 24 bits are at least 2·11 + 2, so this double rounding is innocuous for
//! the four operations (+ − × ÷) and the result is the correctly rounded binary16 operation,
//! subnormals and overflow included; compares and min/max of binary16 values held in binary32
//! are exact. On AVX512-FP16 the operations are binary16's own (`vaddph` … `vdivph`, correctly
//! rounded, subnormals always kept).
//! NaN payloads never influence a non-NaN result or a compare, so the RTI kernels canonicalise
//! NaN only where a value leaves them (every RTI output is arithmetic), and only when a mask
//! shows a NaN lane. A slab output NaN may be arithmetic (canonical in the model) or a NaN t
//! interval passed through the comparators with its payload, so the scalar model redoes a
//! slab batch's NaN lanes after the loop; a one-ray batch with the plain comparator and a
//! number interval cannot make one and skips the check.
//!
//! The slab kernels take either pairs (ray i against box i) or one ray against every box (a
//! node's children, a level): the second reads only the six box columns and picks each axis's
//! near plane once per batch. The plain comparator `t = (x > t) ? x : t` is exactly `vmaxps(x,
//! t)` (the second operand on NaN or equality, ±0 included), so it costs one instruction.
//!
//! RTI also has kernels for bf16 (the scalar model's binary32 arithmetic on binary32 lanes,
//! each result rounded to bf16 in the integer lanes, FTZ flushes in the lanes) and for custom
//! `eEmM` layouts with M ≤ 24 and E ≤ 10 (binary64 lanes behind a filter that sends a lane
//! with a subnormal, overflowing or infinite intermediate to the scalar model; the argument is
//! in [`crate::format::narrow`]), IEEE or FTZ, canonical NaN, either division mode.
//!
//! Eligible formats (binary32 / binary16): the canonical NaN rule, IEEE subnormals or FTZ
//! (flushed in the lanes), either division mode, either culling; every slab variant (the
//! directed one on one-ray batches); others, and machines
//! without AVX2, run the scalar model, as does a det threshold that is negative or NaN (the RTI kernels' sign-flip
//! side tests need det_ok to exclude det = ±0). Columns are processed a vector at a time
//! straight from the SoA inputs; a batch's last `n mod lanes` slots run the scalar model.
//!
//! The dispatch takes the widest kernel the machine has ([`kernels_here`]), within this
//! thread's cap ([`with_kernel_cap`]), so every kernel can be tested and timed on one machine.
//! The AVX-512F and AVX512-FP16 kernels are tested by the same property tests as the AVX2
//! ones, on an emulated machine with both (`emu/avx512`, Bochs 3.0) when the host has neither.

mod batch;
pub mod draw;
mod entries;
pub mod fixed;
pub mod gather;
#[cfg(target_arch = "x86_64")]
mod isa;
#[cfg(target_arch = "x86_64")]
mod kernels;
pub mod mask;
mod select;
#[cfg(all(test, target_arch = "x86_64"))]
mod tests;
pub mod widen;

pub use batch::*;
pub use entries::*;
pub use fixed::{rti_batch_fixed, slab_batch_fixed, slab_ray_fixed, slab_ray_shared_fixed};
pub use select::{cap_process, kernels_here, with_kernel_cap, Kernel};
pub(crate) use select::{f64_lanes, F64Lanes};
