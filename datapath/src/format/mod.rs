//! Number formats. One trait, [`Format`], describes a format and its datapath options; every
//! model is generic over it (as `rustc_apfloat`'s `Semantics` is). Implementations:
//! - [`Ieee`] over an [`IeeeBackend`]: binary32 (native f32 ops), binary16 (`half`),
//!   bfloat16 (f32 compute, own nearest-even rounding) and custom `eEmM` formats (exact integer
//!   soft-float, [`FloatLayout`]), each with the vendor-IP options of [`FpOpts`];
//! - [`Fixed`]: signed two's-complement Q formats up to 64 bits, products in i128.

mod backends;
mod fixed;
pub mod layout;
pub mod narrow;
mod spec;

pub use backends::{Bf16, F16Half, F32Native, IeeeBackend, Soft};
pub use fixed::{Fixed, FxOverflow, FxRound};
pub use layout::FloatLayout;
pub use spec::{AnyFormat, FORMAT_HELP};

use std::fmt::Debug;

/// How subnormal operands and results are treated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Subnormals {
    /// IEEE gradual underflow.
    Ieee,
    /// Flush to zero: subnormal inputs read as signed zero, subnormal results become signed zero.
    Ftz,
}

/// Which NaN an operation returns.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NanMode {
    /// Every NaN result is the one canonical quiet NaN (sign 0, fraction MSB only).
    Canonical,
    /// The first NaN operand, quieted (x86 SSE order); a NaN made from non-NaN operands is canonical.
    Propagate,
}

/// How a datapath divides.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DivMode {
    /// A correctly rounded divide.
    Divide,
    /// Reciprocal `1 ⊘ b` (rounded), then a rounded multiply `a ⊗ (1 ⊘ b)`.
    RecipMul,
}

/// Per-datapath options of a float format (as vendor FP IP offers them).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FpOpts {
    /// Subnormal handling.
    pub subnormals: Subnormals,
    /// NaN result rule.
    pub nan: NanMode,
    /// Division implementation.
    pub div: DivMode,
}

impl Default for FpOpts {
    fn default() -> Self {
        Self { subnormals: Subnormals::Ieee, nan: NanMode::Canonical, div: DivMode::RecipMul }
    }
}

/// What kind of number a format is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormatKind {
    /// IEEE-like binary float.
    Float(FloatLayout),
    /// Signed fixed point with `int_bits` (sign included) and `frac_bits`.
    Fixed {
        /// Integer bits, sign included.
        int_bits: u32,
        /// Fraction bits.
        frac_bits: u32,
    },
}

/// Error model of one rounded operation: `|fl(x) - x| <= u·|fl(x)| + eta`, valid while no
/// magnitude exceeds `max`. Used by the error bounds written next to each model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorModel {
    /// Relative error of one rounding (unit roundoff; 0 for fixed point).
    pub u: f64,
    /// Absolute error of one rounded multiply or divide in the underflow/flush range (or the fixed-point step).
    pub eta: f64,
    /// Absolute error of one add or subtract beyond the relative part (0 unless results are flushed).
    pub add_eta: f64,
    /// Largest representable magnitude; beyond it results overflow.
    pub max: f64,
}

/// The rounding, flush, NaN and overflow rules of a format, in words.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Contract {
    /// Encoding.
    pub encoding: String,
    /// Rounding of every operation and of input conversion.
    pub rounding: String,
    /// Subnormal / flush rule.
    pub subnormals: String,
    /// NaN rule.
    pub nan: String,
    /// Overflow rule.
    pub overflow: String,
    /// Division rule.
    pub division: String,
    /// Comparison rule.
    pub compare: String,
}

