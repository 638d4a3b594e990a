//! The relighting engine: g-buffer, environment and layer stacks on the GPU; resolve, progressive
//! relight passes, and display transforms. Every command that renders drives it.

use super::passes::denoise::DenoisePass;
use super::passes::finalize::{FinalizePass, FinalizePush};
use super::passes::pixel_lists::{PixelLists, RowList};
use super::passes::relight::{Background, RelightPass, Source};
use super::passes::resolve::ResolvePass;
use super::passes::Targets;
use crate::environment::backdrop::Prepared;
use crate::environment::{Environment, GpuEnvironment, Samplers};
use crate::gbuffer::gpu::GpuGBuffer;
use crate::gbuffer::GBuffer;
use crate::gpu::{Buffer, Context, GpuTimer, Image};
use crate::material::stack::{LobesPresent, PackedStacks};
use crate::render::sampling::Sampling;
use crate::shading::brdf::Shading;
use crate::shading::model::Model;
use crate::shading::tonemap::Tonemap;
use crate::Result;
use ash::vk;
use std::cell::{Cell, RefCell};
use std::collections::BTreeSet;

pub use super::passes::relight::{Accumulate, RelightPush, LOBES};
pub use super::passes::RESOLVED_LAYERS;
pub use super::settings::NoiseThreshold;

/// The largest preview block: one relit pixel per 8 × 8.
pub const MAX_PREVIEW_BLOCK: u32 = 8;

/// How the environment lights the scene. A change of the rotation or the intensity restarts
/// accumulation; of `background` alone, only the background is written again.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Degrees about +Y.
    pub rotation_degrees: f32,
    pub intensity: f32,
    /// Whether background pixels show a background ([`Renderer::set_backdrop`] says which:
    /// the environment unless set), or are transparent.
    pub background: bool,
}

impl Lighting {
    /// Whether `other` lights covered pixels as this does: the same but for the background.
    pub fn lights_as(&self, other: &Lighting) -> bool {
        Lighting { background: other.background, ..*self } == *other
    }
}

impl Default for Lighting {
    fn default() -> Self {
        Lighting { rotation_degrees: 0.0, intensity: 1.0, background: true }
    }
}

/// A relighting session for one g-buffer: the g-buffer, environment and layer stacks on the
/// GPU, and the three passes over them (see [`super::passes`]).
pub struct Renderer {
    ctx: Context,
    pub width: u32,
    pub height: u32,
    gbuffer: GpuGBuffer,
    environment: GpuEnvironment,
    targets: Targets,
    resolve: ResolvePass,
    relight: RelightPass,
    finalize: FinalizePass,
    timer: Option<GpuTimer>,
    lighting: Lighting,
    seed: u32,
    /// Samples each row's pixels have in the current accumulation (but the restarted ones').
    row_samples: Vec<u32>,
    /// The covered pixels and the restarted ones, as lists the relight pass runs over.
    lists: PixelLists,
    /// Pixels restarted alone and still catching up with their rows.
    restarted: Option<Restarted>,
    /// Rows whose background image is that of the current lighting and backdrop.
    background_rows: Vec<bool>,
    /// What a shown background is: the environment, the image `backdrop_image`, or a colour.
    backdrop: Background,
    backdrop_colour: [f32; 3],
    /// The backdrop's lat-long image, or a 1×1 placeholder.
    backdrop_image: Image,
    /// Adaptive sampling, when on.
    noise: Option<NoiseThreshold>,
    /// What was asked for with [`Renderer::set_accumulate`]; adaptive sampling adds the variance.
    wanted_accumulate: Accumulate,
    /// Under a noise threshold, each row's pixels still active: counted by the row's last pass,
    /// all its covered pixels before one (and its restarted ones added when they restart).
    row_active: Vec<u32>,
    /// Under a noise threshold, which active list (0 or 1) holds each row's pixels still
    /// sampling, as its last counted pass left them; None where the next pass reads the
    /// covered list (before a first pass, and where pixels restarted).
    row_list: Vec<Option<u32>>,
    /// Whether every row has had a pass since this renderer was made: until then, its display
    /// image holds rows it has not drawn (cleared when made, but not a picture of anything).
    passed: bool,
    /// The block size of the current accumulation's preview, once one is made
    /// ([`Renderer::render_preview`]): rows with no samples yet are shown from it.
    preview: Option<u32>,
    /// The display filter, made when first asked for.
    denoise: Option<DenoisePass>,
    /// The estimator: which environment tables are uploaded.
    sampling: Sampling,
    /// The lobes the relight kernel is specialised for: those of the stacks last set.
    lobes: LobesPresent,
    /// Whether the relight kernel sums shadow catchers' unshadowed light, and the objects that
    /// catch shadows in the stacks last set.
    shadow_catcher: bool,
    shadow_catchers: BTreeSet<u32>,
    /// Whether the relight kernel reads the g-buffer's visibility ([`Renderer::set_visibility`]).
    visibility: bool,
    /// Pixel samples a second of its last dispatch that [`super::progressive::accumulate`]
    /// timed, set-up included: what sizes the next accumulation's first dispatch.
    pace: Option<f64>,
    /// Rows whose radiance image holds their current sums (finalized since they last changed),
    /// so that reading the radiance need not finalize them again: on a CPU driver a finalize of
    /// the whole image costs about as much as a sample of every covered pixel.
    finalized_rows: RefCell<Vec<bool>>,
    /// The exposure and tone map the display image was last made with, which a read of the
    /// radiance keeps when it finalizes rows.
    display_settings: Cell<(f32, Tonemap)>,
}

impl Renderer {
    /// A renderer of the default (Disney 2012) model.
    pub fn new(ctx: &Context, gbuffer: &GBuffer, environment: &Environment) -> Result<Renderer> {
        Renderer::with_model(ctx, gbuffer, environment, &Model::default())
    }

    /// A renderer of a BRDF model (docs/shading.md#brdf-models).
    pub fn with_model(ctx: &Context, gbuffer: &GBuffer, environment: &Environment, model: &Model) -> Result<Renderer> {
        let specialization = Specialization { model: *model, ..Specialization::default() };
        Renderer::with_kernels(ctx, gbuffer, environment, Sampling::default(), KernelSource::Compile(specialization))
    }

