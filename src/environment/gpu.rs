//! The environment on the GPU: descriptor set 1 of every kernel that lights or samples.

use super::product::Product;
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
    /// The product tables (`env_product_buckets`, `env_product_cdf`), or 1×1 placeholders.
    pub product_buckets: Image,
    pub product_cdf: Image,
}

impl GpuEnvironment {
    pub fn upload(ctx: &Context, env: &Environment, distribution: &Distribution) -> Result<GpuEnvironment> {
        GpuEnvironment::upload_with(ctx, env, distribution, None)
    }

    /// As [`GpuEnvironment::upload`], with product tables built from `distribution` when given.
    pub fn upload_with(
        ctx: &Context,
        env: &Environment,
        distribution: &Distribution,
        product: Option<&Product>,
    ) -> Result<GpuEnvironment> {
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
        let (width, bucket_rows, cdf_rows, bucket_texels, cdf_texels) = match product {
            Some(p) => p.table_texels(distribution),
            None => (1, 1, 1, vec![[0.0; 4]], vec![0.0]),
        };
        if width > max || cdf_rows > max {
            return Err(Error::input_file(
                &env.source,
                format!(
                    "its product tables need {width}x{cdf_rows} images, larger than this device's {max} pixel limit"
                ),
            ));
        }
        let product_buckets = Image::new(ctx, vk::Format::R32G32B32A32_SFLOAT, width, bucket_rows, 1, false)?;
        product_buckets.upload(ctx, bytemuck::cast_slice(&bucket_texels))?;
        let product_cdf = Image::new(ctx, vk::Format::R32_SFLOAT, width, cdf_rows, 1, false)?;
        product_cdf.upload(ctx, bytemuck::cast_slice(&cdf_texels))?;
        // EnvInfo: the header, then env_product_index (one unused word when off, as a buffer
        // may not be empty).
        let mut info = vec![0u32; 10];
        info[..8].copy_from_slice(&distribution.header());
        match product {
            Some(p) => {
                info[6..10].copy_from_slice(&[p.grid, p.coarse_columns, p.coarse_rows, p.ratio_row()]);
                info.extend(&p.index);
            }
            None => info.push(0),
        }
        let info = Buffer::with_data(ctx, bytemuck::cast_slice(&info))?;
        Ok(GpuEnvironment { texels, buckets, cdf, info, product_buckets, product_cdf })
    }

    /// The bindings of descriptor set 1, in `environment.glsl` order.
    pub fn bindings(&self) -> [Binding<'_>; 6] {
        [
            Binding::Image(&self.texels),
            Binding::Image(&self.buckets),
            Binding::Image(&self.cdf),
            Binding::Buffer(&self.info),
            Binding::Image(&self.product_buckets),
            Binding::Image(&self.product_cdf),
        ]
    }
}

/// The layout of descriptor set 1.
pub const SET_LAYOUT: [BindingKind; 6] = [
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageBuffer,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
];
