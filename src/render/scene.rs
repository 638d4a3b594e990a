//! The inputs of a render, read and validated before any GPU work starts: g-buffer, look (with
//! its stacks packed for the objects present), environment and settings.

use crate::environment::{self, Environment, LoadOptions};
use crate::gbuffer::source::{Source, SourceOptions};
use crate::gbuffer::GBuffer;
use crate::material::stack::{unused_stack_warnings, PackedStacks};
use crate::material::{Look, Param, Value};
use crate::render::settings::{Overrides, Settings};
use crate::Result;
use std::path::{Path, PathBuf};

/// Size of the built-in shader ball when no g-buffer is given.
pub const BUILTIN_SIZE: u32 = 1024;

/// Everything a render reads from files, validated.
pub struct Scene {
    pub gbuffer: GBuffer,
    /// The g-buffer's path, or "built-in shader ball", for messages.
    pub gbuffer_name: PathBuf,
    pub look: Look,
    pub environment: Environment,
    pub settings: Settings,
    pub stacks: PackedStacks,
}

impl Scene {
    /// Packs the look's stacks for the objects in the g-buffer.
    pub fn new(
        gbuffer: GBuffer,
        gbuffer_name: PathBuf,
        look: Look,
        environment: Environment,
        settings: Settings,
    ) -> Result<Scene> {
        let covered = covered_object_ids(&gbuffer);
        let stacks = PackedStacks::pack(&look, covered.iter().copied(), &gbuffer, &gbuffer_name)?;
        unused_stack_warnings(&look, &covered, &gbuffer_name).into_iter().for_each(crate::warn);
        dark_render_warnings(&gbuffer, &gbuffer_name, &environment, settings.lighting.intensity)
            .into_iter()
            .for_each(crate::warn);
        Ok(Scene { gbuffer, gbuffer_name, look, environment, settings, stacks })
    }

    /// Reads a render's inputs. Without a g-buffer, the built-in shader ball; without a look, the
    /// built-in default look for the shader ball, or the default material for a user g-buffer.
    /// `sets` override parameters on every layer; `overrides` the look's settings.
    pub fn load(
        gbuffer: &GBufferSpec,
        look: Option<&Path>,
        sets: &[(Param, Value)],
        overrides: &Overrides,
        env_options: &LoadOptions,
        quiet: bool,
    ) -> Result<Scene> {
        let mut look = match look {
            Some(path) => Look::load(path)?,
            None if gbuffer.file.is_none() => Look::builtin_default(),
            None => Look::default_material(),
        };
        let had_stacks = !look.objects.is_empty();
        let implicit_default = look.ensure_default_stack();
        for (param, value) in sets {
            look.set_everywhere(*param, *value).map_err(crate::Error::input)?;
        }
        let settings = Settings::resolve(&look, overrides)?;
        let environment = match &settings.environment {
            Some(path) => environment::load::load(path, env_options)?,
            None => Environment::studio(),
        };
        let ReadGBuffer { gbuffer, name: gbuffer_name, claims } = read_gbuffer(gbuffer, &mut look, quiet)?;
        claims.into_iter().for_each(crate::warn);
        if implicit_default && had_stacks {
            let unstyled: Vec<String> = covered_object_ids(&gbuffer)
                .into_iter()
                .filter(|id| !look.objects.iter().any(|o| o.id == Some(*id)))
                .map(|id| id.to_string())
                .collect();
            if !unstyled.is_empty() {
                let name = look.file.as_deref().map(|p| p.display().to_string()).unwrap_or_default();
                crate::warn(format!(
                    "{name}: object id {} has no stack and the look has no default stack; the default material is used",
                    unstyled.join(", ")
                ));
            }
        }
        Scene::new(gbuffer, gbuffer_name, look, environment, settings)
    }

