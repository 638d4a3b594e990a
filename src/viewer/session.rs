//! A viewing session: the document being edited and the renderer that shows it, kept in step.
//! Each frame, [`Session::sync`] hands the renderer only what changed (new stacks when the
//! materials changed, an environment, lighting, seed), so that an edit costs one restart and
//! an exposure change costs no samples at all.

use super::compare::{self, Compare, SnapshotView, Subject};
use super::delta_e::DeltaE;
use super::progressive::Progressive;
use super::snapshots::{Capture, Snapshots};
use crate::environment::backdrop::Prepared;
use crate::environment::{Backdrop, Environment, EnvironmentRef, LoadOptions};
use crate::gbuffer::GBuffer;
use crate::gpu::{Context, Image};
use crate::material::look::{LayerId, Look};
use crate::material::params::Params;
use crate::material::stack::{layer_weights, LayerWeight, PackedStacks};
use crate::render::output::{self, OutputFormat};
use crate::render::renderer::{KernelSource, NoiseThreshold, Specialization};
use crate::render::sampling::Sampling;
use crate::render::scene::covered_object_ids;
use crate::render::{Lighting, Renderer};
use crate::shading::model::Model;
use crate::shading::tonemap::Tonemap;
use crate::viewer_state::{Document, ObjectRef};
use crate::{Error, Result};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Environments kept loaded, so that undoing a switch does not read the file again.
const KEPT_ENVIRONMENTS: usize = 3;

/// What the renderer was last given.
struct Shown {
    material_revision: u64,
    solo: Option<LayerId>,
    environment: Option<EnvironmentRef>,
    lighting: Lighting,
    backdrop: Backdrop,
    seed: u32,
    exposure: f32,
    tonemap: Tonemap,
    model: Model,
    noise: Option<NoiseThreshold>,
}

/// Everything known about one pixel, for the inspector.
#[derive(Clone, Debug)]
pub struct Inspection {
    pub x: u32,
    pub y: u32,
    pub object_id: u32,
    /// The object's name, where the g-buffer names it.
    pub object_name: Option<String>,
    pub coverage: f32,
    /// Every g-buffer mask's value here, by name.
    pub masks: Vec<(String, f32)>,
    /// The full names behind masks whose channel names were made safe (material names).
    pub mask_names: Vec<(String, String)>,
    /// Every g-buffer map channel's value here, by name (`baseColor.R`, `rough`).
    pub maps: Vec<(String, f32)>,
    /// The cosine-weighted share of the hemisphere that sees the sky, where the g-buffer has
    /// visibility and the pixel is covered.
    pub occlusion: Option<f32>,
    /// The stack that shades the pixel, and each of its layers' weight here (`None`: hidden).
    pub stack: Option<ObjectRef>,
    pub layers: Vec<(String, Option<LayerWeight>)>,
    /// The blended material here.
    pub params: Params,
    /// Linear radiance (alpha 1 with the background on, else the coverage) and its sample count.
    pub radiance: [f32; 4],
    pub samples: u32,
}

impl std::fmt::Display for Inspection {
    /// One line, as a script's `pick` prints it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "pixel {},{}: object {}", self.x, self.y, self.object_id)?;
        if let Some(name) = &self.object_name {
            write!(f, " '{name}'")?;
        }
        write!(f, ", coverage {:.4}", self.coverage)?;
        for (name, value) in &self.masks {
            match self.mask_names.iter().find(|(mask, _)| mask == name) {
                Some((_, full)) => write!(f, ", mask.{name} '{full}' {value:.4}")?,
                None => write!(f, ", mask.{name} {value:.4}")?,
            }
        }
        for (name, value) in &self.maps {
            write!(f, ", map.{name} {value:.4}")?;
        }
        if let Some(occlusion) = self.occlusion {
            write!(f, ", occlusion {occlusion:.4}")?;
        }
        if let Some(stack) = self.stack {
            write!(f, "; {stack}:")?;
            for (index, (label, weight)) in self.layers.iter().enumerate() {
                match weight {
                    Some(w) => write!(f, " [{index} {label} blend {:.4} share {:.4}]", w.blend, w.contribution)?,
                    None => write!(f, " [{index} {label} hidden]")?,
                }
            }
            write!(f, "; material")?;
            for param in crate::material::Param::ALL {
                write!(f, " {}={}", param.name(), self.params.get(param).short_text())?;
            }
        }
        let [r, g, b, a] = self.radiance;
        write!(f, "; radiance {r:.6},{g:.6},{b:.6},{a:.6} at {} spp", self.samples)
    }
}

/// The document, the renderer, and what the renderer shows of the document.
pub struct Session {
    ctx: Context,
    pub gbuffer: GBuffer,
    /// The g-buffer's file, or "built-in shader ball".
    pub gbuffer_name: PathBuf,
    /// What the scene reads beyond the look, for saved EXRs' provenance.
    recorded: crate::render::provenance::Recorded,
    pub document: Document,
    renderer: Renderer,
    pub progressive: Progressive,
    packed: PackedStacks,
    /// The object ids that are shaded, ascending.
    objects: Vec<u32>,
    masks: Vec<String>,
    env_options: LoadOptions,
    environments: Vec<(Option<EnvironmentRef>, Environment)>,
    /// The shown backdrop, made ready: what a new B renderer is given.
    backdrop: Prepared,
    shown: Shown,
    /// When the last change reached the renderer, and how long its first full pass took.
    changed_at: Instant,
    pub first_pass_after_change: Option<Duration>,
    pub inspection: Option<Inspection>,
    /// `--exit-after-spp`: the sample count to stop at, whatever the look's target.
    target_override: Option<u32>,
    /// The A/B split's B side, when comparing.
    compare: Option<Compare>,
    /// B sides replaced or turned off this frame: the frame's interface may still draw their
    /// images, so they go at the next frame's start ([`Session::drop_retired`]).
    retired: Vec<Compare>,
    /// Where the split is, as a fraction of the image's width from the left; kept while the
    /// split is off, so turning it back on finds it where it was.
    pub divider: f32,
    /// The look file's snapshots.
    pub snapshots: Snapshots,
    /// The snapshot shown as B, instead of a live renderer.
    snapshot_compare: Option<SnapshotCompare>,
    /// Whether the display filter (denoise) is shown instead of the accumulation's own pixels.
    pub denoise: bool,
    /// Whether the renderers use the g-buffer's visibility ([`Session::set_visibility`]).
    pub visibility: bool,
    /// The sample count the display filter last ran at, `None` when it must run again (a
    /// change, a preview, other display settings).
    denoised_at: Option<u32>,
    /// The layer shown alone in its stack ([`Look::soloed`]): a way of looking, not an edit, so
    /// neither saved nor undone. It lapses when the layer leaves the look.
    pub solo: Option<LayerId>,
}

