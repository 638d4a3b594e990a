//! The Rust BRDF reference against the independent double-precision values in
//! `tests/data/disney_brdf_points.toml` (point values, directional albedos, closed forms).

mod common;

use common::reference::{self, direction};
use glam::Vec3;
use lookdev::shading::brdf::evaluate;
use lookdev::shading::common::PI;

#[test]
fn point_values_match_the_reference() {
    let data = reference::load();
    let points = data["point"].as_array().unwrap();
    assert!(points.len() >= 6);
    for point in points {
        let params = reference::params(point);
        let l = direction(&point["light"]);
        let v = direction(&point["view"]);
        let f = evaluate(&params, l, v);
        let expected = reference::vec3(&point["f"]);
        for c in 0..3 {
            let rel = (f[c] - expected[c]).abs() / expected[c].abs().max(1e-6);
            assert!(rel < 1e-5, "{}: channel {c}: {} vs {}", point["name"], f[c], expected[c]);
        }
    }
}

fn directional_albedo(params: &lookdev::material::Params, theta_v_degrees: f64) -> f64 {
    common::albedo::directional_albedo(params, theta_v_degrees.to_radians())[0]
}

#[test]
fn directional_albedo_matches_the_reference() {
    let data = reference::load();
    for entry in data["albedo"].as_array().unwrap() {
        let params = reference::params(entry);
        let angles = entry["theta_v"].as_array().unwrap();
        let albedos = entry["albedo"].as_array().unwrap();
        for (angle, expected) in angles.iter().zip(albedos) {
            let angle = angle.as_float().or(angle.as_integer().map(|i| i as f64)).unwrap();
            let expected = expected.as_float().unwrap();
            let got = directional_albedo(&params, angle);
            // The reference rounds to 4 decimals.
            assert!((got - expected).abs() < 4e-4, "{} at {angle}°: {got} vs {expected}", entry["name"]);
        }
    }
}

#[test]
fn closed_forms_hold() {
    let data = reference::load();
    for entry in data["closed_form"].as_array().unwrap() {
        let params = reference::params(entry);
        let expected = entry["albedo"].as_float().unwrap();
        let got = directional_albedo(&params, 0.0);
        assert!((got - expected).abs() < 4e-4, "{}: {got} vs {expected}", entry["name"]);
    }
}

#[test]
fn grazing_and_below_horizon_give_zero_not_nan() {
    let params = lookdev::material::Params::default();
    let grazing = Vec3::new(1.0, 0.0, 0.0);
    assert_eq!(evaluate(&params, grazing, grazing), Vec3::ZERO);
    assert_eq!(evaluate(&params, Vec3::new(0.0, 0.6, -0.8), Vec3::Z), Vec3::ZERO);
    let f = evaluate(&params, Vec3::new(0.0, 1.0, 1e-7).normalize(), Vec3::Z);
    assert!(f.is_finite());
    // The diffuse lobe at normal incidence is base/π·Fd, with Fd a little below 1 there.
    assert!(evaluate(&params, Vec3::Z, Vec3::Z).x > 0.8 / PI * 0.9);
}
