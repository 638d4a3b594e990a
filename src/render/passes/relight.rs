//! The relight pass (`relight.comp`): progressive MIS image-based lighting of the resolved
//! materials, accumulated per pixel, with each lobe's share and each estimate's squared
//! luminance beside the total when the AOVs ask for them (docs/formats.md#aovs).

use super::pixel_lists::PixelLists;
use super::Targets;
use crate::environment::{self, GpuEnvironment};
use crate::gbuffer::gpu::GpuGBuffer;
use crate::gpu::{
    shaders, Binding, BindingKind, Buffer, ComputePipeline, Context, DescriptorSet, GlslLayout, Image, Interface,
};
use crate::material::stack::LobesPresent;
use crate::shading::brdf::EnergyTable;
use crate::shading::brdf::Shading;
use crate::shading::model::Model;
use crate::Result;
use ash::vk;
use std::sync::Arc;

/// What `relight.comp` and the host agree on.
pub const INTERFACE: Interface = Interface::compute(
    &shaders::RELIGHT,
    &[&SET, &environment::gpu::SET_LAYOUT, &BACKDROP_SET],
    Some(RelightPush::GLSL),
);

/// Set 2 of `relight.comp`: the lat-long image a [`Background::Image`] background shows.
pub const BACKDROP_SET: [BindingKind; 1] = [BindingKind::StorageImage];

/// What uncovered pixels show (`BACKGROUND_*` in relight.comp).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Background {
    /// Nothing: black, which finalize.comp makes transparent.
    None = 0,
    /// The lighting environment.
    Environment = 1,
    /// The backdrop image (set 2), rotated and scaled as the environment is.
    Image = 2,
    /// The push constants' colour, as it is.
    Colour = 3,
}

/// Set 0 of `relight.comp`: surface, resolved material, accumulation, background, energy
/// table, lobe sums, squared luminances, the covered and restarted pixel lists, the active
/// counts, the visibility, the unshadowed sums, the active lists and their rows. Set 1 is the
/// environment's.
pub const SET: [BindingKind; 14] = [
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageBuffer,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageBuffer,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageBuffer,
];

/// Which pixels a relight dispatch's invocations stand for (`SOURCE_*` in relight.comp).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Source {
    /// Entries of the covered list.
    Covered = 0,
    /// Entries of the restarted list.
    Restarted = 1,
    /// The top-left pixel of each `block` × `block` block, row-major (the preview).
    Preview = 2,
    /// Every pixel, row-major: only its background is written.
    Background = 3,
    /// Entries of an active list, in the covered list's places (under a noise threshold).
    Active = 4,
}

/// `Pass` in relight.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct RelightPush {
    /// Samples the dispatch's pixels have; 0 starts their accumulation.
    pub first_sample: u32,
    pub sample_count: u32,
    pub seed: u32,
    /// A [`Background`].
    pub background: u32,
    /// The environment's rotation about +Y.
    pub cos_rotation: f32,
    pub sin_rotation: f32,
    pub intensity: f32,
    /// A [`Source`].
    pub source: u32,
    /// The invocations' range: list entries, blocks or pixels `first..end`.
    pub first: u32,
    pub end: u32,
    /// Pixels per side of a preview's block.
    pub block: u32,
    /// Above 0, each pixel stops once its estimated relative error is below it.
    pub noise_threshold: f32,
    /// The samples a pixel takes before it may stop (at least 2).
    pub min_samples: u32,
    /// The active list (0 or 1) a [`Source::Active`] dispatch reads; the pixels a dispatch of
    /// it or of the covered list leaves active go to the other.
    pub list_in: u32,
    /// The linear colour a [`Background::Colour`] background shows.
    pub background_r: f32,
    pub background_g: f32,
    pub background_b: f32,
}

crate::glsl_struct!(RelightPush as "Pass", 68 bytes {
    first_sample @ 0,
    sample_count @ 4,
    seed @ 8,
    background @ 12,
    cos_rotation @ 16,
    sin_rotation @ 20,
    intensity @ 24,
    source @ 28,
    first @ 32,
    end @ 36,
    block @ 40,
    noise_threshold @ 44,
    min_samples @ 48,
    list_in @ 52,
    background_r @ 56,
    background_g @ 60,
    background_b @ 64,
});

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

/// The relight kernel's pipelines for one specialisation: the kernel, and the same specialised
/// to write backgrounds only.
pub struct RelightPipelines {
    pub relight: ComputePipeline,
    pub background: ComputePipeline,
}

/// The relight kernel specialised for one BRDF model and one [`Accumulate`], bound to the
/// targets and an environment.
pub struct RelightPass {
    pipeline: ComputePipeline,
    set: DescriptorSet,
    environment_set: DescriptorSet,
    backdrop_set: DescriptorSet,
    /// The kernel specialised to write backgrounds only, with its own sets: what background
    /// pushes run on.
    background: ComputePipeline,
    background_sets: [DescriptorSet; 3],
    /// The model, with its energy table when it compensates.
    pub shading: Shading,
    pub accumulate: Accumulate,
    // The table the set points at, held while it does.
    _energy: Buffer,
}

