//! The denoise pass (`denoise.comp`): the viewer's optional display filter, an edge-avoiding
//! à-trous wavelet filter of the current linear radiance guided by the g-buffer's normals and
//! object ids and the resolved base colour. It writes its own display image and is never read by
//! anything that saves: saved images are the accumulation's own.

use super::{groups, Targets};
use crate::gbuffer::gpu::GpuGBuffer;
use crate::gpu::{
    shaders, Binding, BindingKind, ComputePipeline, Context, DescriptorSet, GlslLayout, Image, Interface,
};
use crate::shading::tonemap::Tonemap;
use crate::Result;
use ash::vk;

/// What `denoise.comp` and the host agree on.
pub const INTERFACE: Interface = Interface::compute(&shaders::DENOISE, &[&SET], Some(DenoisePush::GLSL));

/// Set 0 of `denoise.comp`: source, filtered, surface, object ids, resolved material, display.
pub const SET: [BindingKind; 6] = [BindingKind::StorageImage; 6];

/// Iterations, with taps 1, 2, 4, 8 and 16 pixels apart: a 125-pixel-wide footprint.
pub const ITERATIONS: u32 = 5;

/// `Denoise` in denoise.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DenoisePush {
    /// Pixels between the kernel's taps.
    pub step: i32,
    pub sigma_color: f32,
    pub sigma_albedo: f32,
    pub normal_power: f32,
    /// 1 on the last iteration, which also writes the display pixels.
    pub last: u32,
    /// 2^EV.
    pub exposure_scale: f32,
    /// [`Tonemap::gpu_id`].
    pub tonemap: u32,
    pub show_background: u32,
}

crate::glsl_struct!(DenoisePush as "Denoise", 32 bytes {
    step @ 0,
    sigma_color @ 4,
    sigma_albedo @ 8,
    normal_power @ 12,
    last @ 16,
    exposure_scale @ 20,
    tonemap @ 24,
    show_background @ 28,
});

/// The filter's pipeline, its two ping-pong images and its display image, bound to a
/// renderer's targets.
pub struct DenoisePass {
    pipeline: ComputePipeline,
    /// radiance → ping, ping → pong, pong → ping.
    sets: [DescriptorSet; 3],
    _ping: Image,
    _pong: Image,
    /// The filtered display pixels (sRGB-encoded RGBA8).
    pub display: Image,
}

impl DenoisePass {
    pub fn new(ctx: &Context, gbuffer: &GpuGBuffer, targets: &Targets) -> Result<DenoisePass> {
        let pipeline = ComputePipeline::new(ctx, &shaders::DENOISE, INTERFACE.sets, INTERFACE.push_size())?;
        let (width, height) = (gbuffer.width, gbuffer.height);
        let float = || Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, width, height, 1, false);
        let (ping, pong) = (float()?, float()?);
        let display = Image::display(ctx, width, height)?;
        let bind = |source: &Image, filtered: &Image| {
            pipeline.bind(
                0,
                &[
                    Binding::Image(source),
                    Binding::Image(filtered),
                    Binding::Image(&gbuffer.surface),
                    Binding::Image(&gbuffer.object_ids),
                    Binding::Image(&targets.resolved),
                    Binding::Image(&display),
                ],
            )
        };
        let sets = [bind(&targets.radiance, &ping)?, bind(&ping, &pong)?, bind(&pong, &ping)?];
        Ok(DenoisePass { pipeline, sets, _ping: ping, _pong: pong, display })
    }

    /// Records the [`ITERATIONS`] over a `width` × `height` radiance image, the last making
    /// display pixels with `exposure` (EV) and `tonemap`.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        (width, height): (u32, u32),
        exposure: f32,
        tonemap: Tonemap,
        show_background: bool,
    ) {
        for i in 0..ITERATIONS {
            let push = DenoisePush {
                step: 1 << i,
                // The colour test tightens at each coarser scale (σ halves, as in Dammertz et
                // al.): the fine scales, where the noise is, average freely; the coarse keep detail.
                sigma_color: 0.6 / (1u32 << i) as f32,
                sigma_albedo: 0.1,
                normal_power: 64.0,
                last: (i + 1 == ITERATIONS) as u32,
                exposure_scale: exposure.exp2(),
                tonemap: tonemap.gpu_id(),
                show_background: show_background as u32,
            };
            let set = &self.sets[if i == 0 { 0 } else { 1 + (i as usize + 1) % 2 }];
            self.pipeline.dispatch(cmd, &[set], bytemuck::bytes_of(&push), groups(width, height));
            crate::gpu::context::full_barrier(&ctx.shared.device, cmd);
        }
    }
}