    /// A renderer with the kernels `kernels` gives and the estimator `sampling`: its images are
    /// uploaded first, then it waits for the kernels, which may be compiling on another thread
    /// meanwhile ([`crate::render::startup`]). It starts with the kernels' accumulation and
    /// no noise threshold; set what the render needs, as with any renderer.
    pub fn with_kernels(
        ctx: &Context,
        gbuffer: &GBuffer,
        environment: &Environment,
        sampling: Sampling,
        kernels: KernelSource,
    ) -> Result<Renderer> {
        let (width, height) = (gbuffer.width, gbuffer.height);
        let Specialization { model, accumulate, product, lobes, maps, visibility, shadow_catcher } =
            kernels.specialization();
        let gpu_gbuffer = GpuGBuffer::upload(ctx, gbuffer)?;
        let mut targets = Targets::new(ctx, width, height, accumulate)?;
        if shadow_catcher {
            targets.make_unshadowed(ctx)?;
        }
        let gpu_environment = upload_environment(ctx, environment, sampling)?;
        let lists = PixelLists::new(ctx, gbuffer)?;
        let backdrop_image = backdrop_placeholder(ctx)?;
        let kernels = kernels.wait(ctx)?;
        let resolve = ResolvePass::new(ctx, kernels.resolve, maps);
        let relight = RelightPass::new(
            ctx,
            kernels.relight,
            &model,
            accumulate,
            &gpu_gbuffer,
            &targets,
            &lists,
            &gpu_environment,
            &backdrop_image,
        )?;
        let finalize = FinalizePass::new(kernels.finalize, &gpu_gbuffer, &targets)?;
        let mut renderer = Renderer {
            ctx: ctx.clone(),
            width,
            height,
            gbuffer: gpu_gbuffer,
            environment: gpu_environment,
            targets,
            resolve,
            relight,
            finalize,
            timer: GpuTimer::new(ctx, 2)?,
            lighting: Lighting::default(),
            seed: 0,
            row_samples: vec![0; height as usize],
            row_active: (0..height).map(|y| lists.covered.row_len(y)).collect(),
            row_list: vec![None; height as usize],
            lists,
            restarted: None,
            background_rows: vec![false; height as usize],
            backdrop: Background::Environment,
            backdrop_colour: [0.0; 3],
            backdrop_image,
            noise: None,
            wanted_accumulate: accumulate,
            passed: false,
            preview: None,
            denoise: None,
            sampling,
            lobes,
            shadow_catcher,
            shadow_catchers: BTreeSet::new(),
            visibility: true,
            pace: None,
            finalized_rows: RefCell::new(vec![false; height as usize]),
            display_settings: Cell::new((0.0, Tonemap::Linear)),
        };
        // Kernels compiled for another estimator's sampler, or another visibility grid, are
        // replaced, not used.
        if product != sampling.product_kernel() || visibility != renderer.gbuffer.visibility_side {
            renderer.respecialize(model, accumulate)?;
        }
        Ok(renderer)
    }

    /// Replaces the environment (its texels and sampling tables); accumulation restarts.
    pub fn set_environment(&mut self, environment: &Environment) -> Result<()> {
        let gpu_environment = upload_environment(&self.ctx, environment, self.sampling)?;
        self.relight.set_environment(&gpu_environment)?;
        self.environment = gpu_environment;
        self.background_rows.fill(false);
        self.restart();
        Ok(())
    }

    /// The BRDF model being rendered, with its energy table when it has one.
    pub fn shading(&self) -> &Shading {
        &self.relight.shading
    }

    /// Switches the BRDF model: a new specialization of the relight kernel (and energy table);
    /// accumulation restarts. Nothing happens when the model is the same.
    pub fn set_model(&mut self, model: &Model) -> Result<()> {
        if *model == self.relight.shading.model {
            return Ok(());
        }
        self.respecialize(*model, self.relight.accumulate)
    }

    /// What the relight kernel accumulates beside the total (for the AOVs that need it), with
    /// its images; accumulation restarts. Nothing happens when it is the same.
    pub fn set_accumulate(&mut self, accumulate: Accumulate) -> Result<()> {
        self.wanted_accumulate = accumulate;
        self.apply_accumulate()
    }

    /// Makes the relight kernel accumulate what was asked for, and the variance adaptive
    /// sampling needs; accumulation restarts if that changes.
    fn apply_accumulate(&mut self) -> Result<()> {
        let accumulate = kernel_accumulate(self.wanted_accumulate, self.noise);
        if accumulate == self.relight.accumulate {
            return Ok(());
        }
        self.targets.set_accumulate(&self.ctx, accumulate)?;
        self.respecialize(self.relight.shading.model, accumulate)
    }

    /// What the relight kernel accumulates beside the total, as asked for.
    pub fn accumulate(&self) -> Accumulate {
        self.wanted_accumulate
    }

    /// A new relight pass for this model and accumulation.
    fn respecialize(&mut self, model: Model, accumulate: Accumulate) -> Result<()> {
        self.relight = RelightPass::new(
            &self.ctx,
            RelightPass::pipeline(
                &self.ctx,
                &model,
                accumulate,
                self.sampling.product_kernel(),
                self.lobes,
                self.visibility_side(),
                self.shadow_catcher,
            )?,
            &model,
            accumulate,
            &self.gbuffer,
            &self.targets,
            &self.lists,
            &self.environment,
            &self.backdrop_image,
        )?;
        // The background pass writes which pixels catch shadows.
        self.background_rows.fill(false);
        self.restart();
        Ok(())
    }

    /// Relights with the g-buffer's visibility or as if every direction above the horizon were
    /// seen (for comparison): a kernel specialised without it, whose images are those of a
    /// g-buffer that has none, bit for bit. Accumulation restarts when this changes anything.
    pub fn set_visibility(&mut self, on: bool) -> Result<()> {
        if on == self.visibility {
            return Ok(());
        }
        let before = self.visibility_side();
        self.visibility = on;
        if self.visibility_side() == before {
            return Ok(());
        }
        self.respecialize(self.relight.shading.model, self.relight.accumulate)
    }

    /// The side of the visibility grid the relight kernel reads: 0 when off or absent.
    fn visibility_side(&self) -> u32 {
        if self.visibility {
            self.gbuffer.visibility_side
        } else {
            0
        }
    }

    /// Samples every pixel has accumulated since the last change: the least of any row's
    /// (under a noise threshold, stopped pixels keep fewer).
    pub fn samples(&self) -> u32 {
        (0..self.height).map(|row| self.row_samples(row)).min().unwrap_or(0)
    }

    /// Whether every row has been rendered at least once since the renderer was made (restarts
    /// do not undo it): then its display image shows a whole picture, if not the latest one.
    pub fn has_finished_a_pass(&self) -> bool {
        self.passed
    }

    /// Samples row `row` has in the current accumulation: the least of its pixels', those
    /// restarted alone included.
    pub fn row_samples(&self, row: u32) -> u32 {
        let samples = self.row_samples[row as usize];
        match &self.restarted {
            Some(r) if r.list.row_len(row) > 0 => samples.min(r.samples[row as usize]),
            _ => samples,
        }
    }

