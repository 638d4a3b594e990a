//! The relight pass (`relight.comp`): progressive MIS image-based lighting of the resolved
//! materials, accumulated per pixel, with each lobe's share and each estimate's squared
//! luminance beside the total when the AOVs ask for them (docs/formats.md#aovs).

use super::{groups, Targets};
use crate::environment::{self, GpuEnvironment};
use crate::gbuffer::gpu::GpuGBuffer;
use crate::gpu::{
    shaders, Binding, BindingKind, Buffer, ComputePipeline, Context, DescriptorSet, GlslLayout, Interface,
};
use crate::shading::brdf::EnergyTable;
use crate::shading::brdf::Shading;
use crate::shading::model::Model;
use crate::Result;
use ash::vk;
use std::sync::Arc;

/// What `relight.comp` and the host agree on.
pub const INTERFACE: Interface =
    Interface::compute(&shaders::RELIGHT, &[&SET, &environment::gpu::SET_LAYOUT], Some(RelightPush::GLSL));

/// Set 0 of `relight.comp`: surface, resolved material, accumulation, background, energy
/// table, lobe sums, squared luminances. Set 1 is the environment's.
pub const SET: [BindingKind; 7] = [
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageBuffer,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
];

/// `Pass` in relight.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct RelightPush {
    /// Samples the band's pixels have; 0 starts a new accumulation.
    pub first_sample: u32,
    pub sample_count: u32,
    pub seed: u32,
    pub show_background: u32,
    /// The environment's rotation about +Y.
    pub cos_rotation: f32,
    pub sin_rotation: f32,
    pub intensity: f32,
    /// The band this dispatch covers: rows `first_row..end_row`.
    pub first_row: u32,
    pub end_row: u32,
    /// Pixels per side of the block one invocation covers: 1 for a pass, more for a preview,
    /// which relights each block's top-left pixel only.
    pub block: u32,
}

crate::glsl_struct!(RelightPush as "Pass", 40 bytes {
    first_sample @ 0,
    sample_count @ 4,
    seed @ 8,
    show_background @ 12,
    cos_rotation @ 16,
    sin_rotation @ 20,
    intensity @ 24,
    first_row @ 28,
    end_row @ 32,
    block @ 36,
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

/// The relight kernel specialised for one BRDF model and one [`Accumulate`], bound to the
/// targets and an environment.
pub struct RelightPass {
    pipeline: ComputePipeline,
    set: DescriptorSet,
    environment_set: DescriptorSet,
    /// The model, with its energy table when it compensates.
    pub shading: Shading,
    pub accumulate: Accumulate,
    // The table the set points at, held while it does.
    _energy: Buffer,
}

impl RelightPass {
    pub fn new(
        ctx: &Context,
        model: &Model,
        accumulate: Accumulate,
        gbuffer: &GpuGBuffer,
        targets: &Targets,
        environment: &GpuEnvironment,
    ) -> Result<RelightPass> {
        let mut constants = model.specialization().to_vec();
        constants.extend([accumulate.lobes as u32, accumulate.variance as u32]);
        let pipeline =
            ComputePipeline::specialized(ctx, &shaders::RELIGHT, INTERFACE.sets, INTERFACE.push_size(), &constants)?;
        // The energy table is built on the GPU; a placeholder unless the model compensates.
        let (table, energy) = if model.energy_compensation {
            let table = crate::render::energy::build(ctx, model)?;
            (table.clone(), Some(Arc::new(table)))
        } else {
            (EnergyTable::placeholder(), None)
        };
        let energy_buffer = Buffer::with_data(ctx, bytemuck::cast_slice(&table.values))?;
        let set = pipeline.bind(
            0,
            &[
                Binding::Image(&gbuffer.surface),
                Binding::Image(&targets.resolved),
                Binding::Image(&targets.accumulation),
                Binding::Image(&targets.background),
                Binding::Buffer(&energy_buffer),
                Binding::Image(&targets.lobe_sums),
                Binding::Image(&targets.moments),
            ],
        )?;
        let environment_set = pipeline.bind(1, &environment.bindings())?;
        Ok(RelightPass {
            pipeline,
            set,
            environment_set,
            shading: Shading::new(*model, energy),
            accumulate,
            _energy: energy_buffer,
        })
    }

    /// Binds another environment.
    pub fn set_environment(&mut self, environment: &GpuEnvironment) -> Result<()> {
        self.environment_set = self.pipeline.bind(1, &environment.bindings())?;
        Ok(())
    }

    /// Records the pass over `width` pixels of the rows `push` names, one invocation per block.
    pub fn record(&self, cmd: vk::CommandBuffer, width: u32, push: &RelightPush) {
        let rows = push.end_row - push.first_row;
        let block = push.block.max(1);
        let sets = [&self.set, &self.environment_set];
        self.pipeline.dispatch(
            cmd,
            &sets,
            bytemuck::bytes_of(push),
            groups(width.div_ceil(block), rows.div_ceil(block)),
        );
    }
}
