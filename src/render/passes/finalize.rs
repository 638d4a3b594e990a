//! The finalize pass (`finalize.comp`): each pixel's mean, composited over the background, as
//! linear radiance and as display pixels (exposure, tone map, sRGB); or, for the viewer's preview
//! after a change, the same from one relit pixel per block, interpolated within each object.

use super::{groups, Targets};
use crate::gbuffer::gpu::GpuGBuffer;
use crate::gpu::{shaders, Binding, BindingKind, ComputePipeline, Context, DescriptorSet, GlslLayout, Interface};
use crate::Result;
use ash::vk;

/// What `finalize.comp` and the host agree on.
pub const INTERFACE: Interface = Interface::compute(&shaders::FINALIZE, &[&SET], Some(FinalizePush::GLSL));

/// Set 0 of `finalize.comp`: accumulation, background, surface, radiance, display, object ids.
pub const SET: [BindingKind; 6] = [BindingKind::StorageImage; 6];

/// `Finalize` in finalize.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FinalizePush {
    /// 2^EV.
    pub exposure_scale: f32,
    /// [`crate::shading::tonemap::Tonemap::gpu_id`].
    pub tonemap: u32,
    pub show_background: u32,
    /// The band this dispatch covers: rows `first_row..end_row`.
    pub first_row: u32,
    pub end_row: u32,
    /// 1: every pixel's own sums; more: a preview's, one relit pixel per block this wide.
    pub block: u32,
}

crate::glsl_struct!(FinalizePush as "Finalize", 24 bytes {
    exposure_scale @ 0,
    tonemap @ 4,
    show_background @ 8,
    first_row @ 12,
    end_row @ 16,
    block @ 20,
});

pub struct FinalizePass {
    pipeline: ComputePipeline,
    set: DescriptorSet,
}

impl FinalizePass {
    /// The pass, with its pipeline compiled by [`FinalizePass::pipeline`], bound to `targets`.
    pub fn new(pipeline: ComputePipeline, gbuffer: &GpuGBuffer, targets: &Targets) -> Result<FinalizePass> {
        let set = pipeline.bind(
            0,
            &[
                Binding::Image(&targets.accumulation),
                Binding::Image(&targets.background),
                Binding::Image(&gbuffer.surface),
                Binding::Image(&targets.radiance),
                Binding::Image(&targets.display),
                Binding::Image(&gbuffer.object_ids),
            ],
        )?;
        Ok(FinalizePass { pipeline, set })
    }

    /// Compiles `finalize.comp`.
    pub fn pipeline(ctx: &Context) -> Result<ComputePipeline> {
        ComputePipeline::new(ctx, &shaders::FINALIZE, INTERFACE.sets, INTERFACE.push_size())
    }

    /// Records the pass over `width` pixels of the rows `push` names.
    pub fn record(&self, cmd: vk::CommandBuffer, width: u32, push: &FinalizePush) {
        let rows = push.end_row.saturating_sub(push.first_row);
        self.pipeline.dispatch(cmd, &[&self.set], bytemuck::bytes_of(push), groups(width, rows));
    }
}
