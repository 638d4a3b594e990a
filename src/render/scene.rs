//! The inputs of a render, read and validated before any GPU work starts: g-buffer, look (with
//! its stacks packed for the objects present), environment and settings.

use crate::environment::backdrop::Prepared;
use crate::environment::{Environment, EnvironmentRef, LoadOptions};
use crate::gbuffer::source::{Source, SourceOptions};
use crate::gbuffer::GBuffer;
use crate::material::look::GBufferSettings;
use crate::material::stack::{unused_stack_warnings, PackedStacks};
use crate::material::{Look, Param, Value};
use crate::render::provenance::{self, Recorded};
use crate::render::settings::{Overrides, Settings};
use crate::Result;
use std::path::{Path, PathBuf};

/// Size of the built-in shader ball when no g-buffer is given.
pub const BUILTIN_SIZE: u32 = 1024;
pub use crate::gbuffer::MAX_BUILTIN_SIDE;

/// What a render's inputs are, as a command or the viewer names them. Every command that
/// renders and the viewer describe their inputs so, and [`Scene::load`] reads them: one way to
/// choose the look, apply `--set`, resolve the settings, read the g-buffer or make the shader
/// ball, load the environment and pack the stacks.
#[derive(Clone, Debug, Default)]
pub struct SceneSpec {
    pub look: LookSource,
    pub gbuffer: GBufferSpec,
    /// `--set`: parameters set on every layer of every object.
    pub sets: Vec<(Param, Value)>,
    /// The command line's settings over the look's.
    pub overrides: Overrides,
    pub env_options: LoadOptions,
    /// Leaves out the line saying what another renderer's g-buffer was read as.
    pub quiet: bool,
}

/// Where a scene's look comes from.
#[derive(Clone, Debug, Default)]
pub enum LookSource {
    /// The built-in default look on the built-in shader ball; the default material on a
    /// g-buffer file.
    #[default]
    Default,
    File(PathBuf),
    /// A look made in memory (wedges and contact sheets start from one).
    Given(Box<Look>),
}

/// Everything a render reads from files, validated.
pub struct Scene {
    pub gbuffer: GBuffer,
    /// The g-buffer's path, or "built-in shader ball", for messages.
    pub gbuffer_name: PathBuf,
    pub look: Look,
    pub environment: Environment,
    pub settings: Settings,
    /// The background the settings show, made ready ([`crate::environment::Backdrop::prepare`]).
    pub backdrop: Prepared,
    pub stacks: PackedStacks,
    /// What the render reads beyond the look and the settings, for the EXR's provenance.
    pub recorded: Recorded,
}

