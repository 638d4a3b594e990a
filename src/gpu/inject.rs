//! Injected failures, for the tests only: a named creation step fails as if the driver had
//! refused it, so a test can check that everything made before that step is released.
//!
//! A test arms a step on its own thread with [`fail_at`]; a whole lookdev process is armed with
//! `LOOKDEV_FAIL_AT=<step>` (for the viewer, which only runs as its own process). Nothing else
//! arms a step, so for everyone else each check is a thread-local read and a comparison.

use super::context::ValidationCounter;
use crate::{Error, Result};
use std::cell::RefCell;
use std::sync::{Arc, OnceLock};

/// A creation step that can be made to fail. Each fails in place of its Vulkan call, so what
/// the steps before it made exists and must be released.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// The debug messenger (with validation on), after the instance.
    DebugMessenger,
    /// The window's surface, after the instance and the messenger.
    Surface,
    /// The logical device, after the instance, messenger and surface.
    Device,
    /// The context's command pool, after the device.
    CommandPool,
    /// The end of context creation, when every part of the context exists.
    ContextReady,
    /// The first descriptor set layout of a compute pipeline, after its shader module.
    SetLayout,
    /// A compute pipeline's layout, after its shader module and set layouts.
    PipelineLayout,
    /// The compute pipeline itself, after its shader module, set layouts and layout.
    Pipeline,
    /// The viewer's frame fence, after its command pool, command buffer and semaphore.
    PresenterFence,
    /// The first view of a swapchain image, after the swapchain and every frame object.
    SwapchainView,
}

impl Step {
    pub const ALL: [Step; 10] = [
        Step::DebugMessenger,
        Step::Surface,
        Step::Device,
        Step::CommandPool,
        Step::ContextReady,
        Step::SetLayout,
        Step::PipelineLayout,
        Step::Pipeline,
        Step::PresenterFence,
        Step::SwapchainView,
    ];

    /// The step's name for `LOOKDEV_FAIL_AT`.
    pub fn name(self) -> &'static str {
        match self {
            Step::DebugMessenger => "debug-messenger",
            Step::Surface => "surface",
            Step::Device => "device",
            Step::CommandPool => "command-pool",
            Step::ContextReady => "context-ready",
            Step::SetLayout => "set-layout",
            Step::PipelineLayout => "pipeline-layout",
            Step::Pipeline => "pipeline",
            Step::PresenterFence => "presenter-fence",
            Step::SwapchainView => "swapchain-view",
        }
    }
}

/// What a test armed on its thread, and what it saw while armed.
struct Armed {
    step: Step,
    reached: bool,
    /// Instances made on this thread while armed, less those destroyed: the layer reports leaked
    /// children when their instance is destroyed, but nothing reports an instance never destroyed.
    live_instances: i64,
    /// The validation counters of contexts whose creation began while armed.
    counters: Vec<Arc<ValidationCounter>>,
}

thread_local! {
    static ARMED: RefCell<Option<Armed>> = const { RefCell::new(None) };
}

/// Arms `step` on this thread until the returned guard drops: the first time the thread reaches
/// the step, it fails.
pub fn fail_at(step: Step) -> FailAt {
    ARMED.with(|armed| {
        *armed.borrow_mut() = Some(Armed { step, reached: false, live_instances: 0, counters: Vec::new() });
    });
    FailAt { _thread_bound: std::marker::PhantomData }
}

/// An armed step; disarms when dropped. Read it after the failed creation has returned.
pub struct FailAt {
    /// Arming is per thread, so the guard must stay on its thread.
    _thread_bound: std::marker::PhantomData<*const ()>,
}

impl FailAt {
    fn read<T>(&self, f: impl FnOnce(&Armed) -> T) -> T {
        ARMED.with(|armed| f(armed.borrow().as_ref().expect("armed until the guard drops")))
    }

    /// Whether the step was reached (and so failed).
    pub fn reached(&self) -> bool {
        self.read(|a| a.reached)
    }

    /// Instances made on this thread since arming that have not been destroyed.
    pub fn live_instances(&self) -> i64 {
        self.read(|a| a.live_instances)
    }

    /// Validation errors reported to the contexts whose creation began since arming, those
    /// reported when their instance was destroyed included.
    pub fn validation_errors(&self) -> u32 {
        self.read(|a| a.counters.iter().map(|c| c.errors()).sum())
    }
}

impl Drop for FailAt {
    fn drop(&mut self) {
        ARMED.with(|armed| armed.borrow_mut().take());
    }
}

/// The step `LOOKDEV_FAIL_AT` names, read once per process.
fn from_env() -> Option<Step> {
    static STEP: OnceLock<Option<Step>> = OnceLock::new();
    *STEP.get_or_init(|| {
        let name = std::env::var("LOOKDEV_FAIL_AT").ok()?;
        Step::ALL.into_iter().find(|step| step.name() == name)
    })
}

/// Fails if `step` is armed: called just before the step's Vulkan call.
pub(crate) fn check(step: Step) -> Result<()> {
    let on_thread = ARMED.with(|armed| match armed.borrow_mut().as_mut() {
        Some(armed) if armed.step == step && !armed.reached => {
            armed.reached = true;
            true
        }
        _ => false,
    });
    if on_thread || from_env() == Some(step) {
        return Err(Error::gpu(format!("injected failure at {}", step.name())));
    }
    Ok(())
}

/// Notes a context's validation counter, for [`FailAt::validation_errors`].
pub(crate) fn watch(counter: &Arc<ValidationCounter>) {
    ARMED.with(|armed| {
        if let Some(armed) = armed.borrow_mut().as_mut() {
            armed.counters.push(counter.clone());
        }
    });
}

/// Counts an instance made (+1) or destroyed (−1) on this thread, for [`FailAt::live_instances`].
pub(crate) fn count_instance(change: i64) {
    // try_with: an instance may be dropped while its thread's locals are being torn down.
    let _ = ARMED.try_with(|armed| {
        if let Some(armed) = armed.borrow_mut().as_mut() {
            armed.live_instances += change;
        }
    });
}
