//! Mirror of `glsl/include/material.glsl`: the material the BRDF reads, the eleven Disney
//! parameters and the complex IOR's edge, unpacked from the four vec4s of the GPU layout.
//! `crate::material` converts its `Params` into one (`From<&Params>`), through the same layout.

use glam::Vec3;

/// The BRDF's inputs at one point (GLSL `Material`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Linear Rec.709.
    pub base_color: Vec3,
    pub metallic: f32,
    pub subsurface: f32,
    pub specular: f32,
    pub specular_tint: f32,
    pub roughness: f32,
    pub anisotropic: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub clearcoat: f32,
    pub clearcoat_gloss: f32,
    /// Where the complex IOR lies between its two dielectric ends, per channel.
    pub ior_edge: Vec3,
}

/// GLSL `unpack_material(p0, p1, p2, p3)`, on the sixteen floats of the four vec4s.
pub fn unpack_material(p: &[f32; 16]) -> Material {
    Material {
        base_color: Vec3::new(p[0], p[1], p[2]),
        metallic: p[3],
        subsurface: p[4],
        specular: p[5],
        specular_tint: p[6],
        roughness: p[7],
        anisotropic: p[8],
        sheen: p[9],
        sheen_tint: p[10],
        clearcoat: p[11],
        clearcoat_gloss: p[12],
        ior_edge: Vec3::new(p[13], p[14], p[15]),
    }
}
