//! A unit handle: one model (RTI, slab or op unit) in one format with its options, built from
//! the CLI's strings, evaluated on rows of encodings laid out as the vector files' rows.

use datapath::fault::NoFault;
use datapath::format::AnyFormat;
use datapath::rti::{Cull, HitsSoa, RaysSoa, Rti, RtiConfig, TieRule, TrisSoa};
use datapath::slab::{Aabb, BoxesSoa, Slab, SlabConfig, SlabOutSoa, SlabRaysSoa};
use datapath::{with_format, Format};

/// Which unit a handle models.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Ray–triangle intersection: inputs o, d, tmin, tmax, v0, v1, v2 (17); outputs valid,
    /// hit, t, u, v (5).
    Rti,
    /// Ray–box slab test: inputs o, d, tmin, tmax, box min, box max (14); outputs hit, t_near,
    /// t_far (3).
    Slab,
    /// One operation: inputs op code (0 add, 1 sub, 2 mul, 3 div, 4 lt, 5 le), a, b (3);
    /// outputs result, cmp (2).
    Op,
    /// BVH traversal (2-bit ray history) over the tree of a traverse vector set's BRAM images:
    /// inputs o, d, tmin, tmax (8); outputs the set's expected row (count, the first N leaf
    /// ids, passes, box tests, each level's final history state).
    Traverse,
}

impl Kind {
    /// Encodings in an input row.
    pub fn inputs(self) -> usize {
        match self {
            Kind::Rti => 17,
            Kind::Slab => 14,
            Kind::Op => 3,
            Kind::Traverse => 8,
        }
    }
}

/// The format-specific part of a unit.
trait Eval: Send + Sync {
    /// One row: `out` (the unit's outputs) and, when `stages` is given, every stage signal in
    /// the order of the vector set's stage file (names and bit widths into `names` when given:
    /// a flag is 1 bit, a register the format's width).
    fn eval(
        &self,
        input: &[u64],
        out: &mut [u64],
        stages: Option<&mut Vec<u64>>,
        names: Option<&mut Vec<(String, u32)>>,
    );
    /// The unit as an f32 RTI unit, when it is one (columnar batches of binary32 lanes).
    fn rti_f32(&self) -> Option<&Rti<F32Format>> {
        None
    }
    /// `out` rows for `input` rows (row-major), on the SIMD kernels where the format has them.
    fn batch(&self, input: &[u64], out: &mut [u64]);
}

struct RtiUnit<F: Format> {
    rti: Rti<F>,
}

struct SlabUnit<F: Format> {
    s: Slab<F>,
}

struct OpUnit<F: Format> {
    f: F,
}

/// A format's conversions from and to binary64, behind one object for every unit.
trait Codec: Send + Sync {
    /// The format's encoding of `x` (rounded as the format's conversion rounds).
    fn encode(&self, x: f64) -> u64;
    /// The value of an encoding.
    fn decode(&self, bits: u64) -> f64;
}

impl<F: Format + Send + Sync> Codec for F {
    fn encode(&self, x: f64) -> u64 {
        self.to_bits(self.from_f64(x))
    }
    fn decode(&self, bits: u64) -> f64 {
        self.to_f64(self.from_bits(bits))
    }
}

/// The f32 format (binary32 lanes).
type F32Format = datapath::format::Ieee<datapath::format::F32Native>;

/// Rows per SIMD batch (the columns stay in cache).
const CHUNK: usize = 1024;

/// The names and widths of a recorder's signals.
fn names_of<V>(rec: &datapath::probe::Recorder<V>, width: u32) -> Vec<(String, u32)> {
    use datapath::probe::Signal;
    rec.signals
        .iter()
        .map(|(name, s)| (name.to_string(), if matches!(s, Signal::Flag(_)) { 1 } else { width }))
        .collect()
}

fn copy_rows(out: &mut [u64], rows: [Vec<u64>; 2], stages: Option<&mut Vec<u64>>) {
    let [o, st] = rows;
    out.copy_from_slice(&o);
    if let Some(s) = stages {
        *s = st;
    }
}