    /// The first run of rows with fewer samples than the most-sampled row, as (first row, rows):
    /// what a band-by-band pass still has to do before every row has the same count. While
    /// restarted pixels catch up, the rows from the first to the last that holds them.
    pub fn lagging_rows(&self) -> Option<(u32, u32)> {
        if let Some(r) = &self.restarted {
            let lagging = |&y: &u32| r.lags(y, &self.row_samples);
            if let Some(first) = (0..self.height).find(lagging) {
                let last = (0..self.height).rev().find(lagging).expect("found from the front");
                return Some((first, last - first + 1));
            }
        }
        let most = *self.row_samples.iter().max()?;
        let first = self.row_samples.iter().position(|&n| n < most)?;
        let rows = self.row_samples[first..].iter().take_while(|&&n| n < most).count();
        Some((first as u32, rows as u32))
    }

    /// Changes the lighting; accumulation restarts if the rotation or the intensity changed.
    /// Showing the background or not changes only the background, which each row writes anew
    /// when it is next relit, or every row at once with [`Renderer::write_background`].
    pub fn set_lighting(&mut self, lighting: Lighting) {
        if lighting == self.lighting {
            return;
        }
        let restart = !lighting.lights_as(&self.lighting);
        self.lighting = lighting;
        self.background_rows.fill(false);
        if restart {
            self.restart();
        } else {
            self.finalized_rows.get_mut().fill(false);
        }
    }

    /// Changes what a shown background is. Covered pixels keep their samples: only the
    /// background is written again, and every row finalized anew.
    pub fn set_backdrop(&mut self, backdrop: &Prepared) -> Result<()> {
        let (kind, colour, image) = match backdrop {
            Prepared::Environment => (Background::Environment, [0.0; 3], None),
            Prepared::Colour(rgb) => (Background::Colour, *rgb, None),
            Prepared::Image(env) => (Background::Image, [0.0; 3], Some(env)),
        };
        if let Some(env) = image {
            let max = self.ctx.info().max_image_dimension_2d;
            if env.width > max || env.height > max {
                return Err(crate::Error::input_file(
                    &env.source,
                    format!(
                        "the background is {}x{}, larger than this device's {max} pixel limit",
                        env.width, env.height
                    ),
                ));
            }
            let rgba = vk::Format::R32G32B32A32_SFLOAT;
            let uploaded = Image::filled(&self.ctx, rgba, env.width, env.height, |out: &mut [[f32; 4]]| {
                for (texel, &[r, g, b]) in out.iter_mut().zip(&env.texels) {
                    *texel = [r, g, b, 0.0];
                }
            })?;
            self.relight.set_backdrop(&uploaded)?;
            self.backdrop_image = uploaded;
        } else if self.backdrop == Background::Image {
            // The image is let go of; a placeholder is bound in its place.
            let placeholder = backdrop_placeholder(&self.ctx)?;
            self.relight.set_backdrop(&placeholder)?;
            self.backdrop_image = placeholder;
        }
        self.backdrop = kind;
        self.backdrop_colour = colour;
        self.background_rows.fill(false);
        self.finalized_rows.get_mut().fill(false);
        self.write_background()
    }

    /// Writes the background of every row whose background is not the current one, now,
    /// rather than when the row is next relit: what the viewer does after a change of the
    /// background alone, whose samples are all kept, to show it even once they are all taken.
    /// Nothing happens before the stacks are set (the background pass reads from them which
    /// pixels catch shadows); rows written are finalized anew.
    pub fn write_background(&mut self) -> Result<()> {
        if !self.resolve.has_stacks() || self.background_rows.iter().all(|&done| done) {
            return Ok(());
        }
        self.finalized_rows.get_mut().fill(false);
        let pushes = self.background_pushes(0, self.height);
        self.dispatch(&pushes).map(drop)
    }

    /// Starts a new accumulation with everything unchanged.
    pub fn restart(&mut self) {
        self.row_samples.fill(0);
        self.finalized_rows.get_mut().fill(false);
        self.restarted = None;
        for (y, active) in self.row_active.iter_mut().enumerate() {
            *active = self.lists.covered.row_len(y as u32);
        }
        self.row_list.fill(None);
        self.preview = None;
    }

    /// Restarts the accumulation of `pixels` only (indices `y * width + x`, ascending): every
    /// other pixel keeps its samples, bit for bit. The next passes relight the restarted pixels
    /// alone, from sample 0, until they have their rows' counts ([`Renderer::render_rows`]);
    /// then all go on together, and the image is what a fresh render at that count makes. Until
    /// their first pass they show their old sums. Pixels restarted earlier that have not caught
    /// up yet restart again with these; uncovered pixels have no samples and are left out.
    pub fn restart_pixels(&mut self, pixels: &[u32]) {
        let size = self.width * self.height;
        let mut chosen: Vec<u32> = pixels.iter().copied().filter(|&p| p < size).collect();
        if let Some(r) = &self.restarted {
            let width = self.width;
            chosen.extend(r.list.pixels.iter().map(|&p| (p >> 16) * width + (p & 0xffff)));
        }
        chosen.sort_unstable();
        chosen.dedup();
        // Rows with no samples start over anyway.
        chosen.retain(|&p| self.lists.covered_mask[p as usize] && self.row_samples[(p / self.width) as usize] > 0);
        if chosen.is_empty() {
            self.restarted = None;
            return;
        }
        let list = RowList::from_indices(self.width, self.height, chosen);
        for (y, active) in self.row_active.iter_mut().enumerate() {
            *active = (*active + list.row_len(y as u32)).min(self.lists.covered.row_len(y as u32));
            if list.row_len(y as u32) > 0 {
                // The restarted pixels may have stopped: the row's next pass counts them all again.
                self.row_list[y] = None;
            }
        }
        self.restarted = Some(Restarted { samples: vec![0; self.height as usize], list, uploaded: false });
    }

    /// While pixels restarted alone ([`Renderer::restart_pixels`]) catch up: how many they
    /// are, the samples they have (the least), and the samples the rest have (the least).
    pub fn restarted_region(&self) -> Option<(usize, u32, u32)> {
        let r = self.restarted.as_ref()?;
        let theirs = (0..self.height).filter(|&y| r.list.row_len(y) > 0).map(|y| r.samples[y as usize]).min()?;
        let rest = self.row_samples.iter().copied().min().unwrap_or(0);
        Some((r.list.pixels.len(), theirs, rest))
    }

    /// Turns adaptive sampling on or off (docs/shading.md#adaptive-sampling); accumulation
    /// restarts if that changes anything.
    pub fn set_noise_threshold(&mut self, noise: Option<NoiseThreshold>) -> Result<()> {
        if noise == self.noise {
            return Ok(());
        }
        if let Some(n) = noise {
            NoiseThreshold::new(n.threshold, n.min_samples)?;
        }
        self.noise = noise;
        self.restart();
        self.apply_accumulate()
    }

