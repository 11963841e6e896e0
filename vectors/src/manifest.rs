//! `manifest.json`: what every file, field and bit of a vector set means.

use serde::{Deserialize, Serialize};

/// Manifest schema version.
pub const SCHEMA: u32 = 2;

/// How a field's bits are interpreted.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// Unsigned integer.
    Uint,
    /// One control bit.
    Flag,
    /// IEEE-754-like float: 1 sign, `exp` exponent, `man` fraction bits.
    Ieee {
        /// Exponent bits.
        exp: u32,
        /// Fraction bits.
        man: u32,
    },
    /// Signed two's-complement fixed point.
    Fixed {
        /// Integer bits, sign included.
        int: u32,
        /// Fraction bits.
        frac: u32,
    },
}

/// One field of a row.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Field {
    /// Signal name.
    pub name: String,
    /// "in" (drive the DUT) or "out" (compare).
    pub dir: String,
    /// Interpretation.
    pub kind: Kind,
    /// Width in bits.
    pub width: u32,
    /// Bit offset of the field's LSB within the row (row bit 0 = the last hex digit's LSB).
    pub lsb: u32,
    /// Pipeline stage that produces it (outputs and stage signals).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub stage: Option<u8>,
    /// The field is compared only when this 1-bit field of the expected output row is 1 (rti
    /// `t`, `u`, `v` and the signals after the divide: `valid`); absent: always compared.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub care_when: Option<String>,
    /// The value depends on how a DUT is built (traverse `passes`, `box_tests`): the kit's
    /// testbenches compare it only with `+strict`.
    #[serde(skip_serializing_if = "std::ops::Not::not", default)]
    pub implementation_defined: bool,
}

/// One data file.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct File {
    /// File name within the set.
    pub name: String,
    /// What it holds.
    pub role: String,
    /// Rows (vectors).
    pub rows: usize,
    /// Bits per row.
    pub width: u32,
    /// Hex digits per row: ceil(width / 4), zero-padded at the top.
    pub digits: u32,
    /// Fields, most significant first.
    pub fields: Vec<Field>,
    /// SHA-256 of the file's bytes.
    pub sha256: String,
}

/// One coverage class.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Class {
    /// Id (the `class` field of every input row).
    pub id: u32,
    /// Name.
    pub name: String,
    /// What it covers.
    pub covers: String,
    /// Vectors in the set.
    pub count: usize,
}

/// One stage-table row.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stage {
    /// Stage number.
    pub stage: u8,
    /// Signal.
    pub name: String,
    /// Operation.
    pub op: String,
}

/// The manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Schema version.
    pub schema: u32,
    /// raypipe version.
    pub raypipe_version: String,
    /// Git commit of the generator, when known.
    pub git: String,
    /// The command that wrote the set.
    pub command: String,
    /// Seed of every random stream.
    pub seed: u64,
    /// Vectors requested per coverage class (`--count`; a class can hold fewer, see `classes`).
    #[serde(default)]
    pub count: usize,
    /// Unit: rti, slab or op.
    pub unit: String,
    /// Coverage level.
    pub level: u32,
    /// Format name (parseable by raypipe).
    pub format: String,
    /// The format's rounding, flush, NaN, overflow, division and compare rules.
    pub contract: std::collections::BTreeMap<String, String>,
    /// Unit options (culling, thresholds, tie rule, slab variant, op codes).
    pub options: std::collections::BTreeMap<String, String>,
    /// The contract and unit options as integers (the generated HDL packages' localparams):
    /// `float`, `exp`, `man` or `fx_int`, `fx_frac`; `ftz`, `nan_propagate`, `recip_mul`;
    /// rti `cull_backface`, `det_thr` (bits), `tie_last`; slab `slab_take_on_false`,
    /// `slab_embree`, `slab_delta` (bits), `slab_widen_ulps`.
    pub params: std::collections::BTreeMap<String, u64>,
    /// Pipeline latency in cycles at one stage per cycle.
    pub latency: u32,
    /// The stage table.
    pub stages: Vec<Stage>,
    /// Acceptable values: every output is exact (one value) — no faithful operation is modelled.
    pub acceptable_values: String,
    /// Data files.
    pub files: Vec<File>,
    /// Coverage classes with counts.
    pub classes: Vec<Class>,
    /// A minimal set (`raypipe vectors --minimal`): the subset of the default set that still
    /// detects every fault of the bank the default set detects; absent for a full set.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub minimal: Option<Minimal>,
    /// What wrote the input rows when they are not drawn from the seed (a proof's
    /// counterexamples: `raypipe prove ... --out`); absent for a generated set.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub origin: Option<String>,
    /// The coverage-closure class (`raypipe vectors --close`): its rows are given, found by a
    /// search, not drawn from the seed; absent for a set without one.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub closure: Option<Closure>,
}

/// The class a coverage closure appended (`raypipe vectors --close`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Closure {
    /// Its class id (the last class).
    pub class: u32,
    /// What found its rows (the search, its seed and budget).
    pub origin: String,
}

/// What a minimal set was cut from and what it keeps detecting.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Minimal {
    /// Vectors of the default set it was cut from (the same request without `--minimal`).
    pub from_vectors: usize,
    /// The bank faults (`raypipe faults` names) the set detects, every one of them.
    pub detects: Vec<String>,
    /// Detection is judged on the outputs alone (no stage probes).
    pub outputs_only: bool,
}

impl Manifest {
    /// The manifest of the set in `dir` (its `manifest.json`).
    pub fn read(dir: &std::path::Path) -> Result<Self, String> {
        let path = dir.join("manifest.json");
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
    }
}
