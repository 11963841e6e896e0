//! Test-vector export for RTL testbenches: fixed-width hex fields, MSB first.
#![warn(missing_docs)]

/// Formats `bits` (the low `width` bits) as exactly `ceil(width/4)` lowercase hex digits, no prefix.
pub fn hex_field(bits: u64, width: u32) -> String {
    let digits = width.div_ceil(4) as usize;
    let masked = if width >= 64 { bits } else { bits & ((1u64 << width) - 1) };
    format!("{masked:0digits$x}")
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