/// A snapshot as B: which, how, and its ΔE map against the live image when shown as one.
pub struct SnapshotCompare {
    pub name: String,
    /// The snapshot's [`Snapshot::id`](super::snapshots::Snapshot::id).
    pub id: u64,
    pub view: SnapshotView,
    pub delta: Option<DeltaE>,
    /// The live image's samples and document revision the map was made at.
    delta_key: Option<(u32, u64)>,
}

/// A renderer of `model` and the estimator `sampling` with `packed` set, its relight kernel made
/// for their lobes: compiled once, where setting the stacks on a renderer made for every lobe
/// would compile it again.
fn stacks_renderer(
    ctx: &Context,
    gbuffer: &GBuffer,
    environment: &Environment,
    model: Model,
    sampling: Sampling,
    packed: &PackedStacks,
) -> Result<Renderer> {
    let kernels = KernelSource::Compile(Specialization {
        model,
        product: sampling.product_kernel(),
        lobes: packed.lobes(),
        maps: packed.binds_maps(),
        visibility: gbuffer.visibility.as_ref().map_or(0, |v| v.grid.side()),
        shadow_catcher: packed.has_shadow_catcher(),
        ..Specialization::default()
    });
    let mut renderer = Renderer::with_kernels(ctx, gbuffer, environment, sampling, kernels)?;
    renderer.set_stacks(packed)?;
    Ok(renderer)
}

impl Session {
    /// `environment` is the one `document`'s settings name, already loaded.
    pub fn new(
        ctx: &Context,
        gbuffer: GBuffer,
        gbuffer_name: PathBuf,
        document: Document,
        environment: Environment,
        env_options: LoadOptions,
        recorded: crate::render::provenance::Recorded,
    ) -> Result<Session> {
        let objects = covered_object_ids(&gbuffer);
        let masks: Vec<String> = gbuffer.masks.keys().cloned().collect();
        let packed = PackedStacks::pack(document.look(), objects.iter().copied(), &gbuffer, &gbuffer_name)?;
        let settings = document.settings().clone();
        let mut renderer = stacks_renderer(ctx, &gbuffer, &environment, settings.model, settings.sampling, &packed)?;
        renderer.set_lighting(settings.lighting);
        let backdrop = settings.backdrop.prepare(&environment, &env_options)?;
        renderer.set_backdrop(&backdrop)?;
        renderer.set_seed(settings.seed);
        renderer.set_noise_threshold(settings.noise)?;
        Ok(Session {
            ctx: ctx.clone(),
            progressive: Progressive::new(),
            gbuffer,
            gbuffer_name,
            recorded,
            shown: Shown {
                material_revision: document.material_revision(),
                solo: None,
                environment: settings.environment.clone(),
                lighting: settings.lighting,
                backdrop: settings.backdrop.clone(),
                seed: settings.seed,
                exposure: settings.exposure,
                tonemap: settings.tonemap,
                model: settings.model,
                noise: settings.noise,
            },
            document,
            renderer,
            packed,
            objects,
            masks,
            env_options,
            environments: vec![(settings.environment, environment)],
            backdrop,
            changed_at: Instant::now(),
            first_pass_after_change: None,
            inspection: None,
            target_override: None,
            compare: None,
            retired: Vec::new(),
            divider: 0.5,
            snapshots: Snapshots::default(),
            snapshot_compare: None,
            denoise: false,
            visibility: true,
            denoised_at: None,
            solo: None,
        })
    }

    /// Stops accumulation at `spp` instead of the document's target, without changing the look.
    pub fn override_target(&mut self, spp: u32) {
        self.target_override = Some(spp);
    }

    /// `--exit-after-spp`'s sample count, when it stands in for the document's target.
    pub fn target_override(&self) -> Option<u32> {
        self.target_override
    }

    /// The shaded object ids, ascending.
    pub fn objects(&self) -> &[u32] {
        &self.objects
    }

    /// Refuses an object id the g-buffer does not shade, naming the objects it does: selecting
    /// one would leave no stack and no layer to edit.
    pub fn check_object(&self, object: ObjectRef) -> Result<()> {
        let ObjectRef::Id(id) = object else { return Ok(()) };
        if self.objects.contains(&id) {
            return Ok(());
        }
        let has: Vec<String> = self
            .objects
            .iter()
            .map(|id| match self.gbuffer.object_names.get(id) {
                Some(name) => format!("{id} '{name}'"),
                None => id.to_string(),
            })
            .collect();
        let has = if has.is_empty() { "no objects".to_string() } else { format!("it has: {}", has.join(", ")) };
        Err(Error::input(format!("object {id} is not in the g-buffer {} ({has})", self.gbuffer_name.display())))
    }

    /// The g-buffer's mask names.
    pub fn masks(&self) -> &[String] {
        &self.masks
    }

    pub fn width(&self) -> u32 {
        self.gbuffer.width
    }

    pub fn height(&self) -> u32 {
        self.gbuffer.height
    }