impl<F: Format + Send + Sync + 'static> Eval for RtiUnit<F>
where
    F::V: 'static,
{
    fn eval(
        &self,
        input: &[u64],
        out: &mut [u64],
        stages: Option<&mut Vec<u64>>,
        names: Option<&mut Vec<(String, u32)>>,
    ) {
        let (ray, tri) = vectors::gen::rti_case_of(&self.rti.fmt, input);
        if let Some(n) = names {
            let mut rec = datapath::probe::Recorder::new();
            self.rti.trace(&ray, &tri, &mut rec);
            *n = names_of(&rec, self.rti.fmt.width());
        }
        copy_rows(out, vectors::gen::rti_out_rows(&self.rti, &ray, &tri, &NoFault), stages);
    }
    fn rti_f32(&self) -> Option<&Rti<F32Format>> {
        (&self.rti as &dyn std::any::Any).downcast_ref()
    }
    fn batch(&self, input: &[u64], out: &mut [u64]) {
        let f = &self.rti.fmt;
        // one set of columns for every chunk (refilled, its capacity kept)
        let (mut rays, mut tris) = (RaysSoa::with_capacity(CHUNK), TrisSoa::with_capacity(CHUNK));
        let mut hits = HitsSoa::with_len(CHUNK);
        for (rows, outs) in input.chunks(17 * CHUNK).zip(out.chunks_mut(5 * CHUNK)) {
            // column by column from the rows (17 simple passes over a chunk in cache)
            let col = |v: &mut Vec<F::V>, k: usize| {
                v.clear();
                v.extend(rows.chunks_exact(17).map(|r| f.from_bits(r[k])));
            };
            for a in 0..3 {
                col(&mut rays.o[a], a);
                col(&mut rays.d[a], 3 + a);
                for j in 0..3 {
                    col(&mut tris.v[j][a], 8 + 3 * j + a);
                }
            }
            col(&mut rays.tmin, 6);
            col(&mut rays.tmax, 7);
            hits.resize(rays.len());
            datapath::simd::rti_batch(&self.rti, &rays, &tris, &mut hits);
            for (i, o) in outs.chunks_exact_mut(5).enumerate() {
                o.copy_from_slice(&[
                    hits.valid[i] as u64,
                    hits.hit[i] as u64,
                    f.to_bits(hits.t[i]),
                    f.to_bits(hits.u[i]),
                    f.to_bits(hits.v[i]),
                ]);
            }
        }
    }
}

impl<F: Format + Send + Sync + 'static> Eval for SlabUnit<F>
where
    F::V: 'static,
{
    fn eval(
        &self,
        input: &[u64],
        out: &mut [u64],
        stages: Option<&mut Vec<u64>>,
        names: Option<&mut Vec<(String, u32)>>,
    ) {
        if let Some(n) = names {
            let f = &self.s.fmt;
            let v = |i: usize| f.from_bits(input[i]);
            let mut rec = datapath::probe::Recorder::new();
            let ray = self.s.prepare_faulty([v(0), v(1), v(2)], [v(3), v(4), v(5)], v(6), v(7), &mut rec, &NoFault);
            let b = Aabb { min: [v(8), v(9), v(10)], max: [v(11), v(12), v(13)] };
            self.s.trace(&ray, &b, &mut rec);
            *n = names_of(&rec, f.width());
        }
        copy_rows(out, vectors::gen::slab_out_rows(&self.s, input, &NoFault), stages);
    }
    fn batch(&self, input: &[u64], out: &mut [u64]) {
        let f = &self.s.fmt;
        // one set of columns for every chunk (cleared, its capacity kept)
        let (mut rays, mut boxes) = (SlabRaysSoa::default(), BoxesSoa::default());
        let mut res = SlabOutSoa::with_len(CHUNK);
        for (rows, outs) in input.chunks(14 * CHUNK).zip(out.chunks_mut(3 * CHUNK)) {
            rays.o
                .iter_mut()
                .chain(&mut rays.inv_d)
                .chain(&mut rays.inv_lo)
                .chain(&mut rays.inv_hi)
                .for_each(Vec::clear);
            rays.parallel.iter_mut().for_each(Vec::clear);
            rays.tmin.clear();
            rays.tmax.clear();
            boxes.min.iter_mut().chain(&mut boxes.max).for_each(Vec::clear);
            for row in rows.chunks_exact(14) {
                let v = |i: usize| f.from_bits(row[i]);
                let ray = self.s.prepare_faulty(
                    [v(0), v(1), v(2)],
                    [v(3), v(4), v(5)],
                    v(6),
                    v(7),
                    &mut datapath::probe::NoProbe,
                    &NoFault,
                );
                rays.push(&ray);
                boxes.push(&Aabb { min: [v(8), v(9), v(10)], max: [v(11), v(12), v(13)] });
            }
            let n = rows.len() / 14;
            res.hit.resize(n, false);
            res.t_near.resize(n, f.from_bits(0));
            res.t_far.resize(n, f.from_bits(0));
            datapath::simd::slab_batch(&self.s, &rays, &boxes, &mut res);
            for (i, o) in outs.chunks_exact_mut(3).enumerate() {
                o.copy_from_slice(&[res.hit[i] as u64, f.to_bits(res.t_near[i]), f.to_bits(res.t_far[i])]);
            }
        }
    }
}

