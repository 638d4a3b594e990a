//! The environment on the GPU: descriptor set 1 of every kernel that lights or samples.

use super::{Distribution, Environment};
use crate::gpu::{Binding, BindingKind, Buffer, Context, Image};
use crate::{Error, Result};
use ash::vk;

/// The texels (radiance and cell pdf), the sampling tables and their sizes, uploaded once per
/// environment.
pub struct GpuEnvironment {
    pub texels: Image,
    pub buckets: Image,
    pub cdf: Image,
    pub info: Buffer,
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
        let (width, height, bucket_texels, cdf_texels) = distribution.table_texels();
        let buckets = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, width, height, 1, false)?;
        buckets.upload(ctx, bytemuck::cast_slice(&bucket_texels))?;
        let cdf = Image::new(ctx, vk::Format::R32_SFLOAT, width, height, 1, false)?;
        cdf.upload(ctx, bytemuck::cast_slice(&cdf_texels))?;
        let info = Buffer::with_data(ctx, bytemuck::cast_slice(&distribution.header()))?;
        Ok(GpuEnvironment { texels, buckets, cdf, info })
    }

    /// The bindings of descriptor set 1, in `environment.glsl` order.
    pub fn bindings(&self) -> [Binding<'_>; 4] {
        [
            Binding::Image(&self.texels),
            Binding::Image(&self.buckets),
            Binding::Image(&self.cdf),
            Binding::Buffer(&self.info),
        ]
    }
}

/// The layout of descriptor set 1.
pub const SET_LAYOUT: [BindingKind; 4] =
    [BindingKind::StorageImage, BindingKind::StorageImage, BindingKind::StorageImage, BindingKind::StorageBuffer];