    /// Samples every pixel has (on both sides of a split).
    pub fn samples(&self) -> u32 {
        let a = self.renderer.samples();
        self.compare.as_ref().map_or(a, |b| a.min(b.renderer.samples()))
    }

    /// While the pixels an edit restarted alone catch up with the rest (A's): how many they
    /// are, their samples and the rest's.
    pub fn restarted_region(&self) -> Option<(usize, u32, u32)> {
        self.renderer.restarted_region()
    }

    /// The g-buffer the session shows, as a look's `[gbuffer]` table records it, and what else
    /// its renders record.
    pub fn recorded(&self) -> &crate::render::provenance::Recorded {
        &self.recorded
    }

    /// Where accumulation stops.
    pub fn target(&self) -> u32 {
        self.target_override.unwrap_or(self.document.settings().spp)
    }

    /// Whether accumulation has stopped: every pixel has the target's samples, or under a
    /// noise threshold every pixel has stopped (on both sides of a split).
    pub fn converged(&self) -> bool {
        let target = self.target();
        let done = |r: &Renderer| r.samples() >= target || r.active_pixels() == Some(0);
        done(&self.renderer) && self.compare.as_ref().is_none_or(|b| done(&b.renderer))
    }

    /// Under a noise threshold (`--noise-threshold`), A's pixels still taking samples and the
    /// threshold.
    pub fn adaptive(&self) -> Option<(u64, NoiseThreshold)> {
        self.renderer.active_pixels().zip(self.renderer.noise_threshold())
    }

    /// What the view shows: the display pixels, or with the display filter on, its pixels.
    pub fn display_image(&self) -> &Image {
        shown_image(&self.renderer, self.denoise)
    }

    /// B's display image, when comparing.
    pub fn compare_image(&self) -> Option<&Image> {
        self.compare.as_ref().map(|b| shown_image(&b.renderer, self.denoise))
    }

    /// Relights with the g-buffer's visibility (shadows and occlusion) or without it, for
    /// comparison; both sides of an A/B split alike. Not part of the look: a saved image is
    /// what is shown. Every pixel restarts.
    pub fn set_visibility(&mut self, on: bool) -> Result<()> {
        if on == self.visibility {
            return Ok(());
        }
        self.visibility = on;
        self.renderer.set_visibility(on)?;
        if let Some(b) = &mut self.compare {
            b.renderer.set_visibility(on)?;
            b.progressive.restart();
        }
        self.progressive.restart();
        self.changed_at = Instant::now();
        self.first_pass_after_change = None;
        self.denoised_at = None;
        self.refresh_inspection()
    }

    /// Whether the g-buffer has visibility to switch.
    pub fn has_visibility(&self) -> bool {
        self.gbuffer.visibility.is_some()
    }

    /// Turns the display filter on or off. It changes only what is shown: never the samples,
    /// nor any saved image.
    pub fn set_denoise(&mut self, on: bool) {
        self.denoise = on;
        self.denoised_at = None;
    }

    /// Runs the display filter when it is on and what it filters has changed: after a change
    /// (on the preview), and as each whole pass lands, so that it, too, never shows a frame
    /// half old, half new.
    fn refresh_denoise(&mut self) -> Result<()> {
        let samples = self.samples();
        if !self.denoise || self.denoised_at == Some(samples) {
            return Ok(());
        }
        let settings = self.document.settings();
        let (exposure, tonemap) = (settings.exposure, settings.tonemap);
        let shown = |r: &Renderer| r.preview_block().is_some() || r.samples() > 0;
        if !shown(&self.renderer) {
            return Ok(());
        }
        self.renderer.denoise(exposure, tonemap)?;
        if let Some(b) = self.compare.as_mut().filter(|b| shown(&b.renderer)) {
            b.renderer.denoise(exposure, tonemap)?;
        }
        self.denoised_at = Some(samples);
        Ok(())
    }

    /// Whether B's image is ready to be shown: B has finished its first pass. Until then, B's
    /// half of the split shows A.
    pub fn compare_ready(&self) -> bool {
        self.snapshot_compare.is_some() || self.compare.as_ref().is_some_and(|b| b.renderer.has_finished_a_pass())
    }

    /// What B is, when comparing.
    pub fn compare_subject(&self) -> Option<&Subject> {
        self.compare.as_ref().map(|b| &b.subject)
    }

    /// B's progress figures, when comparing.
    pub fn compare_progressive(&self) -> Option<&Progressive> {
        self.compare.as_ref().map(|b| &b.progressive)
    }

    /// The labels of the two halves, "A: …" and "B: …", when comparing.
    pub fn compare_labels(&self) -> Option<(String, String)> {
        if let Some(shown) = &self.snapshot_compare {
            let spp = self.snapshots.get(&shown.name).map_or(0, |s| s.spp);
            return Some(("A: live".into(), format!("B: snapshot {} · {spp} spp", shown.name)));
        }
        let b = self.compare.as_ref()?;
        let a_model = self.document.settings().model;
        Some(match &b.subject {
            Subject::Model(model) => (format!("A: {}", a_model.label()), format!("B: {}", model.label())),
            Subject::Look { path, look } => {
                let a_name = compare::file_label(self.document.path());
                let b_model = look.model.unwrap_or_default();
                let model_part =
                    |m: Model| if m == Model::default() { String::new() } else { format!(" · {}", m.label()) };
                (
                    format!("A: {a_name}{}", model_part(a_model)),
                    format!("B: {}{}", compare::file_label(Some(path)), model_part(b_model)),
                )
            }
        })
    }

    /// The image column where B starts, when comparing.
    pub fn split_column(&self) -> Option<u32> {
        let snapshot_split = self.snapshot_compare.as_ref().is_some_and(|s| s.view == SnapshotView::Split);
        (self.compare.is_some() || snapshot_split).then(|| compare::split_column(self.divider, self.width()))
    }

