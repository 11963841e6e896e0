//! Test vectors for RTL testbenches: self-describing vector sets (data files of packed hex
//! rows, one vector per line, plus a `manifest.json` that says what every bit means), written
//! atomically and deterministically, and read back to re-check every bit.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

pub mod axis;
pub mod capture;
pub mod check;
pub mod close;
pub mod cover;
pub mod cover_file;
pub mod cover_html;
pub mod cover_reach;
pub mod gen;
pub mod hdl;
pub mod manifest;
pub mod outdir;
pub mod pack;
pub mod read;
mod rows;
pub mod traverse;

pub use pack::{pack, unpack, Bits};

/// Formats `bits` (the low `width` bits) as exactly `ceil(width/4)` lowercase hex digits, no prefix.
pub fn hex_field(bits: u64, width: u32) -> String {
    let masked = if width >= 64 { bits } else { bits & ((1u64 << width) - 1) };
    pack(&[Bits { value: masked, width }])
}

#[cfg(test)]
mod tests {
    use super::hex_field;

    #[test]
    fn exact_digit_counts() {
        assert_eq!(hex_field(0x3c00, 16), "3c00");
        assert_eq!(hex_field(0x1ff, 9), "1ff");
        assert_eq!(hex_field(0xfff, 9), "1ff");
        assert_eq!(hex_field(1, 1), "1");
        assert_eq!(hex_field(u64::MAX, 64), "ffffffffffffffff");
    }
}
pub mod write;
