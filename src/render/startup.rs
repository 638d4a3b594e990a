//! A render's start-up, overlapped: one thread opens the Vulkan device and, as soon as the
//! scene's settings say how the kernels are specialised, compiles them, while the calling
//! thread reads the scene (environment, g-buffer, stacks) and uploads it. On a CPU driver the
//! relight kernel's compile is start-up's longest step, and lavapipe's pipeline cache keeps no
//! compiled code, so the compile overlaps the loading instead (docs/development.md#start-up).
//! Pipeline creation is thread-safe, and the pipeline cache synchronises itself.

use crate::gpu::{Context, ContextOptions};
use crate::render::renderer::{Kernels, Specialization};
use crate::render::scene::{Scene, SceneSpec};
use crate::render::settings::Settings;
use crate::Result;
use std::sync::mpsc::{channel, Sender};
use std::thread::{Scope, ScopedJoinHandle};

/// Kernels compiling on the start-up thread; pass them to
/// [`crate::render::Renderer::with_kernels`], which waits for them once its images are up.
pub struct PendingKernels<'scope> {
    pub specialization: Specialization,
    /// None only when the scene failed before its settings were known.
    thread: ScopedJoinHandle<'scope, Option<Result<Kernels>>>,
}

impl PendingKernels<'_> {
    /// The compiled kernels, or the error compiling them gave.
    pub fn wait(self) -> Result<Kernels> {
        match self.thread.join() {
            Ok(kernels) => kernels.expect("the specialisation was sent before the kernels were pending"),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    }
}

/// A scene loaded, its device open and its kernels compiling.
pub struct Started<'scope> {
    pub scene: Scene,
    pub ctx: Context,
    pub kernels: PendingKernels<'scope>,
}

/// Loads the scene `spec` names on this thread while a thread of `threads` opens the device
/// `options` name and compiles the kernels `specialize` chooses from the scene's settings. The
/// scope joins that thread however this ends, and the thread never waits for settings that
/// will not come. A bad scene is reported before a device that failed to open, as when one
/// step follows the other.
pub fn start<'scope>(
    threads: &'scope Scope<'scope, '_>,
    spec: &SceneSpec,
    options: ContextOptions,
    specialize: impl FnOnce(&Settings) -> Specialization,
) -> Result<Started<'scope>> {
    let (specialization_tx, specialization_rx) = channel::<Specialization>();
    let (ctx_tx, ctx_rx) = channel::<Result<Context>>();
    let thread = threads.spawn(move || {
        let opened = Context::new(&options);
        let ctx = opened.as_ref().ok().cloned();
        // The receiver lives until the context is taken.
        let _ = ctx_tx.send(opened);
        let ctx = ctx?;
        // No specialisation comes when the scene failed first: nothing to compile then.
        let specialization = specialization_rx.recv().ok()?;
        Some(Kernels::compile(&ctx, specialization))
    });
    let scene = {
        let _timing = crate::timings::phase("scene");
        load(spec, specialization_tx, specialize)
    };
    let (scene, specialization) = scene?;
    let ctx = match ctx_rx.recv() {
        Ok(opened) => opened?,
        // The thread ended without sending: it panicked.
        Err(_) => match thread.join() {
            Err(panic) => std::panic::resume_unwind(panic),
            Ok(_) => unreachable!("the thread sends the context before it ends"),
        },
    };
    Ok(Started { scene, ctx, kernels: PendingKernels { specialization, thread } })
}

/// Loads the scene, sending the specialisation as soon as the settings give it. `sender` drops
/// when this returns, whatever the outcome, which tells the device thread whether to compile.
fn load(
    spec: &SceneSpec,
    sender: Sender<Specialization>,
    specialize: impl FnOnce(&Settings) -> Specialization,
) -> Result<(Scene, Specialization)> {
    let start = Scene::start(spec)?;
    let specialization = specialize(&start.settings);
    // Only a device that failed to open has stopped listening; that error comes next.
    let _ = sender.send(specialization);
    Ok((start.finish(spec)?, specialization))
}
