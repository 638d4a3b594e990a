//! A render's start-up, overlapped: one thread opens the Vulkan device while the calling thread
//! reads the scene; once the scene is read and sound, another compiles the kernels its
//! settings specialise while the calling thread uploads the g-buffer and the environment
//! (its sampling tables included). On a CPU driver the relight kernel's compile is start-up's
//! longest step, and lavapipe's pipeline cache keeps no compiled code, so the compile overlaps
//! the uploads instead (docs/development.md, "Start-up"). A bad scene is refused before
//! anything is compiled, in little time and memory. Pipeline creation is thread-safe, and the
//! pipeline cache synchronises itself.

use crate::gpu::{Context, ContextOptions};
use crate::render::renderer::{Kernels, Specialization};
use crate::render::scene::{Scene, SceneSpec};
use crate::Result;
use std::thread::{Scope, ScopedJoinHandle};

/// Kernels compiling on a thread of their own; pass them to
/// [`crate::render::Renderer::with_kernels`], which waits for them once its images are up.
pub struct PendingKernels<'scope> {
    pub specialization: Specialization,
    thread: ScopedJoinHandle<'scope, Result<Kernels>>,
}

impl PendingKernels<'_> {
    /// The compiled kernels, or the error compiling them gave.
    pub fn wait(self) -> Result<Kernels> {
        self.thread.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    }
}

/// A scene loaded, its device open and its kernels compiling.
pub struct Started<'scope> {
    pub scene: Scene,
    pub ctx: Context,
    pub kernels: PendingKernels<'scope>,
}

/// Loads the scene `spec` names on this thread while a thread of `threads` opens the device
/// `options` name; then starts compiling, on another, the kernels `specialize` chooses for the
/// scene. The scope joins the threads however this ends. A bad scene is reported
/// before a device that failed to open, as when one step follows the other.
pub fn start<'scope>(
    threads: &'scope Scope<'scope, '_>,
    spec: &SceneSpec,
    options: ContextOptions,
    specialize: impl FnOnce(&Scene) -> Specialization,
) -> Result<Started<'scope>> {
    let opening = threads.spawn(move || Context::new(&options));
    let scene = {
        let _timing = crate::timings::phase("scene");
        Scene::load(spec)
    };
    let ctx = opening.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
    let (scene, ctx) = (scene?, ctx?);
    let specialization = specialize(&scene);
    let compiling = ctx.clone();
    let thread = threads.spawn(move || Kernels::compile(&compiling, specialization));
    Ok(Started { scene, ctx, kernels: PendingKernels { specialization, thread } })
}
