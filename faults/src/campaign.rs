//! A fault campaign: every fault of the bank for a unit, injected into the stage model, run on
//! every input row of a vector set; a fault is detected when some vector's outputs (rti:
//! valid, hit, t, u, v; slab: hit, t_near, t_far; capture: hit, t, u, v, id; op: result, cmp;
//! traverse: count,
//! leaves and the final history, its implementation-defined passes and box tests left out), or
//! with probes any stage signal, differ from
//! the set's expected rows. The set must first match the fault-free model (else the campaign
//! would measure another model).

use crate::bank::{Spec, BANK};
use crate::inject::Injected;
use datapath::fault::{Fault, NoFault};
use datapath::rti::Rti;
use datapath::slab::Slab;
use datapath::{with_format, AnyFormat, Format};
use serde::Serialize;
use vectors::gen::{rti_case_of, rti_out_rows, slab_out_rows};
use vectors::manifest::Manifest;

/// What the campaign found for one fault.
#[derive(Clone, Debug, Serialize)]
pub struct Outcome {
    /// The fault's name.
    pub name: &'static str,
    /// The site it changes.
    pub site: &'static str,
    /// The RTL bug it stands for.
    pub what: &'static str,
    /// Its outputs equal the fault-free unit's on every input of this configuration.
    pub benign: bool,
    /// Why, when it is benign.
    pub benign_why: Option<&'static str>,
    /// The fault applies: its site exists in this unit's configuration and the fault is
    /// modelled in this format.
    pub applicable: bool,
    /// Why not, when it does not apply.
    pub not_applicable: Option<String>,
    /// Some vector detects it.
    pub detected: bool,
    /// How many vectors detect it.
    pub vectors: usize,
    /// The first detecting vector (0-based input row).
    pub first_vector: Option<usize>,
    /// Every detecting vector (0-based input rows, ascending).
    pub catching: Vec<usize>,
    /// That vector's coverage class.
    pub first_class: Option<String>,
    /// How many vectors of each class detect it (classes in the manifest's order).
    pub by_class: Vec<(String, usize)>,
    /// The coverage that mattered: the rarest bins of the set's coverage model the first
    /// detecting vector hits (at most [`FIRST_BINS`], fewest set vectors first; the class
    /// coverpoint aside), each as `role signal: bin (n of N vectors)`.
    pub first_bins: Vec<String>,
}

/// How many of the first detecting vector's rarest bins an outcome names.
pub const FIRST_BINS: usize = 3;

/// A whole campaign.
#[derive(Clone, Debug, Serialize)]
pub struct Campaign {
    /// Unit.
    pub unit: String,
    /// Format.
    pub format: String,
    /// The set's seed, level and command (from its manifest).
    pub set_seed: u64,
    /// The set's coverage level.
    pub set_level: u32,
    /// The command that wrote the set.
    pub set_command: String,
    /// Vectors run.
    pub vectors: usize,
    /// Only the outputs compared (a DUT without probe ports).
    pub outputs_only: bool,
    /// One outcome per fault of the unit's bank.
    pub faults: Vec<Outcome>,
    /// Applicable non-benign faults detected.
    pub detected: usize,
    /// Applicable non-benign faults no vector detects.
    pub escaped: usize,
}

impl Campaign {
    /// Every applicable non-benign fault is detected.
    pub fn complete(&self) -> bool {
        self.escaped == 0
    }
}

/// The units with fault models.
pub const UNITS: [&str; 5] = ["rti", "slab", "capture", "traverse", "op"];

/// The stage model of a set's unit.
enum Model<F: Format> {
    Rti(Rti<F>),
    Slab(Slab<F>),
    Capture(Rti<F>),
    Op(F),
    Traverse { slab: Slab<F>, tree: datapath::bvh::HwTree<datapath::slab::Aabb<F::V>>, leaves: usize },
}