    /// The adaptive sampling in effect, if any.
    pub fn noise_threshold(&self) -> Option<NoiseThreshold> {
        self.noise
    }

    /// Under a noise threshold, the covered pixels still taking samples: as each row's last
    /// pass left them (all of a row's before its first pass). None without a threshold.
    pub fn active_pixels(&self) -> Option<u64> {
        self.noise.map(|_| self.row_active.iter().map(|&n| n as u64).sum())
    }

    /// The covered pixels: every pixel the relight pass samples.
    pub fn covered_pixels(&self) -> usize {
        self.lists.covered.pixels.len()
    }

    /// The pixels the next pass relights: the restarted ones while they catch up, else those
    /// still active under a noise threshold, else every covered pixel.
    pub fn pixels_to_relight(&self) -> usize {
        match (&self.restarted, self.active_pixels()) {
            (Some(r), _) => r.list.pixels.len(),
            (None, Some(active)) => active as usize,
            (None, None) => self.covered_pixels(),
        }
    }

    /// Pixel samples a second that a timed dispatch of this renderer reached, set-up included
    /// ([`Renderer::set_pace`]); None before one.
    pub fn pace(&self) -> Option<f64> {
        self.pace
    }

    /// Notes the pace a dispatch reached, for the next accumulation's first dispatch.
    pub fn set_pace(&mut self, samples_per_second: f64) {
        self.pace = Some(samples_per_second);
    }

    pub fn set_seed(&mut self, seed: u32) {
        if seed != self.seed {
            self.seed = seed;
            self.restart();
        }
    }

    /// Uploads new layer stacks and resolves them into one material per covered pixel (once per
    /// edit, not per sample; only the pixels of the stacks that changed). Accumulation restarts,
    /// and the relight kernel is respecialised first if the stacks have other lobes
    /// ([`PackedStacks::lobes`]): a kernel the driver refuses leaves the renderer as it was.
    pub fn set_stacks(&mut self, packed: &PackedStacks) -> Result<()> {
        self.set_kernel_needs(packed)?;
        self.resolve_stacks(packed)?;
        self.restart();
        Ok(())
    }

    /// Uploads `packed` and resolves the pixels of the stacks that changed.
    fn resolve_stacks(&mut self, packed: &PackedStacks) -> Result<()> {
        self.resolve.set_stacks(&self.ctx, &mut self.gbuffer, packed, &self.targets, &self.lists)?;
        self.timed(|renderer, cmd| renderer.resolve.record(cmd))?;
        self.resolve.mark_resolved(packed);
        Ok(())
    }

    /// Specialises the relight kernel for the lobes and shadow catchers of `packed` and
    /// restarts accumulation, unless it already is specialised for them; a change of which
    /// objects catch shadows restarts it too, as their backgrounds are written again. Returns
    /// whether accumulation restarted; if respecialising fails, the kernel and what it is for
    /// stay as they were.
    fn set_kernel_needs(&mut self, packed: &PackedStacks) -> Result<bool> {
        let catchers = packed.shadow_catcher_objects();
        let catchers_changed = catchers != self.shadow_catchers;
        let (lobes, shadow_catcher) = (packed.lobes(), !catchers.is_empty());
        if lobes != self.lobes || shadow_catcher != self.shadow_catcher {
            // The unshadowed sums are made before a kernel writes them (the relight pass binds
            // them when respecialised).
            if shadow_catcher && self.targets.make_unshadowed(&self.ctx)? {
                self.finalize.rebind(&self.gbuffer, &self.targets)?;
            }
            let previous = (self.lobes, self.shadow_catcher);
            (self.lobes, self.shadow_catcher) = (lobes, shadow_catcher);
            if let Err(e) = self.respecialize(self.relight.shading.model, self.relight.accumulate) {
                (self.lobes, self.shadow_catcher) = previous;
                return Err(e);
            }
        } else if !catchers_changed {
            return Ok(false);
        }
        self.shadow_catchers = catchers;
        self.background_rows.fill(false);
        self.restart();
        Ok(true)
    }

    /// The lobes the relight kernel is specialised for.
    pub fn lobes(&self) -> LobesPresent {
        self.lobes
    }

    /// Runs `record` in one submission, bracketed by timestamps when the device has them.
    fn timed(&self, record: impl FnOnce(&Renderer, vk::CommandBuffer)) -> Result<Option<f64>> {
        self.ctx.run(|cmd| {
            if let Some(timer) = &self.timer {
                timer.reset(cmd);
                timer.begin(cmd, 0);
            }
            record(self, cmd);
            if let Some(timer) = &self.timer {
                timer.end(cmd, 0);
            }
            Ok(())
        })?;
        match &self.timer {
            Some(timer) => Ok(Some(timer.read(1)?[0])),
            None => Ok(None),
        }
    }

    /// Accumulates `count` more samples per pixel in one dispatch. Returns its GPU time.
    pub fn render_samples(&mut self, count: u32) -> Result<Option<f64>> {
        self.render_rows(0, self.height, count)
    }

    /// Accumulates `count` more samples for the pixels of rows `first_row..first_row + rows`
    /// only: how the viewer bounds the work of one frame. Rows keep their own counts, so bands may
    /// differ by a pass; [`Renderer::samples`] counts what every row has. Rows with different
    /// counts take a dispatch each (usually there is one). While pixels restarted alone
    /// ([`Renderer::restart_pixels`]) lag, only they are relit, and no further than their rows'
    /// counts. Returns the GPU time.
    pub fn render_rows(&mut self, first_row: u32, rows: u32, count: u32) -> Result<Option<f64>> {
        assert!(self.resolve.has_stacks(), "set_stacks() must run before rendering");
        if count == 0 {
            return Ok(Some(0.0));
        }
        let end = first_row.saturating_add(rows).min(self.height);
        self.finalized_rows.get_mut()[first_row.min(end) as usize..end as usize].fill(false);
        if self.restarted.as_ref().is_some_and(|r| (0..self.height).any(|y| r.lags(y, &self.row_samples))) {
            return self.render_restarted(first_row, end, count);
        }
        self.restarted = None;
        let mut total = Some(0.0);
        let mut start = first_row;
        while start < end {
            let first_sample = self.row_samples[start as usize];
            let list = self.row_list[start as usize];
            let run_end = (start..end)
                .find(|&r| self.row_samples[r as usize] != first_sample || self.row_list[r as usize] != list)
                .unwrap_or(end);
            let mut pushes = self.background_pushes(start, run_end);
            let (first, last) = self.lists.covered.range(start, run_end);
            let counting = self.noise.is_some();
            // Under a noise threshold, a row's pass after its first reads the pixels the last
            // left active, and the pass writes those it leaves into the other list. The covered
            // list's pass writes list 0.
            let (source, list_in) = match list {
                Some(list) if counting => (Source::Active, list),
                _ => (Source::Covered, 1),
            };
            if source == Source::Active {
                self.lists.set_entering(start, run_end, &self.row_active);
            }
            pushes.push(RelightPush { list_in, ..self.push(source, first, last, first_sample, count) });
            if counting {
                self.lists.clear_active(start, run_end);
            }
            let time = self.dispatch(&pushes)?;
            if counting {
                for y in start..run_end {
                    self.row_active[y as usize] = self.lists.active(y);
                    self.row_list[y as usize] = Some(1 - list_in);
                }
            }
            total = total.zip(time).map(|(a, b)| a + b);
            self.row_samples[start as usize..run_end as usize].iter_mut().for_each(|n| *n += count);
            start = run_end;
        }
        self.passed |= self.samples() > 0;
        Ok(total)
    }

