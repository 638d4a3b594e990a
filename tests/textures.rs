//! Textured assets render in their own colours: a glTF written here, baked, imported and
//! rendered through the command line, against each pixel's parameters rendered as constants.
//!
//! The asset is a camera-facing quad under an orthographic camera that frames it exactly, so each
//! pixel's texture coordinates are known. It carries a base colour texture of many hues (a hue
//! wheel under a checker) with a KHR_texture_transform, a metallic-roughness texture of
//! independent gradients on TEXCOORD_1, and an emissive texture whose transform moves it to
//! TEXCOORD_1. This file works out, on the CPU and from glTF's own definitions, what every pixel's
//! material must be: the factor times the texture, filtered bilinearly (the textures are
//! magnified, so no mip level below the first is read) and averaged over the bake's samples. The
//! reference is then the CPU mirror of the relight kernel rendering each pixel with those
//! constants, with the same seed, under a broad sky whose light varies slowly, so that the noise
//! is far below the tolerance.
//!
//! `LOOKDEV_ASSET_BIN=<another lookdev>` bakes and imports with another build (an older one, for
//! instance), which the same render and reference then judge.

mod common;

use common::cli::{assert_success, stderr};
use common::gltf::{plane, srgb_to_linear, Gltf};
use glam::{Mat3, Vec3};
use lookdev::asset::bake::jitter_pattern;
use lookdev::gbuffer::GBuffer;
use lookdev::material::Params;
use lookdev::render::sampling::Sampling;
use lookdev::render::Lighting;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Image size in pixels; the quad fills it.
const SIZE: u32 = 64;
/// Texture size: half the image's, so every texture is magnified.
const TEXELS: u32 = 32;
/// Bake samples per pixel (a 4×4 grid).
const SAMPLES: u32 = 16;
const SPP: u32 = 256;
const BASE_COLOR_FACTOR: [f32; 3] = [0.9, 0.8, 1.0];
const METALLIC_FACTOR: f32 = 1.0;
const ROUGHNESS_FACTOR: f32 = 0.9;
const EMISSIVE_FACTOR: [f32; 3] = [1.0, 0.6, 0.3];
const EMISSIVE_STRENGTH: f32 = 0.5;
/// KHR_texture_transform of the base colour texture: offset, rotation, scale.
const BASE_COLOR_TRANSFORM: ([f32; 2], f32, [f32; 2]) = ([0.1, 0.05], 0.3, [0.8, 0.8]);
/// KHR_texture_transform of the emissive texture, which also moves it to TEXCOORD_1.
const EMISSIVE_TRANSFORM: ([f32; 2], f32, [f32; 2]) = ([-0.2, 0.1], -0.5, [1.5, 1.25]);

/// A hue wheel about the texture's centre (saturation growing outward) under a checker of
/// 4×4-texel cells, one of which is darkened.
fn base_color_texture() -> image::RgbaImage {
    image::RgbaImage::from_fn(TEXELS, TEXELS, |x, y| {
        let (dx, dy) = (x as f32 + 0.5 - TEXELS as f32 / 2.0, y as f32 + 0.5 - TEXELS as f32 / 2.0);
        let hue = (dy.atan2(dx) / std::f32::consts::TAU + 1.0).fract() * 6.0;
        let saturation = ((dx * dx + dy * dy).sqrt() / (TEXELS as f32 / 2.0)).min(1.0);
        let value = if (x / 4 + y / 4) % 2 == 0 { 1.0 } else { 0.55 };
        let f = |n: f32| {
            let k = (n + hue) % 6.0;
            value * (1.0 - saturation * k.min(4.0 - k).clamp(0.0, 1.0))
        };
        let rgb = [f(5.0), f(3.0), f(1.0)].map(|c| (c * 255.0).round() as u8);
        image::Rgba([rgb[0], rgb[1], rgb[2], 255])
    })
}

/// Metallic (blue) rising along x and roughness (green) along y, independently.
fn metal_rough_texture() -> image::RgbaImage {
    image::RgbaImage::from_fn(TEXELS, TEXELS, |x, y| {
        let ramp = |i: u32| ((i as f32 + 0.5) / TEXELS as f32 * 255.0).round() as u8;
        image::Rgba([0, 40 + ramp(y) * 215 / 255, ramp(x), 255])
    })
}