/// A number format with its datapath options; all model arithmetic goes through it.
pub trait Format: Copy + Debug + Send + Sync + 'static {
    /// The value type (one register of the datapath).
    type V: Copy + Debug + Default + Send + Sync + 'static;

    /// Canonical name, parseable by [`AnyFormat`]'s `FromStr`.
    fn name(&self) -> String;
    /// Float layout or fixed-point widths.
    fn kind(&self) -> FormatKind;
    /// Width of one value in bits.
    fn width(&self) -> u32;
    /// The rules of this format in words.
    fn contract(&self) -> Contract;
    /// Error model for bounds.
    fn error_model(&self) -> ErrorModel;
    /// How this datapath divides.
    fn div_mode(&self) -> DivMode;

    /// Input conversion from f64 (correctly rounded; flushed under FTZ).
    #[allow(clippy::wrong_self_convention)] // a format carries run-time parameters
    fn from_f64(&self, x: f64) -> Self::V;
    /// Value as f64 (exact for every float format and for fixed values below 2^53 steps).
    fn to_f64(&self, v: Self::V) -> f64;
    /// [`Format::to_f64`] of a column: `dst[k] = to_f64(src[k])` for every `k` (equal lengths).
    fn to_f64_column(&self, src: &[Self::V], dst: &mut [f64]) {
        assert_eq!(src.len(), dst.len(), "to_f64_column: columns of different lengths");
        for (d, &x) in dst.iter_mut().zip(src) {
            *d = self.to_f64(x);
        }
    }
    /// Whether [`Format::to_f64_column`] runs at vector speed (a hint for callers choosing
    /// between converting and keeping an f64 copy; the values are the same either way).
    fn fast_f64_column(&self) -> bool {
        false
    }
    /// The stage-0 input read of an encoding a unit receives (both units, every input): a NaN
    /// reads as the canonical NaN under `canonical` and quieted (fraction MSB set, sign and
    /// the rest of the payload kept) under `propagate`; under FTZ a subnormal reads as zero of
    /// its sign; every other encoding reads as itself (fixed point: always itself).
    fn read_input(&self, v: Self::V) -> Self::V {
        v
    }
    /// Encoding, right-aligned in a u64.
    fn to_bits(&self, v: Self::V) -> u64;
    /// Value from its encoding (low `width` bits).
    #[allow(clippy::wrong_self_convention)] // a format carries run-time parameters
    fn from_bits(&self, b: u64) -> Self::V;

    /// a + b.
    fn add(&self, a: Self::V, b: Self::V) -> Self::V;
    /// a - b.
    fn sub(&self, a: Self::V, b: Self::V) -> Self::V;
    /// a × b.
    fn mul(&self, a: Self::V, b: Self::V) -> Self::V;
    /// a ÷ b per [`Format::div_mode`].
    fn div(&self, a: Self::V, b: Self::V) -> Self::V;
    /// a < b (false when either is NaN; -0 == +0).
    fn lt(&self, a: Self::V, b: Self::V) -> bool;
    /// a <= b (false when either is NaN; -0 == +0).
    fn le(&self, a: Self::V, b: Self::V) -> bool;
    /// True for NaN (never for fixed point).
    fn is_nan(&self, v: Self::V) -> bool;
    /// |a| (sign cleared; fixed point saturates the most negative value).
    fn abs(&self, a: Self::V) -> Self::V;
    /// +0.
    fn zero(&self) -> Self::V;
    /// 1 (rounded into range for fixed formats without room for it).
    fn one(&self) -> Self::V {
        self.from_f64(1.0)
    }
    /// Spacing of the format's grid near |x|.
    fn ulp(&self, x: f64) -> f64;
    /// Subnormal results are flushed to zero.
    fn flushes(&self) -> bool {
        false
    }
    /// A NaN result carries the first NaN operand's payload (quieted) instead of the canonical NaN.
    fn nan_propagates(&self) -> bool {
        false
    }
    /// Out-of-range results wrap around (fixed point `wrap`) instead of saturating or overflowing to ∞.
    fn wraps(&self) -> bool {
        false
    }
    /// The sign bit (fixed point: negative).
    fn sign_bit(&self, v: Self::V) -> bool;
    /// The next value toward +∞ (NaN and +∞ unchanged; under FTZ it skips the subnormals).
    fn next_up(&self, v: Self::V) -> Self::V;
    /// The next value toward −∞ (NaN and −∞ unchanged; under FTZ it skips the subnormals).
    fn next_down(&self, v: Self::V) -> Self::V;
    /// The largest value <= x (x not NaN): a directed, conservative input conversion.
    fn round_down(&self, x: f64) -> Self::V {
        let v = self.from_f64(x);
        if self.to_f64(v) > x {
            self.next_down(v)
        } else {
            v
        }
    }
    /// The smallest value >= x (x not NaN).
    fn round_up(&self, x: f64) -> Self::V {
        let v = self.from_f64(x);
        if self.to_f64(v) < x {
            self.next_up(v)
        } else {
            v
        }
    }
    /// Hex digits of one encoding: `ceil(width / 4)`.
    fn hex(&self, v: Self::V) -> String {
        format!("{:0w$x}", self.to_bits(v), w = self.width().div_ceil(4) as usize)
    }
}

