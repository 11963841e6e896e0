//! The coverage model's reference (`docs/coverage-model.md`), generated from the model itself
//! ([`vectors::cover::Coverage::model`] of the sets the generator writes), so that it cannot
//! drift from it: every coverpoint of every unit with its bins, and each bin the model marks
//! unreachable with its reason.

use crate::scene::Scene;
use datapath::rti::RtiConfig;
use datapath::AnyFormat;
use vectors::cover::Coverage;
use vectors::gen::{generate, Request, Unit};

/// The sets whose coverage models the reference lists: (title, unit, format, slab variant).
pub const MODELS: [(&str, Unit, &str, &str); 9] = [
    ("rti, fp16 (reciprocal then multiply)", Unit::Rti, "fp16", "plain"),
    ("rti, fp16:divide", Unit::Rti, "fp16:divide", "plain"),
    ("slab plain, fp16", Unit::Slab, "fp16", "plain"),
    ("slab conservative, fp16", Unit::Slab, "fp16", "conservative"),
    ("slab embree, fp16", Unit::Slab, "fp16", "embree"),
    ("op, fp16", Unit::Op, "fp16", "plain"),
    ("capture, fp16", Unit::Capture, "fp16", "plain"),
    ("traverse, fp16 (built-in scene, N = 4)", Unit::Traverse, "fp16", "plain"),
    ("rti, q8.24 (fixed point)", Unit::Rti, "q8.24", "plain"),
];

fn request(unit: Unit, format: &str, variant: &str, scene: &Scene) -> Result<Request, String> {
    let tree = (unit == Unit::Traverse).then(|| {
        let b = crate::bvh::build(scene, 4);
        vectors::traverse::TreeInput { name: scene.name.clone(), nodes: b.nodes, root: 0 }
    });
    Ok(Request {
        unit,
        format: format.parse::<AnyFormat>()?,
        count: 1,
        seed: 1,
        level: 1,
        threads: 1,
        command: "raypipe vectors".into(),
        rti: RtiConfig::default(),
        slab_variant: variant.into(),
        tree,
        leaves: 4,
        max_levels: 64,
        explicit: None,
        closure: None,
    })
}

/// The reference as Markdown.
pub fn coverage_reference() -> Result<String, String> {
    let scene = Scene::builtin();
    let mut out = String::from(
        "# The coverage model, coverpoint by coverpoint\n\n\
         Generated from the coverage model itself (`src/cover_reference.rs`; \
         `RAYPIPE_BLESS_DOCS=1 cargo test --release --test docs` rewrites it, and the test fails \
         when it is stale). The bins of each kind and how a row is counted are in \
         [Functional coverage](coverage.md). Each unit is listed for one format; another format \
         changes the value-class bins (fixed point: 7 bins) and the reasons that depend on the \
         format (flush-to-zero, the NaN rule), as the reasons below say.\n\n",
    );
    let mut reasons: Vec<&'static str> = Vec::new();
    let mut sections = String::new();
    for (title, unit, format, variant) in MODELS {
        let set = generate(&request(unit, format, variant, &scene)?)?;
        let c = Coverage::model(&set.manifest);
        let (_, reachable) = c.totals();
        let all: usize = c.coverpoints.iter().map(|p| p.bins.len()).sum();
        sections += &format!(
            "## {title}\n\n{} coverpoints, {all} bins, {reachable} reachable (`raypipe vectors --unit {} --format {format}{}`).\n\n\
             | file | signal | stage | kind | bins | unreachable (reason) |\n|---|---|---|---|---|---|\n",
            c.coverpoints.len(),
            set.manifest.unit,
            if unit == Unit::Slab { format!(" --variant {variant}") } else { String::new() }
        );
        for p in &c.coverpoints {
            let mut un = Vec::new();
            for b in &p.bins {
                if let Some(r) = b.unreachable {
                    let k = match reasons.iter().position(|x| *x == r) {
                        Some(k) => k,
                        None => {
                            reasons.push(r);
                            reasons.len() - 1
                        }
                    };
                    un.push(format!("`{}` R{}", b.name, k + 1));
                }
            }
            let bins = if p.kind == "class" {
                format!("{} classes", p.bins.len())
            } else {
                p.bins.iter().map(|b| format!("`{}`", b.name)).collect::<Vec<_>>().join(" ")
            };
            sections += &format!(
                "| {} | {} | {} | {} | {} | {} |\n",
                p.role,
                p.signal.replace('|', "\\|"),
                p.stage.map_or("-".into(), |s| s.to_string()),
                p.kind,
                bins,
                un.join(", ")
            );
        }
        sections += "\n";
    }
    out += "## The reasons\n\nA bin marked unreachable is left out of the totals. Every reason is checked: a set \
            whose rows hit a bin marked unreachable is an error (\"the coverage model is wrong\"), and the \
            closure's search (`vectors --close`) hunts for such rows in every format the tests close \
            (`vectors/tests/cover.rs`).\n\n";
    for (k, r) in reasons.iter().enumerate() {
        out += &format!("- **R{}**: {r}\n", k + 1);
    }
    out += "\n";
    out += &sections;
    Ok(out)
}
