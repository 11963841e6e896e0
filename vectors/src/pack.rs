//! Packing fields into one fixed-width hex word per line (MSB first, exact digit count, no
//! prefix, no X/Z) and unpacking them again.

/// One field of a packed row: its bits (right-aligned) and width.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bits {
    /// Value, right-aligned.
    pub value: u64,
    /// Width in bits (1..=64).
    pub width: u32,
}

/// Total width of a row.
pub fn row_width(fields: &[Bits]) -> u32 {
    fields.iter().map(|f| f.width).sum()
}

/// Packs `fields` (the first is the most significant) into `ceil(total / 4)` lowercase hex digits.
pub fn pack(fields: &[Bits]) -> String {
    let total = row_width(fields) as usize;
    let digits = total.div_ceil(4);
    let mut bits = vec![false; digits * 4];
    let mut pos = digits * 4 - total; // leading pad bits stay zero
    for f in fields {
        for k in (0..f.width).rev() {
            bits[pos] = (f.value >> k) & 1 == 1;
            pos += 1;
        }
    }
    bits.chunks(4)
        .map(|c| {
            let v = c.iter().fold(0u8, |a, &b| (a << 1) | b as u8);
            char::from_digit(v as u32, 16).expect("nibble")
        })
        .collect()
}

/// Unpacks a hex word into fields of the given widths (first = most significant).
pub fn unpack(hex: &str, widths: &[u32]) -> Result<Vec<u64>, String> {
    let total: usize = widths.iter().map(|&w| w as usize).sum();
    if hex.len() != total.div_ceil(4) {
        return Err(format!("expected {} hex digits, got {}", total.div_ceil(4), hex.len()));
    }
    let mut bits = Vec::with_capacity(hex.len() * 4);
    for c in hex.chars() {
        let v = c.to_digit(16).ok_or_else(|| format!("'{c}' is not a hex digit"))?;
        for k in (0..4).rev() {
            bits.push((v >> k) & 1 == 1);
        }
    }
    let pad = bits.len() - total;
    if bits[..pad].iter().any(|&b| b) {
        return Err("non-zero padding bits".into());
    }
    let mut pos = pad;
    Ok(widths
        .iter()
        .map(|&w| {
            let v = bits[pos..pos + w as usize].iter().fold(0u64, |a, &b| (a << 1) | b as u64);
            pos += w as usize;
            v
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pack_unpack_round_trip_and_digit_counts() {
        let f = [Bits { value: 0x5, width: 3 }, Bits { value: 0x1ffffff, width: 25 }, Bits { value: 1, width: 1 }];
        let h = pack(&f);
        assert_eq!(h.len(), 8); // 29 bits -> 8 digits, 3 pad bits
        assert_eq!(h, "17ffffff");
        assert_eq!(unpack(&h, &[3, 25, 1]).unwrap(), vec![5, 0x1ffffff, 1]);
        assert!(unpack("ffffffff", &[3, 25, 1]).is_err(), "padding must be zero");
        assert!(unpack("17fffff", &[3, 25, 1]).is_err());
        assert!(unpack("17ffffxf", &[3, 25, 1]).is_err());
        assert_eq!(pack(&[Bits { value: 0x3c00, width: 16 }]), "3c00");
    }
}
