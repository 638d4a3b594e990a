//! The flags every rendering command shares: the g-buffer, lighting, sampling, display, and
//! `--set`, gathered in [`SceneArgs`] for `render`, `turntable` and `view`, and turned into
//! the [`SceneSpec`] that [`crate::render::scene::Scene::load`] reads.

use crate::environment::{EnvironmentRef, LoadOptions};
use crate::gbuffer::source::{Channels, SourceOptions, Up};
use crate::material::{Look, Param, Value};
use crate::render::scene::{GBufferSpec, LookSource, SceneSpec, MAX_BUILTIN_SIDE};
use crate::render::settings::Overrides;
use crate::shading::tonemap::Tonemap;
use crate::{Error, Result};
use clap::Args;
use std::path::{Path, PathBuf};

/// The flags `render`, `turntable` and `view` share, flattened into each.
#[derive(Args, Debug, Default)]
pub struct SceneArgs {
    #[command(flatten)]
    pub gbuffer: GBufferArgs,
    /// Override a parameter on every layer of every object, e.g. --set metallic=1.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    #[command(flatten)]
    pub lighting: LightingArgs,
    #[command(flatten)]
    pub sampling: SamplingArgs,
    #[command(flatten)]
    pub display: DisplayArgs,
    /// The built-in shader ball's size in pixels (default 1024 1024); not with --gbuffer.
    #[arg(long, num_args = 2, value_names = ["W", "H"])]
    pub size: Option<Vec<u32>>,
}

impl SceneArgs {
    /// The scene these flags describe with the look `look` (the default one if `None`) and
    /// the AOVs `aovs`.
    pub fn spec(&self, look: Option<&Path>, aovs: &[String], quiet: bool) -> Result<SceneSpec> {
        let size = self.builtin_size()?;
        Ok(SceneSpec {
            look: look.map_or(LookSource::Default, |path| LookSource::File(path.to_path_buf())),
            gbuffer: GBufferSpec { builtin_size: size, size_given: size.is_some(), ..self.gbuffer.spec()? },
            sets: parse_sets(&self.set)?,
            overrides: Overrides { aovs: aovs.to_vec(), ..overrides(&self.lighting, &self.sampling, &self.display) },
            env_options: self.lighting.load_options(),
            quiet,
        })
    }

    /// `--size W H`, checked: within [`MAX_BUILTIN_SIDE`], and only for the built-in scene.
    fn builtin_size(&self) -> Result<Option<(u32, u32)>> {
        let Some(size) = &self.size else { return Ok(None) };
        let [width, height] = size[..] else {
            return Err(Error::input("--size takes a width and a height, e.g. --size 1920 1080"));
        };
        if let Some(file) = &self.gbuffer.gbuffer {
            return Err(Error::input(format!(
                "--size {width} {height} sizes the built-in shader ball, but --gbuffer {} is rendered at its own size",
                file.display()
            )));
        }
        if !(1..=MAX_BUILTIN_SIDE).contains(&width) || !(1..=MAX_BUILTIN_SIDE).contains(&height) {
            return Err(Error::input(format!(
                "--size {width} {height}: each side must be 1 to {MAX_BUILTIN_SIDE} pixels"
            )));
        }
        Ok(Some((width, height)))
    }

    /// Refuses bad flags before anything is read: `--set`, the g-buffer's channel flags, and
    /// the look's settings as the flags (and `aovs`) override them.
    pub fn check(&self, aovs: &[String]) -> Result<()> {
        let spec = self.spec(None, aovs, true)?;
        crate::render::settings::Settings::resolve(&Look::default_material(), &spec.overrides).map(|_| ())
    }
}

