//! The relighting engine: g-buffer, environment and layer stacks on the GPU; resolve, progressive
//! relight passes, and display transforms. Every command that renders drives it.

use crate::environment::{self, Distribution, Environment, GpuEnvironment};
use crate::gbuffer::{GBuffer, MAP_PREFIX, MASK_PREFIX};
use crate::gpu::pipeline::group_count;
use crate::gpu::{shaders, Binding, BindingKind, Buffer, ComputePipeline, Context, DescriptorSet, GpuTimer, Image};
use crate::material::stack::PackedStacks;
use crate::render::tonemap::Tonemap;
use crate::shading::brdf::Shading;
use crate::shading::energy::EnergyTable;
use crate::shading::model::Model;
use crate::Result;
use ash::vk;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Workgroup size of the 2D kernels (`local_size_x`, `local_size_y` in glsl/*.comp).
const LOCAL_SIZE_X: u32 = 16;
const LOCAL_SIZE_Y: u32 = 16;

/// How the environment lights the scene. Any change restarts accumulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Degrees about +Y.
    pub rotation_degrees: f32,
    pub intensity: f32,
    /// Whether background pixels show the environment.
    pub background: bool,
}

impl Default for Lighting {
    fn default() -> Self {
        Lighting { rotation_degrees: 0.0, intensity: 1.0, background: true }
    }
}

/// `Pass` in relight.comp.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct RelightPush {
    first_sample: u32,
    sample_count: u32,
    seed: u32,
    show_background: u32,
    cos_rotation: f32,
    sin_rotation: f32,
    intensity: f32,
    first_row: u32,
    end_row: u32,
}

/// What the relight kernel accumulates beside the total, for the AOVs that need it
/// (docs/formats.md#aovs). What is off costs nothing: the kernel is specialised without it,
/// and a 1×1 placeholder stands for its image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Accumulate {
    /// Each lobe's share of every estimate: diffuse, specular, clearcoat, sheen.
    pub lobes: bool,
    /// Each estimate's squared luminance, for the variance of the mean.
    pub variance: bool,
}

/// The layers of the lobe sums, in `relight.comp`'s order.
pub const LOBES: [&str; 4] = ["diffuse", "specular", "clearcoat", "sheen"];

/// `Finalize` in finalize.comp.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FinalizePush {
    exposure_scale: f32,
    tonemap: u32,
    show_background: u32,
    first_row: u32,
    end_row: u32,
}

/// The per-object material inputs on the GPU: which stack each pixel uses and the layers. Held
/// only to keep them alive while the resolve set points at them.
struct GpuStacks {
    _stack_index: Image,
    _stacks: Buffer,
    _layers: Buffer,
    _set: DescriptorSet,
}

/// A relighting session for one g-buffer.
pub struct Renderer {
    ctx: Context,
    pub width: u32,
    pub height: u32,
    resolve: ComputePipeline,
    relight: ComputePipeline,
    finalize: ComputePipeline,
    /// The BRDF model the relight pipeline is specialized for, with its energy table.
    shading: Shading,
    // Held so the GPU resources that descriptor sets point at stay alive.
    _energy: Buffer,
    accumulate: Accumulate,
    /// The lobe sums (4 layers) and the squared luminances, or 1×1 placeholders.
    lobe_sums: Image,
    moments: Image,
    resolved: Image,
    background: Image,
    accumulation: Image,
    surface: Image,
    radiance: Image,
    display: Image,
    object_ids: Vec<u32>,
    /// The g-buffer's masks and maps by full channel name, for the stacks to choose from.
    channels: BTreeMap<String, Vec<f32>>,
    stacks: Option<GpuStacks>,
    /// The mask and map channels the stacks read, one layer each, and their names: kept while
    /// edits leave the list alone, so that changing a value uploads no channel again.
    channel_layers: Option<(Vec<String>, Image)>,
    _environment: GpuEnvironment,
    environment_set: DescriptorSet,
    relight_set: DescriptorSet,
    finalize_set: DescriptorSet,
    timer: Option<GpuTimer>,
    lighting: Lighting,
    seed: u32,
    /// Samples each row has in the current accumulation.
    row_samples: Vec<u32>,
}

/// The resolved material's layers: the five vec4s of `Params::to_gpu`.
pub const RESOLVED_LAYERS: u32 = (crate::material::params::GPU_FLOATS / 4) as u32;

/// The g-buffer's masks and maps, keyed by their full channel names as packed stacks name them.
fn layer_channels(gbuffer: &GBuffer) -> BTreeMap<String, Vec<f32>> {
    let masks = gbuffer.masks.iter().map(|(name, values)| (format!("{MASK_PREFIX}{name}"), values.clone()));
    let maps = gbuffer.maps.iter().map(|(name, values)| (format!("{MAP_PREFIX}{name}"), values.clone()));
    masks.chain(maps).collect()
}

fn float_image(ctx: &Context, width: u32, height: u32, layers: u32, data: &[[f32; 4]]) -> Result<Image> {
    let image = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, width, height, layers, layers > 1)?;
    image.upload(ctx, bytemuck::cast_slice(data))?;
    Ok(image)
}

/// The images `accumulate` needs: the lobe sums (4 layers) and the squared luminances, each
/// 1×1 when not asked for.
fn accumulation_images(ctx: &Context, width: u32, height: u32, accumulate: Accumulate) -> Result<(Image, Image)> {
    let size = |on: bool| if on { (width, height) } else { (1, 1) };
    let (w, h) = size(accumulate.lobes);
    let lobes = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, w, h, LOBES.len() as u32, true)?;
    let (w, h) = size(accumulate.variance);
    let moments = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, w, h, 1, false)?;
    Ok((lobes, moments))
}

/// The relight pipeline for a model, and the energy table it reads (a placeholder unless the
/// model compensates energy; the table itself is built on the GPU).
fn relight_pipeline(
    ctx: &Context,
    model: &Model,
    accumulate: Accumulate,
) -> Result<(ComputePipeline, Shading, Buffer)> {
    let image = BindingKind::StorageImage;
    let buffer = BindingKind::StorageBuffer;
    let mut constants = model.specialization().to_vec();
    constants.extend([accumulate.lobes as u32, accumulate.variance as u32]);
    let relight = ComputePipeline::specialized(
        ctx,
        &shaders::RELIGHT,
        &[&[image, image, image, image, buffer, image, image], &environment::gpu::SET_LAYOUT],
        std::mem::size_of::<RelightPush>() as u32,
        &constants,
    )?;
    let (table, energy) = if model.energy_compensation {
        let table = crate::render::energy::build(ctx, model)?;
        (table.clone(), Some(Arc::new(table)))
    } else {
        (EnergyTable::placeholder(), None)
    };
    let energy_buffer = Buffer::with_data(ctx, bytemuck::cast_slice(&table.values))?;
    Ok((relight, Shading::new(*model, energy), energy_buffer))
}

impl Renderer {
    /// A renderer of the default (Disney 2012) model.
    pub fn new(ctx: &Context, gbuffer: &GBuffer, environment: &Environment) -> Result<Renderer> {
        Renderer::with_model(ctx, gbuffer, environment, &Model::default())
    }

    /// A renderer of a BRDF model (docs/shading.md#brdf-models).
    pub fn with_model(ctx: &Context, gbuffer: &GBuffer, environment: &Environment, model: &Model) -> Result<Renderer> {
        let (width, height) = (gbuffer.width, gbuffer.height);
        let image = BindingKind::StorageImage;
        let buffer = BindingKind::StorageBuffer;
        let resolve = ComputePipeline::new(ctx, &shaders::RESOLVE, &[&[image, image, buffer, buffer, image]], 0)?;
        let accumulate = Accumulate::default();
        let (relight, shading, energy) = relight_pipeline(ctx, model, accumulate)?;
        let finalize =
            ComputePipeline::new(ctx, &shaders::FINALIZE, &[&[image; 5]], std::mem::size_of::<FinalizePush>() as u32)?;

        let mut surface_data = Vec::with_capacity(3 * gbuffer.pixel_count());
        surface_data.extend(gbuffer.normal.iter().zip(&gbuffer.coverage).map(|(n, a)| [n[0], n[1], n[2], *a]));
        surface_data.extend(gbuffer.view.iter().map(|v| [v[0], v[1], v[2], 0.0]));
        surface_data.extend(gbuffer.tangent.iter().map(|t| [t[0], t[1], t[2], 0.0]));
        let surface = float_image(ctx, width, height, 3, &surface_data)?;
        let resolved = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, width, height, RESOLVED_LAYERS, true)?;
        let float_target = || Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, width, height, 1, false);
        let accumulation = float_target()?;
        let background = float_target()?;

        let radiance = float_target()?;
        let display = Image::display(ctx, width, height)?;

        let distribution = Distribution::for_device(environment, ctx.info().max_image_dimension_2d);
        let gpu_environment = GpuEnvironment::upload(ctx, environment, &distribution)?;
        let environment_set = relight.bind(1, &gpu_environment.bindings())?;
        let (lobe_sums, moments) = accumulation_images(ctx, width, height, accumulate)?;
        let relight_set = relight.bind(
            0,
            &[
                Binding::Image(&surface),
                Binding::Image(&resolved),
                Binding::Image(&accumulation),
                Binding::Image(&background),
                Binding::Buffer(&energy),
                Binding::Image(&lobe_sums),
                Binding::Image(&moments),
            ],
        )?;
        let finalize_set = finalize.bind(
            0,
            &[
                Binding::Image(&accumulation),
                Binding::Image(&background),
                Binding::Image(&surface),
                Binding::Image(&radiance),
                Binding::Image(&display),
            ],
        )?;
        Ok(Renderer {
            ctx: ctx.clone(),
            width,
            height,
            resolve,
            relight,
            finalize,
            shading,
            _energy: energy,
            accumulate,
            lobe_sums,
            moments,
            resolved,
            accumulation,
            background,
            surface,
            radiance,
            display,
            object_ids: gbuffer.object_id.clone(),
            channels: layer_channels(gbuffer),
            stacks: None,
            channel_layers: None,
            _environment: gpu_environment,
            environment_set,
            relight_set,
            finalize_set,
            timer: GpuTimer::new(ctx, 2)?,
            lighting: Lighting::default(),
            seed: 0,
            row_samples: vec![0; height as usize],
        })
    }

    /// Replaces the environment (its texels and sampling tables); accumulation restarts.
    pub fn set_environment(&mut self, environment: &Environment) -> Result<()> {
        let distribution = Distribution::for_device(environment, self.ctx.info().max_image_dimension_2d);
        let gpu_environment = GpuEnvironment::upload(&self.ctx, environment, &distribution)?;
        self.environment_set = self.relight.bind(1, &gpu_environment.bindings())?;
        self._environment = gpu_environment;
        self.restart();
        Ok(())
    }

    /// The BRDF model being rendered, with its energy table when it has one.
    pub fn shading(&self) -> &Shading {
        &self.shading
    }

    /// Switches the BRDF model: a new specialization of the relight kernel (and energy table);
    /// accumulation restarts. Nothing happens when the model is the same.
    pub fn set_model(&mut self, model: &Model) -> Result<()> {
        if *model == self.shading.model {
            return Ok(());
        }
        self.respecialize(*model, self.accumulate)
    }

    /// What the relight kernel accumulates beside the total (for the AOVs that need it), with
    /// its images; accumulation restarts. Nothing happens when it is the same.
    pub fn set_accumulate(&mut self, accumulate: Accumulate) -> Result<()> {
        if accumulate == self.accumulate {
            return Ok(());
        }
        let (lobe_sums, moments) = accumulation_images(&self.ctx, self.width, self.height, accumulate)?;
        self.lobe_sums = lobe_sums;
        self.moments = moments;
        self.respecialize(self.shading.model, accumulate)
    }

    /// A new relight kernel for this model and accumulation, bound to the renderer's images.
    fn respecialize(&mut self, model: Model, accumulate: Accumulate) -> Result<()> {
        let (relight, shading, energy) = relight_pipeline(&self.ctx, &model, accumulate)?;
        let environment_set = relight.bind(1, &self._environment.bindings())?;
        let relight_set = relight.bind(
            0,
            &[
                Binding::Image(&self.surface),
                Binding::Image(&self.resolved),
                Binding::Image(&self.accumulation),
                Binding::Image(&self.background),
                Binding::Buffer(&energy),
                Binding::Image(&self.lobe_sums),
                Binding::Image(&self.moments),
            ],
        )?;
        self.relight_set = relight_set;
        self.environment_set = environment_set;
        self.relight = relight;
        self.shading = shading;
        self._energy = energy;
        self.accumulate = accumulate;
        self.restart();
        Ok(())
    }

    /// Samples every pixel has accumulated since the last change.
    pub fn samples(&self) -> u32 {
        self.row_samples.iter().copied().min().unwrap_or(0)
    }

    /// Samples row `row` has in the current accumulation.
    pub fn row_samples(&self, row: u32) -> u32 {
        self.row_samples[row as usize]
    }

    /// The first run of rows with fewer samples than the most-sampled row, as (first row, rows):
    /// what a band-by-band pass still has to do before every row has the same count.
    pub fn lagging_rows(&self) -> Option<(u32, u32)> {
        let most = *self.row_samples.iter().max()?;
        let first = self.row_samples.iter().position(|&n| n < most)?;
        let rows = self.row_samples[first..].iter().take_while(|&&n| n < most).count();
        Some((first as u32, rows as u32))
    }

    /// Changes the lighting; accumulation restarts if anything changed.
    pub fn set_lighting(&mut self, lighting: Lighting) {
        if lighting != self.lighting {
            self.lighting = lighting;
            self.restart();
        }
    }

    /// Starts a new accumulation with everything unchanged.
    pub fn restart(&mut self) {
        self.row_samples.fill(0);
    }

    pub fn set_seed(&mut self, seed: u32) {
        if seed != self.seed {
            self.seed = seed;
            self.restart();
        }
    }

    /// Uploads new layer stacks and resolves them into one material per pixel (once per edit,
    /// not per sample). Accumulation restarts.
    pub fn set_stacks(&mut self, packed: &PackedStacks) -> Result<()> {
        let ctx = &self.ctx;
        let (width, height) = (self.width, self.height);
        let pixels = self.object_ids.len();
        // Uncovered pixels may carry ids the stacks leave out; they shade nothing, so stack 0 does.
        let index: Vec<u32> =
            self.object_ids.iter().map(|id| packed.stack_of_object.get(id).copied().unwrap_or(0)).collect();
        let stack_index = Image::new(ctx, vk::Format::R32_UINT, width, height, 1, false)?;
        stack_index.upload(ctx, bytemuck::cast_slice(&index))?;
        if self.channel_layers.as_ref().is_none_or(|(names, _)| *names != packed.channels) {
            // At least one channel layer, so the binding is always valid.
            let layers = packed.channels.len().max(1) as u32;
            let mut channel_data = vec![0.0f32; pixels * layers as usize];
            for (i, name) in packed.channels.iter().enumerate() {
                let values = self.channels.get(name).expect("pack() checked the masks and maps");
                channel_data[i * pixels..(i + 1) * pixels].copy_from_slice(values);
            }
            let image = Image::new(ctx, vk::Format::R32_SFLOAT, width, height, layers, true)?;
            image.upload(ctx, bytemuck::cast_slice(&channel_data))?;
            self.channel_layers = Some((packed.channels.clone(), image));
        }
        let (_, channels) = self.channel_layers.as_ref().expect("just made");
        let stacks = Buffer::with_data(ctx, bytemuck::cast_slice(&packed.stacks))?;
        let layer_buffer = Buffer::with_data(ctx, bytemuck::cast_slice(&packed.layers))?;
        let set = self.resolve.bind(
            0,
            &[
                Binding::Image(&stack_index),
                Binding::Image(channels),
                Binding::Buffer(&stacks),
                Binding::Buffer(&layer_buffer),
                Binding::Image(&self.resolved),
            ],
        )?;
        let groups = [group_count(width, LOCAL_SIZE_X), group_count(height, LOCAL_SIZE_Y), 1];
        self.timed(|renderer, cmd| renderer.resolve.dispatch(cmd, &[&set], &[], groups))?;
        self.stacks = Some(GpuStacks { _stack_index: stack_index, _stacks: stacks, _layers: layer_buffer, _set: set });
        self.restart();
        Ok(())
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
    /// counts take a dispatch each (usually there is one). Returns the GPU time.
    pub fn render_rows(&mut self, first_row: u32, rows: u32, count: u32) -> Result<Option<f64>> {
        assert!(self.stacks.is_some(), "set_stacks() must run before rendering");
        let end = first_row.saturating_add(rows).min(self.height);
        let mut total = Some(0.0);
        let mut start = first_row;
        while start < end {
            let first_sample = self.row_samples[start as usize];
            let run_end = (start..end).find(|&r| self.row_samples[r as usize] != first_sample).unwrap_or(end);
            let time = self.dispatch_relight(start, run_end, first_sample, count)?;
            total = total.zip(time).map(|(a, b)| a + b);
            self.row_samples[start as usize..run_end as usize].iter_mut().for_each(|n| *n += count);
            start = run_end;
        }
        Ok(total)
    }

    fn dispatch_relight(&self, first_row: u32, end_row: u32, first_sample: u32, count: u32) -> Result<Option<f64>> {
        let rotation = self.lighting.rotation_degrees.to_radians();
        let push = RelightPush {
            first_sample,
            sample_count: count,
            seed: self.seed,
            show_background: self.lighting.background as u32,
            cos_rotation: rotation.cos(),
            sin_rotation: rotation.sin(),
            intensity: self.lighting.intensity,
            first_row,
            end_row,
        };
        let groups = [group_count(self.width, LOCAL_SIZE_X), group_count(end_row - first_row, LOCAL_SIZE_Y), 1];
        self.timed(|renderer, cmd| {
            renderer.relight.dispatch(
                cmd,
                &[&renderer.relight_set, &renderer.environment_set],
                bytemuck::bytes_of(&push),
                groups,
            )
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
    /// and the display pixels of the current sums.
    pub fn record_finalize(&self, cmd: vk::CommandBuffer, first_row: u32, rows: u32, exposure: f32, tonemap: Tonemap) {
        let push = FinalizePush {
            exposure_scale: exposure.exp2(),
            tonemap: tonemap.gpu_id(),
            show_background: self.lighting.background as u32,
            first_row,
            end_row: first_row + rows.min(self.height.saturating_sub(first_row)),
        };
        let rows = rows.min(self.height.saturating_sub(first_row));
        let groups = [group_count(self.width, LOCAL_SIZE_X), group_count(rows, LOCAL_SIZE_Y), 1];
        self.finalize.dispatch(cmd, &[&self.finalize_set], bytemuck::bytes_of(&push), groups);
        crate::gpu::context::full_barrier(&self.ctx.device, cmd);
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
        &self.display
    }

    /// Linear radiance per pixel, row 0 at the top: rgb composited over the background with
    /// alpha 1, or, with the background off, premultiplied by coverage with alpha = coverage.
    pub fn read_radiance(&self) -> Result<Vec<[f32; 4]>> {
        self.check_rendered()?;
        let staging = Buffer::staging(&self.ctx, self.radiance.byte_size())?;
        self.ctx.run(|cmd| {
            self.record_finalize(cmd, 0, self.height, 0.0, Tonemap::Linear);
            self.radiance.record_read(cmd, &staging);
            Ok(())
        })?;
        Ok(bytemuck::cast_slice(&staging.bytes()[..self.radiance.byte_size() as usize]).to_vec())
    }

    /// The linear radiance of one pixel, as [`Renderer::read_radiance`] gives it. Its row's
    /// display pixels are remade with `exposure` and `tonemap`, so what the viewer shows stays.
    pub fn read_radiance_pixel(&self, x: u32, y: u32, exposure: f32, tonemap: Tonemap) -> Result<[f32; 4]> {
        self.check_rendered()?;
        let staging = Buffer::staging(&self.ctx, 16)?;
        self.ctx.run(|cmd| {
            self.record_finalize(cmd, y, 1, exposure, tonemap);
            self.radiance.record_read_texel(cmd, &staging, x, y);
            Ok(())
        })?;
        Ok(bytemuck::pod_read_unaligned(&staging.bytes()[..16]))
    }

    /// Display pixels: exposure, tone map and sRGB, as RGBA8; straight alpha (the coverage) when
    /// the background is off, opaque otherwise.
    pub fn read_display(&self, exposure: f32, tonemap: Tonemap) -> Result<Vec<u8>> {
        self.check_rendered()?;
        let staging = Buffer::staging(&self.ctx, self.display.byte_size())?;
        self.ctx.run(|cmd| {
            self.record_finalize(cmd, 0, self.height, exposure, tonemap);
            self.display.record_read(cmd, &staging);
            Ok(())
        })?;
        Ok(staging.bytes()[..self.display.byte_size() as usize].to_vec())
    }

    /// The running sums (rgb) and sample counts (a) of the covered pixels; uncovered pixels hold
    /// whatever was last written there.
    fn read_sums(&self) -> Result<Vec<[f32; 4]>> {
        self.check_rendered()?;
        Ok(bytemuck::cast_slice(&self.accumulation.read(&self.ctx)?).to_vec())
    }

    /// Each lobe's mean share of the estimate per pixel ([`LOBES`] order), not yet weighted by
    /// coverage: zero where no sample was taken. Needs [`Accumulate::lobes`].
    pub fn read_lobes(&self, coverage: &[f32]) -> Result<Vec<Vec<[f32; 3]>>> {
        assert!(self.accumulate.lobes, "read_lobes() needs Accumulate::lobes");
        let sums = self.read_sums()?;
        let layers: Vec<[f32; 4]> = bytemuck::cast_slice(&self.lobe_sums.read(&self.ctx)?).to_vec();
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

    /// The variance of each covered pixel's mean luminance, from the sum of the estimates and of
    /// their squares: (Σx² − (Σx)²/n) / (n(n − 1)); zero with fewer than two samples. Needs
    /// [`Accumulate::variance`].
    pub fn read_variance(&self, coverage: &[f32]) -> Result<Vec<f32>> {
        assert!(self.accumulate.variance, "read_variance() needs Accumulate::variance");
        let sums = self.read_sums()?;
        let squares: Vec<[f32; 4]> = bytemuck::cast_slice(&self.moments.read(&self.ctx)?).to_vec();
        Ok(sums
            .iter()
            .zip(&squares)
            .zip(coverage)
            .map(|((sum, square), &a)| {
                let n = sum[3] as f64;
                if a <= 0.0 || n < 2.0 {
                    return 0.0;
                }
                let total = crate::shading::common::luminance(glam::Vec3::new(sum[0], sum[1], sum[2])) as f64;
                ((square[0] as f64 - total * total / n) / (n * (n - 1.0))).max(0.0) as f32
            })
            .collect())
    }

    /// The resolved material per pixel, as [`RESOLVED_LAYERS`] layers of vec4 in the layout of
    /// [`crate::material::Params::to_gpu`] (for tests and inspection).
    pub fn read_resolved(&self) -> Result<Vec<[f32; 4]>> {
        Ok(bytemuck::cast_slice(&self.resolved.read(&self.ctx)?).to_vec())
    }
}