impl Scene {
    /// Reads and checks everything `spec` names, printing the warnings; see [`SceneSpec`].
    pub fn load(spec: &SceneSpec) -> Result<Scene> {
        let mut look = match &spec.look {
            LookSource::File(path) => Look::load(path)?,
            LookSource::Given(look) => (**look).clone(),
            LookSource::Default if spec.gbuffer.file.is_none() => Look::builtin_default(),
            LookSource::Default => Look::default_material(),
        };
        prepare_look(&mut look, &spec.sets)?;
        let settings = Settings::resolve(&look, &spec.overrides)?;
        let environment = load_environment(settings.environment.as_ref(), &spec.env_options).map_err(|e| {
            // An environment the look names is reported at the look's line, with the path it resolved to.
            match (&spec.overrides.environment, &look.environment.source) {
                (None, Some(EnvironmentRef::File(_))) => crate::Error {
                    message: format!("{}: [environment] file: {}", look.place("environment.file"), e.message),
                    ..e
                },
                _ => e,
            }
        })?;
        let backdrop = prepare_backdrop(&look, &settings, &environment, &spec.env_options)?;
        let recorded = recorded(spec, &look, &settings);
        // read_gbuffer leaves the visibility out under --no-visibility, of a file and of the ball.
        let ReadGBuffer { gbuffer, name: gbuffer_name, claims } = read_gbuffer(&spec.gbuffer, &mut look, spec.quiet)?;
        claims.into_iter().for_each(crate::warn);
        let covered = covered_object_ids(&gbuffer);
        let stacks = PackedStacks::pack(&look, covered.iter().copied(), &gbuffer, &gbuffer_name)?;
        look_warnings(&look, &covered, &gbuffer_name).into_iter().for_each(crate::warn);
        shadowless_catchers(&look, &covered, &gbuffer, &gbuffer_name).into_iter().for_each(crate::warn);
        dark_render_warnings(&gbuffer, &gbuffer_name, &environment, settings.lighting.intensity)
            .into_iter()
            .for_each(crate::warn);
        Ok(Scene { gbuffer, gbuffer_name, look, environment, settings, backdrop, stacks, recorded })
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
        if let Some(visibility) = &self.gbuffer.visibility {
            let rows = crate::gbuffer::gpu::visibility_rows(self.gbuffer.pixel_count(), visibility.grid);
            if rows > max as u64 {
                return Err(crate::Error::input_file(
                    &self.gbuffer_name,
                    format!(
                        "its visibility ({} directions a pixel at {w}x{h}) needs an image {rows} rows tall, more than \
                         {}'s {max}: bake it with a smaller --visibility, or render with --no-visibility",
                        visibility.grid.cells(),
                        info.name
                    ),
                ));
            }
        }
        if self.stacks.channels.len() as u32 > info.max_image_array_layers {
            return Err(crate::Error::input(format!(
                "{}: the look uses {} mask and map channels, more than {}'s {} image layers",
                self.look.place(""),
                self.stacks.channels.len(),
                info.name,
                info.max_image_array_layers
            )));
        }
        Ok(())
    }
}

/// What `spec` reads beyond `look` and `settings` (see [`Recorded`]).
fn recorded(spec: &SceneSpec, look: &Look, settings: &Settings) -> Recorded {
    let g = &spec.gbuffer;
    let file = g.file.clone().or_else(|| look.gbuffer.file.clone());
    let mut flags = Vec::new();
    if let Some(factor) = g.supersample {
        flags.extend(["--supersample".to_string(), factor.to_string()]);
    }
    if g.ignore_visibility {
        flags.push("--no-visibility".into());
    }
    if spec.env_options.clamp_invalid {
        flags.push("--env-clamp".into());
    }
    if spec.env_options.any_aspect {
        flags.push("--env-any-aspect".into());
    }
    if settings.sampling != Default::default() {
        flags.extend(["--sampling".to_string(), settings.sampling.name().to_string()]);
    }
    let aovs =
        if spec.overrides.aovs.is_empty() { look.render.aovs.clone() } else { Some(spec.overrides.aovs.clone()) };
    Recorded {
        gbuffer: GBufferSettings {
            // The built-in scene's size, given or by default, so that the look reopens at it.
            size: file.is_none().then(|| g.builtin_size.or(look.gbuffer.size).unwrap_or((BUILTIN_SIZE, BUILTIN_SIZE))),
            file: file.as_deref().map(provenance::absolute),
            source: SourceOptions {
                occluders: g
                    .source
                    .occluders
                    .clone()
                    .or_else(|| look.gbuffer.source.occluders.clone())
                    .map(|f| provenance::absolute(&f)),
                ..g.source.over(&look.gbuffer.source)
            },
        },
        aovs: aovs.filter(|a| !a.is_empty()),
        flags,
    }
}

/// The g-buffer to render and how to read it, as the command line gives them; the look's
/// `[gbuffer]` table fills in what they leave out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GBufferSpec {
    pub file: Option<PathBuf>,
    pub source: SourceOptions,
    /// The built-in shader ball's size when no file is named ([`BUILTIN_SIZE`] square if
    /// `None`).
    pub builtin_size: Option<(u32, u32)>,
    /// `builtin_size` came from `--size`: a g-buffer file the look names is then an error, not
    /// a silent change of size.
    pub size_given: bool,
    /// Leaves the g-buffer's visibility out (`--no-visibility`): every direction above the
    /// horizon is seen, as in a g-buffer without it.
    pub ignore_visibility: bool,
    /// The g-buffer's supersampling factor (`--supersample`), instead of the one its file
    /// records ([`GBuffer::supersample`]).
    pub supersample: Option<u32>,
}

