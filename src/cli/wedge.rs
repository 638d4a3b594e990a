//! `lookdev wedge`: a look rendered once per value of a parameter, in labelled rows; with
//! `--param all`, one row per parameter, as in figure 16 of Burley's 2012 notes.

use super::inputs::{self, DisplayArgs, LightingArgs};
use super::progress::Progress;
use crate::material::params::{check, Param, Value};
use crate::material::Look;
use crate::render::batch::Batch;
use crate::render::scene::Scene;
use crate::render::sheet;
use crate::{Error, Result};
use clap::Args;
use std::path::PathBuf;

/// The most values a wedge renders a row of (`--values`).
const MAX_VALUES: usize = 64;

#[derive(Args, Debug)]
pub struct WedgeArgs {
    /// The parameter to vary, or "all" for one row per parameter.
    #[arg(long)]
    pub param: String,
    /// The values, comma-separated (default 0, 0.1, …, 1). For base_color each is a grey level.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub values: Vec<f32>,
    /// The look to vary (default: one material, BRDF Explorer's default gold-ish base colour,
    /// lit as the built-in default look).
    #[arg(long, value_name = "FILE.toml")]
    pub look: Option<PathBuf>,
    #[command(flatten)]
    pub lighting: LightingArgs,
    #[command(flatten)]
    pub display: DisplayArgs,
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Choose a BRDF model variant over the look's [model], as render's --model (repeatable).
    #[arg(long = "model", value_name = "KEY=VALUE")]
    pub model: Vec<String>,
    /// Side of each render in pixels.
    #[arg(long, default_value_t = 128)]
    pub size: u32,
    #[arg(long, value_name = "NAME")]
    pub device: Option<String>,
    #[arg(long, short)]
    pub quiet: bool,
    #[arg(long, value_name = "FILE.png")]
    pub out: PathBuf,
}

/// BRDF Explorer's default base colour (0.82, 0.67, 0.16), linearised with its 2.2 gamma: the
/// material of Burley's figure 16.
pub const FIGURE_16_BASE_COLOR: [f32; 3] = [0.646235, 0.414347, 0.017745];

/// One material of [`FIGURE_16_BASE_COLOR`], lit as the built-in default look lights the ball.
fn default_look() -> Look {
    let mut look = Look::default_material();
    look.objects[0].layers[0].params.base_color = FIGURE_16_BASE_COLOR;
    look.environment = Look::builtin_default().environment;
    look
}

/// A parameter whose effect only shows when another is on: sheen_tint tints the sheen and
/// clearcoat_gloss shapes the clearcoat. Where the look has the other at 0, the row turns it to 1
/// (and its title says so), as Burley's figure does.
fn enabler(param: Param) -> Option<Param> {
    match param {
        Param::SheenTint => Some(Param::Sheen),
        Param::ClearcoatGloss => Some(Param::Clearcoat),
        _ => None,
    }
}

fn value_label(v: f32) -> String {
    let text = format!("{v:.3}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

pub fn run(args: WedgeArgs) -> Result<()> {
    crate::render::output::require_png(&args.out)?;
    let params: Vec<Param> = match args.param.as_str() {
        "all" => Param::ALL.to_vec(),
        name => vec![Param::from_name(name).ok_or_else(|| {
            let names: Vec<&str> = std::iter::once("all").chain(Param::ALL.map(Param::name)).collect();
            Error::input(format!("--param {name}: {}", crate::suggest::unknown("parameter", name, "", &names)))
        })?],
    };
    let values = if args.values.is_empty() { (0..=10).map(|i| i as f32 / 10.0).collect() } else { args.values.clone() };
    if values.len() > MAX_VALUES {
        return Err(Error::input(format!(
            "--values: {} values, more than the {MAX_VALUES} a wedge shows",
            values.len()
        )));
    }
    for &param in &params {
        for &v in &values {
            let value = if param.is_color() { Value::Color([v; 3]) } else { Value::Scalar(v) };
            check(param, value).map_err(|e| Error::input(format!("--values: {e}")))?;
        }
    }
    if args.spp == 0 {
        return Err(Error::input("--spp 0: the sample count must be at least 1"));
    }
    if !(16..=2048).contains(&args.size) {
        return Err(Error::input(format!("--size {}: renders must be 16 to 2048 pixels", args.size)));
    }
    let look = match &args.look {
        Some(path) => Look::load(path)?,
        // The default look's light, unless another environment is given.
        None if args.lighting.env.is_some() => Look { environment: Default::default(), ..default_look() },
        None => default_look(),
    };
    let Scene { gbuffer, gbuffer_name, look, environment, settings, backdrop, .. } =
        Scene::load(&inputs::ball_spec(look, &args.lighting, &args.display, args.spp, &args.model, args.size))?;
    let ctx = super::context(args.device.clone())?;
    let counter = ctx.validation_counter();
    let rows = {
        let mut batch = Batch::new(&ctx, &gbuffer, &gbuffer_name, &environment)?;
        batch.set_backdrop(&backdrop)?;
        let mut progress = Progress::new((params.len() * values.len()) as u64, "wedge", args.quiet);
        let mut rows = Vec::new();
        for &param in &params {
            // Every object is reached: the wedge's value is set on every layer, so the look
            // needs a stack for every object, as `--set` gives it one.
            let mut row_look = look.clone();
            row_look.ensure_default_stack();
            let mut title = param.name().to_string();
            if let Some(other) = enabler(param) {
                let off =
                    row_look.objects.iter().flat_map(|o| &o.layers).all(|l| l.params.get(other) == Value::Scalar(0.0));
                if off {
                    row_look.set_everywhere(other, Value::Scalar(1.0)).map_err(Error::input)?;
                    title = format!("{title} ({other} 1)");
                }
            }
            let mut cells = Vec::new();
            for &v in &values {
                let mut variant = row_look.clone();
                let value = if param.is_color() { Value::Color([v; 3]) } else { Value::Scalar(v) };
                variant.set_everywhere(param, value).map_err(Error::input)?;
                batch.render(&variant, &settings, |_| {})?;
                let pixels = batch.display(&settings)?;
                let image = image::RgbaImage::from_raw(args.size, args.size, pixels).expect("size matches");
                cells.push((value_label(v), image));
                progress.update((rows.len() * values.len() + cells.len()) as u64);
            }
            rows.push((title, cells));
        }
        progress.finish();
        rows
    };
    drop(ctx);
    super::check_validation(&counter)?;
    let image = sheet::rows(&rows);
    crate::render::output::write_png_image(&args.out, &image)?;
    if !args.quiet {
        eprintln!(
            "lookdev: wrote {} ({} × {} renders, {}x{})",
            args.out.display(),
            rows.len(),
            values.len(),
            image.width(),
            image.height()
        );
    }
    Ok(())
}