/// A format's edge magnitudes, where stress and vector classes probe it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edges {
    /// The least positive value (the smallest subnormal; under FTZ the smallest normal; fixed
    /// point: one step).
    pub least: f64,
    /// The least positive normal value (fixed point: one step).
    pub min_normal: f64,
    /// The largest finite value.
    pub max: f64,
}

/// The edge magnitudes of format `f`.
pub fn edges<F: Format>(f: &F) -> Edges {
    match f.kind() {
        FormatKind::Float(l) => {
            let n = l.min_normal();
            let least = if f.flushes() { n } else { layout::pow2(l.emin() - l.man_bits as i32) };
            Edges { least, min_normal: n, max: l.max_finite() }
        }
        FormatKind::Fixed { frac_bits, .. } => {
            let step = layout::pow2(-(frac_bits as i32));
            Edges { least: step, min_normal: step, max: f.error_model().max }
        }
    }
}

/// An IEEE-like float format: a bit-exact backend plus the datapath's [`FpOpts`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ieee<B: IeeeBackend> {
    /// The arithmetic backend.
    pub backend: B,
    /// Flush, NaN and division options.
    pub opts: FpOpts,
}

impl<B: IeeeBackend> Ieee<B> {
    /// The format with the given options.
    pub fn new(backend: B, opts: FpOpts) -> Self {
        Self { backend, opts }
    }

    #[inline(always)]
    fn lay(&self) -> FloatLayout {
        self.backend.layout()
    }

    /// Operand read: under FTZ a subnormal reads as zero of the same sign.
    #[inline(always)]
    fn read(&self, v: B::V) -> B::V {
        if self.opts.subnormals == Subnormals::Ftz {
            let l = self.lay();
            let b = B::bits(v);
            if l.is_subnormal(b) {
                return B::from_bits(b & l.sign_mask());
            }
        }
        v
    }

    /// Result write: NaN rule, then under FTZ a subnormal result becomes zero of the same sign.
    #[inline(always)]
    fn write(&self, a: B::V, b: B::V, r: B::V) -> B::V {
        let l = self.lay();
        let rb = B::bits(r);
        if l.is_nan(rb) {
            let (ab, bb) = (B::bits(a), B::bits(b));
            let out = match self.opts.nan {
                NanMode::Canonical => l.canonical_nan(),
                NanMode::Propagate if l.is_nan(ab) => l.quiet(ab),
                NanMode::Propagate if l.is_nan(bb) => l.quiet(bb),
                NanMode::Propagate => l.canonical_nan(),
            };
            return B::from_bits(out);
        }
        if self.opts.subnormals == Subnormals::Ftz && l.is_subnormal(rb) {
            return B::from_bits(rb & l.sign_mask());
        }
        r
    }
}

