use super::lanes::*;
#[cfg(target_arch = "x86_64")]
use super::ymm;

fn lanes(name: &str) -> Lanes {
    match name.parse::<crate::AnyFormat>().expect("a format") {
        crate::AnyFormat::Fixed(f) => Lanes::of(&f).expect("at most 32 bits"),
        _ => unreachable!("{name} is fixed point"),
    }
}

/// The biased AVX2 lanes admit exactly the formats whose shifted products stay below 2^51
/// under saturation (2w − 2 − F ≤ 50), and every wrapping one.
#[cfg(target_arch = "x86_64")]
#[test]
fn the_biased_lanes_admit_the_documented_formats() {
    for (name, sat) in [
        ("q16.16", true),
        ("q8.24", true),
        ("q1.31", true),
        ("q20.12", true),
        ("q21.11", false),
        ("q24.8", false),
        ("q32.0", false),
        ("q26.0", true),
        ("q27.0", false),
        ("q2.6", true),
    ] {
        let c = lanes(name);
        assert_eq!(ymm::Y::fits(&c, false), sat, "{name} saturating");
        assert!(ymm::Y::fits(&c, true), "{name} wrapping");
    }
}
