//! Fuzzing of the format-name parser: any string gives a format or a clear error, never a
//! panic; a format's canonical name parses back to the same format, and its arithmetic on a
//! few values (specials included) does not panic. Run: `cargo fuzz run format -s none`.
#![no_main]

use datapath::{with_format, AnyFormat, Format};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match text.parse::<AnyFormat>() {
        Ok(f) => {
            let again: AnyFormat = f.name().parse().expect("a canonical name parses");
            assert_eq!(again, f, "{text} -> {}", f.name());
            with_format!(f, |f| {
                let xs = [0.0, -0.0, 1.0, -1.5, 1e-300, 3e38, f64::INFINITY, f64::NAN, 65504.0];
                for &a in &xs {
                    for &b in &xs {
                        let (x, y) = (f.from_f64(a), f.from_f64(b));
                        let _ = (f.add(x, y), f.sub(x, y), f.mul(x, y), f.div(x, y), f.lt(x, y), f.le(x, y));
                        let _ = (f.next_up(x), f.next_down(x), f.to_bits(x), f.hex(x));
                    }
                }
            });
        }
        Err(e) => assert!(!e.is_empty()),
    }
});
