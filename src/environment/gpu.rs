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
    /// The product tables (`env_product_buckets`, `env_product_cdf`, `env_product_spans`), or
    /// 1×1 placeholders; `buckets` is one too when only the product sampler runs
    /// ([`Samplers::Product`]).
    pub product_buckets: Image,
    pub product_cdf: Image,
    pub product_spans: Image,
    /// [`Product::index`] as `env_product_index` reads it ([`INDEX_WIDTH`] words a row), or a
    /// 1×1 placeholder.
    pub product_index: Image,
}

/// Words per row of the `env_product_index` image: a power of two, so a word's texel is found
/// by a mask and a shift.
pub const INDEX_WIDTH: u32 = 1024;

/// The environment samplers the kernels bound to an environment run, which decide the tables
/// it needs.
#[derive(Clone, Copy)]
pub enum Samplers<'a> {
    /// The global tables' (`env_sample`).
    Global,
    /// A cluster's product tables alone (`env_sample_cluster`: the relight kernel's with
    /// product sampling). They refine the global CDFs, but never read the global bucket
    /// entries, which are left out (a 1×1 placeholder).
    Product(&'a Product),
    /// Both, and their mixture (`env_sample_mixture`).
    Mixture(&'a Product),
}

impl GpuEnvironment {
    pub fn upload(ctx: &Context, env: &Environment, distribution: &Distribution) -> Result<GpuEnvironment> {
        GpuEnvironment::upload_with(ctx, env, distribution, Samplers::Global)
    }

    /// As [`GpuEnvironment::upload`], with the tables `samplers` need, built from
    /// `distribution`. Each image's texels are written straight into the memory its upload
    /// copies from.
    pub fn upload_with(
        ctx: &Context,
        env: &Environment,
        distribution: &Distribution,
        samplers: Samplers,
    ) -> Result<GpuEnvironment> {
        let max = ctx.info().max_image_dimension_2d;
        if env.width > max || env.height > max {
            return Err(Error::input_file(
                &env.source,
                format!("the environment is {}x{}, larger than this device's {max} pixel limit", env.width, env.height),
            ));
        }
        let (rgba, r32) = (vk::Format::R32G32B32A32_SFLOAT, vk::Format::R32_SFLOAT);
        let texels = Image::filled_rows(ctx, rgba, env.width, env.height, |first_row, out| {
            distribution.write_texel_rows(env, first_row, out)
        })?;
        let (width, height) = distribution.table_size();
        let buckets = match samplers {
            Samplers::Product(_) => placeholder(ctx, rgba)?,
            _ => Image::filled(ctx, rgba, width, height, |out| distribution.write_buckets(out))?,
        };
        let cdf = Image::filled(ctx, r32, width, height, |out| distribution.write_cdfs(out))?;
        let product = match samplers {
            Samplers::Global => None,
            Samplers::Product(p) | Samplers::Mixture(p) => Some(p),
        };
        let (product_buckets, product_cdf, product_spans, product_index) = match product {
            Some(p) => {
                let (width, bucket_rows, cdf_rows) = p.table_size();
                if width > max || cdf_rows > max {
                    return Err(Error::input_file(
                        &env.source,
                        format!(
                            "its product tables need {width}x{cdf_rows} images, larger than this device's {max} pixel limit"
                        ),
                    ));
                }
                (
                    Image::filled(ctx, rgba, width, bucket_rows, |out| p.write_buckets(distribution, out))?,
                    Image::filled(ctx, r32, width, cdf_rows, |out| p.write_cdfs(distribution, out))?,
                    Image::filled(ctx, vk::Format::R32_UINT, p.columns, p.rows, |out: &mut [u32]| {
                        out.copy_from_slice(&p.spans)
                    })?,
                    Image::rows_of(ctx, vk::Format::R32_UINT, INDEX_WIDTH, &p.index)?,
                )
            }
            None => (
                placeholder(ctx, rgba)?,
                placeholder(ctx, r32)?,
                placeholder(ctx, vk::Format::R32_UINT)?,
                placeholder(ctx, vk::Format::R32_UINT)?,
            ),
        };
        // EnvInfo: the header, with the product tables' sizes when they are on.
        let mut info = vec![0u32; 10];
        info[..8].copy_from_slice(&distribution.header());
        if let Some(p) = product {
            info[6..10].copy_from_slice(&[p.grid, p.coarse_columns, p.coarse_rows, p.ratio_row()]);
        }
        let info = Buffer::uniform(ctx, bytemuck::cast_slice(&info))?;
        Ok(GpuEnvironment { texels, buckets, cdf, info, product_buckets, product_cdf, product_spans, product_index })
    }

    /// The bindings of descriptor set 1, in `environment.glsl` order.
    pub fn bindings(&self) -> [Binding<'_>; 8] {
        [
            Binding::Image(&self.texels),
            Binding::Image(&self.buckets),
            Binding::Image(&self.cdf),
            Binding::Buffer(&self.info),
            Binding::Image(&self.product_buckets),
            Binding::Image(&self.product_cdf),
            Binding::Image(&self.product_spans),
            Binding::Image(&self.product_index),
        ]
    }
}

/// A 1×1 image of zeros bound where a table is not needed.
fn placeholder(ctx: &Context, format: vk::Format) -> Result<Image> {
    Image::new(ctx, format, 1, 1, 1, false)
}

/// The layout of descriptor set 1.
pub const SET_LAYOUT: [BindingKind; 8] = [
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::UniformBuffer,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
    BindingKind::StorageImage,
];
