//! The environment on the GPU: descriptor set 1 of every kernel that lights or samples.

use super::{Distribution, Environment};
use crate::gpu::{Binding, Buffer, Context, Image};
use crate::{Error, Result};
use ash::vk;

/// The radiance image and the sampling tables, uploaded once per environment.
pub struct GpuEnvironment {
    pub radiance: Image,
    pub marginal: Buffer,
    pub conditional: Buffer,
    pub cell_pdf: Buffer,
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
        let radiance = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, env.width, env.height, 1, false)?;
        let rgba: Vec<f32> = env.texels.iter().flat_map(|t| [t[0], t[1], t[2], 1.0]).collect();
        radiance.upload(ctx, bytemuck::cast_slice(&rgba))?;
        Ok(GpuEnvironment {
            radiance,
            marginal: Buffer::with_data(ctx, &distribution.marginal_gpu_bytes())?,
            conditional: Buffer::with_data(ctx, bytemuck::cast_slice(&distribution.conditional_cdf))?,
            cell_pdf: Buffer::with_data(ctx, bytemuck::cast_slice(&distribution.cell_pdf))?,
        })
    }

    /// The four bindings of descriptor set 1, in `environment.glsl` order.
    pub fn bindings(&self) -> [Binding<'_>; 4] {
        [
            Binding::Image(&self.radiance),
            Binding::Buffer(&self.marginal),
            Binding::Buffer(&self.conditional),
            Binding::Buffer(&self.cell_pdf),
        ]
    }
}

/// The layout of descriptor set 1.
pub const SET_LAYOUT: [crate::gpu::BindingKind; 4] = [
    crate::gpu::BindingKind::StorageImage,
    crate::gpu::BindingKind::StorageBuffer,
    crate::gpu::BindingKind::StorageBuffer,
    crate::gpu::BindingKind::StorageBuffer,
];