    /// Shows B: A's stacks under `model`. Replaces whatever B was.
    pub fn compare_model(&mut self, model: Model) -> Result<()> {
        let packed = self.packed.clone();
        self.start_compare(Subject::Model(model), packed)
    }

    /// Shows B: the look at `path`, its stacks and model under A's lighting and settings. A look
    /// that does not load or fit the g-buffer changes nothing.
    pub fn compare_look(&mut self, path: &Path) -> Result<()> {
        let (look, packed, warnings) = crate::render::scene::load_look_for(path, &self.gbuffer, &self.gbuffer_name)?;
        warnings.into_iter().for_each(crate::warn);
        self.start_compare(Subject::Look { path: path.to_path_buf(), look: Box::new(look) }, packed)
    }

    fn start_compare(&mut self, subject: Subject, packed: PackedStacks) -> Result<()> {
        let environment = self
            .environments
            .iter()
            .find(|(p, _)| *p == self.shown.environment)
            .map(|(_, e)| e)
            .ok_or_else(|| Error::gpu("the environment on screen is not loaded"))?;
        // B samples as A does.
        let sampling = self.renderer.sampling();
        let mut renderer = stacks_renderer(&self.ctx, &self.gbuffer, environment, subject.model(), sampling, &packed)?;
        renderer.set_lighting(self.shown.lighting);
        renderer.set_backdrop(&self.backdrop)?;
        renderer.set_seed(self.shown.seed);
        renderer.set_noise_threshold(self.shown.noise)?;
        // Its display image starts cleared and is not shown until its first pass has landed
        // (see `compare_ready`).
        let progressive = Progressive::new();
        self.snapshot_compare = None;
        self.retired.extend(self.compare.replace(Compare { subject, renderer, progressive, packed }));
        Ok(())
    }

    /// Back to the plain image: B's renderer goes and A has the whole frame budget.
    pub fn compare_off(&mut self) {
        self.snapshot_compare = None;
        self.retired.extend(self.compare.take());
    }

    /// Lets go of B sides that were replaced or turned off, once the GPU is done with them.
    pub fn drop_retired(&mut self) -> Result<()> {
        if !self.retired.is_empty() {
            unsafe { self.ctx.shared.device.device_wait_idle() }?;
            self.retired.clear();
        }
        Ok(())
    }

    /// Swaps the halves of a model comparison: A's look takes B's model (an undoable edit) and B
    /// shows A's old one. Each side keeps its samples: the renderers swap too.
    pub fn swap_models(&mut self) -> Result<()> {
        let Some(b) = &mut self.compare else {
            return Err(Error::input("swap: nothing is being compared"));
        };
        let Subject::Model(b_model) = b.subject else {
            return Err(Error::input("swap: B is a look, not a model"));
        };
        let a_model = self.document.settings().model;
        self.document.apply(crate::viewer_state::Edit::SetModel(b_model)).map_err(Error::input)?;
        b.subject = Subject::Model(a_model);
        std::mem::swap(&mut self.renderer, &mut b.renderer);
        std::mem::swap(&mut self.progressive, &mut b.progressive);
        self.shown.model = b_model;
        Ok(())
    }

    pub fn device_name(&self) -> &str {
        &self.ctx.info().name
    }

    /// Loads an environment (or the default built-in) and keeps it for [`Session::sync`]:
    /// called before the edit that switches to it, so that a file that does not load changes
    /// nothing.
    pub fn load_environment(&mut self, source: Option<&EnvironmentRef>) -> Result<()> {
        let key = source.cloned();
        if let Some(i) = self.environments.iter().position(|(p, _)| *p == key) {
            let entry = self.environments.remove(i);
            self.environments.push(entry);
            return Ok(());
        }
        let environment = EnvironmentRef::or_default(source).load(&self.env_options)?;
        self.environments.push((key, environment));
        if self.environments.len() > KEPT_ENVIRONMENTS {
            // Never the one on screen: it may be needed again by an undo.
            let on_screen = self.shown.environment.clone();
            if let Some(i) = self.environments.iter().position(|(p, _)| *p != on_screen) {
                self.environments.remove(i);
            }
        }
        Ok(())
    }

    /// Gives the renderer whatever changed in the document since the last call. An error leaves
    /// the renderer showing the previous state; the caller undoes the change.
    pub fn sync(&mut self) -> Result<()> {
        self.apply_changes(false)
    }