impl<B: IeeeBackend> Format for Ieee<B> {
    type V = B::V;

    fn name(&self) -> String {
        let mut opts = Vec::new();
        if self.opts.subnormals == Subnormals::Ftz {
            opts.push("ftz");
        }
        if self.opts.nan == NanMode::Propagate {
            opts.push("propagate");
        }
        if self.opts.div == DivMode::Divide {
            opts.push("divide");
        }
        let base = self.backend.name();
        if opts.is_empty() {
            base
        } else {
            format!("{base}:{}", opts.join("+"))
        }
    }
    fn kind(&self) -> FormatKind {
        FormatKind::Float(self.lay())
    }
    fn width(&self) -> u32 {
        self.lay().width()
    }
    fn contract(&self) -> Contract {
        let l = self.lay();
        Contract {
            encoding: format!(
                "IEEE-754-like binary: 1 sign, {} exponent (bias {}), {} fraction bits; {} bits",
                l.exp_bits,
                l.bias(),
                l.man_bits,
                l.width()
            ),
            rounding: "every + - x / and the f64 input conversion rounded once, to nearest, ties to even; no fused multiply-add".into(),
            subnormals: match self.opts.subnormals {
                Subnormals::Ieee => "IEEE gradual underflow (subnormals kept)".into(),
                Subnormals::Ftz => "flush to zero: subnormal operands read as zero of the same sign; a result that is subnormal after rounding becomes zero of the same sign; the f64 input conversion and the stage-0 read of every input encoding flush the same way".into(),
            },
            nan: match self.opts.nan {
                NanMode::Canonical => format!(
                    "every NaN result is the canonical quiet NaN 0x{c:x} (sign 0); a NaN input reads as 0x{c:x} at stage 0 (both units, every input), so no input payload reaches any signal",
                    c = l.canonical_nan()
                ),
                NanMode::Propagate => format!(
                    "a NaN result is the first NaN operand, quieted (x86 order); invalid operations give 0x{:x}; a NaN input reads quieted at stage 0 (fraction MSB set, sign and payload kept; both units, every input), so input payloads propagate: through operations, and unchanged through compare-selects",
                    l.canonical_nan()
                ),
            },
            overflow: "overflow rounds to ±infinity (nearest-even)".into(),
            division: match self.opts.div {
                DivMode::Divide => "a ⊘ b correctly rounded".into(),
                DivMode::RecipMul => "a ⊗ (1 ⊘ b): reciprocal rounded (and flushed), then a rounded multiply".into(),
            },
            compare: "IEEE ordered compare after the operand read: NaN compares false, -0 == +0".into(),
        }
    }
    fn error_model(&self) -> ErrorModel {
        let l = self.lay();
        let eta = match self.opts.subnormals {
            Subnormals::Ieee => layout::pow2(l.emin() - l.man_bits as i32 - 1),
            Subnormals::Ftz => l.min_normal(),
        };
        let add_eta = match self.opts.subnormals {
            Subnormals::Ieee => 0.0, // a sum on the subnormal grid is exact
            Subnormals::Ftz => l.min_normal(),
        };
        ErrorModel { u: l.unit_roundoff(), eta, add_eta, max: l.max_finite() }
    }
    fn div_mode(&self) -> DivMode {
        self.opts.div
    }

    #[allow(clippy::wrong_self_convention)] // a format carries run-time parameters
    fn from_f64(&self, x: f64) -> B::V {
        let v = self.backend.from_f64(x);
        let z = self.zero();
        self.write(z, z, v)
    }
    fn to_f64(&self, v: B::V) -> f64 {
        self.backend.to_f64(v)
    }
    fn to_f64_column(&self, src: &[B::V], dst: &mut [f64]) {
        self.backend.to_f64_column(src, dst)
    }
    fn fast_f64_column(&self) -> bool {
        self.backend.fast_f64_column()
    }
    fn to_bits(&self, v: B::V) -> u64 {
        B::bits(v)
    }
    #[allow(clippy::wrong_self_convention)] // a format carries run-time parameters
    fn from_bits(&self, b: u64) -> B::V {
        B::from_bits(b & (self.lay().sign_mask() << 1).wrapping_sub(1))
    }