impl<F: Format> Model<F> {
    /// The expected and stage rows of input row `bits` (without its class) with fault `x`.
    fn rows<X: Fault<F>>(&self, bits: &[u64], x: &X) -> [Vec<u64>; 2] {
        match self {
            Model::Rti(rti) => {
                let (ray, tri) = rti_case_of(&rti.fmt, bits);
                rti_out_rows(rti, &ray, &tri, x)
            }
            Model::Slab(slab) => slab_out_rows(slab, bits, x),
            Model::Capture(rti) => vectors::capture::out_rows(rti, bits, x),
            Model::Op(f) => vectors::gen::op_out_rows(f, bits, x),
            Model::Traverse { slab, tree, leaves } => {
                [vectors::traverse::ray_row(slab, tree, *leaves, bits, x), Vec::new()]
            }
        }
    }
}

/// Runs the bank of the set's unit over the set (`rows`: its files' rows in manifest order).
pub fn run(m: &Manifest, rows: &[Vec<Vec<u64>>], outputs_only: bool) -> Result<Campaign, String> {
    if !UNITS.contains(&m.unit.as_str()) {
        return Err(format!("unit {} has no fault models yet (units with a bank: {})", m.unit, UNITS.join(", ")));
    }
    let any: AnyFormat = m.format.parse().map_err(|e| format!("manifest.json: field format: {e}"))?;
    let variant = (m.unit == "slab").then(|| m.options.get("variant").map_or("plain", |v| v.as_str()));
    let bank: Vec<&Spec> = BANK.iter().filter(|s| s.unit == m.unit).collect();
    let (inputs, expected) = match rows {
        [i, e, ..] => (i, e),
        _ => return Err("the set has no input and expected files".into()),
    };
    // the stage file, when the unit has one (traverse has none)
    let no_stages = vec![Vec::new(); inputs.len()];
    let stages = m.files.iter().position(|f| f.role == vectors::hdl::STAGE_ROLE).map_or(&no_stages, |k| &rows[k]);
    /// When a field is compared.
    #[derive(Clone, Copy)]
    enum Rule {
        Always,
        Never,
        /// Only where the expected output row's field k is 1.
        When(usize),
    }
    // the fields the kit's testbenches compare, by the manifest's acceptance rules: a field
    // with care_when F only where F is 1 in the expected output row, an implementation-defined
    // field (the traverse unit's passes and box tests) never (only with +strict)
    let rules = |file: usize| -> Vec<Rule> {
        let out = &m.files[1].fields;
        m.files.get(file).map_or(Vec::new(), |fm| {
            fm.fields
                .iter()
                .map(|f| match (&f.care_when, f.implementation_defined) {
                    (_, true) => Rule::Never,
                    (Some(flag), _) => out.iter().position(|o| &o.name == flag).map_or(Rule::Always, Rule::When),
                    (None, false) => Rule::Always,
                })
                .collect()
        })
    };
    let stage_file = m.files.iter().position(|f| f.role == vectors::hdl::STAGE_ROLE);
    let (out_rules, stage_rules) = (rules(1), stage_file.map_or(Vec::new(), rules));
    let differ = |rules: &[Rule], got: &[u64], want: &[u64], want_out: &[u64]| {
        got.len() != want.len()
            || got.iter().zip(want).zip(rules).any(|((a, b), r)| {
                a != b
                    && match *r {
                        Rule::Always => true,
                        Rule::Never => false,
                        Rule::When(k) => want_out.get(k) == Some(&1),
                    }
            })
    };
    let class_name = |id: u64| m.classes.iter().find(|c| c.id as u64 == id).map_or(format!("{id}"), |c| c.name.clone());
    let mut outcomes: Vec<Outcome> = bank
        .iter()
        .map(|s| (s, s.benign.and_then(|b| b.applies(variant))))
        .map(|(s, why)| Outcome {
            name: s.name,
            site: s.site,
            what: s.what,
            benign: why.is_some(),
            benign_why: why,
            applicable: true,
            not_applicable: None,
            detected: false,
            vectors: 0,
            first_vector: None,
            catching: Vec::new(),
            first_class: None,
            by_class: m.classes.iter().map(|c| (c.name.clone(), 0)).collect(),
            first_bins: Vec::new(),
        })
        .collect();
    with_format!(any, |f| {
        let model = match m.unit.as_str() {
            "rti" => Model::Rti(Rti::new(f, vectors::read::rti_config_from(m)?)),
            "capture" => Model::Capture(vectors::read::capture_rti_from(f, m)),
            "op" => Model::Op(f),
            "traverse" => {
                let slab = Slab::new(f, vectors::read::slab_config_from(m)?);
                let (root, images) = vectors::read::tree_images(m, rows)?;
                let banks: Vec<_> = images.into_iter().map(|(a, b)| (a.clone(), b.clone())).collect();
                let tree = vectors::traverse::tree_from_images(&slab, root, &banks)?;
                let leaves = m.params.get("leaves").copied().ok_or("manifest has no leaves parameter")? as usize;
                Model::Traverse { slab, tree, leaves }
            }
            _ => Model::Slab(Slab::new(f, vectors::read::slab_config_from(m)?)),
        };
        let injected: Vec<Injected> = bank.iter().map(|s| Injected::new(s)).collect();
        for (i, input) in inputs.iter().enumerate() {
            let class = input[0];
            // the set is the fault-free model's
            if model.rows(&input[1..], &NoFault) != [&expected[i][..], &stages[i][..]] {
                return Err(format!(
                    "vector {} (input row {}): the set's expected rows differ from this raypipe's model; check the set with `raypipe vectors --check`",
                    i,
                    i + 1
                ));
            }
            for (x, o) in injected.iter().zip(outcomes.iter_mut()) {
                x.next_test();
                let [fo, fp] = model.rows(&input[1..], x);
                let e = &expected[i];
                if differ(&out_rules, &fo, e, e) || (!outputs_only && differ(&stage_rules, &fp, &stages[i], e)) {
                    o.vectors += 1;
                    o.catching.push(i);
                    if o.first_vector.is_none() {
                        o.first_vector = Some(i);
                        o.first_class = Some(class_name(class));
                    }
                    if let Some(c) = m.classes.iter().position(|c| c.id as u64 == class) {
                        o.by_class[c].1 += 1;
                    }
                }
            }
        }
        for (x, o) in injected.iter().zip(outcomes.iter_mut()) {
            o.detected = o.vectors > 0;
            if !x.reached() {
                o.applicable = false;
                o.not_applicable = Some("the site is not in this configuration's datapath".into());
            } else if x.inherent() {
                o.applicable = false;
                o.not_applicable =
                    Some(format!("{} flushes every subnormal result already: the fault is the datapath", m.format));
            } else if x.unmodelled() {
                o.applicable = false;
                o.not_applicable = Some(format!("not modelled in {}", m.format));
            }
        }
        Ok::<(), String>(())
    })?;
    // which coverage mattered: the first detecting vector's rarest bins in this set
    let cov = vectors::cover::Coverage::measure(m, rows)?;
    let row_bins = vectors::cover::RowBins::new(m).with_set(rows)?;
    let mut hits = Vec::new();
    for o in &mut outcomes {
        let Some(i) = o.first_vector else { continue };
        hits.clear();
        row_bins.hits(rows, i, &mut hits)?;
        let mut named: Vec<(u64, usize, String)> = hits
            .iter()
            .filter(|&&(p, _)| cov.coverpoints[p].kind != "class")
            .map(|&(p, b)| {
                let (cp, bin) = (&cov.coverpoints[p], &cov.coverpoints[p].bins[b]);
                (
                    bin.count,
                    p,
                    format!("{} {}: {} ({} of {} vectors)", cp.role, cp.signal, bin.name, bin.count, cov.vectors),
                )
            })
            .collect();
        named.sort_by_key(|&(n, p, _)| (n, p));
        o.first_bins = named.into_iter().take(FIRST_BINS).map(|x| x.2).collect();
    }
    let counted = |o: &&Outcome| o.applicable && !o.benign;
    Ok(Campaign {
        unit: m.unit.clone(),
        format: m.format.clone(),
        set_seed: m.seed,
        set_level: m.level,
        set_command: m.command.clone(),
        vectors: inputs.len(),
        outputs_only,
        detected: outcomes.iter().filter(counted).filter(|o| o.detected).count(),
        escaped: outcomes.iter().filter(counted).filter(|o| !o.detected).count(),
        faults: outcomes,
    })
}