/// A look made ready to render with `sets`: with any, it gets a default stack if it has none,
/// so that they reach every object as they reach every layer; then they are applied.
pub fn prepare_look(look: &mut Look, sets: &[(Param, Value)]) -> Result<()> {
    if !sets.is_empty() {
        look.ensure_default_stack();
    }
    for (param, value) in sets {
        look.set_everywhere(*param, *value).map_err(crate::Error::input)?;
    }
    Ok(())
}

/// A look file read for a g-buffer already read (the viewer opening a look, or its B look):
/// prepared as [`Scene::load`] prepares looks, its object names resolved and its stacks packed,
/// with the warnings for the caller to show its way.
pub fn load_look_for(path: &Path, gbuffer: &GBuffer, gbuffer_name: &Path) -> Result<(Look, PackedStacks, Vec<String>)> {
    let mut look = Look::load(path)?;
    prepare_look(&mut look, &[])?;
    let mut warnings = look.resolve_object_names(&gbuffer.object_names, gbuffer_name)?;
    let covered = covered_object_ids(gbuffer);
    let stacks = PackedStacks::pack(&look, covered.iter().copied(), gbuffer, gbuffer_name)?;
    warnings.extend(look_warnings(&look, &covered, gbuffer_name));
    warnings.extend(shadowless_catchers(&look, &covered, gbuffer, gbuffer_name));
    Ok((look, stacks, warnings))
}

/// What may be unintended in how a look styles the covered objects: stacks for objects the
/// g-buffer lacks, and objects left in the default material by a look with stacks but no
/// default stack.
pub fn look_warnings(look: &Look, covered: &[u32], gbuffer_name: &Path) -> Vec<String> {
    let mut warnings = unused_stack_warnings(look, covered, gbuffer_name);
    let stackless: Vec<String> =
        covered.iter().filter(|&&id| look.stack_for(id).is_none()).map(|id| id.to_string()).collect();
    if !look.objects.is_empty() && !stackless.is_empty() {
        let name = look.file.as_deref().map(|p| p.display().to_string()).unwrap_or_default();
        warnings.push(format!(
            "{name}: object id {} has no stack and the look has no default stack; the default material is used",
            stackless.join(", ")
        ));
    }
    warnings
}

/// One line for each stack of a covered object that catches shadows when `gbuffer` has no
/// visibility (or it is left out): nothing can shadow it, so it shows the background unchanged.
pub fn shadowless_catchers(look: &Look, covered: &[u32], gbuffer: &GBuffer, gbuffer_name: &Path) -> Vec<String> {
    if gbuffer.visibility.is_some() {
        return Vec::new();
    }
    let file = look.file.as_deref().map(|p| p.display().to_string()).unwrap_or_else(|| "the look".into());
    look.objects
        .iter()
        .filter(|stack| {
            stack.shadow_catcher
                && covered.iter().any(|&id| look.stack_for(id).is_some_and(|s| std::ptr::eq(s, *stack)))
        })
        .map(|stack| {
            format!(
                "{file}:{}: this stack catches shadows, but {} has no visibility (or --no-visibility leaves it out), \
                 so its objects show the background unshadowed",
                stack.line,
                gbuffer_name.display()
            )
        })
        .collect()
}

