//! A validated GPU context for tests, and a check that it saw no validation errors.

use lookdev::gpu::{Context, ContextOptions};

/// A context on the default device with the Khronos validation layer on. Tests fail, rather
/// than skip, when the layer is missing: validation is part of what they check.
pub fn context() -> Context {
    with_options(false)
}

/// Like [`context`], on a queue that can also draw (for baking).
pub fn graphics_context() -> Context {
    with_options(true)
}

fn with_options(graphics: bool) -> Context {
    let device_name = std::env::var("LOOKDEV_TEST_DEVICE").ok();
    Context::new(&ContextOptions { device_name, validation: true, graphics }).unwrap_or_else(|e| panic!("{e}"))
}

/// Drops the context (destroying the device, which reports leaks) and asserts zero errors.
pub fn finish(ctx: Context) {
    let counter = ctx.validation_counter();
    drop(ctx);
    assert_eq!(counter.errors(), 0, "Vulkan validation reported errors (see stderr)");
}

/// The energy table a kernel specialized for `model` reads, built on the GPU as the renderer
/// builds it (a placeholder of zeros when the model does not compensate), with the shading the
/// Rust reference needs to mirror the kernel.
pub fn model_shading(
    ctx: &Context,
    model: &lookdev::shading::model::Model,
) -> (lookdev::gpu::Buffer, lookdev::shading::brdf::Shading) {
    use lookdev::shading::brdf::EnergyTable;
    let table = if model.energy_compensation {
        lookdev::render::energy::build(ctx, model).unwrap()
    } else {
        EnergyTable::placeholder()
    };
    let buffer = lookdev::gpu::Buffer::with_data(ctx, bytemuck::cast_slice(&table.values)).unwrap();
    let energy = model.energy_compensation.then(|| std::sync::Arc::new(table));
    (buffer, lookdev::shading::brdf::Shading::new(*model, energy))
}
