//! The white furnace: spheres over roughness × metallic under a uniform white environment. A
//! sphere that reflects exactly what it receives vanishes against the background.

use super::{directional_albedo, Subject};
use crate::environment::Environment;
use crate::gbuffer::{stable_tangent, GBuffer};
use crate::gpu::Context;
use crate::material::stack::PackedStacks;
use crate::material::{Look, Params};
use crate::render::{Lighting, Renderer};
use crate::shading::model::Model;
use crate::shading::tonemap::Tonemap;
use crate::Result;
use glam::Vec3;
use image::RgbaImage;
use std::collections::BTreeMap;
use std::path::Path;

/// A unit sphere under an orthographic camera looking down −Z, filling a `size`² image.
pub fn sphere(size: u32) -> GBuffer {
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
        maps: BTreeMap::new(),
        object_names: BTreeMap::from([(1, "sphere".to_string())]),
        mask_names: BTreeMap::new(),
        visibility: None,
        has_view: false,
        has_tangent: false,
        supersample: 1,
    };
    for y in 0..size {
        for x in 0..size {
            let px = (x as f32 + 0.5) / size as f32 * 2.0 - 1.0;
            let py = 1.0 - (y as f32 + 0.5) / size as f32 * 2.0;
            let r2 = px * px + py * py;
            let covered = r2 < 0.999;
            let n = if covered { [px, py, (1.0 - r2).sqrt()] } else { [0.0, 0.0, 1.0] };
            g.normal.push(n);
            g.tangent.push(stable_tangent(n));
            g.coverage.push(if covered { 1.0 } else { 0.0 });
            g.object_id.push(u32::from(covered));
        }
    }
    g
}

/// One sphere of the grid: its material, its render, the rendered value at the centre pixel
/// (seen head-on) and the integrator's albedo there.
pub struct Cell {
    pub params: Params,
    pub image: RgbaImage,
    pub centre: Vec3,
    pub integrated: Vec3,
}

/// Renders the grid, row by row of `metallic`, each row across `roughness`.
pub fn render(
    ctx: &Context,
    model: &Model,
    base: &Params,
    roughness: &[f32],
    metallic: &[f32],
    size: u32,
    spp: u32,
) -> Result<Vec<Vec<Cell>>> {
    let gbuffer = sphere(size);
    let env = Environment::uniform([1.0; 3], 64, 32);
    let mut renderer = Renderer::with_model(ctx, &gbuffer, &env, model)?;
    renderer.set_lighting(Lighting::default());
    let centre = ((size / 2) * size + size / 2) as usize;
    let mut rows = Vec::new();
    for &m in metallic {
        let mut row = Vec::new();
        for &r in roughness {
            let params = Params { metallic: m, roughness: r, ..*base };
            let mut look = Look::default_material();
            look.objects[0].layers[0].params = params;
            let stacks = PackedStacks::pack(&look, vec![1], &gbuffer, Path::new("furnace"))?;
            renderer.set_stacks(&stacks)?;
            crate::render::progressive::accumulate(&mut renderer, spp, |_| {})?;
            let radiance = renderer.read_radiance()?;
            let rgba = renderer.read_display(0.0, Tonemap::Linear)?;
            let image = RgbaImage::from_fn(size, size, |x, y| {
                let i = ((y * size + x) * 4) as usize;
                image::Rgba([rgba[i], rgba[i + 1], rgba[i + 2], 255])
            });
            let subject = Subject { label: String::new(), params, shading: renderer.shading().clone() };
            let c = radiance[centre];
            row.push(Cell {
                params,
                image,
                centre: Vec3::new(c[0], c[1], c[2]),
                integrated: directional_albedo(&subject, (gbuffer.normal[centre][2]).clamp(-1.0, 1.0).acos()),
            });
        }
        rows.push(row);
    }
    Ok(rows)
}