impl<F: Format + Send + Sync + 'static> Eval for OpUnit<F> {
    fn eval(
        &self,
        input: &[u64],
        out: &mut [u64],
        stages: Option<&mut Vec<u64>>,
        names: Option<&mut Vec<(String, u32)>>,
    ) {
        if let Some(n) = names {
            n.clear();
        }
        copy_rows(out, vectors::gen::op_out_rows(&self.f, input, &NoFault), stages);
    }
    fn batch(&self, input: &[u64], out: &mut [u64]) {
        for (row, o) in input.chunks_exact(3).zip(out.chunks_exact_mut(2)) {
            self.eval(row, o, None, None);
        }
    }
}

struct TraverseUnit<F: Format> {
    s: Slab<F>,
    hw: datapath::bvh::HwTree<Aabb<F::V>>,
    leaves: usize,
    /// Values in an output row (the expected file's fields).
    outputs: usize,
}

impl<F: Format + Send + Sync + 'static> Eval for TraverseUnit<F>
where
    F::V: Send + Sync,
{
    fn eval(
        &self,
        input: &[u64],
        out: &mut [u64],
        stages: Option<&mut Vec<u64>>,
        names: Option<&mut Vec<(String, u32)>>,
    ) {
        if let Some(n) = names {
            n.clear();
        }
        if let Some(s) = stages {
            s.clear();
        }
        out.copy_from_slice(&vectors::traverse::ray_row(&self.s, &self.hw, self.leaves, input, &NoFault));
    }
    fn batch(&self, input: &[u64], out: &mut [u64]) {
        for (row, o) in input.chunks_exact(8).zip(out.chunks_exact_mut(self.outputs)) {
            self.eval(row, o, None, None);
        }
    }
}

/// One model in one format with its options (immutable: share it across threads freely).
pub struct Unit {
    /// The unit.
    pub kind: Kind,
    /// The format's canonical name.
    pub format: String,
    /// Bits of one encoding.
    pub width: u32,
    /// The stage signals' names, in the order of the vector set's stage file (none for op).
    pub stage_names: Vec<String>,
    /// Each stage signal's bits (1 for a flag, the format's width for a register).
    pub stage_widths: Vec<u32>,
    /// The same names, NUL-terminated (for C).
    pub stage_cnames: Vec<std::ffi::CString>,
    /// False for the directed slab variant, whose signal set depends on the data (no stage
    /// file either): its stage signals are not offered.
    pub has_stages: bool,
    /// Each output's bits (1 for a flag, the format's width for a value, the field's width in
    /// the set for traverse).
    pub output_widths: Vec<u32>,
    /// Each output's name (the expected file's field names).
    pub output_names: Vec<String>,
    /// The vector sets of this unit, format and options (`None`: the traverse unit, whose
    /// sets depend on a tree): what defines its coverage model.
    pub request: Option<vectors::gen::Request>,
    /// The format's conversions.
    codec: Box<dyn Codec>,
    eval: Box<dyn Eval>,
}

/// The options a unit takes, as the CLI spells them.
#[derive(Default)]
struct Options {
    cull: bool,
    det_threshold: f64,
    tie: Option<TieRule>,
    variant: Option<String>,
}

