//! `raypipe render`: render through the bit-accurate pipeline (slab traversal → RTI min-capture) and diff with the golden.

use super::prelude::*;

/// The options of `raypipe render`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// OBJ scene (default: the built-in scene).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Format of both units.
    #[arg(long, value_parser = parse_format, default_value = "f32")]
    pub format: AnyFormat,
    /// Slab variant: plain, conservative, directed, take-on-false, embree.
    #[arg(long, default_value = "plain")]
    pub variant: String,
    /// Image width.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub width: u32,
    /// Image height.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub height: u32,
    /// Triangles per leaf at most.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=255))]
    pub leaf_size: u32,
    /// Eye position X,Y,Z (default: the automatic view, which frames the scene's bounding box from in front, to the right and above, or stands inside an enclosed scene).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<[f64; 3]>,
    /// The point at the image centre X,Y,Z (default: the bounding box's centre).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub look_at: Option<[f64; 3]>,
    /// Up direction X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,1,0")]
    pub up: [f64; 3],
    /// Vertical field of view in degrees, in (0, 180).
    #[arg(long, default_value_t = 45.0, allow_hyphen_values = true)]
    pub fov: f64,
    /// Output directory for render.png and diff.png.
    #[arg(long, default_value = "render-out")]
    pub out: PathBuf,
    /// Print the counts as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `raypipe render`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { scene, format, variant, width, height, leaf_size, eye, look_at, up, fov, out, json } = a;
    with_format!(format, |f| SlabConfig::named_for(&variant, &f).map(|_| ()))?;
    let scene = load_scene(scene.as_deref())?;
    let auto = raypipe::camera::Camera::auto(&scene, fov, width as f64 / height as f64);
    let camera =
        raypipe::camera::Camera { eye: eye.unwrap_or(auto.eye), look_at: look_at.unwrap_or(auto.look_at), up, fov };
    camera.check()?;
    let dir = OutDir::check(&out, &raypipe::render::FILES)?;
    let rep = with_format!(format, |f| raypipe::render::render(
        f, &variant, &scene, &camera, width, height, leaf_size, &dir
    ))?;
    emit(json, &rep, |rep| {
        format!(
            "raypipe render: scene {}, format {}, slab variant {}: {} pixels, golden hits {}, holes (golden hit, pipeline miss) {}, false hits {}, other triangle {}; wrote {}/render.png and {}/diff.png (red: hole, blue: false hit, yellow: other triangle)",
            scene.name, rep.format, rep.variant, rep.pixels, rep.golden_hits, rep.holes, rep.false_hits, rep.other_triangle, out.display(), out.display()
        ) + &format!("\ncamera: --eye {} --look-at {} --up {} --fov {}", vec3(rep.camera.eye), vec3(rep.camera.look_at), vec3(rep.camera.up), rep.camera.fov) + &format!("\nboxes the slab unit culled on the way to the golden closest hit: {}{}\n", rep.culled,
            if rep.conservative { if rep.culled > 0 { " (VIOLATION: the variant is conservative in this format)" } else { " (the variant is conservative in this format: must be 0)" } } else { "" })
            + &rep.vacuous().map(|why| format!("culling check: INCONCLUSIVE: {why}\n")).unwrap_or_default()
    })?;
    Ok(rep.outcome())
}