    /// Whether this device can hold the g-buffer: checked once the device is known, and
    /// reported as bad input naming the file, since only a smaller g-buffer can fix it.
    pub fn check_device(&self, info: &crate::gpu::DeviceInfo) -> Result<()> {
        let max = info.max_image_dimension_2d;
        let (w, h) = (self.gbuffer.width, self.gbuffer.height);
        if w > max || h > max {
            return Err(crate::Error::input_file(
                &self.gbuffer_name,
                format!("the g-buffer is {w}x{h}, larger than {}'s {max}-pixel image limit", info.name),
            ));
        }
        if self.stacks.channels.len() as u32 > info.max_image_array_layers {
            return Err(crate::Error::input(format!(
                "the look uses {} mask and map channels, more than {}'s {} image layers",
                self.stacks.channels.len(),
                info.name,
                info.max_image_array_layers
            )));
        }
        Ok(())
    }
}

/// The g-buffer to render and how to read it, as the command line gives them; the look's
/// `[gbuffer]` table fills in what they leave out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GBufferSpec {
    pub file: Option<PathBuf>,
    pub source: SourceOptions,
}

/// A g-buffer as a render reads it.
pub struct ReadGBuffer {
    pub gbuffer: GBuffer,
    /// Its file, or "built-in shader ball", for messages.
    pub name: PathBuf,
    /// One line for each stack that claims an object an earlier stack claims.
    pub claims: Vec<String>,
}

/// Reads the g-buffer `spec` and the look's `[gbuffer]` table name (the built-in shader ball
/// when neither names one), prints what its file was detected as (unless `quiet`) and its
/// warnings, and gives the look's stacks that name their objects those objects' ids.
pub fn read_gbuffer(spec: &GBufferSpec, look: &mut Look, quiet: bool) -> Result<ReadGBuffer> {
    let file = spec.file.clone().or_else(|| look.gbuffer.file.clone());
    let (gbuffer, name) = match file {
        Some(path) => {
            let read = GBuffer::read_with(&path, &spec.source.over(&look.gbuffer.source))?;
            if !quiet && read.detected.source != Source::Lookdev {
                eprintln!("lookdev: {}", crate::printable(&read.detected.summary(&path)));
            }
            read.warnings.into_iter().for_each(crate::warn);
            (read.gbuffer, path)
        }
        None => (GBuffer::shaderball(BUILTIN_SIZE, BUILTIN_SIZE), PathBuf::from("built-in shader ball")),
    };
    let claims = look.resolve_object_names(&gbuffer.object_names, &name)?;
    Ok(ReadGBuffer { gbuffer, name, claims })
}

/// What makes a valid render come out black, or show only the background, each as a warning
/// naming its cause: a g-buffer that covers no pixel, an environment that is 0 everywhere, an
/// intensity of 0.
pub fn dark_render_warnings(
    gbuffer: &GBuffer,
    gbuffer_name: &Path,
    environment: &Environment,
    intensity: f32,
) -> Vec<String> {
    let mut warnings = Vec::new();
    if gbuffer.coverage.iter().all(|&a| a == 0.0) {
        warnings.push(format!(
            "{}: no pixel is covered (A is 0 everywhere), so the render shows only the background",
            gbuffer_name.display()
        ));
    }
    if environment.texels.iter().flatten().all(|&v| v == 0.0) {
        warnings.push(format!("{}: every texel is 0, so the render is black", environment.source));
    } else if intensity == 0.0 {
        warnings.push("the environment's intensity is 0, so the render is black".to_string());
    }
    warnings
}

/// The distinct object ids of the pixels that are shaded (coverage > 0), ascending.
pub fn covered_object_ids(gbuffer: &GBuffer) -> Vec<u32> {
    let mut ids: Vec<u32> =
        gbuffer.object_id.iter().zip(&gbuffer.coverage).filter(|(_, &a)| a > 0.0).map(|(&id, _)| id).collect();
    ids.sort_unstable();
    ids.dedup();
    ids
}
