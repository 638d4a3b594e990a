//! The environment on the GPU: descriptor set 1 of every kernel that lights or samples.

use super::{Distribution, Environment};
use crate::gpu::{Binding, BindingKind, Buffer, Context, Image};
use crate::{Error, Result};
use ash::vk;

/// The texels (radiance and cell pdf) and the sampling tables, uploaded once per environment.
pub struct GpuEnvironment {
    pub texels: Image,
    pub marginal: Buffer,
    pub conditional: Buffer,
    pub guides: Buffer,
}

impl GpuEnvironment {
    pub fn upload(ctx: &Context, env: &Environment, distribution: &Distribution) -> Result<GpuEnvironment> {
        let max = ctx.info().max_image_dimension_2d;
        if env.width > max || env.height > max {
            return Err(Error::input_file(
                &env.source,
                format!("the environment is {}x{}, larger than this device's {max} pixel limit", env.width, env.height),
            ));
        }
        let texels = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, env.width, env.height, 1, false)?;
        let rgba: Vec<[f32; 4]> =
            env.texels.iter().zip(distribution.texel_pdf()).map(|(t, pdf)| [t[0], t[1], t[2], pdf]).collect();
        texels.upload(ctx, bytemuck::cast_slice(&rgba))?;
        let mut marginal = bytemuck::cast_slice::<u32, u8>(&distribution.header()).to_vec();
        marginal.extend_from_slice(bytemuck::cast_slice(&distribution.marginal_cdf));
        let guides: Vec<u32> =
            distribution.marginal_guide.iter().chain(&distribution.conditional_guide).copied().collect();
        Ok(GpuEnvironment {
            texels,
            marginal: Buffer::with_data(ctx, &marginal)?,
            conditional: Buffer::with_data(ctx, bytemuck::cast_slice(&distribution.conditional_cdf))?,
            guides: Buffer::with_data(ctx, bytemuck::cast_slice(&guides))?,
        })
    }

    /// The four bindings of descriptor set 1, in `environment.glsl` order.
    pub fn bindings(&self) -> [Binding<'_>; 4] {
        [
            Binding::Image(&self.texels),
            Binding::Buffer(&self.marginal),
            Binding::Buffer(&self.conditional),
            Binding::Buffer(&self.guides),
        ]
    }
}

/// The layout of descriptor set 1.
pub const SET_LAYOUT: [BindingKind; 4] =
    [BindingKind::StorageImage, BindingKind::StorageBuffer, BindingKind::StorageBuffer, BindingKind::StorageBuffer];