    /// [`Session::sync`]; with `everything`, as if every part had changed. A change of the
    /// materials alone restarts only the pixels whose resolved material it changed; any other
    /// change restarts every pixel (docs/commands.md#edit-local-re-convergence).
    fn apply_changes(&mut self, everything: bool) -> Result<()> {
        let settings = self.document.settings().clone();
        let mut restarted = false;
        let mut restarted_locally = false;
        // A solo whose layer has gone (removed, or undone) lapses.
        self.solo = self.solo.filter(|&id| self.document.look().soloed(id).is_some());
        let material_changed = everything
            || self.document.material_revision() != self.shown.material_revision
            || self.solo != self.shown.solo;
        // Whether anything but the materials changes every pixel's image.
        let whole = everything
            || settings.environment != self.shown.environment
            || !settings.lighting.lights_as(&self.shown.lighting)
            || settings.seed != self.shown.seed
            || settings.model != self.shown.model
            || settings.noise != self.shown.noise;
        if material_changed {
            let packed = PackedStacks::pack(
                &self.rendered_look(),
                self.objects.iter().copied(),
                &self.gbuffer,
                &self.gbuffer_name,
            )?;
            if everything || packed != self.packed {
                // Locally only once a first pass has replaced the preview: until then, rows
                // still shown from it would keep the old materials.
                if !whole && self.progressive.first_pass.is_some() {
                    // None: the edit changed the scene's lobes, and everything restarted.
                    restarted_locally = self.renderer.set_stacks_local(&packed)?.is_some();
                    restarted = !restarted_locally;
                } else {
                    self.renderer.set_stacks(&packed)?;
                    restarted = true;
                }
                if let Some(b) = self.compare.as_mut().filter(|b| matches!(b.subject, Subject::Model(_))) {
                    if !whole && b.progressive.first_pass.is_some() {
                        match b.renderer.set_stacks_local(&packed)? {
                            Some(_) => b.progressive.restart_local(),
                            None => b.progressive.restart(),
                        }
                    } else {
                        b.renderer.set_stacks(&packed)?;
                        b.progressive.restart();
                    }
                    b.packed = packed.clone();
                }
                self.packed = packed;
            }
            self.shown.material_revision = self.document.material_revision();
            self.shown.solo = self.solo;
        }
        if everything || settings.environment != self.shown.environment {
            self.load_environment(settings.environment.as_ref())?;
            let (_, environment) = self.environments.last().expect("just loaded");
            self.renderer.set_environment(environment)?;
            if let Some(b) = &mut self.compare {
                b.renderer.set_environment(environment)?;
                b.progressive.restart();
            }
            self.shown.environment = settings.environment.clone();
            restarted = true;
        }
        let environment_changed = everything || settings.environment != self.shown.environment;
        if everything || !settings.lighting.lights_as(&self.shown.lighting) || settings.seed != self.shown.seed {
            self.renderer.set_lighting(settings.lighting);
            self.renderer.set_seed(settings.seed);
            if let Some(b) = &mut self.compare {
                b.renderer.set_lighting(settings.lighting);
                b.renderer.set_seed(settings.seed);
                b.progressive.restart();
            }
            self.shown.lighting = settings.lighting;
            self.shown.seed = settings.seed;
            restarted = true;
        }
        // The background alone: every sample is kept.
        let blurred = matches!(settings.backdrop, Backdrop::Blurred(_));
        if everything || settings.backdrop != self.shown.backdrop || (environment_changed && blurred) {
            let (_, environment) = self.environments.last().expect("the environment on screen is loaded");
            self.backdrop = settings.backdrop.prepare(environment, &self.env_options)?;
            self.renderer.set_backdrop(&self.backdrop)?;
            if let Some(b) = &mut self.compare {
                b.renderer.set_backdrop(&self.backdrop)?;
            }
            self.shown.backdrop = settings.backdrop.clone();
            self.denoised_at = None;
        }
        if settings.lighting != self.shown.lighting {
            self.renderer.set_lighting(settings.lighting);
            self.renderer.write_background()?;
            if let Some(b) = &mut self.compare {
                b.renderer.set_lighting(settings.lighting);
                b.renderer.write_background()?;
            }
            self.shown.lighting = settings.lighting;
            self.denoised_at = None;
        }
        if everything || settings.model != self.shown.model {
            self.renderer.set_model(&settings.model)?;
            self.shown.model = settings.model;
            restarted = true;
        }
        if everything || settings.noise != self.shown.noise {
            self.renderer.set_noise_threshold(settings.noise)?;
            if let Some(b) = &mut self.compare {
                b.renderer.set_noise_threshold(settings.noise)?;
                b.progressive.restart();
            }
            self.shown.noise = settings.noise;
            restarted = true;
        }
        if restarted {
            self.progressive.restart();
        } else if restarted_locally {
            self.progressive.restart_local();
        }
        if restarted || restarted_locally {
            self.changed_at = Instant::now();
            self.first_pass_after_change = None;
            self.denoised_at = None;
        }
        if restarted || material_changed {
            // The layer names and weights may change with no change to what is rendered.
            self.refresh_inspection()?;
        }
        if everything || (settings.exposure, settings.tonemap) != (self.shown.exposure, self.shown.tonemap) {
            self.shown.exposure = settings.exposure;
            self.shown.tonemap = settings.tonemap;
            // The same samples, shown anew: nothing restarts.
            self.renderer.finalize_rows(0, self.height(), settings.exposure, settings.tonemap)?;
            if let Some(b) = &self.compare {
                b.renderer.finalize_rows(0, self.height(), settings.exposure, settings.tonemap)?;
            }
            self.denoised_at = None;
        }
        Ok(())
    }

    /// A session on `scene`'s g-buffer and environment, editing `document`: how the unit tests
    /// of the panels and the session make one.
    #[cfg(test)]
    pub fn of_scene(ctx: &Context, scene: crate::render::scene::Scene, document: Document) -> Result<Session> {
        let crate::render::scene::Scene { gbuffer, gbuffer_name, environment, recorded, .. } = scene;
        Session::new(ctx, gbuffer, gbuffer_name, document, environment, Default::default(), recorded)
    }

    /// Relights for about `budget`, shared by the renderers on screen, unless the target is
    /// reached. Returns whether anything was relit. What it relit is shown once
    /// [`Self::prepare_display`] has run.
    pub fn step(&mut self, budget: Duration) -> Result<bool> {
        let target = self.target();
        let share = if self.compare.is_some() { budget / 2 } else { budget };
        let mut stepped = self.progressive.step(&mut self.renderer, target, share)?;
        if let Some(b) = &mut self.compare {
            stepped |= b.progressive.step(&mut b.renderer, target, share)?;
        }
        if self.first_pass_after_change.is_none() && self.samples() > 0 {
            self.first_pass_after_change = Some(self.changed_at.elapsed());
        }
        // The inspector's radiance follows the accumulation, read back at 1, 2, 4, … samples
        // and at the target rather than every frame.
        let samples = self.samples();
        if self.inspection.as_ref().is_some_and(|i| super::progressive::read_again(i.samples, samples, target)) {
            self.refresh_inspection()?;
        }
        Ok(stepped)
    }

    /// Makes the display pixels of what was relit since the last draw, and the display filter's
    /// image when it is on: what the window is about to show.
    pub fn prepare_display(&mut self) -> Result<()> {
        let settings = self.document.settings();
        let (exposure, tonemap) = (settings.exposure, settings.tonemap);
        self.renderer.finalize_stale(exposure, tonemap)?;
        if let Some(b) = &self.compare {
            b.renderer.finalize_stale(exposure, tonemap)?;
        }
        self.refresh_denoise()
    }