fn parse_options(s: &str) -> Result<Options, String> {
    let mut o = Options::default();
    let mut it = s.split_whitespace();
    while let Some(w) = it.next() {
        let mut value = |name: &str| it.next().ok_or_else(|| format!("option {name} needs a value"));
        match w {
            "--cull" => o.cull = true,
            "--det-threshold" => {
                let v = value(w)?;
                o.det_threshold = v.parse().map_err(|_| format!("--det-threshold: not a number: {v}"))?;
                if !(o.det_threshold >= 0.0 && o.det_threshold.is_finite()) {
                    return Err(format!("--det-threshold must be a finite number >= 0, got {v}"));
                }
            }
            "--tie" => {
                o.tie = Some(match value(w)? {
                    "first" => TieRule::First,
                    "last" => TieRule::Last,
                    v => return Err(format!("--tie: first or last, got {v}")),
                })
            }
            "--variant" => o.variant = Some(value(w)?.to_string()),
            _ => {
                return Err(format!(
                    "unknown option {w} (the unit options are --cull, --det-threshold X, --tie first|last, --variant V)"
                ))
            }
        }
    }
    Ok(o)
}

impl Unit {
    /// The unit named `unit` (rti, slab or op) in format `format` (e.g. `f32`, `e8m16:ftz`,
    /// `q8.24:divide`) with `options` (the CLI's flags: `--cull`, `--det-threshold X`,
    /// `--tie first|last` for rti; `--variant V` for slab).
    pub fn new(unit: &str, format: &str, options: &str) -> Result<Self, String> {
        let kind = match unit {
            "rti" => Kind::Rti,
            "slab" => Kind::Slab,
            "op" => Kind::Op,
            "traverse" => {
                return Err("the traverse unit runs over a set's tree: open the set (rp_traverse_open)".into())
            }
            _ => return Err(format!("unknown unit {unit:?}: rti, slab or op")),
        };
        let any: AnyFormat = format.parse().map_err(|e| format!("format {format:?}: {e}"))?;
        let o = parse_options(options)?;
        let rti_only = o.cull || o.det_threshold != 0.0 || o.tie.is_some();
        if kind != Kind::Rti && rti_only {
            return Err("--cull, --det-threshold and --tie are options of the rti unit".into());
        }
        if kind != Kind::Slab && o.variant.is_some() {
            return Err("--variant is an option of the slab unit".into());
        }
        let (name, width) = with_format!(&any, |f| (f.name(), f.width()));
        let cfg = RtiConfig {
            cull: if o.cull { Cull::Backface } else { Cull::TwoSided },
            det_threshold: o.det_threshold,
            tie: o.tie.unwrap_or(TieRule::First),
        };
        let eval: Box<dyn Eval> = match kind {
            Kind::Rti => {
                with_format!(any, |f| Box::new(RtiUnit { rti: Rti::new(f, cfg) }))
            }
            Kind::Slab => {
                let v = o.variant.as_deref().unwrap_or("plain");
                with_format!(any, |f| {
                    let cfg = SlabConfig::named_for(v, &f)?;
                    Box::new(SlabUnit { s: Slab::new(f, cfg) })
                })
            }
            Kind::Op => with_format!(any, |f| Box::new(OpUnit { f })),
            Kind::Traverse => return Err("the traverse unit runs over a set's tree: open the set".into()),
        };
        let has_stages = kind != Kind::Slab || o.variant.as_deref() != Some("directed");
        let (output_widths, names): (Vec<u32>, &[&str]) = match kind {
            Kind::Rti => (vec![1, 1, width, width, width], &["valid", "hit", "t", "u", "v"]),
            Kind::Slab => (vec![1, width, width], &["hit", "t_near", "t_far"]),
            _ => (vec![width, 1], &["result", "cmp"]),
        };
        let output_names = names.iter().map(|n| n.to_string()).collect();
        let mut request = vectors::gen::Request::new(
            match kind {
                Kind::Rti => vectors::gen::Unit::Rti,
                Kind::Slab => vectors::gen::Unit::Slab,
                _ => vectors::gen::Unit::Op,
            },
            any,
        );
        request.rti = cfg;
        request.slab_variant = o.variant.clone().unwrap_or_else(|| "plain".into());
        let mut u = Unit {
            kind,
            format: name,
            width,
            stage_names: Vec::new(),
            stage_widths: Vec::new(),
            stage_cnames: Vec::new(),
            has_stages,
            output_widths,
            output_names,
            request: Some(request),
            codec: with_format!(any, |f| Box::new(f) as Box<dyn Codec>),
            eval,
        };
        let (zero, mut out, mut names) = (vec![0u64; kind.inputs()], vec![0u64; u.outputs()], Vec::new());
        if has_stages {
            u.eval.eval(&zero, &mut out, None, Some(&mut names));
        }
        u.stage_cnames = names.iter().map(|(n, _)| std::ffi::CString::new(n.as_str()).unwrap_or_default()).collect();
        u.stage_widths = names.iter().map(|&(_, w)| w).collect();
        u.stage_names = names.into_iter().map(|(n, _)| n).collect();
        Ok(u)
    }

