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

/// Set 0 of `finalize.comp`: accumulation, background, surface, radiance, display, object ids,
/// unshadowed sums.
pub const SET: [BindingKind; 7] = [BindingKind::StorageImage; 7];

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
    /// Without the preview's code ([`FinalizePass::pipeline`]).
    pipeline: ComputePipeline,
    set: DescriptorSet,
    /// With it, and its set: made for the first preview ([`FinalizePass::prepare_preview`]).
    preview: Option<(ComputePipeline, DescriptorSet)>,
}

impl FinalizePass {
    /// The pass, with its pipeline compiled by [`FinalizePass::pipeline`] without the
    /// preview's code, bound to `targets`.
    pub fn new(pipeline: ComputePipeline, gbuffer: &GpuGBuffer, targets: &Targets) -> Result<FinalizePass> {
        let set = FinalizePass::bind(&pipeline, gbuffer, targets)?;
        Ok(FinalizePass { pipeline, set, preview: None })
    }

    /// Compiles and binds the pipeline with the preview's code, unless it is made.
    pub fn prepare_preview(&mut self, ctx: &Context, gbuffer: &GpuGBuffer, targets: &Targets) -> Result<()> {
        if self.preview.is_none() {
            let pipeline = FinalizePass::pipeline(ctx, true)?;
            let set = FinalizePass::bind(&pipeline, gbuffer, targets)?;
            self.preview = Some((pipeline, set));
        }
        Ok(())
    }

    /// Binds the pipelines to `targets` again, after one of their images was replaced.
    pub fn rebind(&mut self, gbuffer: &GpuGBuffer, targets: &Targets) -> Result<()> {
        self.set = FinalizePass::bind(&self.pipeline, gbuffer, targets)?;
        if let Some((pipeline, set)) = &mut self.preview {
            *set = FinalizePass::bind(pipeline, gbuffer, targets)?;
        }
        Ok(())
    }

    fn bind(pipeline: &ComputePipeline, gbuffer: &GpuGBuffer, targets: &Targets) -> Result<DescriptorSet> {
        pipeline.bind(
            0,
            &[
                Binding::Image(&targets.accumulation),
                Binding::Image(&targets.background),
                Binding::Image(&gbuffer.surface),
                Binding::Image(&targets.radiance),
                Binding::Image(&targets.display),
                Binding::Image(&gbuffer.object_ids),
                Binding::Image(&targets.unshadowed),
            ],
        )
    }

    /// Compiles `finalize.comp`, with the preview's interpolation when `preview` (which costs
    /// the other rows too on a CPU driver).
    pub fn pipeline(ctx: &Context, preview: bool) -> Result<ComputePipeline> {
        ComputePipeline::specialized(ctx, &shaders::FINALIZE, INTERFACE.sets, INTERFACE.push_size(), &[preview as u32])
    }

    /// Records the pass over `width` pixels of the rows `push` names. A preview's rows
    /// (`block` > 1) need [`FinalizePass::prepare_preview`] first.
    pub fn record(&self, cmd: vk::CommandBuffer, width: u32, push: &FinalizePush) {
        let rows = push.end_row.saturating_sub(push.first_row);
        let (pipeline, set) = match (&self.preview, push.block > 1) {
            (Some((pipeline, set)), true) => (pipeline, set),
            (None, true) => panic!("a preview's rows are finalized after prepare_preview()"),
            (_, false) => (&self.pipeline, &self.set),
        };
        pipeline.dispatch(cmd, &[set], bytemuck::bytes_of(push), groups(width, rows));
    }
}
