//! The streaming verification engine.
//!
//! A run is a space of work items (rays, stress cases, operand pairs) cut into chunks of
//! consecutive items. Each chunk is generated from (seed, item index) alone, run through
//! model → golden → judge by the caller's closure, and folded into an accumulator that
//! implements [`Merge`]; then it is dropped. The accumulators of the chunks are merged in chunk
//! order by a parallel reduction, so:
//!
//! - memory is O(threads × chunk), independent of the number of items;
//! - the result is identical for any thread count and any chunk size, because every
//!   accumulator here is an exact commutative monoid (integer counts, exact maxima, histograms
//!   with integer counts, the first record by item index) and items do not depend on chunking.
//!
//! ```text
//!  item space 0..n ──chunk──▶ [c0][c1][c2]…   (each chunk: generate → model → golden → judge)
//!                               │   │   │
//!                               ▼   ▼   ▼
//!                              A0  A1  A2 …   accumulators (counts, histograms, first records)
//!                               └─merge─┘ …    in chunk order, any tree shape
//!                                   ▼
//!                                report
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod acc;
pub mod progress;
pub mod run;

pub use acc::{Bits, Counts, First, Hist, Merge, Tally};
pub use progress::Progress;
pub use run::{run, Engine, Shard};
