//! `lookdev bake`: a glTF asset rasterized into a g-buffer.

use super::progress::Progress;
use crate::asset::bake::{bake, BakeOptions, Step, MAX_SAMPLES};
use crate::asset::camera::{CameraChoice, DEFAULT_FOV, DEFAULT_PITCH, DEFAULT_YAW};
use crate::asset::Asset;
use crate::gpu::ContextOptions;
use crate::visibility::{self, Grid};
use crate::{Error, Result};
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct BakeArgs {
    /// The asset: a .gltf (with its buffers and images) or a .glb.
    #[arg(value_name = "MODEL.gltf|.glb")]
    pub model: PathBuf,
    #[arg(long, value_name = "GBUFFER.exr")]
    pub out: PathBuf,
    /// Width and height in pixels.
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [1024, 1024])]
    pub size: Vec<u32>,
    /// Look through the asset's camera of this name (the camera's or its node's). Without it
    /// or --auto-camera, the scene's first camera is used, else the scene is framed.
    #[arg(long, value_name = "NAME", conflicts_with = "auto_camera")]
    pub camera: Option<String>,
    /// Frame the scene's bounding sphere, even when the asset has cameras.
    #[arg(long)]
    pub auto_camera: bool,
    /// Framing direction: degrees about +Y, from +Z toward +X.
    #[arg(long, value_name = "DEG", requires = "auto_camera", allow_negative_numbers = true)]
    pub yaw: Option<f32>,
    /// Framing elevation: degrees above the horizon (the camera looks down), within ±89.
    #[arg(long, value_name = "DEG", requires = "auto_camera", allow_negative_numbers = true)]
    pub pitch: Option<f32>,
    /// Framing vertical field of view in degrees.
    #[arg(long, value_name = "DEG", requires = "auto_camera")]
    pub fov: Option<f32>,
    /// Samples per pixel for antialiased coverage, normals, masks and maps (1 to 1024).
    #[arg(long, default_value_t = 16)]
    pub samples: u32,
    /// Write the g-buffer at N times --size on each side, recording N, so that renders relight
    /// each pixel's surfaces apart and filter down to --size (edges and creases; 1 to 8).
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub supersample: u32,
    /// Each pixel's visibility, traced through the asset's triangles: the side of its grid of
    /// directions (8, 16, 32 or 64; 32 stores 1024 directions, 128 bytes a pixel), off, or auto:
    /// 64 up to half a megapixel, 32 above.
    #[arg(long, value_name = "SIDE|auto|off", default_value = "auto", value_parser = parse_visibility)]
    pub visibility: Visibility,
    /// Vulkan device to use: part of its name (lavapipe is "llvmpipe").
    #[arg(long, value_name = "NAME")]
    pub device: Option<String>,
    /// No progress bar or summary.
    #[arg(long, short)]
    pub quiet: bool,
}

/// `--visibility`: a grid, the one the image's size calls for, or none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Visibility {
    Side(Grid),
    Auto,
    Off,
}

impl Visibility {
    /// The grid for a g-buffer of `pixels` pixels.
    fn grid(self, pixels: usize) -> Option<Grid> {
        match self {
            Visibility::Side(grid) => Some(grid),
            Visibility::Auto => Some(Grid::new(visibility::default_side(pixels)).expect("a default side is a side")),
            Visibility::Off => None,
        }
    }
}

fn parse_visibility(text: &str) -> std::result::Result<Visibility, String> {
    match text {
        "off" => Ok(Visibility::Off),
        "auto" => Ok(Visibility::Auto),
        _ => {
            let side = text
                .parse::<u32>()
                .map_err(|_| format!("'{text}' is not a grid side ({}), auto or off", visibility::side_list()))?;
            Grid::new(side).map(Visibility::Side)
        }
    }
}

/// The flags' values, before anything is read.
pub fn check(args: &BakeArgs) -> Result<()> {
    if !(1..=MAX_SAMPLES).contains(&args.samples) {
        return Err(Error::input(format!("--samples {}: must be 1 to {MAX_SAMPLES}", args.samples)));
    }
    let max = crate::gbuffer::MAX_SUPERSAMPLE;
    if !(1..=max).contains(&args.supersample) {
        return Err(Error::input(format!("--supersample {}: must be 1 to {max}", args.supersample)));
    }
    Ok(())
}

pub fn run(args: BakeArgs) -> Result<()> {
    if !args.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
        return Err(Error::input_file(&args.out, "a g-buffer is written as an .exr file"));
    }
    if let Some(parent) = args.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(Error::input_file(&args.out, "the output folder does not exist"));
        }
    }
    let camera = match (&args.camera, args.auto_camera) {
        (Some(name), _) => CameraChoice::Named(name.clone()),
        (None, true) => CameraChoice::Frame {
            yaw_degrees: args.yaw.unwrap_or(DEFAULT_YAW),
            pitch_degrees: args.pitch.unwrap_or(DEFAULT_PITCH),
            fov_degrees: args.fov.unwrap_or(DEFAULT_FOV),
        },
        (None, false) => CameraChoice::Default,
    };
    let start = Instant::now();
    let asset = Asset::load(&args.model)?;
    let unsupported = asset.unsupported_extensions();
    if !unsupported.is_empty() {
        crate::warn(format!("{}: ignoring unsupported extensions: {}", args.model.display(), unsupported.join(", ")));
    }
    let (width, height) =
        (args.size[0].saturating_mul(args.supersample), args.size[1].saturating_mul(args.supersample));
    let options = BakeOptions {
        width,
        height,
        samples: args.samples,
        camera,
        visibility: args.visibility.grid(width as usize * height as usize),
    };

    let ctx = crate::gpu::Context::new(&ContextOptions { graphics: true, ..ContextOptions::from_env(args.device) })?;
    let counter = ctx.validation_counter();
    let device_name = ctx.info().name.clone();
    let mut gbuffer = {
        let mut current: Option<(Step, Progress)> = None;
        let gbuffer = bake(&ctx, &asset, &options, |step, done, total| {
            if current.as_ref().is_none_or(|(s, _)| *s != step) {
                if let Some((_, progress)) = current.take() {
                    progress.finish();
                }
                let (label, unit) = match step {
                    Step::Meshes => ("reading meshes", "primitives"),
                    Step::Passes => ("baking", "passes"),
                    Step::Visibility => ("tracing visibility", "steps"),
                };
                current = Some((step, Progress::counting(total as u64, label, unit, args.quiet)));
            }
            if let Some((_, progress)) = &mut current {
                progress.update(done as u64);
            }
        })?;
        if let Some((_, progress)) = current {
            progress.finish();
        }
        gbuffer
    };
    drop(ctx);
    super::check_validation(&counter)?;
    if gbuffer.coverage.iter().all(|&a| a == 0.0) {
        crate::warn(format!(
            "{}: the camera sees none of the asset, so no pixel of the g-buffer is covered (check the asset's scale and the camera)",
            args.model.display()
        ));
    }
    gbuffer.supersample = args.supersample;
    gbuffer.write(&args.out)?;
    if !args.quiet {
        let supersampled = match args.supersample {
            1 => String::new(),
            n => format!(", supersampled {n}x{n} for {}x{}", args.size[0], args.size[1]),
        };
        eprintln!(
            "lookdev: wrote {} ({}x{}{supersampled}, {} objects, {} masks, {} maps, {} samples, {:.2} s on {device_name})",
            args.out.display(),
            gbuffer.width,
            gbuffer.height,
            gbuffer.object_names.len(),
            gbuffer.masks.len(),
            gbuffer.maps().len(),
            args.samples,
            start.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
