//! The environment contract, checked against an implementation written here from the format's
//! text rather than with the renderer's own mapping: u = 0.5 + atan2(d.x, −d.z)/2π,
//! v = acos(d.y)/π, row 0 the zenith, and a rotation r looks up R_y(−r)·d. A non-uniform map lights
//! a sphere, and each pixel must equal the integral of f·cosθ·L over the map's texels.

mod common;

use common::scenes::{orthographic_sphere, renderer};
use glam::Vec3;
use lookdev::environment::Environment;
use lookdev::material::{Look, Params};
use lookdev::render::Lighting;
use lookdev::shading::brdf::evaluate;
use std::f64::consts::PI;

/// The unit direction at the centre of texel (x, y), by the format's definition, in environment
/// space.
fn texel_direction(x: f64, y: f64, width: u32, height: u32) -> [f64; 3] {
    let (u, v) = (x / width as f64, y / height as f64);
    let (theta, phi) = (PI * v, 2.0 * PI * (u - 0.5));
    [theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos()]
}

/// Environment space to world: the inverse of the lookup's R_y(−r), that is R_y(r).
fn to_world(d: [f64; 3], rotation_degrees: f64) -> [f64; 3] {
    let (s, c) = rotation_degrees.to_radians().sin_cos();
    [d[0] * c + d[2] * s, d[1], -d[0] * s + d[2] * c]
}

/// A map with a broad warm glow toward +X, a cool sky and a dim floor.
fn glow_map() -> Environment {
    let (w, h) = (48u32, 24u32);
    let mut texels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let d = texel_direction(x as f64 + 0.5, y as f64 + 0.5, w, h);
            let toward_x = d[0].max(0.0).powi(4) as f32;
            let sky = if d[1] > 0.0 { 0.3 + 0.4 * d[1] as f32 } else { 0.05 };
            texels.push([sky + 4.0 * toward_x, sky + 2.0 * toward_x, sky * 1.6 + 0.5 * toward_x]);
        }
    }
    Environment::new(w, h, texels, "glow")
}

/// ∫ f(l, v)·cosθ·L(l) dl for a pixel, over the texels of `env`, each integrated uniformly in
/// azimuth and cos θ with a `sub`×`sub` grid.
fn integrate(env: &Environment, rotation: f64, params: &Params, n: Vec3, t: Vec3, v_world: Vec3, sub: u32) -> [f64; 3] {
    let b = n.cross(t);
    let local = |w: [f64; 3]| {
        let w = Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32);
        Vec3::new(w.dot(t), w.dot(b), w.dot(n))
    };
    let v = local([v_world.x as f64, v_world.y as f64, v_world.z as f64]);
    let mut sum = [0.0f64; 3];
    for y in 0..env.height {
        let (z0, z1) = ((PI * y as f64 / env.height as f64).cos(), (PI * (y + 1) as f64 / env.height as f64).cos());
        let omega = 2.0 * PI / env.width as f64 * (z0 - z1);
        for x in 0..env.width {
            let radiance = env.texel(x, y);
            let mut texel_sum = [0.0f64; 3];
            for i in 0..sub {
                let z = z0 + (z1 - z0) * (i as f64 + 0.5) / sub as f64;
                let r = (1.0 - z * z).max(0.0).sqrt();
                for j in 0..sub {
                    let u = (x as f64 + (j as f64 + 0.5) / sub as f64) / env.width as f64;
                    let phi = 2.0 * PI * (u - 0.5);
                    let l = local(to_world([r * phi.sin(), z, -r * phi.cos()], rotation));
                    if l.z <= 0.0 {
                        continue;
                    }
                    let f = evaluate(params, l, v);
                    for c in 0..3 {
                        texel_sum[c] += f[c] as f64 * l.z as f64;
                    }
                }
            }
            for c in 0..3 {
                sum[c] += texel_sum[c] / (sub * sub) as f64 * omega * radiance[c] as f64;
            }
        }
    }
    sum
}

fn one_material(params: Params) -> Look {
    let mut look = Look::default_material();
    look.objects[0].layers[0].params = params;
    look
}