    /// Relights the restarted pixels of rows `first_row..end_row` that lag their rows, up to
    /// `count` samples and no further than their rows' counts: a dispatch per run of rows whose
    /// restarted pixels have the same count and catch up to the same.
    fn render_restarted(&mut self, first_row: u32, end_row: u32, count: u32) -> Result<Option<f64>> {
        let mut restarted = self.restarted.take().expect("called while pixels are restarted");
        let result = (|| {
            if !restarted.uploaded {
                self.lists.upload_restarted(&self.ctx, &restarted.list)?;
                restarted.uploaded = true;
            }
            // Each row's (samples, target), or None where nothing of it is to be relit.
            let key = |r: &Restarted, y: u32| {
                r.lags(y, &self.row_samples).then(|| (r.samples[y as usize], self.row_samples[y as usize]))
            };
            let mut total = Some(0.0);
            let mut start = first_row;
            while start < end_row {
                let Some((first_sample, target)) = key(&restarted, start) else {
                    start += 1;
                    continue;
                };
                // Rows without restarted pixels add nothing to the list's range, so may join.
                let run_end = (start..end_row)
                    .find(|&y| key(&restarted, y) != Some((first_sample, target)) && restarted.list.row_len(y) > 0)
                    .unwrap_or(end_row);
                let n = count.min(target - first_sample);
                let (first, last) = restarted.list.range(start, run_end);
                let push = self.push(Source::Restarted, first, last, first_sample, n);
                let time = self.dispatch(&[push])?;
                total = total.zip(time).map(|(a, b)| a + b);
                for y in start..run_end {
                    if restarted.list.row_len(y) > 0 {
                        restarted.samples[y as usize] += n;
                    }
                }
                start = run_end;
            }
            Ok(total)
        })();
        if (0..self.height).any(|y| restarted.lags(y, &self.row_samples)) {
            self.restarted = Some(restarted);
        }
        result
    }

    /// Relights the top-left pixel of every `block` × `block` block with sample 0 of the new
    /// accumulation, and writes every pixel's background: the viewer's first, whole frame after
    /// a change, at a `block`²-th of a pass's cost. Rows without samples are then shown from it
    /// ([`Renderer::finalize_rows`]), interpolated within each object. The accumulation is left as
    /// a pass will make it: the first pass writes the same sample 0 over those pixels, so the
    /// preview changes no bits of any render. It must come before the first pass.
    pub fn render_preview(&mut self, block: u32) -> Result<Option<f64>> {
        assert!(self.resolve.has_stacks(), "set_stacks() must run before rendering");
        if !(2..=MAX_PREVIEW_BLOCK).contains(&block) {
            return Err(crate::Error::input(format!(
                "a preview block is 2 to {MAX_PREVIEW_BLOCK} pixels, not {block}"
            )));
        }
        if self.row_samples.iter().any(|&n| n > 0) {
            return Err(crate::Error::gpu("a preview comes before the first pass of an accumulation"));
        }
        self.finalize.prepare_preview(&self.ctx, &self.gbuffer, &self.targets)?;
        self.finalized_rows.get_mut().fill(false);
        let mut pushes = self.background_pushes(0, self.height);
        let blocks = self.width.div_ceil(block) * self.height.div_ceil(block);
        pushes.push(RelightPush { block, ..self.push(Source::Preview, 0, blocks, 0, 1) });
        let time = self.dispatch(&pushes)?;
        // `passed` stays as it was: until a first pass, an A/B split's B half shows A, as it
        // did before previews.
        self.preview = Some(block);
        Ok(time)
    }

    /// The block size of the current accumulation's preview, if one was made.
    pub fn preview_block(&self) -> Option<u32> {
        self.preview
    }

    /// The background pass over rows `first_row..end_row` whose background is not the current
    /// lighting's (none when all are), marking them done: once per lighting, not per sample.
    fn background_pushes(&mut self, first_row: u32, end_row: u32) -> Vec<RelightPush> {
        let stale = |y: &u32| !self.background_rows[*y as usize];
        let Some(first) = (first_row..end_row).find(stale) else {
            return Vec::new();
        };
        let last = (first_row..end_row).rev().find(stale).expect("found from the front");
        self.background_rows[first as usize..=last as usize].fill(true);
        vec![self.push(Source::Background, first * self.width, (last + 1) * self.width, 0, 0)]
    }

    /// A relight dispatch of `source`'s invocations `first..end`, adding `count` samples to
    /// pixels that have `first_sample`.
    fn push(&self, source: Source, first: u32, end: u32, first_sample: u32, count: u32) -> RelightPush {
        let rotation = self.lighting.rotation_degrees.to_radians();
        RelightPush {
            first_sample,
            sample_count: count,
            seed: self.seed,
            background: if self.lighting.background { self.backdrop } else { Background::None } as u32,
            cos_rotation: rotation.cos(),
            sin_rotation: rotation.sin(),
            intensity: self.lighting.intensity,
            source: source as u32,
            first,
            end,
            block: 1,
            noise_threshold: self.noise.map_or(0.0, |n| n.threshold),
            min_samples: self.noise.map_or(2, |n| n.min_samples),
            list_in: 0,
            background_r: self.backdrop_colour[0],
            background_g: self.backdrop_colour[1],
            background_b: self.backdrop_colour[2],
        }
    }

    /// Runs the relight dispatches `pushes` in one timed submission.
    fn dispatch(&self, pushes: &[RelightPush]) -> Result<Option<f64>> {
        self.timed(|renderer, cmd| {
            for push in pushes {
                renderer.relight.record(cmd, push);
            }
        })
    }

    /// Reading the image before the first pass would show whatever an earlier accumulation left.
    fn check_rendered(&self) -> Result<()> {
        if self.row_samples.iter().all(|&n| n == 0) {
            return Err(crate::Error::gpu("nothing has been rendered since the last change"));
        }
        Ok(())
    }

