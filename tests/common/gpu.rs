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
