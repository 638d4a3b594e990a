//! Small scenes for GPU tests: analytic g-buffers, looks, and a renderer around them.

use glam::Vec3;
use lookdev::environment::Environment;
use lookdev::gbuffer::{stable_tangent, GBuffer};
use lookdev::gpu::Context;
use lookdev::material::stack::PackedStacks;
use lookdev::material::Look;
use lookdev::render::{Lighting, Renderer};
use std::path::Path;

/// A unit sphere seen by an orthographic camera looking down −Z (V = (0,0,1) everywhere),
/// filling a `size`×`size` image; pixels outside it are background. Coverage is 1 or 0 (no
/// antialiasing), so every covered pixel is a clean furnace sample. Object id 1; masks
/// `left` (x < 0) and `ramp` (x from 0 at the left edge to 1 at the right).
pub fn orthographic_sphere(size: u32) -> GBuffer {
    let mut g = lookdev::lab::furnace::sphere(size);
    let mut left = Vec::with_capacity(g.normal.len());
    let mut ramp = Vec::with_capacity(g.normal.len());
    for (p, n) in g.normal.iter().enumerate() {
        let x = p as u32 % size;
        // Tangents around +Y, as on the shader ball, except at the poles.
        let around = Vec3::Y.cross(Vec3::from(*n));
        g.tangent[p] = if around.length() > 1e-3 { around.normalize().to_array() } else { stable_tangent(*n) };
        let px = (x as f32 + 0.5) / size as f32 * 2.0 - 1.0;
        left.push(if px < 0.0 { 1.0 } else { 0.0 });
        ramp.push((x as f32 + 0.5) / size as f32);
    }
    g.has_tangent = true;
    g.masks.insert("left".into(), left);
    g.masks.insert("ramp".into(), ramp);
    g
}

/// A renderer for a g-buffer, environment and look, with stacks resolved and lighting set.
pub fn renderer(ctx: &Context, gbuffer: &GBuffer, env: &Environment, look: &Look, lighting: Lighting) -> Renderer {
    let ids = lookdev::render::scene::covered_object_ids(gbuffer);
    let stacks = PackedStacks::pack(look, ids, gbuffer, Path::new("test g-buffer")).unwrap();
    let mut renderer = Renderer::new(ctx, gbuffer, env).unwrap();
    renderer.set_stacks(&stacks).unwrap();
    renderer.set_lighting(lighting);
    renderer
}

/// A look from TOML text (presets resolve against the built-ins).
pub fn look(text: &str) -> Look {
    Look::parse(text, Path::new("test-look.toml")).unwrap()
}

/// A look in which the ball (object 1) emits red and everything else green, under no light:
/// each object's own colour, for tests of filters that must not mix objects.
pub const TWO_EMITTERS: &str = r#"
[[object]]
[[object.layer]]
[object.layer.set]
emission = [0.0, 0.8, 0.1]

[[object]]
id = 1
[[object.layer]]
[object.layer.set]
emission = [0.9, 0.05, 0.0]
"#;

/// The default look with its one layer set to `params`: one material everywhere.
pub fn one_material(params: lookdev::material::Params) -> Look {
    let mut look = Look::default_material();
    look.objects[0].layers[0].params = params;
    look
}