/// The g-buffer and how to read it (docs/formats.md#production-renders).
#[derive(Args, Debug, Default, Clone)]
pub struct GBufferArgs {
    /// The g-buffer EXR to relight: lookdev's own, a Blender/Cycles multilayer EXR or Arnold-style
    /// AOVs (default: the look's [gbuffer] file, else the built-in shader ball, 1024x1024).
    #[arg(long, value_name = "FILE.exr")]
    pub gbuffer: Option<PathBuf>,
    /// The Blender view layer, or the part of a multi-part EXR, to read.
    #[arg(long, value_name = "NAME")]
    pub gbuffer_layer: Option<String>,
    /// The g-buffer's up axis: y (lookdev, Maya, Houdini, Arnold) or z (Blender); default: the
    /// source's own.
    #[arg(long, value_name = "y|z", value_parser = Up::parse)]
    pub up: Option<Up>,
    /// Where the camera was, in the g-buffer's own coordinates, for view vectors from positions
    /// when the file does not record it.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_point)]
    pub camera_position: Option<glam::Vec3>,
    /// Where one of lookdev's channels comes from in the g-buffer: ROLE is normal, position,
    /// view, tangent (layer names), coverage, id or mask (channel names), e.g.
    /// --gbuffer-channel normal=N_world. Repeatable; mask adds one each time.
    #[arg(long = "gbuffer-channel", value_name = "ROLE=NAME")]
    pub channels: Vec<String>,
    /// The g-buffer was written at N times the output's resolution on each side: every pixel is
    /// relit, then each N x N block averaged, so edges and creases are shaded surface by surface
    /// (default: the factor the file records, else 1; 1 to 8).
    #[arg(long, value_name = "N")]
    pub supersample: Option<u32>,
    /// Relight as if nothing stood between any surface and the sky, leaving out the g-buffer's
    /// visibility (its shadows and occlusion), for comparison.
    #[arg(long)]
    pub no_visibility: bool,
    /// The scene's triangles as glTF (.glb or .gltf, Y up, the g-buffer's units), to trace the
    /// shadows and occlusion of a production render from its positions (P or Position); by
    /// default, the file the header names (lookdev's Blender script writes one).
    #[arg(long, value_name = "FILE.glb")]
    pub occluders: Option<PathBuf>,
}

fn parse_point(text: &str) -> std::result::Result<glam::Vec3, String> {
    crate::gbuffer::source::camera::parse_vector(text).ok_or_else(|| format!("'{text}' is not three numbers X,Y,Z"))
}

impl GBufferArgs {
    /// The g-buffer file and how to read it, as the flags say.
    pub fn spec(&self) -> Result<GBufferSpec> {
        let mut channels = Channels::default();
        for text in &self.channels {
            let (role, name) = text.split_once('=').ok_or_else(|| {
                Error::input(format!("--gbuffer-channel {text}: expected ROLE=NAME, e.g. normal=N_world"))
            })?;
            channels.set(role.trim(), name).map_err(|e| Error::input(format!("--gbuffer-channel {text}: {e}")))?;
        }
        let source = SourceOptions {
            layer: self.gbuffer_layer.clone(),
            up: self.up,
            camera_position: self.camera_position,
            channels,
            occluders: self.occluders.clone(),
            no_visibility: false,
        };
        Ok(GBufferSpec {
            file: self.gbuffer.clone(),
            source,
            ignore_visibility: self.no_visibility,
            supersample: self.supersample,
            ..GBufferSpec::default()
        })
    }
}

/// The environment and how it lights the scene.
#[derive(Args, Debug, Default)]
pub struct LightingArgs {
    /// Equirectangular environment file, or a built-in's name (builtin:NAME, or NAME where no
    /// such file exists): studio, courtyard, city, interior, sunrise. Default: the look's, else
    /// the default built-in.
    #[arg(long, value_name = "FILE.exr|.hdr|NAME", value_parser = EnvironmentRef::parse)]
    pub env: Option<EnvironmentRef>,
    /// Environment rotation about +Y, in degrees.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub rotation: Option<f32>,
    /// Environment radiance scale.
    #[arg(long, value_name = "X")]
    pub intensity: Option<f32>,
    /// Environment radiance scale in stops: --intensity-stops 1 is --intensity 2.
    #[arg(long, value_name = "EV", allow_hyphen_values = true, conflicts_with = "intensity", value_parser = intensity_stops)]
    pub intensity_stops: Option<f32>,
    /// Show black (EXR: transparent) instead of the environment behind the objects.
    #[arg(long)]
    pub no_background: bool,
    /// Read an environment that is not 2:1 as equirectangular anyway.
    #[arg(long)]
    pub env_any_aspect: bool,
    /// Replace NaN, infinite and negative environment texels instead of refusing the file.
    #[arg(long)]
    pub env_clamp: bool,
}