    /// Inspects the picked pixel again, after an edit, an undo or more samples.
    fn refresh_inspection(&mut self) -> Result<()> {
        if let Some(Inspection { x, y, .. }) = self.inspection {
            self.inspect(x, y)?;
        }
        Ok(())
    }

    /// Brings every row to the same sample count (rows may be a band apart mid-pass, and
    /// pixels an edit restarted may still be catching up), so that what is saved is a whole
    /// number of passes, as `lookdev render` makes.
    fn complete_pass(&mut self) -> Result<()> {
        let settings = self.document.settings();
        let (exposure, tonemap) = (settings.exposure, settings.tonemap);
        while let Some((first, rows)) = self.renderer.lagging_rows() {
            // Restarted pixels stop at their rows' counts, so may take several samples at once;
            // lagging rows are one band's samples behind.
            let count =
                if self.renderer.restarted_region().is_some() { super::progressive::CATCH_UP_SAMPLES } else { 1 };
            self.renderer.render_rows(first, rows, count)?;
            self.renderer.finalize_rows(first, rows, exposure, tonemap)?;
        }
        Ok(())
    }

    /// Saves the render as `lookdev render --out` would at the same spp and seed: a PNG of the
    /// display pixels (exposure and tone map applied), or an EXR of linear radiance.
    pub fn save_image(&mut self, path: &Path) -> Result<u32> {
        let format = OutputFormat::from_path(path)?;
        self.complete_pass()?;
        if self.samples() == 0 {
            return Err(Error::input_file(path, "not saved: nothing has been rendered yet"));
        }
        let settings = self.document.settings().clone();
        let (width, height) = (self.width(), self.height());
        match format {
            OutputFormat::Exr => {
                let radiance = self.renderer.read_radiance()?;
                let environment = self.environments.iter().find(|(p, _)| *p == self.shown.environment).map(|(_, e)| e);
                let metadata = environment
                    .map(|e| output::Metadata::of_render(self.document.look(), &settings, e, &self.recorded))
                    .unwrap_or_default();
                output::write_exr_with(
                    path,
                    width,
                    height,
                    &radiance,
                    settings.lighting.background,
                    Vec::new(),
                    &metadata.entries,
                )?;
            }
            OutputFormat::Png => {
                output::check_finite(path, &self.renderer.read_radiance()?)?;
                let pixels = self.renderer.read_display(settings.exposure, settings.tonemap)?;
                output::write_png(path, width, height, &pixels, !settings.lighting.background)?;
            }
        }
        Ok(self.samples())
    }

    /// Inspects pixel (x, y): its object, masks, layer weights, material and radiance.
    pub fn inspect(&mut self, x: u32, y: u32) -> Result<Inspection> {
        if x >= self.width() || y >= self.height() {
            return Err(Error::input(format!("pixel {x},{y} is outside the {}x{} image", self.width(), self.height())));
        }
        let index = (y * self.width() + x) as usize;
        let object_id = self.gbuffer.object_id[index];
        let coverage = self.gbuffer.coverage[index];
        let masks: Vec<(String, f32)> =
            self.gbuffer.masks.iter().map(|(name, values)| (name.clone(), values[index])).collect();
        let maps: Vec<(String, f32)> =
            self.gbuffer.maps.iter().map(|(name, values)| (name.clone(), values[index])).collect();
        let mask_value = |key: &str| {
            let channel = format!("{}{key}", crate::gbuffer::MASK_PREFIX);
            self.gbuffer.stack_channel_at(&channel, index).unwrap_or(0.0)
        };
        let shaded = coverage > 0.0;
        let stack = shaded.then(|| self.stack_of(object_id));
        let layers = match stack.and_then(|object| self.document.stack(object)) {
            Some(stack) => {
                let weights = layer_weights(stack, mask_value);
                stack.layers.iter().zip(weights).map(|(layer, weight)| (layer_label(layer), weight)).collect()
            }
            None => Vec::new(),
        };
        let params = if shaded { self.packed.resolve_gbuffer_pixel(&self.gbuffer, index) } else { Params::default() };
        let settings = self.document.settings();
        let radiance = if self.samples() > 0 {
            self.renderer.read_radiance_pixel(x, y, settings.exposure, settings.tonemap)?
        } else {
            [0.0; 4]
        };
        let inspection = Inspection {
            x,
            y,
            object_id,
            object_name: self.gbuffer.object_names.get(&object_id).cloned(),
            coverage,
            mask_names: self.gbuffer.mask_names.iter().map(|(m, n)| (m.clone(), n.clone())).collect(),
            masks,
            maps,
            occlusion: self.gbuffer.visibility.as_ref().filter(|_| shaded).map(|visibility| {
                let normal = glam::Vec3::from(self.gbuffer.normal[index]);
                crate::visibility::Quadrature::new(visibility.grid).occlusion(visibility.pixel(index), normal)
            }),
            stack,
            layers,
            params,
            radiance,
            samples: self.samples(),
        };
        self.inspection = Some(inspection.clone());
        Ok(inspection)
    }

    /// The stack that shades an object: its own, else the default one.
    pub fn stack_of(&self, object_id: u32) -> ObjectRef {
        let own = self.document.look().objects.iter().any(|o| o.id == Some(object_id));
        if own {
            ObjectRef::Id(object_id)
        } else {
            ObjectRef::Default
        }
    }

    /// Replaces the document (another look was opened) and everything shown of it. On error
    /// (the look's masks or environment do not fit), the old document stays.
    pub fn replace_document(&mut self, document: Document) -> Result<()> {
        PackedStacks::pack(document.look(), self.objects.iter().copied(), &self.gbuffer, &self.gbuffer_name)?;
        self.load_environment(document.settings().environment.as_ref())?;
        self.document = document;
        self.inspection = None;
        self.apply_changes(true)
    }