    #[inline(always)]
    fn add(&self, a: B::V, b: B::V) -> B::V {
        self.write(a, b, self.backend.add(self.read(a), self.read(b)))
    }
    #[inline(always)]
    fn sub(&self, a: B::V, b: B::V) -> B::V {
        self.write(a, b, self.backend.sub(self.read(a), self.read(b)))
    }
    #[inline(always)]
    fn mul(&self, a: B::V, b: B::V) -> B::V {
        self.write(a, b, self.backend.mul(self.read(a), self.read(b)))
    }
    #[inline(always)]
    fn div(&self, a: B::V, b: B::V) -> B::V {
        match self.opts.div {
            DivMode::Divide => self.write(a, b, self.backend.div(self.read(a), self.read(b))),
            DivMode::RecipMul => {
                let one = self.one();
                let r = self.write(one, b, self.backend.div(one, self.read(b)));
                self.mul(a, r)
            }
        }
    }
    #[inline(always)]
    fn lt(&self, a: B::V, b: B::V) -> bool {
        self.backend.lt(self.read(a), self.read(b))
    }
    #[inline(always)]
    fn le(&self, a: B::V, b: B::V) -> bool {
        self.backend.le(self.read(a), self.read(b))
    }
    #[inline(always)]
    fn read_input(&self, v: B::V) -> B::V {
        let l = self.lay();
        let b = B::bits(v);
        if l.is_nan(b) {
            return B::from_bits(match self.opts.nan {
                NanMode::Canonical => l.canonical_nan(),
                NanMode::Propagate => l.quiet(b),
            });
        }
        self.read(v)
    }
    #[inline(always)]
    fn is_nan(&self, v: B::V) -> bool {
        self.lay().is_nan(B::bits(v))
    }
    #[inline(always)]
    fn abs(&self, a: B::V) -> B::V {
        B::from_bits(B::bits(a) & !self.lay().sign_mask())
    }
    #[inline(always)]
    fn zero(&self) -> B::V {
        B::from_bits(0)
    }
    #[inline(always)]
    fn one(&self) -> B::V {
        let l = self.lay();
        B::from_bits((l.bias() as u64) << l.man_bits)
    }
    fn ulp(&self, x: f64) -> f64 {
        self.lay().ulp(x)
    }
    fn flushes(&self) -> bool {
        self.opts.subnormals == Subnormals::Ftz
    }
    fn nan_propagates(&self) -> bool {
        self.opts.nan == NanMode::Propagate
    }
    #[inline(always)]
    fn sign_bit(&self, v: B::V) -> bool {
        self.lay().is_neg(B::bits(v))
    }
    fn next_up(&self, v: B::V) -> B::V {
        let l = self.lay();
        let b = B::bits(v);
        if l.is_nan(b) || b == l.inf(false) {
            return v;
        }
        let ftz = self.opts.subnormals == Subnormals::Ftz;
        let r = if l.is_zero(b) {
            if ftz {
                1 << l.man_bits // smallest normal
            } else {
                1
            }
        } else if l.is_neg(b) {
            b - 1
        } else {
            b + 1
        };
        if ftz && l.is_subnormal(r) {
            // only reachable stepping up from the negative smallest normal
            return B::from_bits(l.sign_mask());
        }
        B::from_bits(r)
    }
    fn next_down(&self, v: B::V) -> B::V {
        let m = self.lay().sign_mask();
        let flip = |x: B::V| B::from_bits(B::bits(x) ^ m);
        if self.is_nan(v) {
            return v;
        }
        flip(self.next_up(flip(v)))
    }
}
