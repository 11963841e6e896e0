//! The rows of a vector set's files, their generation per coverage class and the slab
//! options of a manifest: what the unit generators (`gen` for rti / slab / op, `traverse` for
//! the traversal) share, so neither imports the other.

use crate::manifest::{Field, Kind};
use crate::pack::{pack, Bits};
use datapath::format::FormatKind;
use datapath::rng::SplitMix64;
use datapath::slab::SlabConfig;
use datapath::Format;
use std::collections::BTreeMap;

/// The manifest kind of a format.
pub(crate) fn kind_of<F: Format>(f: &F) -> Kind {
    match f.kind() {
        FormatKind::Float(l) => Kind::Ieee { exp: l.exp_bits, man: l.man_bits },
        FormatKind::Fixed { int_bits, frac_bits } => Kind::Fixed { int: int_bits, frac: frac_bits },
    }
}

/// Field list builder: names, directions, kinds and widths, most significant first.
pub(crate) struct Layout(pub(crate) Vec<(String, &'static str, Kind, u32, Option<u8>)>);

impl Layout {
    pub(crate) fn fields(&self) -> Vec<Field> {
        let total: u32 = self.0.iter().map(|f| f.3).sum();
        let mut top = total;
        self.0
            .iter()
            .map(|(name, dir, kind, width, stage)| {
                top -= width;
                Field {
                    name: name.clone(),
                    dir: dir.to_string(),
                    kind: kind.clone(),
                    width: *width,
                    lsb: top,
                    stage: *stage,
                    care_when: None,
                    implementation_defined: false,
                }
            })
            .collect()
    }
    pub(crate) fn widths(&self) -> Vec<u32> {
        self.0.iter().map(|f| f.3).collect()
    }
}

/// Rows of one file.
pub(crate) struct Rows {
    pub(crate) name: String,
    pub(crate) role: String,
    pub(crate) layout: Layout,
    pub(crate) lines: Vec<String>,
}

impl Rows {
    /// An empty file.
    pub(crate) fn new(name: &str, role: &str, layout: Layout) -> Self {
        Rows { name: name.into(), role: role.into(), layout, lines: Vec::new() }
    }

    /// Appends one row.
    pub(crate) fn push(&mut self, values: &[u64]) {
        let bits: Vec<Bits> =
            values.iter().zip(self.layout.widths()).map(|(&value, width)| Bits { value, width }).collect();
        self.lines.push(pack(&bits));
    }
}

/// Rows of every class, each class drawn from its own random stream (seed, class id), classes
/// in parallel on the current rayon pool and collected in class order: the output does not
/// depend on the number of threads. `case` returns the rows of one vector (None: the class
/// does not apply to the format).
pub(crate) type ClassRows = Vec<Vec<Vec<u64>>>;
pub(crate) fn per_class_rows(
    seed: u64,
    classes: usize,
    count: usize,
    case: impl Fn(usize, &mut SplitMix64) -> Result<Option<Vec<Vec<u64>>>, String> + Sync,
) -> Result<Vec<ClassRows>, String> {
    use rayon::prelude::*;
    (0..classes)
        .into_par_iter()
        .map(|c| {
            let mut r = SplitMix64::new(class_seed(seed, c));
            let mut rows = Vec::new();
            for _ in 0..count {
                match case(c, &mut r)? {
                    Some(row) => rows.push(row),
                    None => break,
                }
            }
            Ok(rows)
        })
        .collect()
}

/// The seed of class `c`'s random stream.
pub(crate) fn class_seed(seed: u64, c: usize) -> u64 {
    SplitMix64::new(seed ^ (c as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)).next_u64()
}

/// Appends per-class rows to the files (row k of a vector goes to file k); the counts.
pub(crate) fn push_rows(files: &mut [Rows], per_class: Vec<ClassRows>) -> Vec<usize> {
    per_class
        .into_iter()
        .map(|rows| {
            for row in &rows {
                for (file, vals) in files.iter_mut().zip(row) {
                    file.push(vals);
                }
            }
            rows.len()
        })
        .collect()
}

/// The format is a float (not fixed point).
pub(crate) fn is_float<F: Format>(f: &F) -> bool {
    matches!(f.kind(), FormatKind::Float(_))
}

/// The stage-0 input read of a unit's input encodings in words (manifest `options.input_read`).
pub(crate) fn input_read<F: Format>(f: &F) -> String {
    let FormatKind::Float(l) = f.kind() else {
        return "every input reads as itself (fixed point has no NaN and no subnormal)".into();
    };
    let nan = if f.nan_propagates() {
        "a NaN input reads quieted: fraction MSB set, sign and the rest of the payload kept, and the payload propagates (through operations as their first NaN operand, unchanged through compare-selects)".to_string()
    } else {
        format!("a NaN input reads as the canonical NaN 0x{:x}: no input payload reaches any signal", l.canonical_nan())
    };
    let sub =
        if f.flushes() { "a subnormal input reads as zero of its sign" } else { "a subnormal input reads as itself" };
    format!(
        "stage 0 reads every input encoding before any other use: {nan}; {sub}; every other encoding reads as itself"
    )
}

/// The slab unit's configuration as manifest options, one key per rule, in words.
pub(crate) fn slab_options(options: &mut BTreeMap<String, String>, sc: &SlabConfig) {
    use datapath::slab::{DirPrep, SlabNan, STEP_RULES};
    options.insert(
        "slab_comparator".into(),
        match sc.nan {
            SlabNan::Ignore => {
                "ignore: near t = (x > t) ? x : t, far t = (x < t) ? x : t (a NaN x loses every compare and is ignored)"
            }
            SlabNan::TakeOnFalse => {
                "take-on-false: near t = (x <= t) ? t : x, far t = (t <= x) ? t : x (a NaN on either side takes x)"
            }
        }
        .into(),
    );
    options.insert(
        "slab_direction_prep".into(),
        match sc.prep {
            DirPrep::Plain => "plain: inv_d = 1 / d (a ±0 component gives ±inf)",
            DirPrep::Embree => "embree: |d| < delta (params.slab_delta) becomes +delta or -delta by the sign bit of d, then inv_d = 1 / d",
        }
        .into(),
    );
    options.insert(
        "slab_widening".into(),
        format!(
            "t_near = tn_xyz stepped {0} times toward -inf (nextDown) and t_far = tf_xyz stepped {0} times toward +inf (nextUp); {STEP_RULES}",
            sc.widen_ulps
        ),
    );
    options.insert(
        "slab_guard".into(),
        if sc.guard {
            "on: inv_d of a finite nonzero pd whose quotient is not a normal number (+-inf, +-0 or subnormal) is the canonical NaN; a stage-1 difference of finite operands that is +-inf (overflow) is the canonical NaN; the products they feed are NaN and the comparator ignores them"
        } else {
            "off"
        }
        .into(),
    );
}