    /// What A's renderer accumulates beside the total, for the light and variance views. A
    /// change restarts A's accumulation.
    pub fn set_accumulate(&mut self, accumulate: crate::render::renderer::Accumulate) -> Result<()> {
        if accumulate == self.renderer.accumulate() {
            return Ok(());
        }
        self.renderer.set_accumulate(accumulate)?;
        self.progressive.restart();
        self.changed_at = Instant::now();
        self.first_pass_after_change = None;
        Ok(())
    }

    /// A's samples (B's may lag in a split): what A's views are made of.
    pub fn a_samples(&self) -> u32 {
        self.renderer.samples()
    }

    /// A's AOV layers, as `lookdev render --aov` computes them.
    pub fn aov_layers(&self, aovs: &[crate::render::aov::Aov]) -> Result<Vec<crate::render::aov::Layer>> {
        let sources = crate::render::aov::Sources {
            gbuffer: &self.gbuffer,
            look: self.document.look(),
            renderer: &self.renderer,
        };
        crate::render::aov::layers(aovs, &sources)
    }

    /// A's linear radiance, as `read_radiance` gives it.
    pub fn radiance(&self) -> Result<Vec<[f32; 4]>> {
        self.renderer.read_radiance()
    }
}

impl Session {
    /// The image as `save-image` saves it (the pass completed, so a whole number of passes):
    /// linear radiance with the render's metadata, and the display pixels.
    fn capture(&mut self) -> Result<Capture> {
        self.complete_pass()?;
        if self.samples() == 0 {
            return Err(Error::input("snapshot: nothing has been rendered yet"));
        }
        let settings = self.document.settings().clone();
        let radiance = self.renderer.read_radiance()?;
        output::check_finite(Path::new("snapshot"), &radiance)?;
        let display = self.renderer.read_display(settings.exposure, settings.tonemap)?;
        let environment = self.environments.iter().find(|(p, _)| *p == self.shown.environment).map(|(_, e)| e);
        let metadata = environment
            .map(|e| output::Metadata::of_render(self.document.look(), &settings, e, &self.recorded))
            .unwrap_or_default();
        Ok(Capture {
            radiance,
            display,
            spp: self.renderer.samples(),
            metadata: metadata.entries,
            background: settings.lighting.background,
        })
    }

    /// The look as rendered: the document's, with the solo layer alone in its stack.
    pub fn rendered_look(&self) -> std::borrow::Cow<'_, Look> {
        match self.solo.and_then(|id| self.document.look().soloed(id)) {
            Some(look) => std::borrow::Cow::Owned(look),
            None => std::borrow::Cow::Borrowed(self.document.look()),
        }
    }

    /// Snapshots the live image with the look and settings that made it (a soloed layer's
    /// snapshot keeps the others hidden, as it shows them). Returns its name.
    pub fn take_snapshot(&mut self, name: Option<&str>) -> Result<String> {
        let name = self.snapshots.name_for_new(name)?;
        let capture = self.capture()?;
        let (look, settings) = (self.rendered_look().into_owned(), self.document.settings().clone());
        let size = (self.width(), self.height());
        Ok(self.snapshots.add(name, &look, &settings, capture, size)?.name.clone())
    }

    /// Shows a snapshot as B. Its image must be the live image's size.
    pub fn compare_snapshot(&mut self, name: &str, view: SnapshotView) -> Result<()> {
        let snapshot = self.snapshots.get(name)?;
        if (snapshot.width, snapshot.height) != (self.width(), self.height()) {
            return Err(Error::input(format!(
                "snapshot '{name}' is {}x{}, but the g-buffer {} is {}x{}: it was taken of another g-buffer",
                snapshot.width,
                snapshot.height,
                self.gbuffer_name.display(),
                self.width(),
                self.height()
            )));
        }
        let id = snapshot.id;
        self.compare_off();
        self.snapshot_compare =
            Some(SnapshotCompare { name: name.to_string(), id, view, delta: None, delta_key: None });
        self.refresh_delta_e()
    }

    /// The snapshot shown as B, if one is.
    pub fn snapshot_compare(&self) -> Option<&SnapshotCompare> {
        self.snapshot_compare.as_ref()
    }

    /// Remakes the ΔE map when the live image has changed: at 1, 2, 4, … samples and at the
    /// target, as the inspector follows accumulation, and after every change of the look.
    pub fn refresh_delta_e(&mut self) -> Result<()> {
        let (samples, revision, target) = (self.samples(), self.document.revision(), self.target());
        let Some(shown) = self.snapshot_compare.as_mut().filter(|s| s.view == SnapshotView::DeltaE) else {
            return Ok(());
        };
        let key = Some((samples, revision));
        let due = match shown.delta_key {
            Some((shown_samples, shown_revision)) => {
                shown_revision != revision || super::progressive::read_again(shown_samples, samples, target)
            }
            None => true,
        };
        if samples == 0 || shown.delta_key == key || !due {
            return Ok(());
        }
        let Some(snapshot) = self.snapshots.list.iter().find(|s| s.id == shown.id) else { return Ok(()) };
        let settings = self.document.settings();
        let live = self.renderer.read_display(settings.exposure, settings.tonemap)?;
        shown.delta = Some(DeltaE::between(self.gbuffer.width, self.gbuffer.height, &live, &snapshot.display));
        shown.delta_key = key;
        Ok(())
    }

    /// The ΔE map's live sample count, when one is shown.
    pub fn delta_e_samples(&self) -> Option<u32> {
        self.snapshot_compare.as_ref().and_then(|s| s.delta.as_ref().and(s.delta_key)).map(|(samples, _)| samples)
    }

    /// Lists the snapshots of the document's look file when that file changed (a look was
    /// opened, or saved under another name). When it did, returns warnings for snapshots that
    /// cannot be read.
    pub fn follow_look_file(&mut self) -> Option<Vec<String>> {
        if self.snapshots.look_file() == self.document.path() {
            return None;
        }
        let (snapshots, warnings) = Snapshots::open(self.document.path());
        self.snapshots = snapshots;
        self.snapshot_compare = None;
        Some(warnings)
    }

    /// The edit that restores a snapshot's look and settings, once they are known to fit the
    /// g-buffer and its environment is loaded.
    pub fn restore_edit(&mut self, name: &str) -> Result<crate::viewer_state::Edit> {
        let snapshot = self.snapshots.get(name)?;
        let (look, settings) = (snapshot.look.clone(), snapshot.settings.clone());
        PackedStacks::pack(&look, self.objects.iter().copied(), &self.gbuffer, &self.gbuffer_name)
            .map_err(|e| Error::input(format!("snapshot '{name}' cannot be restored: {e}")))?;
        self.load_environment(settings.environment.as_ref())?;
        Ok(crate::viewer_state::Edit::Restore { look: Box::new(look), settings: Box::new(settings) })
    }

    /// Deletes a snapshot; comparing against it ends.
    pub fn delete_snapshot(&mut self, name: &str) -> Result<()> {
        self.snapshots.delete(name)?;
        if self.snapshot_compare.as_ref().is_some_and(|s| s.name == name) {
            self.snapshot_compare = None;
        }
        Ok(())
    }
}

