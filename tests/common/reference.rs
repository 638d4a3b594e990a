//! Reading `tests/data/disney_brdf_points.toml`.

use glam::Vec3;
use lookdev::material::{Param, Params, Value};

pub fn load() -> toml::Table {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/disney_brdf_points.toml");
    std::fs::read_to_string(path).unwrap().parse().unwrap()
}

fn number(v: &toml::Value) -> f32 {
    v.as_float().or(v.as_integer().map(|i| i as f64)).unwrap() as f32
}

pub fn vec3(v: &toml::Value) -> Vec3 {
    let a = v.as_array().unwrap();
    Vec3::new(number(&a[0]), number(&a[1]), number(&a[2]))
}

/// (θ, φ) in degrees to (sinθ cosφ, sinθ sinφ, cosθ).
pub fn direction(v: &toml::Value) -> Vec3 {
    let a = v.as_array().unwrap();
    let (t, p) = ((number(&a[0]) as f64).to_radians(), (number(&a[1]) as f64).to_radians());
    Vec3::new((t.sin() * p.cos()) as f32, (t.sin() * p.sin()) as f32, t.cos() as f32)
}

/// The entry's parameters over the defaults.
pub fn params(entry: &toml::Value) -> Params {
    let mut params = Params::default();
    for param in Param::ALL {
        if let Some(v) = entry.get(param.name()) {
            let value = if param.is_color() { Value::Color(vec3(v).to_array()) } else { Value::Scalar(number(v)) };
            params.set(param, value).unwrap();
        }
    }
    params
}
