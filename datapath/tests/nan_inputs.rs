//! The stage-0 input read (docs/formats.md, "Input read"): both units read every input the
//! same way — a NaN as the canonical NaN, quieted with its payload kept under `propagate`; a
//! subnormal as ±0 under FTZ. In the slab unit the rule shows in the pass-through signals
//! (`dx`…`dz`, and `tmin`/`tmax` through the compare-selects); in the RTI unit every input
//! feeds an operation or a compare first, so reading the inputs first changes no signal.

use datapath::probe::{Recorder, Signal};
use datapath::rng::SplitMix64;
use datapath::rti::{Ray, Rti, RtiConfig, Tri};
use datapath::slab::{Aabb, Slab, SlabConfig};
use datapath::{with_format, AnyFormat, Format};

fn fmt(name: &str) -> AnyFormat {
    name.parse().unwrap()
}

/// Every recorded signal as bits (values) or 0/1 (flags), by name.
fn bits<F: Format>(f: &F, r: &Recorder<F::V>) -> Vec<(&'static str, u64)> {
    r.signals
        .iter()
        .map(|(n, s)| match s {
            Signal::Value(v) => (*n, f.to_bits(*v)),
            Signal::Flag(b) => (*n, *b as u64 | 1 << 63),
        })
        .collect()
}

/// The slab unit on a ray with a NaN `d.x` (0xffee3e98) and a signalling-NaN `tmax`
/// (0x7fb22873): the values the docs give, under canonical and propagate.
#[test]
fn slab_reads_nan_inputs_by_the_nan_rule() {
    for (name, dx, tfx) in [("f32", 0x7fc0_0000u64, 0x7fc0_0000u64), ("f32:propagate", 0xffee_3e98, 0x7ff2_2873)] {
        with_format!(fmt(name), |f| {
            let s = Slab::new(f, SlabConfig::named("plain").unwrap());
            let v = |x: f64| f.from_f64(x);
            let o = [v(0.5), v(0.5), v(-1.0)];
            let d = [f.from_bits(0xffee_3e98), v(0.0), v(1.0)];
            let mut p = Recorder::new();
            let ray = s.prepare_faulty(o, d, v(0.0), f.from_bits(0x7fb2_2873), &mut p, &datapath::fault::NoFault);
            assert_eq!(f.to_bits(p.value("dx").unwrap()), dx, "{name} dx");
            let b = Aabb { min: [v(0.0); 3], max: [v(1.0); 3] };
            let mut q = Recorder::new();
            s.trace(&ray, &b, &mut q);
            assert_eq!(f.to_bits(q.value("tf_x").unwrap()), tfx, "{name} tf_x");
        });
    }
    // fp16 and a custom layout: the canonical NaN, or the input quieted
    for (name, input, canonical, quieted) in
        [("fp16", 0xfd01u64, 0x7e00u64, 0xff01u64), ("e6m9", 0x7e01, 0x7f00, 0x7f01)]
    {
        for (opt, want) in [("", canonical), (":propagate", quieted)] {
            let full = format!("{name}{opt}");
            with_format!(fmt(&full), |f| {
                let s = Slab::new(f, SlabConfig::named("plain").unwrap());
                let one = f.one();
                let mut p = Recorder::new();
                s.prepare_faulty(
                    [one; 3],
                    [f.from_bits(input), one, one],
                    f.zero(),
                    one,
                    &mut p,
                    &datapath::fault::NoFault,
                );
                assert_eq!(f.to_bits(p.value("dx").unwrap()), want, "{full} dx");
                assert_eq!(f.to_bits(f.read_input(f.from_bits(input))), want, "{full} read_input");
            });
        }
    }
    // FTZ: a subnormal input reads as zero of its sign
    with_format!(fmt("f32:ftz"), |f| {
        assert_eq!(f.to_bits(f.read_input(f.from_bits(0x8000_0001))), 0x8000_0000);
        assert_eq!(f.to_bits(f.read_input(f.from_bits(0x0080_0000))), 0x0080_0000);
    });
    // fixed point reads every input as itself
    with_format!(fmt("q8.24"), |f| assert_eq!(f.to_bits(f.read_input(f.from_bits(0xdead_beef))), 0xdead_beef));
}

/// An input encoding: mostly NaNs of random payload, sign and signalling bit, subnormals, ±0,
/// ±∞ and numbers.
fn input<F: Format>(f: &F, r: &mut SplitMix64) -> F::V {
    let datapath::format::FormatKind::Float(l) = f.kind() else { unreachable!() };
    let man = (1u64 << l.man_bits) - 1;
    let exp = ((1u64 << l.exp_bits) - 1) << l.man_bits;
    let sign = (r.below(2)) << (l.exp_bits + l.man_bits);
    let b = match r.below(6) {
        0 | 1 => sign | exp | (r.next_u64() & man).max(1),
        2 => sign | (r.next_u64() & man),
        3 => sign | exp,
        _ => return f.from_f64(r.range(-2.0, 2.0)),
    };
    f.from_bits(b)
}

/// The RTI unit's signals, every one, are the same whether or not its inputs were read first:
/// 4,000 tests per format of NaN-payload, subnormal and infinite inputs.
#[test]
fn rti_signals_do_not_change_when_the_inputs_are_read_first() {
    for name in
        ["f32", "f32:propagate", "f32:ftz+propagate", "fp16:propagate", "bf16:propagate", "e6m9:propagate+divide"]
    {
        let nan_signals = with_format!(fmt(name), |f| rti_equivalence(f, name));
        assert!(nan_signals > 1000, "{name}: the NaN inputs reached {nan_signals} signals");
    }
}

/// Runs the RTI unit on raw and on read inputs, asserting equal signals; returns how many
/// NaN signals it saw.
fn rti_equivalence<F: Format>(f: F, name: &str) -> usize {
    let rti = Rti::new(f, RtiConfig::default());
    let mut r = SplitMix64::new(0x6e61_6e73);
    let mut nan_signals = 0;
    let make = |x: &[F::V; 17]| {
        (
            Ray { o: [x[0], x[1], x[2]], d: [x[3], x[4], x[5]], tmin: x[6], tmax: x[7] },
            Tri { v: [[x[8], x[9], x[10]], [x[11], x[12], x[13]], [x[14], x[15], x[16]]] },
        )
    };
    for _ in 0..4000 {
        let x: [F::V; 17] = std::array::from_fn(|_| input(&f, &mut r));
        let read = x.map(|v| f.read_input(v));
        let ((ra, ta), (rb, tb)) = (make(&x), make(&read));
        let (mut pa, mut pb) = (Recorder::new(), Recorder::new());
        rti.trace(&ra, &ta, &mut pa);
        rti.trace(&rb, &tb, &mut pb);
        assert_eq!(bits(&f, &pa), bits(&f, &pb), "{name}: inputs {:x?}", x.map(|v| f.to_bits(v)));
        nan_signals += pa.signals.iter().filter(|(_, s)| matches!(s, Signal::Value(v) if f.is_nan(*v))).count();
    }
    nan_signals
}