impl LightingArgs {
    pub fn load_options(&self) -> LoadOptions {
        LoadOptions { any_aspect: self.env_any_aspect, clamp_invalid: self.env_clamp }
    }
}

/// Samples per pixel, the sequence's seed, and the BRDF model they estimate.
#[derive(Args, Debug, Default)]
pub struct SamplingArgs {
    /// Samples per pixel (each one environment and one BRDF sample).
    #[arg(long, value_name = "N")]
    pub spp: Option<u32>,
    #[arg(long, value_name = "N")]
    pub seed: Option<u32>,
    /// Choose a BRDF model variant over the look's [model], e.g. --model diffuse=oren-nayar
    /// (keys: diffuse, specular_d, specular_g, fresnel, gtr_gamma, energy_compensation).
    #[arg(long = "model", value_name = "KEY=VALUE")]
    pub model: Vec<String>,
    /// The estimator: compensated (default) or plain; both unbiased, they differ in noise
    /// (see `lookdev bench --convergence`).
    #[arg(long, value_name = "NAME", value_parser = crate::render::sampling::Sampling::parse)]
    pub sampling: Option<crate::render::sampling::Sampling>,
}

/// How linear radiance becomes PNG pixels.
#[derive(Args, Debug, Default)]
pub struct DisplayArgs {
    /// Exposure in stops, for PNG output.
    #[arg(long, value_name = "EV", allow_hyphen_values = true)]
    pub exposure: Option<f32>,
    /// PNG tone map: linear, neutral (Khronos PBR Neutral), aces or agx.
    #[arg(long, value_name = "NAME", value_parser = Tonemap::parse)]
    pub tonemap: Option<Tonemap>,
}

/// The command-line overrides of a look's settings.
fn overrides(lighting: &LightingArgs, sampling: &SamplingArgs, display: &DisplayArgs) -> Overrides {
    Overrides {
        environment: lighting.env.clone(),
        rotation: lighting.rotation,
        intensity: lighting.intensity.or(lighting.intensity_stops.map(f32::exp2)),
        no_background: lighting.no_background,
        spp: sampling.spp,
        seed: sampling.seed,
        exposure: display.exposure,
        tonemap: display.tonemap,
        model: sampling.model.clone(),
        aovs: Vec::new(),
        sampling: sampling.sampling,
        // `render` and `turntable` set these from their own flags.
        noise_threshold: None,
        min_spp: None,
    }
}

/// `--intensity-stops EV`: stops whose intensity, 2^EV, is one an intensity may be.
fn intensity_stops(text: &str) -> std::result::Result<f32, String> {
    let stops: f32 = text.parse().map_err(|_| format!("'{text}' is not a number of stops"))?;
    let most = crate::environment::MAX_INTENSITY.log2();
    if stops.is_finite() && stops.abs() <= most {
        Ok(stops)
    } else {
        Err(format!(
            "{text} stops is outside ±{most:.2} (an intensity from 2^-{most:.2} to {:e})",
            crate::environment::MAX_INTENSITY
        ))
    }
}

/// Parses every `--set NAME=VALUE`.
fn parse_sets(texts: &[String]) -> Result<Vec<(Param, Value)>> {
    texts.iter().map(|t| super::parse_set(t)).collect()
}

/// What `presets sheet` and `wedge` render: `look` under the flags, `spp` and `model`, on the
/// built-in shader ball `size` pixels square.
pub fn ball_spec(
    look: Look,
    lighting: &LightingArgs,
    display: &DisplayArgs,
    spp: u32,
    model: &[String],
    size: u32,
) -> SceneSpec {
    let sampling = SamplingArgs { spp: Some(spp), model: model.to_vec(), ..SamplingArgs::default() };
    SceneSpec {
        look: LookSource::Given(Box::new(look)),
        gbuffer: GBufferSpec { builtin_size: Some((size, size)), ..GBufferSpec::default() },
        overrides: overrides(lighting, &sampling, display),
        env_options: lighting.load_options(),
        ..SceneSpec::default()
    }
}
