//! Small scenes for GPU tests: analytic g-buffers, looks, and a renderer around them.

use glam::Vec3;
use lookdev::environment::Environment;
use lookdev::gbuffer::{stable_tangent, GBuffer};
use lookdev::gpu::Context;
use lookdev::material::stack::PackedStacks;
use lookdev::material::Look;
use lookdev::render::{Lighting, Renderer};
use std::collections::BTreeMap;
use std::path::Path;

/// A unit sphere seen by an orthographic camera looking down −Z (V = (0,0,1) everywhere),
/// filling a `size`×`size` image; pixels outside it are background. Coverage is 1 or 0 (no
/// antialiasing), so every covered pixel is a clean furnace sample. Object id 1; masks
/// `left` (x < 0) and `ramp` (x from 0 at the left edge to 1 at the right).
pub fn orthographic_sphere(size: u32) -> GBuffer {
    let pixels = (size * size) as usize;
    let mut g = GBuffer {
        width: size,
        height: size,
        normal: Vec::with_capacity(pixels),
        view: vec![[0.0, 0.0, 1.0]; pixels],
        tangent: Vec::with_capacity(pixels),
        coverage: Vec::with_capacity(pixels),
        object_id: Vec::with_capacity(pixels),
        masks: BTreeMap::new(),
        object_names: BTreeMap::from([(1, "sphere".to_string())]),
        has_view: false,
        has_tangent: true,
    };
    let mut left = Vec::with_capacity(pixels);
    let mut ramp = Vec::with_capacity(pixels);
    for y in 0..size {
        for x in 0..size {
            let px = (x as f32 + 0.5) / size as f32 * 2.0 - 1.0;
            let py = 1.0 - (y as f32 + 0.5) / size as f32 * 2.0;
            let r2 = px * px + py * py;
            let covered = r2 < 0.999;
            let n = if covered { [px, py, (1.0 - r2).sqrt()] } else { [0.0, 0.0, 1.0] };
            // Tangents around +Y, as on the shader ball, except at the poles.
            let around = Vec3::Y.cross(Vec3::from(n));
            let t = if around.length() > 1e-3 { around.normalize().to_array() } else { stable_tangent(n) };
            g.normal.push(n);
            g.tangent.push(t);
            g.coverage.push(if covered { 1.0 } else { 0.0 });
            g.object_id.push(if covered { 1 } else { 0 });
            left.push(if px < 0.0 { 1.0 } else { 0.0 });
            ramp.push((x as f32 + 0.5) / size as f32);
        }
    }
    g.masks.insert("left".into(), left);
    g.masks.insert("ramp".into(), ramp);
    g
}

/// A renderer for a g-buffer, environment and look, with stacks resolved and lighting set.
pub fn renderer(ctx: &Context, gbuffer: &GBuffer, env: &Environment, look: &Look, lighting: Lighting) -> Renderer {
    let ids = lookdev::render::scene::covered_object_ids(gbuffer);
    let masks: Vec<String> = gbuffer.masks.keys().cloned().collect();
    let stacks = PackedStacks::pack(look, ids, &masks, Path::new("test g-buffer")).unwrap();
    let mut renderer = Renderer::new(ctx, gbuffer, env).unwrap();
    renderer.set_stacks(&stacks).unwrap();
    renderer.set_lighting(lighting);
    renderer
}

/// A look from TOML text (presets resolve against the built-ins).
pub fn look(text: &str) -> Look {
    Look::parse(text, Path::new("test-look.toml")).unwrap()
}