    /// Records finalize.comp over rows `first_row..first_row + rows`: the linear radiance image
    /// and the display pixels of the current sums. Rows with no samples yet are made from the
    /// preview, when there is one; a dispatch per run of rows of either kind.
    pub fn record_finalize(&self, cmd: vk::CommandBuffer, first_row: u32, rows: u32, exposure: f32, tonemap: Tonemap) {
        let end = first_row + rows.min(self.height.saturating_sub(first_row));
        self.finalized_rows.borrow_mut()[first_row.min(end) as usize..end as usize].fill(true);
        self.display_settings.set((exposure, tonemap));
        let block_of = |row: u32| match self.preview {
            Some(block) if self.row_samples[row as usize] == 0 => block,
            _ => 1,
        };
        let mut start = first_row;
        while start < end {
            let block = block_of(start);
            let run_end = (start..end).find(|&r| block_of(r) != block).unwrap_or(end);
            let push = FinalizePush {
                exposure_scale: exposure.exp2(),
                tonemap: tonemap.gpu_id(),
                show_background: self.lighting.background as u32,
                first_row: start,
                end_row: run_end,
                block,
            };
            self.finalize.record(cmd, self.width, &push);
            start = run_end;
        }
        crate::gpu::context::full_barrier(&self.ctx.shared.device, cmd);
    }

    /// Makes the display pixels (and linear radiance) of every row relit since it was last
    /// finalized, with `exposure` and `tonemap`, in one submission: what the viewer does before
    /// it draws, however many bands were relit since.
    pub fn finalize_stale(&self, exposure: f32, tonemap: Tonemap) -> Result<()> {
        let stale = runs_of_false(&self.finalized_rows.borrow());
        if stale.is_empty() {
            return Ok(());
        }
        self.ctx.run(|cmd| {
            for &(first, rows) in &stale {
                self.record_finalize(cmd, first, rows, exposure, tonemap);
            }
            Ok(())
        })
    }

    /// Makes the display pixels (and linear radiance) of rows `first_row..first_row + rows` from
    /// their current sums, for the viewer to show.
    pub fn finalize_rows(&self, first_row: u32, rows: u32, exposure: f32, tonemap: Tonemap) -> Result<()> {
        self.ctx.run(|cmd| {
            self.record_finalize(cmd, first_row, rows, exposure, tonemap);
            Ok(())
        })
    }

    /// The display image (sRGB-encoded RGBA8), which the viewer samples through its sRGB view.
    pub fn display_image(&self) -> &Image {
        &self.targets.display
    }

    /// Linear radiance per pixel, row 0 at the top: rgb composited over the background with
    /// alpha 1, or, with the background off, premultiplied by coverage with alpha = coverage.
    /// Rows not finalized since they last changed are finalized first, their display pixels
    /// with the exposure and tone map of the last finalize, so what the viewer shows stays.
    pub fn read_radiance(&self) -> Result<Vec<[f32; 4]>> {
        self.check_rendered()?;
        let staging = Buffer::staging(&self.ctx, self.targets.radiance.byte_size())?;
        let stale: Vec<(u32, u32)> = runs_of_false(&self.finalized_rows.borrow());
        let (exposure, tonemap) = self.display_settings.get();
        self.ctx.run(|cmd| {
            for &(first, rows) in &stale {
                self.record_finalize(cmd, first, rows, exposure, tonemap);
            }
            self.targets.radiance.record_read(cmd, &staging);
            Ok(())
        })?;
        Ok(bytemuck::cast_slice(&staging.bytes()[..self.targets.radiance.byte_size() as usize]).to_vec())
    }

    /// The linear radiance of one pixel, as [`Renderer::read_radiance`] gives it. Its row's
    /// display pixels are remade with `exposure` and `tonemap`, so what the viewer shows stays.
    pub fn read_radiance_pixel(&self, x: u32, y: u32, exposure: f32, tonemap: Tonemap) -> Result<[f32; 4]> {
        self.check_rendered()?;
        let staging = Buffer::staging(&self.ctx, 16)?;
        self.ctx.run(|cmd| {
            self.record_finalize(cmd, y, 1, exposure, tonemap);
            self.targets.radiance.record_read_texel(cmd, &staging, x, y);
            Ok(())
        })?;
        Ok(bytemuck::pod_read_unaligned(&staging.bytes()[..16]))
    }

    /// Display pixels: exposure, tone map and sRGB, as RGBA8; straight alpha (the coverage) when
    /// the background is off, opaque otherwise.
    pub fn read_display(&self, exposure: f32, tonemap: Tonemap) -> Result<Vec<u8>> {
        self.check_rendered()?;
        let staging = Buffer::staging(&self.ctx, self.targets.display.byte_size())?;
        self.ctx.run(|cmd| {
            self.record_finalize(cmd, 0, self.height, exposure, tonemap);
            self.targets.display.record_read(cmd, &staging);
            Ok(())
        })?;
        Ok(staging.bytes()[..self.targets.display.byte_size() as usize].to_vec())
    }

    /// Filters the linear radiance as it stands (what [`Self::read_shown_display`] shows) with
    /// the g-buffer-guided display filter, into [`Self::denoised_image`]. The accumulation and
    /// the images saved are untouched.
    pub fn denoise(&mut self, exposure: f32, tonemap: Tonemap) -> Result<()> {
        if self.denoise.is_none() {
            self.denoise = Some(DenoisePass::new(&self.ctx, &self.gbuffer, &self.targets)?);
        }
        let pass = self.denoise.as_ref().expect("just made");
        let size = (self.width, self.height);
        let background = self.lighting.background;
        self.ctx.run(|cmd| {
            pass.record(&self.ctx, cmd, size, exposure, tonemap, background);
            Ok(())
        })
    }

    /// The display filter's image (sRGB-encoded RGBA8), once [`Self::denoise`] has run.
    pub fn denoised_image(&self) -> Option<&Image> {
        self.denoise.as_ref().map(|d| &d.display)
    }

    /// The display filter's pixels, as [`Self::read_shown_display`] reads the unfiltered ones.
    pub fn read_denoised(&self) -> Result<Vec<u8>> {
        let image = self.denoised_image().ok_or_else(|| crate::Error::gpu("the display filter has not run"))?;
        image.read(&self.ctx)
    }

    /// The display pixels as they stand, not remade: what the viewer shows now (a preview, or
    /// rows a band of passes apart).
    pub fn read_shown_display(&self) -> Result<Vec<u8>> {
        self.targets.display.read(&self.ctx)
    }

    /// The linear radiance as it stands, not remade: the image behind [`Self::read_shown_display`].
    pub fn read_shown_radiance(&self) -> Result<Vec<[f32; 4]>> {
        Ok(bytemuck::cast_slice(&self.targets.radiance.read(&self.ctx)?).to_vec())
    }

