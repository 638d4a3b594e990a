// Renders forever in batches of N (for profiling): dispatch_loop SIZE BATCH
use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::gpu::{Context, ContextOptions};
use lookdev::material::Look;
use lookdev::render::scene::Scene;
use lookdev::render::settings::{Overrides, Settings};
use lookdev::render::Renderer;
fn main() {
    let size: u32 = std::env::args().nth(1).unwrap().parse().unwrap();
    let batch: u32 = std::env::args().nth(2).unwrap().parse().unwrap();
    let ctx = Context::new(&ContextOptions::default()).unwrap();
    let look = Look::builtin_default();
    let settings = Settings::resolve(&look, &Overrides::default()).unwrap();
    let scene = Scene::new(GBuffer::shaderball(size, size), "x".into(), look, Environment::studio(), settings).unwrap();
    let mut r = Renderer::new(&ctx, &scene.gbuffer, &scene.environment).unwrap();
    r.set_stacks(&scene.stacks).unwrap();
    loop {
        r.set_seed(r.samples() + 1);
        r.render_samples(batch).unwrap();
    }
}