impl RelightPass {
    /// Compiles `relight.comp` specialised for `model` and `accumulate`, sampling the environment
    /// by the product tables when `product` is set, with the code of the lobes in `lobes` only,
    /// reading visibility on a grid of `visibility_side` cells a side (0: none), and summing
    /// shadow catchers' unshadowed light when `shadow_catcher` is set.
    pub fn pipeline(
        ctx: &Context,
        model: &Model,
        accumulate: Accumulate,
        product: bool,
        lobes: LobesPresent,
        visibility_side: u32,
        shadow_catcher: bool,
    ) -> Result<RelightPipelines> {
        let mut constants = model.specialization().to_vec();
        constants.extend([accumulate.lobes as u32, accumulate.variance as u32, product as u32]);
        constants.extend([lobes.diffuse as u32, lobes.clearcoat as u32, visibility_side, shadow_catcher as u32]);
        let specialized = |kernel: &shaders::Kernel, background_only: u32| {
            let constants = [&constants[..], &[background_only]].concat();
            ComputePipeline::specialized(ctx, kernel, INTERFACE.sets, INTERFACE.push_size(), &constants)
        };
        Ok(RelightPipelines {
            relight: specialized(&shaders::RELIGHT, 0)?,
            background: specialized(&shaders::RELIGHT_BACKGROUND, 1)?,
        })
    }

    /// The pass, with `pipeline` from [`RelightPass::pipeline`] for the same `model` and
    /// `accumulate`, bound to the targets and an environment.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: &Context,
        pipelines: RelightPipelines,
        model: &Model,
        accumulate: Accumulate,
        gbuffer: &GpuGBuffer,
        targets: &Targets,
        lists: &PixelLists,
        environment: &GpuEnvironment,
        backdrop: &Image,
    ) -> Result<RelightPass> {
        // The energy table is built on the GPU; a placeholder unless the model compensates.
        let (table, energy) = if model.energy_compensation {
            let table = crate::render::energy::build(ctx, model)?;
            (table.clone(), Some(Arc::new(table)))
        } else {
            (EnergyTable::placeholder(), None)
        };
        let energy_buffer = Buffer::with_data(ctx, bytemuck::cast_slice(&table.values))?;
        let RelightPipelines { relight: pipeline, background } = pipelines;
        let bindings = [
            Binding::Image(&gbuffer.surface),
            Binding::Image(&targets.resolved),
            Binding::Image(&targets.accumulation),
            Binding::Image(&targets.background),
            Binding::Buffer(&energy_buffer),
            Binding::Image(&targets.lobe_sums),
            Binding::Image(&targets.moments),
            Binding::Image(&lists.covered_image),
            Binding::Image(&lists.restarted_image),
            Binding::Buffer(&lists.active),
            Binding::Image(&gbuffer.visibility),
            Binding::Image(&targets.unshadowed),
            Binding::Image(&targets.active_lists),
            Binding::Buffer(&lists.active_rows),
        ];
        let set = pipeline.bind(0, &bindings)?;
        let environment_set = pipeline.bind(1, &environment.bindings())?;
        let backdrop_set = pipeline.bind(2, &[Binding::Image(backdrop)])?;
        let background_sets = [
            background.bind(0, &bindings)?,
            background.bind(1, &environment.bindings())?,
            background.bind(2, &[Binding::Image(backdrop)])?,
        ];
        Ok(RelightPass {
            pipeline,
            set,
            environment_set,
            backdrop_set,
            background,
            background_sets,
            shading: Shading::new(*model, energy),
            accumulate,
            _energy: energy_buffer,
        })
    }

    /// Binds another environment.
    pub fn set_environment(&mut self, environment: &GpuEnvironment) -> Result<()> {
        self.environment_set = self.pipeline.bind(1, &environment.bindings())?;
        self.background_sets[1] = self.background.bind(1, &environment.bindings())?;
        Ok(())
    }

    /// Binds another backdrop image (set 2).
    pub fn set_backdrop(&mut self, backdrop: &Image) -> Result<()> {
        self.backdrop_set = self.pipeline.bind(2, &[Binding::Image(backdrop)])?;
        self.background_sets[2] = self.background.bind(2, &[Binding::Image(backdrop)])?;
        Ok(())
    }

    /// Records the pass over the invocations `push.first..push.end`, in as many dispatches as
    /// the workgroup limit needs. Their pixels are disjoint, so the dispatches need no barrier.
    pub fn record(&self, cmd: vk::CommandBuffer, push: &RelightPush) {
        let (pipeline, sets) = if push.source == Source::Background as u32 {
            (&self.background, [&self.background_sets[0], &self.background_sets[1], &self.background_sets[2]])
        } else {
            (&self.pipeline, [&self.set, &self.environment_set, &self.backdrop_set])
        };
        for (first, end, groups) in super::list_dispatches(push.first, push.end) {
            let chunk = RelightPush { first, end, ..*push };
            pipeline.dispatch(cmd, &sets, bytemuck::bytes_of(&chunk), groups);
        }
    }
}