    /// The running sums (rgb) and sample counts (a) of the covered pixels; uncovered pixels hold
    /// whatever was last written there.
    fn read_sums(&self) -> Result<Vec<[f32; 4]>> {
        self.check_rendered()?;
        Ok(bytemuck::cast_slice(&self.targets.accumulation.read(&self.ctx)?).to_vec())
    }

    /// The samples each pixel has in the current accumulation (its accumulation's alpha), 0
    /// where uncovered: under a noise threshold, where each pixel stopped.
    pub fn read_sample_counts(&self) -> Result<Vec<u32>> {
        let sums = self.read_sums()?;
        Ok(sums
            .iter()
            .zip(&self.lists.covered_mask)
            .map(|(sum, &covered)| if covered { sum[3] as u32 } else { 0 })
            .collect())
    }

    /// Each lobe's mean share of the estimate per pixel ([`LOBES`] order), not yet weighted by
    /// coverage: zero where no sample was taken. Needs [`Accumulate::lobes`].
    pub fn read_lobes(&self, coverage: &[f32]) -> Result<Vec<Vec<[f32; 3]>>> {
        assert!(self.relight.accumulate.lobes, "read_lobes() needs Accumulate::lobes");
        let sums = self.read_sums()?;
        let layers: Vec<[f32; 4]> = bytemuck::cast_slice(&self.targets.lobe_sums.read(&self.ctx)?).to_vec();
        let pixels = sums.len();
        Ok((0..LOBES.len())
            .map(|k| {
                (0..pixels)
                    .map(|p| {
                        let (sum, n) = (layers[k * pixels + p], sums[p][3]);
                        if coverage[p] > 0.0 && n > 0.0 {
                            [sum[0] / n, sum[1] / n, sum[2] / n]
                        } else {
                            [0.0; 3]
                        }
                    })
                    .collect()
            })
            .collect())
    }

    /// Per pixel of an object that catches shadows, the share of its light that reaches it, per
    /// channel: its sums over its unshadowed sums, as finalize.comp divides them (1 in a channel
    /// with no light even unshadowed). 1 on every other pixel (docs/formats.md#shadow-catchers).
    pub fn read_shadow(&self) -> Result<Vec<[f32; 3]>> {
        let sums = self.read_sums()?;
        if !self.shadow_catcher {
            return Ok(vec![[1.0; 3]; sums.len()]);
        }
        let open: Vec<[f32; 4]> = bytemuck::cast_slice(&self.targets.unshadowed.read(&self.ctx)?).to_vec();
        let behind: Vec<[f32; 4]> = bytemuck::cast_slice(&self.targets.background.read(&self.ctx)?).to_vec();
        Ok((0..sums.len())
            .map(|p| {
                let catcher = self.lists.covered_mask[p] && behind[p][3] != 0.0;
                std::array::from_fn(|c| if catcher && open[p][c] != 0.0 { sums[p][c] / open[p][c] } else { 1.0 })
            })
            .collect())
    }

    /// Whether the kernels sum shadow catchers' unshadowed light: some object catches shadows.
    pub fn has_shadow_catcher(&self) -> bool {
        self.shadow_catcher
    }

    /// The variance of each covered pixel's mean luminance, from the sum of the estimates and of
    /// their squares: (Σx² − (Σx)²/n) / (n(n − 1)); zero with fewer than two samples. Needs
    /// [`Accumulate::variance`].
    pub fn read_variance(&self, coverage: &[f32]) -> Result<Vec<f32>> {
        /// relight.comp's MOMENT_SCALE, 2^-40.
        const MOMENT_SCALE: f64 = 1.0 / (1u64 << 40) as f64;
        assert!(self.relight.accumulate.variance, "read_variance() needs Accumulate::variance");
        let sums = self.read_sums()?;
        let squares: Vec<[f32; 4]> = bytemuck::cast_slice(&self.targets.moments.read(&self.ctx)?).to_vec();
        let variance: Vec<f64> = sums
            .iter()
            .zip(&squares)
            .zip(coverage)
            .map(|((sum, square), &a)| {
                let n = sum[3] as f64;
                if a <= 0.0 || n < 2.0 {
                    return 0.0;
                }
                let total = crate::shading::common::luminance(glam::Vec3::new(sum[0], sum[1], sum[2])) as f64;
                // The kernel sums squares of luminances scaled by MOMENT_SCALE (relight.comp).
                let squares = square[0] as f64 / (MOMENT_SCALE * MOMENT_SCALE);
                ((squares - total * total / n) / (n * (n - 1.0))).max(0.0)
            })
            .collect();
        let beyond = variance.iter().filter(|&&v| v > f32::MAX as f64).count();
        if beyond > 0 {
            crate::warn(format!(
                "the variance is beyond the largest 32-bit float at {beyond} pixels, which hold {:e} instead",
                f32::MAX
            ));
        }
        Ok(variance.into_iter().map(|v| v.min(f32::MAX as f64) as f32).collect())
    }

    /// The resolved material per pixel, as [`RESOLVED_LAYERS`] layers of vec4 in the layout of
    /// [`crate::material::Params::to_gpu`] (for tests and inspection).
    pub fn read_resolved(&self) -> Result<Vec<[f32; 4]>> {
        Ok(bytemuck::cast_slice(&self.targets.resolved.read(&self.ctx)?).to_vec())
    }

    /// The estimator (docs/shading.md#sampling).
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// Switches the estimator, with the tables it samples `environment` (the one being rendered)
    /// by; accumulation restarts. Nothing happens when it is the same.
    pub fn set_sampling(&mut self, sampling: Sampling, environment: &Environment) -> Result<()> {
        if sampling == self.sampling {
            return Ok(());
        }
        let respecialize = sampling.product_kernel() != self.sampling.product_kernel();
        self.sampling = sampling;
        self.set_environment(environment)?;
        if respecialize {
            self.respecialize(self.relight.shading.model, self.relight.accumulate)?;
        }
        Ok(())
    }

    /// Uploads new layer stacks and resolves them, as [`Renderer::set_stacks`] does, but
    /// restarts only the covered pixels whose resolved material changed, bit for bit
    /// ([`Renderer::restart_pixels`]); every other pixel keeps its samples. Returns how many
    /// changed: an edit of one object's stack restarts that object's pixels, one of a masked
    /// layer those where its weight is not 0 (docs/commands.md#edit-local-re-convergence).
    /// An edit that gives the scene a lobe no pixel had, or takes away the last pixel's, needs
    /// another specialisation of the relight kernel ([`PackedStacks::lobes`]): then everything
    /// restarts, as with [`Renderer::set_stacks`], and this returns None.
    pub fn set_stacks_local(&mut self, packed: &PackedStacks) -> Result<Option<usize>> {
        let restarted = self.set_kernel_needs(packed)?;
        self.resolve_stacks(packed)?;
        if restarted {
            return Ok(None);
        }
        let changed = self.resolve.changed_pixels(self.width as usize * self.height as usize)?;
        self.restart_pixels(&changed);
        Ok(Some(changed.len()))
    }
}

