//! Shared helpers of the model tests: the formats under test and seeded case generators.
#![allow(dead_code)]

use datapath::rng::SplitMix64;
use datapath::AnyFormat;
use golden::{Ray64, Tri64};

/// Every format family and option the tests cover.
pub const FORMATS: [&str; 14] = [
    "f32",
    "f32:divide",
    "f32:ftz+propagate",
    "fp16",
    "fp16:divide",
    "fp16:ftz",
    "bf16",
    "e8m16",
    "e6m9",
    "e5m10",
    "q8.24",
    "q8.24:divide",
    "q16.16:nearest+divide",
    "q12.20:ceil+wrap+divide",
];

/// The formats, parsed.
pub fn formats() -> Vec<AnyFormat> {
    FORMATS.iter().map(|f| f.parse().unwrap()).collect()
}

/// A ray aimed at a barycentric point (b1, b2) of a random triangle in [-1, 1]^3, from a random
/// origin; barycentrics in [-0.3, 1.3] so that about half the rays miss.
pub fn aimed_case(r: &mut SplitMix64) -> (Ray64, Tri64) {
    let mut p = || [r.range(-1.0, 1.0), r.range(-1.0, 1.0), r.range(-1.0, 1.0)];
    let tri = Tri64 { v: [p(), p(), p()] };
    let o = p();
    let (b1, b2) = (r.range(-0.3, 1.3), r.range(-0.3, 1.3));
    let b0 = 1.0 - b1 - b2;
    let target: [f64; 3] = std::array::from_fn(|a| b0 * tri.v[0][a] + b1 * tri.v[1][a] + b2 * tri.v[2][a]);
    let d = [target[0] - o[0], target[1] - o[1], target[2] - o[2]];
    let tmax = if r.below(4) == 0 { r.range(0.0, 2.0) } else { f64::INFINITY };
    (Ray64 { o, d, tmin: 0.0, tmax }, tri)
}

/// Raw input encodings for the 17 RTI inputs: mostly in-range values, some random bit patterns
/// (NaN, infinities, subnormals, huge values) so that special cases reach every stage.
pub fn raw_inputs(r: &mut SplitMix64, f: &AnyFormat) -> [u64; 17] {
    use datapath::{with_format, Format};
    with_format!(f, |f| {
        std::array::from_fn(|_| if r.below(5) == 0 { r.next_u64() } else { f.to_bits(f.from_f64(r.range(-1.0, 1.0))) })
    })
}
