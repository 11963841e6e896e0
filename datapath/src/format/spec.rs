//! Format names: parsing `f32`, `fp16`, `bf16`, `eEmM`, `qI.F` with `:option+...` suffixes into
//! [`AnyFormat`], the run-time choice that dispatches to the generic models.

use super::{
    Bf16, DivMode, F16Half, F32Native, Fixed, FloatLayout, FpOpts, FxOverflow, FxRound, Ieee, NanMode, Soft, Subnormals,
};
use std::fmt;
use std::str::FromStr;

/// The grammar of format names, for error messages and `--help`.
pub const FORMAT_HELP: &str = "format names: f32 | fp16 | bf16 | eEmM (custom IEEE-like, E=2..11 exponent, M=1..52 fraction bits, e.g. e8m16) | qI.F (signed fixed point, I integer bits incl. sign, F fraction bits, I+F <= 64, e.g. q8.24); options after ':' joined by '+': floats ftz|ieee, canonical|propagate, recip|divide; fixed floor|ceil|trunc|nearest, saturate|wrap, recip|divide (e.g. fp16:ftz+divide or q8.24:nearest+wrap)";

/// A format chosen at run time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AnyFormat {
    /// binary32 on native f32.
    F32(Ieee<F32Native>),
    /// binary16 through `half`.
    F16(Ieee<F16Half>),
    /// bfloat16.
    Bf16(Ieee<Bf16>),
    /// Custom IEEE-like layout in soft-float.
    Soft(Ieee<Soft>),
    /// Fixed point.
    Fixed(Fixed),
}

/// Runs `$body` with `$f` bound to the concrete format inside an [`AnyFormat`].
#[macro_export]
macro_rules! with_format {
    ($any:expr, |$f:ident| $body:expr) => {
        match $any {
            $crate::format::AnyFormat::F32($f) => $body,
            $crate::format::AnyFormat::F16($f) => $body,
            $crate::format::AnyFormat::Bf16($f) => $body,
            $crate::format::AnyFormat::Soft($f) => $body,
            $crate::format::AnyFormat::Fixed($f) => $body,
        }
    };
}

impl AnyFormat {
    /// Canonical name.
    pub fn name(&self) -> String {
        use super::Format;
        with_format!(self, |f| f.name())
    }
}

impl fmt::Display for AnyFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// Each option group of a format name may be given once: `fp16:ftz+ieee` is refused, not
/// settled by the last one.
struct OptionGroups<'a> {
    name: &'a str,
    seen: Vec<(&'static str, String)>,
}

impl<'a> OptionGroups<'a> {
    fn new(name: &'a str) -> Self {
        Self { name, seen: Vec::new() }
    }

    fn once(&mut self, group: &'static str, opt: &str) -> Result<(), String> {
        if let Some((_, first)) = self.seen.iter().find(|(g, _)| *g == group) {
            return Err(format!(
                "format '{}': options '{first}' and '{opt}' both set the {group} rule; give one; {FORMAT_HELP}",
                self.name
            ));
        }
        self.seen.push((group, opt.to_string()));
        Ok(())
    }
}

fn parse_custom(s: &str) -> Option<(u32, u32)> {
    let rest = s.strip_prefix('e')?;
    let (e, m) = rest.split_once('m')?;
    Some((e.parse().ok()?, m.parse().ok()?))
}

fn parse_q(s: &str) -> Option<(u32, u32)> {
    let rest = s.strip_prefix('q')?;
    let (i, f) = rest.split_once('.')?;
    Some((i.parse().ok()?, f.parse().ok()?))
}