/// Rings of three colours.
fn emissive_texture() -> image::RgbaImage {
    image::RgbaImage::from_fn(TEXELS, TEXELS, |x, y| {
        let (dx, dy) = (x as f32 - 10.0, y as f32 - 20.0);
        let ring = ((dx * dx + dy * dy).sqrt() / 5.0) as u32 % 3;
        let rgb = [[250u8, 40, 10], [20, 200, 60], [0, 0, 0]][ring as usize];
        image::Rgba([rgb[0], rgb[1], rgb[2], 255])
    })
}

/// The textureInfo extension for a transform.
fn transform_json((offset, rotation, scale): ([f32; 2], f32, [f32; 2])) -> serde_json::Value {
    json!({ "offset": offset, "rotation": rotation, "scale": scale })
}

/// Writes the asset; returns its path.
fn write_asset(dir: &Path) -> PathBuf {
    let mut gltf = Gltf::new();
    gltf.uses_extension("KHR_texture_transform");
    gltf.uses_extension("KHR_materials_emissive_strength");
    let base_color = gltf.texture(&base_color_texture());
    let metal_rough = gltf.texture(&metal_rough_texture());
    let emissive = gltf.texture(&emissive_texture());
    // Linear filtering with mip maps (which magnification never reaches), repeating; the
    // emissive texture clamps.
    gltf.json["samplers"] = json!([{ "magFilter": 9729, "minFilter": 9987 }, { "magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 33071 }]);
    for (texture, sampler) in [(base_color, 0), (metal_rough, 0), (emissive, 1)] {
        gltf.json["textures"][texture]["sampler"] = json!(sampler);
    }
    let [r, g, b] = BASE_COLOR_FACTOR;
    let material = gltf.material(json!({
        "name": "tiles",
        "pbrMetallicRoughness": {
            "baseColorTexture": { "index": base_color, "extensions": { "KHR_texture_transform": transform_json(BASE_COLOR_TRANSFORM) } },
            "baseColorFactor": [r, g, b, 1.0],
            "metallicRoughnessTexture": { "index": metal_rough, "texCoord": 1 },
            "metallicFactor": METALLIC_FACTOR,
            "roughnessFactor": ROUGHNESS_FACTOR
        },
        "emissiveTexture": {
            "index": emissive,
            "extensions": { "KHR_texture_transform": { "texCoord": 1, "offset": EMISSIVE_TRANSFORM.0, "rotation": EMISSIVE_TRANSFORM.1, "scale": EMISSIVE_TRANSFORM.2 } }
        },
        "emissiveFactor": EMISSIVE_FACTOR,
        "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": EMISSIVE_STRENGTH } }
    }));
    let mut quad = plane(1.0);
    // The second set runs mirrored and shifted: u' = 1 − u, v' = 0.5 + v/2.
    quad.uvs1 = Some(quad.uvs.iter().map(|&[u, v]| [1.0 - u, 0.5 + 0.5 * v]).collect());
    let mesh = gltf.mesh("quad", &[(&quad, Some(material))]);
    gltf.node(json!({ "name": "quad", "mesh": mesh }));
    let camera = gltf.camera(json!({
        "type": "orthographic",
        "orthographic": { "xmag": 1.0, "ymag": 1.0, "znear": 0.1, "zfar": 10.0 }
    }));
    gltf.node(json!({ "name": "front", "camera": camera, "translation": [0.0, 0.0, 2.0] }));
    gltf.write_gltf(dir, "tiles")
}

/// KHR_texture_transform: translation · rotation · scale, with rotation = mat3(cos, −sin, 0, sin,
/// cos, 0, 0, 0, 1) (columns), the sign its TextureTransformTest sample asset checks.
fn transformed((offset, rotation, scale): ([f32; 2], f32, [f32; 2]), uv: [f32; 2]) -> [f32; 2] {
    let (s, c) = rotation.sin_cos();
    let translation = Mat3::from_cols(Vec3::X, Vec3::Y, Vec3::new(offset[0], offset[1], 1.0));
    let rotation = Mat3::from_cols(Vec3::new(c, -s, 0.0), Vec3::new(s, c, 0.0), Vec3::Z);
    let scale = Mat3::from_diagonal(Vec3::new(scale[0], scale[1], 1.0));
    let t = translation * rotation * scale * Vec3::new(uv[0], uv[1], 1.0);
    [t.x, t.y]
}

/// A texture's linear values, bilinearly filtered at `uv` as a GPU samples its first level:
/// texel centres at (i + ½)/size, repeating or clamping to the edge.
fn bilinear(texels: &[[f32; 4]], uv: [f32; 2], repeat: bool) -> [f32; 4] {
    let n = TEXELS as i64;
    let wrap = |i: i64| if repeat { i.rem_euclid(n) } else { i.clamp(0, n - 1) };
    let (sx, sy) = (uv[0] * n as f32 - 0.5, uv[1] * n as f32 - 0.5);
    let (x0, y0) = (sx.floor() as i64, sy.floor() as i64);
    let (fx, fy) = (sx - x0 as f32, sy - y0 as f32);
    let at = |x: i64, y: i64| texels[(wrap(y) * n + wrap(x)) as usize];
    std::array::from_fn(|k| {
        let top = at(x0, y0)[k] * (1.0 - fx) + at(x0 + 1, y0)[k] * fx;
        let bottom = at(x0, y0 + 1)[k] * (1.0 - fx) + at(x0 + 1, y0 + 1)[k] * fx;
        top * (1.0 - fy) + bottom * fy
    })
}

/// A texture as linear values: colours decoded from sRGB, data (and alpha) as stored.
fn linear(image: &image::RgbaImage, srgb: bool) -> Vec<[f32; 4]> {
    image
        .pixels()
        .map(|p| std::array::from_fn(|k| if srgb && k < 3 { srgb_to_linear(p.0[k]) } else { p.0[k] as f32 / 255.0 }))
        .collect()
}

/// What the material must be at pixel (x, y): each factor times its texture, the texture
/// averaged over the bake's sample positions in the pixel.
fn expected_params(x: u32, y: u32) -> Params {
    let (base, metal_rough, emissive) =
        (linear(&base_color_texture(), true), linear(&metal_rough_texture(), false), linear(&emissive_texture(), true));
    let offsets = jitter_pattern(SAMPLES);
    let mut sums = [[0.0f32; 4]; 3];
    for &(ox, oy) in &offsets {
        // The quad's u runs along +x and v down the image, over the whole frame.
        let uv0 = [(x as f32 + 0.5 + ox) / SIZE as f32, (y as f32 + 0.5 + oy) / SIZE as f32];
        let uv1 = [1.0 - uv0[0], 0.5 + 0.5 * uv0[1]];
        let samples = [
            bilinear(&base, transformed(BASE_COLOR_TRANSFORM, uv0), true),
            bilinear(&metal_rough, uv1, true),
            bilinear(&emissive, transformed(EMISSIVE_TRANSFORM, uv1), false),
        ];
        for (sum, sample) in sums.iter_mut().zip(samples) {
            (0..4).for_each(|k| sum[k] += sample[k] / offsets.len() as f32);
        }
    }
    let [base, metal_rough, emissive] = sums;
    Params {
        base_color: [0, 1, 2].map(|k| BASE_COLOR_FACTOR[k] * base[k]),
        metallic: METALLIC_FACTOR * metal_rough[2],
        roughness: ROUGHNESS_FACTOR * metal_rough[1],
        // IOR 1.5: F0 0.04, Disney's specular 0.5.
        specular: 0.5,
        emission: [0, 1, 2].map(|k| EMISSIVE_FACTOR[k] * EMISSIVE_STRENGTH * emissive[k]),
        ..Params::default()
    }
}

/// A sky that varies slowly, so that a render converges quickly: blue above, a broad warm glow
/// toward +X, a dim floor. Written as an EXR for the command line; returns its path.
fn write_sky(dir: &Path) -> PathBuf {
    let (width, height) = (64u32, 32u32);
    let mut texels = Vec::new();
    for y in 0..height {
        for x in 0..width {
            // The direction of the texel's centre, by the environment format's definition.
            let (u, v) = ((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32);
            let (theta, phi) = (std::f32::consts::PI * v, std::f32::consts::TAU * (u - 0.5));
            let d = Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos());
            let glow = d.x.max(0.0).powi(2);
            let sky = if d.y > 0.0 { 0.3 + 0.5 * d.y } else { 0.08 };
            texels.push([sky * 0.8 + 1.2 * glow, sky * 0.9 + 0.8 * glow, sky * 1.3 + 0.3 * glow, 1.0]);
        }
    }
    let path = dir.join("sky.exr");
    lookdev::render::output::write_exr(&path, width, height, &texels, true).unwrap();
    path
}

fn run(binary: &Path, args: &[&str]) {
    let output = Command::new(binary).args(args).env("LOOKDEV_VALIDATION", "1").output().unwrap();
    assert_success(&output);
    assert!(!stderr(&output).contains("panicked"));
}

fn read_exr(path: &Path) -> Vec<[f32; 4]> {
    use exr::prelude::{read_first_rgba_layer_from_file, RgbaChannels};
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _: &RgbaChannels| vec![[0.0f32; 4]; resolution.width() * resolution.height()],
        |pixels, position, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[position.y() * SIZE as usize + position.x()] = [r, g, b, a];
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels
}

#[test]
fn every_pixel_renders_as_its_own_parameters_rendered_as_constants() {
    let dir = tempfile::tempdir().unwrap();
    let asset = write_asset(dir.path());
    let arg = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let this = PathBuf::from(env!("CARGO_BIN_EXE_lookdev"));
    let asset_bin = std::env::var_os("LOOKDEV_ASSET_BIN").map(PathBuf::from).unwrap_or_else(|| this.clone());
    let size = SIZE.to_string();
    let samples = SAMPLES.to_string();
    let asset_arg = asset.to_string_lossy();
    run(&asset_bin, &["bake", &asset_arg, "--out", &arg("g.exr"), "--size", &size, &size, "--samples", &samples]);
    run(&asset_bin, &["import", &asset_arg, "--presets", &arg("presets"), "--look", &arg("look.toml")]);
    let spp = SPP.to_string();
    let sky = write_sky(dir.path());
    let sky_arg = sky.to_string_lossy();
    let render = [
        "render",
        "--gbuffer",
        &arg("g.exr"),
        "--look",
        &arg("look.toml"),
        "--env",
        &sky_arg,
        "--spp",
        &spp,
        "--quiet",
    ];
    run(&this, &[&render[..], &["--out", &arg("render.exr")]].concat());

    let gbuffer = GBuffer::read(&dir.path().join("g.exr")).unwrap();
    assert_eq!((gbuffer.width, gbuffer.height), (SIZE, SIZE));
    let radiance = read_exr(&dir.path().join("render.exr"));
    let env = lookdev::environment::load::load(&sky, &Default::default()).unwrap();
    let reference =
        common::reference_render::Reference::new(&gbuffer, &env, Sampling::default(), Lighting::default(), 0);
    // Interior pixels: away from the quad's edges, where the frame's rounding could show.
    let interior = 2..SIZE - 2;
    let (mut worst, mut worst_at, mut sum, mut count) = (0.0f32, (0, 0), 0.0f64, 0usize);
    let mut hues = Vec::new();
    for y in interior.clone() {
        for x in interior.clone() {
            let i = (y * SIZE + x) as usize;
            assert_eq!(gbuffer.coverage[i], 1.0, "pixel ({x}, {y}) is on the quad");
            let params = expected_params(x, y);
            let want = reference.pixel(x, y, &params, SPP);
            let got = glam::Vec4::from(radiance[i]);
            // Relative to the pixel's radiance: its largest channel difference over its largest
            // channel (a near-black channel beside a bright one is judged against the bright one).
            let error = (got - want).truncate().abs().max_element() / want.truncate().max_element().max(0.02);
            if error > worst {
                (worst, worst_at) = (error, (x, y));
            }
            sum += error as f64;
            count += 1;
            let [r, g, b] = params.base_color;
            hues.push((g - b).atan2(2.0 * r - g - b));
        }
    }
    let mean = sum / count as f64;
    eprintln!(
        "{count} interior pixels: mean relative error {:.3}%, worst {:.3}% at {worst_at:?}",
        100.0 * mean,
        100.0 * worst
    );
    // The asset is what it should be: hues all round the wheel, so no two-colour axis holds it.
    hues.sort_by(f32::total_cmp);
    let widest_gap =
        hues.windows(2).map(|w| w[1] - w[0]).fold(hues[0] + std::f32::consts::TAU - hues[hues.len() - 1], f32::max);
    assert!(widest_gap < 1.0, "the base colours span too few hues (a gap of {widest_gap} rad)");
    assert!(worst < 0.02, "pixel {worst_at:?} is off by {:.2}%", 100.0 * worst);
    assert!(mean < 0.005, "interior pixels are off by {:.3}% on average", 100.0 * mean);
}