/// A renderer's display image, or its display filter's once that has run.
fn shown_image(renderer: &Renderer, denoise: bool) -> &Image {
    match renderer.denoised_image() {
        Some(image) if denoise => image,
        _ => renderer.display_image(),
    }
}

/// A layer's name in the panels: its own name, else its preset's, else "custom".
pub fn layer_label(layer: &crate::material::look::Layer) -> String {
    layer.name.clone().or_else(|| layer.preset.clone()).unwrap_or_else(|| "custom".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::ContextOptions;
    use crate::render::scene::{GBufferSpec, Scene, SceneSpec};

    fn session(ctx: &Context, size: (u32, u32)) -> Session {
        let spec = SceneSpec {
            gbuffer: GBufferSpec { builtin_size: Some(size), ..GBufferSpec::default() },
            ..SceneSpec::default()
        };
        let scene = Scene::load(&spec).unwrap();
        let document = Document::new(scene.look.clone(), None, scene.settings.clone());
        Session::of_scene(ctx, scene, document).unwrap()
    }

    /// Budgets that change from step to step, as the scheduler's do between interactive frames
    /// and idle slices, give bands of different counts; every row still reaches the target,
    /// and none passes it.
    #[test]
    fn any_mix_of_budgets_brings_every_row_exactly_to_the_target() {
        let ctx = Context::new(&ContextOptions::from_env(std::env::var("LOOKDEV_TEST_DEVICE").ok())).unwrap();
        let mut session = session(&ctx, (48, 96));
        session.override_target(37);
        let budgets = [1, 300, 3, 40, 1, 1, 120].map(Duration::from_millis);
        let mut steps = 0;
        while session.step(budgets[steps % budgets.len()]).unwrap() {
            steps += 1;
            assert!(steps < 5000, "the accumulation never ends: {} spp", session.samples());
        }
        assert!(session.converged());
        let rows: Vec<u32> = (0..session.height()).map(|row| session.renderer.row_samples(row)).collect();
        assert!(rows.iter().all(|&n| n == 37), "{rows:?}");
        drop(session);
        drop(ctx);
    }

    /// A soloed layer alone fills its objects, other stacks are left alone, the look itself
    /// (what is saved) keeps every layer, and the solo lapses when its layer is undone away.
    #[test]
    fn a_solo_shows_one_layer_alone_without_editing_the_look() {
        use crate::viewer_state::Edit;
        let ctx = Context::new(&ContextOptions::from_env(std::env::var("LOOKDEV_TEST_DEVICE").ok())).unwrap();
        let mut session = session(&ctx, (48, 48));
        let ball = ObjectRef::Id(crate::gbuffer::BALL_ID);
        let gold = session.document.stack(ball).unwrap().layers[1].clone();
        let look_before = session.document.look().clone();
        let pixel = (0..session.gbuffer.pixel_count())
            .find(|&i| session.gbuffer.object_id[i] == crate::gbuffer::BALL_ID && session.gbuffer.coverage[i] == 1.0)
            .unwrap();
        let pedestal = (0..session.gbuffer.pixel_count())
            .find(|&i| {
                session.gbuffer.object_id[i] == crate::gbuffer::PEDESTAL_ID && session.gbuffer.coverage[i] == 1.0
            })
            .unwrap();
        let pedestal_before = session.packed.resolve_gbuffer_pixel(&session.gbuffer, pedestal);

        session.solo = Some(gold.id);
        session.sync().unwrap();
        assert_eq!(session.packed.resolve_gbuffer_pixel(&session.gbuffer, pixel), gold.params, "gold fills the ball");
        assert_eq!(session.packed.resolve_gbuffer_pixel(&session.gbuffer, pedestal), pedestal_before);
        assert_eq!(*session.document.look(), look_before, "a solo is no edit");
        assert!(!session
            .rendered_look()
            .objects
            .iter()
            .flat_map(|o| &o.layers)
            .filter(|l| l.id != gold.id)
            .all(|l| l.enabled));

        // Duplicated then undone: the copy's solo lapses, and the stack blends again.
        session.document.apply(Edit::DuplicateLayer { object: ball, layer: 1 }).unwrap();
        session.solo = Some(session.document.stack(ball).unwrap().layers[2].id);
        session.sync().unwrap();
        session.document.undo();
        session.sync().unwrap();
        assert_eq!(session.solo, None);
        assert_ne!(session.packed.resolve_gbuffer_pixel(&session.gbuffer, pixel), gold.params);
        drop(session);
        drop(ctx);
    }
}
