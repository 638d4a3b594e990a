use lookdev::environment::Environment;
use lookdev::gbuffer::GBuffer;
use lookdev::gpu::{Context, ContextOptions};
use lookdev::material::Look;
use lookdev::render::scene::Scene;
use lookdev::render::settings::{Overrides, Settings};
use lookdev::render::Renderer;
use std::time::Instant;
fn main() {
    let size: u32 = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(512);
    let ctx = Context::new(&ContextOptions::default()).unwrap();
    let look = Look::builtin_default();
    let settings = Settings::resolve(&look, &Overrides::default()).unwrap();
    let scene = Scene::new(GBuffer::shaderball(size, size), "x".into(), look, Environment::studio(), settings).unwrap();
    let mut r = Renderer::new(&ctx, &scene.gbuffer, &scene.environment).unwrap();
    r.set_stacks(&scene.stacks).unwrap();
    r.render_samples(1).unwrap();
    for batch in [1u32, 4, 16, 64] {
        r.set_seed(batch);
        let t = Instant::now();
        let mut gpu = 0.0;
        for _ in 0..(64 / batch) {
            gpu += r.render_samples(batch).unwrap().unwrap_or(0.0);
        }
        println!("batch {batch:3}: wall {:.3} s, gpu {:.3} s for 64 spp", t.elapsed().as_secs_f64(), gpu);
    }
}