impl FromStr for AnyFormat {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let lower = s.trim().to_ascii_lowercase();
        let (base, opts) = match lower.split_once(':') {
            Some((b, o)) => (b, o.split('+').filter(|t| !t.is_empty()).collect::<Vec<_>>()),
            None => (lower.as_str(), Vec::new()),
        };
        let unknown = |what: &str| format!("unknown format option '{what}' in '{s}'; {FORMAT_HELP}");
        if let Some((i, f)) = parse_q(base) {
            let mut round = FxRound::Floor;
            let mut overflow = FxOverflow::Saturate;
            let mut div = DivMode::RecipMul;
            let mut seen = OptionGroups::new(s);
            for o in opts {
                match o {
                    "floor" | "ceil" | "trunc" | "nearest" => seen.once("rounding", o)?,
                    "saturate" | "wrap" => seen.once("overflow", o)?,
                    "recip" | "divide" => seen.once("division", o)?,
                    _ => {}
                }
                match o {
                    "floor" => round = FxRound::Floor,
                    "ceil" => round = FxRound::Ceil,
                    "trunc" => round = FxRound::Trunc,
                    "nearest" => round = FxRound::NearestEven,
                    "saturate" => overflow = FxOverflow::Saturate,
                    "wrap" => overflow = FxOverflow::Wrap,
                    "recip" => div = DivMode::RecipMul,
                    "divide" => div = DivMode::Divide,
                    other => return Err(unknown(other)),
                }
            }
            return Fixed::new(i, f, round, overflow, div)
                .map(AnyFormat::Fixed)
                .map_err(|e| format!("{e}; {FORMAT_HELP}"));
        }
        let mut o = FpOpts::default();
        let mut seen = OptionGroups::new(s);
        for t in opts {
            match t {
                "ftz" | "ieee" => seen.once("subnormals", t)?,
                "canonical" | "propagate" => seen.once("NaN", t)?,
                "recip" | "divide" => seen.once("division", t)?,
                _ => {}
            }
            match t {
                "ftz" => o.subnormals = Subnormals::Ftz,
                "ieee" => o.subnormals = Subnormals::Ieee,
                "canonical" => o.nan = NanMode::Canonical,
                "propagate" => o.nan = NanMode::Propagate,
                "recip" => o.div = DivMode::RecipMul,
                "divide" => o.div = DivMode::Divide,
                other => return Err(unknown(other)),
            }
        }
        match base {
            "f32" | "fp32" | "binary32" => Ok(AnyFormat::F32(Ieee::new(F32Native, o))),
            "fp16" | "f16" | "binary16" => Ok(AnyFormat::F16(Ieee::new(F16Half, o))),
            "bf16" | "bfloat16" => Ok(AnyFormat::Bf16(Ieee::new(Bf16, o))),
            _ => match parse_custom(base) {
                Some((e, m)) => FloatLayout::validate(e, m)
                    .map(|l| AnyFormat::Soft(Ieee::new(Soft(l), o)))
                    .map_err(|err| format!("format '{s}': {err}; {FORMAT_HELP}")),
                None => Err(format!("unknown format '{s}'; {FORMAT_HELP}")),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for n in [
            "f32",
            "fp16",
            "bf16",
            "e8m16",
            "e5m2",
            "q8.24",
            "fp16:ftz",
            "f32:ftz+propagate+divide",
            "q16.16:nearest+wrap",
        ] {
            let f: AnyFormat = n.parse().unwrap();
            assert_eq!(f.name(), n);
            assert_eq!(f.name().parse::<AnyFormat>().unwrap(), f);
        }
    }

    #[test]
    fn bad_names_are_clear_errors() {
        for n in [
            "f31",
            "e12m3",
            "e8m0",
            "q0.8",
            "q40.40",
            "fp16:fast",
            "q8.8:ftz",
            "",
            "e8",
            "q8",
            "fp16:ftz+ieee",
            "f32:divide+recip",
            "q8.24:saturate+wrap",
            "q8.24:floor+nearest",
            "bf16:canonical+propagate",
            "fp16:ftz+ftz",
            // widths whose sum overflows u32 (found by the `format` fuzz target): a wrapped
            // sum of 2..=64 must not be accepted as a format
            "q4294967295.3",
            "q4294967295.1",
            "q1.4294967295",
            "q4294967295.4294967295",
            "e4294967295m3",
            "e8m4294967295",
        ] {
            let e = n.parse::<AnyFormat>().unwrap_err();
            assert!(e.contains("format"), "{n}: {e}");
        }
    }
}