/// An environment with the sampling tables `sampling` uses, on the GPU.
fn upload_environment(ctx: &Context, environment: &Environment, sampling: Sampling) -> Result<GpuEnvironment> {
    let distribution = sampling.distribution(environment, ctx.info().max_image_dimension_2d);
    let product = sampling.product(&distribution);
    let samplers = product.as_ref().map_or(Samplers::Global, Samplers::Product);
    GpuEnvironment::upload_with(ctx, environment, &distribution, samplers)
}

/// A 1×1 image bound as the backdrop where none is shown.
fn backdrop_placeholder(ctx: &Context) -> Result<Image> {
    Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, 1, 1, 1, false)
}

/// The runs of `false` in `flags`: (first index, length) each.
fn runs_of_false(flags: &[bool]) -> Vec<(u32, u32)> {
    let mut runs = Vec::new();
    let mut start = None;
    for (i, &flag) in flags.iter().chain([&true]).enumerate() {
        match (flag, start) {
            (false, None) => start = Some(i),
            (true, Some(first)) => {
                runs.push((first as u32, (i - first) as u32));
                start = None;
            }
            _ => {}
        }
    }
    runs
}

/// Pixels restarted alone, catching up with their rows.
struct Restarted {
    /// The pixels, row by row.
    list: RowList,
    /// The samples each row's restarted pixels have.
    samples: Vec<u32>,
    /// Whether the list is on the GPU.
    uploaded: bool,
}

impl Restarted {
    /// Whether row `y`'s restarted pixels have fewer samples than the rest of the row.
    fn lags(&self, y: u32, row_samples: &[u32]) -> bool {
        self.list.row_len(y) > 0 && self.samples[y as usize] < row_samples[y as usize]
    }
}

/// What the relight kernel accumulates: what was asked for, and the variance adaptive
/// sampling needs.
fn kernel_accumulate(wanted: Accumulate, noise: Option<NoiseThreshold>) -> Accumulate {
    Accumulate { variance: wanted.variance || noise.is_some(), ..wanted }
}

/// What the renderer's kernels are specialised for: the BRDF model, what the relight kernel
/// accumulates, its environment sampler and the lobes its materials have. A scene and the AOVs
/// a command writes give it, so the kernels can compile while the scene uploads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Specialization {
    pub model: Model,
    pub accumulate: Accumulate,
    /// The environment sampled by product tables ([`Sampling::product_kernel`]).
    pub product: bool,
    /// The lobes of the scene's stacks ([`PackedStacks::lobes`]).
    pub lobes: LobesPresent,
    /// Whether the scene's stacks bind maps ([`PackedStacks::binds_maps`]), for the resolve.
    pub maps: bool,
    /// The side of the g-buffer's visibility grid, 0 without visibility.
    pub visibility: u32,
    /// Whether some object catches shadows ([`PackedStacks::has_shadow_catcher`]).
    pub shadow_catcher: bool,
}

impl Default for Specialization {
    /// The default model and estimator, accumulating nothing beside the total.
    fn default() -> Self {
        Specialization {
            model: Model::default(),
            accumulate: Accumulate::default(),
            product: Sampling::default().product_kernel(),
            lobes: LobesPresent::default(),
            maps: false,
            visibility: 0,
            shadow_catcher: false,
        }
    }
}

impl Specialization {
    /// The kernels a render of `scene` needs when it accumulates `wanted` for its AOVs: the
    /// specialisation the renderer comes to once its settings and stacks are set, so nothing
    /// compiles twice.
    pub fn of_render(scene: &crate::render::scene::Scene, wanted: Accumulate) -> Specialization {
        let settings = &scene.settings;
        Specialization {
            model: settings.model,
            accumulate: kernel_accumulate(wanted, settings.noise),
            product: settings.sampling.product_kernel(),
            lobes: scene.stacks.lobes(),
            maps: scene.stacks.binds_maps(),
            visibility: scene.gbuffer.visibility.as_ref().map_or(0, |v| v.grid.side()),
            shadow_catcher: scene.stacks.has_shadow_catcher(),
        }
    }
}

/// The renderer's compiled pipelines, for one [`Specialization`].
pub struct Kernels {
    pub specialization: Specialization,
    resolve: crate::gpu::ComputePipeline,
    relight: crate::render::passes::relight::RelightPipelines,
    finalize: crate::gpu::ComputePipeline,
}

impl Kernels {
    /// Compiles them, the relight kernel (by far the slowest) first. Pipeline creation is
    /// thread-safe, so this may run on any thread while the context is used on others.
    pub fn compile(ctx: &Context, specialization: Specialization) -> Result<Kernels> {
        let Specialization { model, accumulate, product, lobes, maps, visibility, shadow_catcher } = specialization;
        Ok(Kernels {
            specialization,
            relight: RelightPass::pipeline(ctx, &model, accumulate, product, lobes, visibility, shadow_catcher)?,
            resolve: ResolvePass::pipeline(ctx, maps)?,
            finalize: FinalizePass::pipeline(ctx, false)?,
        })
    }
}

/// Where a new renderer's kernels come from.
pub enum KernelSource<'scope> {
    /// Compiled when the renderer needs them.
    Compile(Specialization),
    /// Already compiling on another thread.
    Pending(crate::render::startup::PendingKernels<'scope>),
}

impl Default for KernelSource<'_> {
    /// The default model's kernels, accumulating nothing beside the total, compiled when needed.
    fn default() -> Self {
        KernelSource::Compile(Specialization::default())
    }
}

impl KernelSource<'_> {
    pub fn specialization(&self) -> Specialization {
        match self {
            KernelSource::Compile(specialization) => *specialization,
            KernelSource::Pending(pending) => pending.specialization,
        }
    }

    /// The kernels, once compiled.
    fn wait(self, ctx: &Context) -> Result<Kernels> {
        match self {
            KernelSource::Compile(specialization) => Kernels::compile(ctx, specialization),
            KernelSource::Pending(pending) => pending.wait(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::runs_of_false;

    #[test]
    fn runs_of_false_are_found_at_either_end_and_between() {
        assert_eq!(runs_of_false(&[]), vec![]);
        assert_eq!(runs_of_false(&[true, true]), vec![]);
        assert_eq!(runs_of_false(&[false, false, true, false, true, true, false]), vec![(0, 2), (3, 1), (6, 1)]);
    }
}
