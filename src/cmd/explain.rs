//! `raypipe explain`: print every stage signal of one ray–triangle (or ray–box) test beside the references.

use super::prelude::*;

/// The options of `raypipe explain`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Unit: rti or slab.
    #[arg(long, default_value = "rti")]
    pub unit: String,
    /// Format name.
    #[arg(long, value_parser = parse_format)]
    pub format: AnyFormat,
    /// Ray: ox,oy,oz,dx,dy,dz.
    #[arg(long, allow_hyphen_values = true)]
    pub ray: String,
    /// Triangle (unit rti): x0,y0,z0,x1,y1,z1,x2,y2,z2.
    #[arg(long, allow_hyphen_values = true)]
    pub tri: Option<String>,
    /// Box (unit slab): minx,miny,minz,maxx,maxy,maxz.
    #[arg(long = "box", allow_hyphen_values = true)]
    pub aabb: Option<String>,
    /// Slab variant: plain, conservative, directed, take-on-false, embree.
    #[arg(long, default_value = "plain")]
    pub variant: String,
    /// Smallest accepted t.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub tmin: f64,
    /// Largest accepted t.
    #[arg(long, default_value_t = f64::INFINITY, allow_hyphen_values = true)]
    pub tmax: f64,
    #[command(flatten)]
    pub rti: RtiArgs,
    /// Print the trace as JSON (every signal's value and bits, the references, the verdict).
    #[arg(long)]
    pub json: bool,
    /// Run the RTI model with this fault of the bank (as `verify --inject`).
    #[arg(long)]
    pub inject: Option<String>,
    /// Slab variant changes (a mutant, as `raypipe prove` refutes them).
    #[command(flatten)]
    pub mutation: SlabMutation,
}

/// Runs `raypipe explain`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { unit, format, ray, tri, aabb, variant, tmin, tmax, rti, json, inject, mutation } = a;
    let cfg = rti.config()?;
    let inject = inject.as_deref().map(rti_fault).transpose()?;
    if inject.is_some() && unit != "rti" {
        return Err("--inject: explain injects RTI faults (--unit rti)".into());
    }
    let r = parse_list("--ray", &ray, 6)?;
    check_interval(tmin, tmax)?;
    let ray = Ray64 { o: [r[0], r[1], r[2]], d: [r[3], r[4], r[5]], tmin, tmax };
    match unit.as_str() {
        "rti" => {
            let t = parse_list("--tri", tri.as_deref().ok_or("--unit rti needs --tri")?, 9)?;
            let tri = Tri64 { v: [[t[0], t[1], t[2]], [t[3], t[4], t[5]], [t[6], t[7], t[8]]] };
            let t = with_format!(format, |f| raypipe::explain::trace_rti_faulty(&Rti::new(f, cfg), &ray, &tri, inject));
            emit(json, &t, raypipe::explain::render_rti)?;
        }
        "slab" => {
            let b = parse_list("--box", aabb.as_deref().ok_or("--unit slab needs --box")?, 6)?;
            let (lo, hi) = ([b[0], b[1], b[2]], [b[3], b[4], b[5]]);
            let t = with_format!(format, |f| {
                let sc = mutation.apply(SlabConfig::named_for(&variant, &f)?);
                raypipe::explain::trace_slab(&Slab::new(f, sc), &variant, &ray, lo, hi)
            })?;
            emit(json, &t, raypipe::explain::render_slab)?;
        }
        other => return Err(format!("unknown unit '{other}'; units: rti, slab")),
    }
    Ok(Outcome::Pass)
}
