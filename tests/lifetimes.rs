//! Vulkan objects are released when creation fails part-way. Each case arms an injected failure
//! (`lookdev::gpu::inject`) at one creation step, so that the steps before it have made their
//! objects, and checks that nothing was left alive: the validation layer reports an object still
//! alive when its device or instance is destroyed, and the hook counts instances never destroyed,
//! which nothing else would see. The viewer's steps are covered in `tests/viewer.rs`, under Xvfb.

mod common;

use lookdev::gpu::inject::{fail_at, Step};
use lookdev::gpu::{shaders, BindingKind, ComputePipeline, Context, ContextOptions, Presentation};
use lookdev::Error;

/// Two set layouts, so a failure after them has more than one to release.
const SETS: [&[BindingKind]; 2] = [&[BindingKind::StorageBuffer; 3], &[BindingKind::StorageImage]];

fn options() -> ContextOptions {
    ContextOptions { device_name: std::env::var("LOOKDEV_TEST_DEVICE").ok(), validation: true, graphics: false }
}

fn assert_injected(error: Option<Error>, step: Step) {
    let error = error.unwrap_or_else(|| panic!("{step:?}: creation succeeded despite the injected failure"));
    assert!(error.to_string().contains(&format!("injected failure at {}", step.name())), "{step:?}: {error}");
}

#[test]
fn a_compute_pipeline_that_fails_part_way_releases_what_it_made() {
    for step in [Step::SetLayout, Step::PipelineLayout, Step::Pipeline] {
        let ctx = common::gpu::context();
        let fail = fail_at(step);
        let made = ComputePipeline::new(&ctx, &shaders::BRDF_PROBE, &SETS, 0);
        assert!(fail.reached(), "{step:?} was never reached");
        assert_injected(made.err(), step);
        drop(fail);
        // The context is still whole: the same pipeline can be made once the failure is gone.
        drop(ComputePipeline::new(&ctx, &shaders::BRDF_PROBE, &SETS, 0).unwrap());
        // Destroying the device reports the shader module or layouts if they were left alive.
        common::gpu::finish(ctx);
    }
}

#[test]
fn a_context_that_fails_part_way_releases_what_it_made() {
    // After the instance; after the instance and messenger; after the device; after everything.
    for step in [Step::DebugMessenger, Step::Device, Step::CommandPool, Step::ContextReady] {
        for graphics in [false, true] {
            let fail = fail_at(step);
            let made = Context::new(&ContextOptions { graphics, ..options() });
            assert!(fail.reached(), "{step:?} was never reached");
            assert_injected(made.err(), step);
            assert_eq!(fail.live_instances(), 0, "{step:?}: the instance was not destroyed");
            // Destroying the instance reports a messenger or device left alive.
            assert_eq!(fail.validation_errors(), 0, "{step:?}: validation errors (see stderr)");
        }
    }
}

#[test]
fn a_context_for_a_window_that_fails_at_its_surface_releases_the_instance() {
    // A window's surface needs a display; these fail before it is made (the viewer's tests cover
    // failures after it, under Xvfb).
    let refuse = |_: &ash::Entry, _: &ash::Instance| -> lookdev::Result<ash::vk::SurfaceKHR> {
        Err(Error::gpu("no window here"))
    };
    let presentation = || Presentation { instance_extensions: &[], create_surface: &refuse };

    let fail = fail_at(Step::Surface);
    let made = Context::with_surface(&options(), presentation());
    assert!(fail.reached());
    assert_injected(made.err(), Step::Surface);
    assert_eq!(fail.live_instances(), 0, "the instance was not destroyed");
    assert_eq!(fail.validation_errors(), 0, "validation errors (see stderr)");
    drop(fail);

    // The window system refusing the surface unwinds the same way.
    let fail = fail_at(Step::ContextReady);
    let made = Context::with_surface(&options(), presentation());
    let error = made.err().expect("the surface was refused");
    assert!(error.to_string().contains("no window here"), "{error}");
    assert!(!fail.reached(), "creation went on past the refused surface");
    assert_eq!(fail.live_instances(), 0, "the instance was not destroyed");
    assert_eq!(fail.validation_errors(), 0, "validation errors (see stderr)");
}

#[test]
fn the_hook_counts_the_instance_of_a_context_made_and_dropped() {
    // A step this test never reaches, armed only to read the hook's counts.
    let fail = fail_at(Step::SwapchainView);
    let ctx = common::gpu::context();
    drop(ComputePipeline::new(&ctx, &shaders::BRDF_PROBE, &SETS, 0).unwrap());
    assert_eq!(fail.live_instances(), 1);
    common::gpu::finish(ctx);
    assert_eq!(fail.live_instances(), 0);
    assert_eq!(fail.validation_errors(), 0);
    assert!(!fail.reached());
}
