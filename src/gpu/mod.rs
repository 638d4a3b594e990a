//! The Vulkan layer: one [`Context`] (instance, device, queue, memory), buffers and images,
//! compute pipelines built from the committed SPIR-V, the bake's graphics pipeline, and GPU
//! timestamps.

pub mod context;
pub mod driver_cache;
pub mod graphics;
#[doc(hidden)]
pub mod inject;
pub mod interface;
pub mod memory;
pub mod pipeline;
mod pipeline_cache;
pub mod shaders;
pub mod timer;

pub use context::{Context, ContextOptions, DeviceInfo, Presentation, Surface};
pub use interface::{GlslLayout, GlslStruct, Interface};
pub use memory::{Buffer, Image};
pub use pipeline::{Binding, BindingKind, ComputePipeline, DescriptorSet};
pub use timer::GpuTimer;