    /// Checks one input row: its length, every encoding within the format's width, an op
    /// code 0..=5.
    pub fn check_row(&self, row: &[u64]) -> Result<(), String> {
        if row.len() != self.kind.inputs() {
            return Err(format!(
                "an input row of the {:?} unit has {} values, not {}",
                self.kind,
                self.kind.inputs(),
                row.len()
            ));
        }
        for (i, &b) in row.iter().enumerate() {
            if self.kind == Kind::Op && i == 0 {
                if b > 5 {
                    return Err(format!("op code {b}: 0 add, 1 sub, 2 mul, 3 div, 4 lt, 5 le"));
                }
            } else {
                self.check_bits(b).map_err(|e| format!("input {i}: {e}"))?;
            }
        }
        Ok(())
    }

    /// An encoding of the format: no bits above its width.
    pub fn check_bits(&self, b: u64) -> Result<(), String> {
        match self.width < 64 && b >> self.width != 0 {
            true => Err(format!("{b:#x} has bits above the format's {} bits", self.width)),
            false => Ok(()),
        }
    }

    /// Values in an output row.
    pub fn outputs(&self) -> usize {
        self.output_widths.len()
    }

    /// The bits of output `i` (1 for a flag, the format's width for a value), if in range.
    pub fn output_width(&self, i: usize) -> Option<u32> {
        self.output_widths.get(i).copied()
    }