#[test]
fn a_non_uniform_map_lights_each_pixel_as_the_integral_says() {
    let ctx = common::gpu::context();
    let env = glow_map();
    let size = 16;
    let gbuffer = orthographic_sphere(size);
    let rotation = 30.0;
    let materials = [
        Params { base_color: [0.7, 0.5, 0.3], roughness: 0.6, ..Params::default() },
        Params { base_color: [0.9, 0.8, 0.6], metallic: 1.0, roughness: 0.45, ..Params::default() },
    ];
    for params in materials {
        let lighting = Lighting { rotation_degrees: rotation as f32, intensity: 1.0, background: false };
        let mut r = renderer(&ctx, &gbuffer, &env, &one_material(params), lighting);
        lookdev::render::progressive::accumulate(&mut r, 4096, |_| {}).unwrap();
        let radiance = r.read_radiance().unwrap();
        for (x, y) in [(8, 8), (3, 8), (13, 8), (8, 3), (8, 13), (12, 5)] {
            let i = (y * size + x) as usize;
            assert_eq!(gbuffer.coverage[i], 1.0);
            let expected = integrate(
                &env,
                rotation,
                &params,
                Vec3::from(gbuffer.normal[i]),
                Vec3::from(gbuffer.tangent[i]),
                Vec3::from(gbuffer.view[i]),
                12,
            );
            for c in 0..3 {
                let got = radiance[i][c] as f64;
                let error = (got - expected[c]).abs() / expected[c].max(0.02);
                assert!(
                    error < 0.02,
                    "{params:?} pixel ({x}, {y}) channel {c}: rendered {got:.4}, integrated {:.4}",
                    expected[c]
                );
            }
        }
        drop(r);
    }
    common::gpu::finish(ctx);
}

#[test]
fn the_map_is_oriented_and_rotated_as_specified() {
    let ctx = common::gpu::context();
    // Four quadrants of u, each its own colour: the background shows which one lies behind.
    let (w, h) = (64u32, 32u32);
    let quadrant_colour =
        |x: u32| [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.0]][(x * 4 / w) as usize];
    let texels = (0..w * h).map(|i| quadrant_colour(i % w)).collect();
    let env = Environment::new(w, h, texels, "quadrants");
    let gbuffer = orthographic_sphere(16);
    let corner = 0; // a background pixel; the orthographic camera looks down −Z
    for (rotation, expected_u) in [(0.0f64, 0.5), (90.0, 0.75), (-90.0, 0.25), (180.0, 0.0)] {
        // The spec's answer: the background shows direction −V = −Z, looked up at R_y(−r)·(−Z).
        let (s, c) = (-rotation).to_radians().sin_cos();
        let d = [-s, 0.0, -c]; // R_y(−r)·(0, 0, −1)
        let u = (0.5 + d[0].atan2(-d[2]) / (2.0 * PI)).rem_euclid(1.0);
        assert!((u - expected_u).abs() < 1e-9 || (u - expected_u).abs() > 1.0 - 1e-9, "rotation {rotation}: u {u}");
        // The quadrant seams sit at exactly these u, so render a hundredth of a turn further:
        // the background then lies a hundredth of the width past `u`.
        let x = (((u + 0.01) * w as f64) as u32) % w;
        let look = one_material(Params::default());
        let nudged = Lighting { rotation_degrees: rotation as f32 + 3.6, ..Lighting::default() };
        let mut r = renderer(&ctx, &gbuffer, &env, &look, nudged);
        r.render_samples(1).unwrap();
        let background = r.read_radiance().unwrap()[corner];
        let want = quadrant_colour(x);
        for k in 0..3 {
            assert!(
                (background[k] - want[k]).abs() < 1e-4,
                "rotation {rotation}: background {background:?}, expected {want:?}"
            );
        }
        drop(r);
    }

    // A single hot texel toward +X (u = 0.75, the horizon) lights normals that face +X.
    let mut texels = vec![[0.0f32; 3]; (w * h) as usize];
    texels[((h / 2) * w + w * 3 / 4) as usize] = [1000.0; 3];
    let env = Environment::new(w, h, texels, "hot +X");
    let look = one_material(Params { roughness: 1.0, ..Params::default() });
    let mut r = renderer(&ctx, &gbuffer, &env, &look, Lighting { background: false, ..Lighting::default() });
    r.render_samples(256).unwrap();
    let radiance = r.read_radiance().unwrap();
    let (right, left) = (radiance[8 * 16 + 14][1], radiance[8 * 16 + 1][1]);
    assert!(right > 0.1 && left < 1e-4, "+X side {right}, −X side {left}");
    // Turned by −90°, the same texel lies toward +Z, in front of the sphere: the centre is lit
    // most, and the two sides alike.
    r.set_lighting(Lighting { rotation_degrees: -90.0, background: false, ..Lighting::default() });
    r.render_samples(256).unwrap();
    let radiance = r.read_radiance().unwrap();
    let (centre, right, left) = (radiance[8 * 16 + 8][1], radiance[8 * 16 + 14][1], radiance[8 * 16 + 1][1]);
    assert!(centre > 1.5 * right && (right - left).abs() < 0.2 * right, "centre {centre}, sides {left} {right}");
    // Turned by +90°, it lies toward −Z, behind the sphere: nothing the camera sees faces it.
    r.set_lighting(Lighting { rotation_degrees: 90.0, background: false, ..Lighting::default() });
    r.render_samples(256).unwrap();
    let radiance = r.read_radiance().unwrap();
    assert!(radiance[8 * 16 + 8][1] < 1e-4, "lit from behind: {}", radiance[8 * 16 + 8][1]);
    drop(r);
    common::gpu::finish(ctx);
}