/// The environment a look's settings name, or the default built-in.
pub fn load_environment(source: Option<&EnvironmentRef>, options: &LoadOptions) -> Result<Environment> {
    EnvironmentRef::or_default(source).load(options)
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
    if let (true, Some(path), Some((width, height))) = (spec.size_given, &file, spec.builtin_size) {
        let look_name = look.file.as_deref().map_or("the look".into(), |p| p.display().to_string());
        return Err(crate::Error::input(format!(
            "--size {width} {height} sizes the built-in shader ball, but {look_name} names the g-buffer {} ([gbuffer] file)",
            path.display()
        )));
    }
    let (gbuffer, name) = match file {
        Some(path) => {
            let options = SourceOptions { no_visibility: spec.ignore_visibility, ..spec.source.clone() };
            // Tracing a production render's shadows can take minutes: a bar shows it.
            let bar = std::sync::Mutex::new(crate::cli::progress::Progress::counting(
                0,
                format!("tracing the shadows of {}", path.display()),
                "pixel runs",
                quiet,
            ));
            let progress = |done: usize, total: usize| {
                if let Ok(mut bar) = bar.lock() {
                    bar.set_total(total as u64);
                    bar.update(done as u64);
                }
            };
            let read = GBuffer::read_reporting(&path, &options.over(&look.gbuffer.source), &progress)?;
            if let Ok(bar) = bar.into_inner() {
                bar.finish();
            }
            if !quiet && read.detected.source != Source::Lookdev {
                eprintln!("lookdev: {}", crate::printable(&read.detected.summary(&path)));
            }
            read.warnings.into_iter().for_each(crate::warn);
            (read.gbuffer, path)
        }
        None => {
            let (width, height) = spec.builtin_size.or(look.gbuffer.size).unwrap_or((BUILTIN_SIZE, BUILTIN_SIZE));
            let visibility = !spec.ignore_visibility;
            (GBuffer::shaderball_with(width, height, visibility), PathBuf::from("built-in shader ball"))
        }
    };
    let mut gbuffer = gbuffer;
    if let Some(factor) = spec.supersample {
        crate::gbuffer::check_supersample(factor, gbuffer.width, gbuffer.height)
            .map_err(|problem| crate::Error::input_file(&name, format!("--supersample {factor}: {problem}")))?;
        gbuffer.supersample = factor;
    }
    let claims = look.resolve_object_names(&gbuffer.object_names, &name)?;
    Ok(ReadGBuffer { gbuffer, name, claims })
}

/// The background `settings` show, made ready: an environment the look names for it is
/// reported at the look's line.
fn prepare_backdrop(
    look: &Look,
    settings: &Settings,
    environment: &Environment,
    options: &LoadOptions,
) -> Result<Prepared> {
    if !settings.lighting.background {
        return Ok(Prepared::Environment);
    }
    settings.backdrop.prepare(environment, options).map_err(|e| crate::Error {
        message: format!(
            "{}: [environment] background_environment: {}",
            look.place("environment.background_environment"),
            e.message
        ),
        ..e
    })
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
    warnings.extend(blind_objects(gbuffer).into_iter().map(|finding| format!("{}: {finding}", gbuffer_name.display())));
    if environment.texels.iter().flatten().all(|&v| v == 0.0) {
        warnings.push(format!("{}: every texel is 0, so the render is black", environment.source));
    } else if intensity == 0.0 {
        warnings.push("the environment's intensity is 0, so the render is black".to_string());
    }
    warnings
}

/// Share of an object's pixels that see no sky above which its visibility is suspect.
pub const BLIND_SHARE: f32 = 0.5;

/// One line for each object more than [`BLIND_SHARE`] of whose pixels see the environment along
/// no direction, so render black under any light.
pub fn blind_objects(gbuffer: &GBuffer) -> Vec<String> {
    crate::visibility::blind_shares(gbuffer)
        .into_iter()
        .filter(|&(_, share)| share > BLIND_SHARE)
        .map(|(id, share)| {
            let name = gbuffer.object_names.get(&id).map(|n| format!(" '{n}'")).unwrap_or_default();
            format!(
                "object {id}{name}: {:.0}% of its pixels see the sky along no direction, so they render black in any light \
                 (was its visibility traced from inside the surfaces?); --no-visibility renders without it",
                share * 100.0
            )
        })
        .collect()
}

/// The distinct object ids of the pixels that are shaded (coverage > 0), ascending.
pub fn covered_object_ids(gbuffer: &GBuffer) -> Vec<u32> {
    let mut ids: Vec<u32> =
        gbuffer.object_id.iter().zip(&gbuffer.coverage).filter(|(_, &a)| a > 0.0).map(|(&id, _)| id).collect();
    ids.sort_unstable();
    ids.dedup();
    ids
}