    /// The traverse unit of the vector set in `dir` (unit traverse): its format, slab variant,
    /// N and tree, the tree read from the set's BRAM images; every file is checked against the
    /// manifest's sha256 and every address word against the next level's rows.
    pub fn open_set(dir: &std::path::Path) -> Result<Self, String> {
        let path = dir.join("manifest.json");
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let m: vectors::manifest::Manifest =
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        if m.unit != "traverse" {
            return Err(format!("{} is a set of unit {}, not traverse", dir.display(), m.unit));
        }
        let contents = vectors::read::read_files(dir, &m)?;
        let (root, images) = vectors::read::tree_images(&m, &contents)?;
        let banks: Vec<_> = images.into_iter().map(|(a, b)| (a.clone(), b.clone())).collect();
        let leaves = m.params.get("leaves").copied().ok_or("manifest.json: params has no leaves")? as usize;
        let variant = m.options.get("variant").map_or("plain", |s| s.as_str()).to_string();
        let any: AnyFormat = m.format.parse().map_err(|e| format!("manifest.json: format {}: {e}", m.format))?;
        let expected =
            m.files.iter().find(|f| f.name == "traverse_expected.hex").ok_or("the set has no traverse_expected.hex")?;
        let output_widths: Vec<u32> = expected.fields.iter().map(|f| f.width).collect();
        let output_names: Vec<String> = expected.fields.iter().map(|f| f.name.clone()).collect();
        let (name, width) = with_format!(&any, |f| (f.name(), f.width()));
        let eval: Box<dyn Eval> = with_format!(any, |f| {
            let s = Slab::new(f, SlabConfig::named(&variant)?);
            let hw = vectors::traverse::tree_from_images(&s, root, &banks)?;
            Box::new(TraverseUnit { s, hw, leaves, outputs: output_names.len() })
        });
        let u = Unit {
            kind: Kind::Traverse,
            format: name,
            width,
            stage_names: Vec::new(),
            stage_widths: Vec::new(),
            stage_cnames: Vec::new(),
            has_stages: false,
            output_widths,
            output_names,
            request: None,
            codec: with_format!(any, |f| Box::new(f) as Box<dyn Codec>),
            eval,
        };
        // the tree and N must give rows of the set's width
        let mut out = vec![0u64; u.outputs()];
        let probe =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| u.eval.eval(&[0; 8], &mut out, None, None)));
        if probe.is_err() {
            return Err("the set's tree does not give rows of its traverse_expected.hex layout".into());
        }
        Ok(u)
    }

    /// The format's encoding of `x`, rounded as the format's conversion from binary64 rounds.
    pub fn encode(&self, x: f64) -> u64 {
        self.codec.encode(x)
    }

    /// The value of encoding `bits` as binary64 (exact for every format of at most 53
    /// significant bits); an error when `bits` is not an encoding of the format.
    pub fn decode(&self, bits: u64) -> Result<f64, String> {
        self.check_bits(bits)?;
        Ok(self.codec.decode(bits))
    }

    /// f32 RTI tests from columns: `cols` holds the 17 input columns of `n` tests one after the
    /// other (in the order of the input row); the outputs go to `valid`, `hit`, `t`, `u`, `v`
    /// (n each). The columns stream through the binary32 kernels in L1-sized chunks: the
    /// layout the kernels read, no per-row conversion. An error for a unit that is not f32 RTI
    /// or lengths that do not fit.
    pub fn rti_columns_f32(
        &self,
        cols: &[f32],
        valid: &mut [bool],
        hit: &mut [bool],
        t: &mut [f32],
        u: &mut [f32],
        v: &mut [f32],
    ) -> Result<(), String> {
        let rti = self.eval.rti_f32().ok_or("columnar batches run rti units in f32")?;
        let n = valid.len();
        if cols.len() != 17 * n || [hit.len(), t.len(), u.len(), v.len()].iter().any(|&l| l != n) {
            return Err(format!("{} column values and outputs of {n}: not 17 columns of {n}", cols.len()));
        }
        let col = |k: usize| &cols[k * n..(k + 1) * n];
        let (mut rays, mut tris) = (RaysSoa::<f32>::with_capacity(CHUNK), TrisSoa::<f32>::with_capacity(CHUNK));
        let mut hits = HitsSoa::<f32>::with_len(CHUNK);
        let mut start = 0;
        while start < n {
            let end = (start + CHUNK).min(n);
            let fill = |dst: &mut Vec<f32>, k: usize| {
                dst.clear();
                dst.extend_from_slice(&col(k)[start..end]);
            };
            for a in 0..3 {
                fill(&mut rays.o[a], a);
                fill(&mut rays.d[a], 3 + a);
                for j in 0..3 {
                    fill(&mut tris.v[j][a], 8 + 3 * j + a);
                }
            }
            fill(&mut rays.tmin, 6);
            fill(&mut rays.tmax, 7);
            hits.resize(end - start);
            datapath::simd::rti_batch_f32(rti, &rays, &tris, &mut hits);
            valid[start..end].copy_from_slice(&hits.valid);
            hit[start..end].copy_from_slice(&hits.hit);
            t[start..end].copy_from_slice(&hits.t);
            u[start..end].copy_from_slice(&hits.u);
            v[start..end].copy_from_slice(&hits.v);
            start = end;
        }
        Ok(())
    }

    /// One row's outputs and, when `stages` is given, its stage signals (the row is checked).
    pub fn eval(&self, row: &[u64], out: &mut [u64], stages: Option<&mut Vec<u64>>) -> Result<(), String> {
        self.check_row(row)?;
        self.eval.eval(row, out, stages, None);
        Ok(())
    }

    /// The outputs of `n` rows (`input`: n × inputs, `out`: n × outputs, row-major), every row
    /// checked first.
    pub fn batch(&self, input: &[u64], out: &mut [u64]) -> Result<(), String> {
        let (ni, no) = (self.kind.inputs(), self.outputs());
        if !input.len().is_multiple_of(ni) {
            return Err(format!("{} values are not whole rows of {ni}", input.len()));
        }
        let rows = input.len() / ni;
        if out.len() != rows * no {
            return Err(format!("{rows} input rows take {} outputs, got room for {}", rows * no, out.len()));
        }
        // the fast check (an OR over the encodings, op codes apart); the slow one names the row
        let w = self.width.min(63);
        let bad = match self.kind {
            Kind::Op => input.chunks_exact(3).any(|r| r[0] > 5 || (r[1] | r[2]) >> w != 0),
            _ => input.iter().fold(0, |a, &b| a | b) >> w != 0,
        };
        if bad && self.width < 64 {
            for (k, row) in input.chunks(ni).enumerate() {
                self.check_row(row).map_err(|e| format!("row {k}: {e}"))?;
            }
        }
        self.eval.batch(input, out);
        Ok(())
    }
}
