//! The eleven parameters of the Disney 2012 principled BRDF, plus emission, their defaults, ranges
//! and GPU layout.

use std::fmt;

/// Upper limits for the three parameters that may exceed 1 (Burley 2012, principle 4).
/// `specular` 2.5 is F0 = 0.2, an IOR of about 2.6 (diamond is 2.42); `sheen` 2 doubles the
/// retro-reflective rim; `clearcoat` 4 cancels the model's 0.25 factor, a full-strength IOR 1.5 coat.
pub const SPECULAR_MAX: f32 = 2.5;
pub const SHEEN_MAX: f32 = 2.0;
pub const CLEARCOAT_MAX: f32 = 4.0;
/// The largest emitted radiance per channel: the largest half float, so that any value
/// survives a half-float EXR.
pub const EMISSION_MAX: f32 = 65504.0;

/// One BRDF parameter, by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Param {
    BaseColor,
    Metallic,
    Subsurface,
    Specular,
    SpecularTint,
    Roughness,
    Anisotropic,
    Sheen,
    SheenTint,
    Clearcoat,
    ClearcoatGloss,
    /// Not part of the Disney BRDF: the surface's own radiance, added to the reflected light, so
    /// that emissive assets look like themselves.
    Emission,
}

impl Param {
    /// All parameters: Burley's eleven in the order of his figure 16 and of the GPU layout,
    /// then emission.
    pub const ALL: [Param; 12] = [
        Param::BaseColor,
        Param::Metallic,
        Param::Subsurface,
        Param::Specular,
        Param::SpecularTint,
        Param::Roughness,
        Param::Anisotropic,
        Param::Sheen,
        Param::SheenTint,
        Param::Clearcoat,
        Param::ClearcoatGloss,
        Param::Emission,
    ];

    /// The name used in presets, looks and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Param::BaseColor => "base_color",
            Param::Metallic => "metallic",
            Param::Subsurface => "subsurface",
            Param::Specular => "specular",
            Param::SpecularTint => "specular_tint",
            Param::Roughness => "roughness",
            Param::Anisotropic => "anisotropic",
            Param::Sheen => "sheen",
            Param::SheenTint => "sheen_tint",
            Param::Clearcoat => "clearcoat",
            Param::ClearcoatGloss => "clearcoat_gloss",
            Param::Emission => "emission",
        }
    }

    pub fn from_name(name: &str) -> Option<Param> {
        Param::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The parameter named `name`, or the message that lists the names and suggests the closest.
    pub fn parse(name: &str) -> Result<Param, String> {
        Param::from_name(name)
            .ok_or_else(|| crate::suggest::unknown("parameter", name, "", &Param::ALL.map(Param::name)))
    }

    /// Whether the value is a linear RGB colour (`base_color`, `emission`) rather than a number.
    pub fn is_color(self) -> bool {
        matches!(self, Param::BaseColor | Param::Emission)
    }

    /// The largest value allowed (the smallest is always 0).
    pub fn max(self) -> f32 {
        match self {
            Param::Specular => SPECULAR_MAX,
            Param::Sheen => SHEEN_MAX,
            Param::Clearcoat => CLEARCOAT_MAX,
            Param::Emission => EMISSION_MAX,
            _ => 1.0,
        }
    }

    /// Where the parameter sits in [`Params::to_gpu`]'s layout (a colour takes three places).
    pub fn gpu_index(self) -> usize {
        use std::mem::offset_of;
        let offset = match self {
            Param::BaseColor => offset_of!(GpuParams, base_color),
            Param::Metallic => offset_of!(GpuParams, metallic),
            Param::Subsurface => offset_of!(GpuParams, subsurface),
            Param::Specular => offset_of!(GpuParams, specular),
            Param::SpecularTint => offset_of!(GpuParams, specular_tint),
            Param::Roughness => offset_of!(GpuParams, roughness),
            Param::Anisotropic => offset_of!(GpuParams, anisotropic),
            Param::Sheen => offset_of!(GpuParams, sheen),
            Param::SheenTint => offset_of!(GpuParams, sheen_tint),
            Param::Clearcoat => offset_of!(GpuParams, clearcoat),
            Param::ClearcoatGloss => offset_of!(GpuParams, clearcoat_gloss),
            Param::Emission => offset_of!(GpuParams, emission),
        };
        offset / 4
    }
}

/// A heading the layer panel and the docs group parameters under, as look-dev tools do.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Group {
    Base,
    Specular,
    Coat,
    Sheen,
    Subsurface,
}

/// Every parameter under its group, groups and parameters in the order the panel shows them:
/// the one place the grouping is written (the UI, the docs and [`Param::group`] read it).
pub const GROUPS: [(Group, &[Param]); 5] = [
    (Group::Base, &[Param::BaseColor, Param::Metallic, Param::Roughness, Param::Emission]),
    (Group::Specular, &[Param::Specular, Param::SpecularTint, Param::Anisotropic]),
    (Group::Coat, &[Param::Clearcoat, Param::ClearcoatGloss]),
    (Group::Sheen, &[Param::Sheen, Param::SheenTint]),
    (Group::Subsurface, &[Param::Subsurface]),
];

impl Group {
    pub fn name(self) -> &'static str {
        match self {
            Group::Base => "Base",
            Group::Specular => "Specular",
            Group::Coat => "Coat",
            Group::Sheen => "Sheen",
            Group::Subsurface => "Subsurface",
        }
    }

    /// The group's parameters, in panel order.
    pub fn params(self) -> &'static [Param] {
        GROUPS.iter().find(|(group, _)| *group == self).map_or(&[], |(_, params)| params)
    }
}

impl Param {
    /// The group the parameter is shown under.
    pub fn group(self) -> Group {
        GROUPS.iter().find(|(_, params)| params.contains(&self)).map_or(Group::Base, |(group, _)| *group)
    }
}

impl fmt::Display for Param {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A parameter value: a linear RGB colour for `base_color`, a scalar for everything else.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Scalar(f32),
    Color([f32; 3]),
}

impl Value {
    /// The value for people to read: four decimals, trailing zeros dropped, so that a blend's
    /// float noise (0.9999996, 2.5e-7) reads as what it means (1, 0).
    pub fn short_text(self) -> String {
        let short = |x: f32| {
            let text = format!("{x:.4}");
            let text = text.trim_end_matches('0').trim_end_matches('.');
            if text == "-0" {
                "0".to_string()
            } else {
                text.to_string()
            }
        };
        match self {
            Value::Scalar(v) => short(v),
            Value::Color([r, g, b]) => format!("[{}, {}, {}]", short(r), short(g), short(b)),
        }
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Scalar(v) => write!(f, "{v}"),
            Value::Color([r, g, b]) => write!(f, "[{r}, {g}, {b}]"),
        }
    }
}

/// The twelve parameters of one material: the eleven of the BRDF, and emission. All are
/// normalised to [0, 1] except where [`Param::max`] allows more; colours are linear Rec.709.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    pub base_color: [f32; 3],
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
    /// Not one of the eleven: where the complex IOR of a measured metal (its preset's `ior_n`
    /// and `ior_k`) lies between the two dielectric IORs of the same F0, per channel, so that
    /// `base_color` (its F0) and this give (n, k) back. 0 for a dielectric. Only the
    /// `conductor` Fresnel model reads it; it blends between layers like every parameter.
    pub ior_edge: [f32; 3],
    /// Emitted radiance, linear Rec.709, added to the reflected light; 0 by default.
    pub emission: [f32; 3],
}

impl Default for Params {
    fn default() -> Self {
        Params {
            base_color: [0.8, 0.8, 0.8],
            metallic: 0.0,
            subsurface: 0.0,
            specular: 0.5,
            specular_tint: 0.0,
            roughness: 0.5,
            anisotropic: 0.0,
            sheen: 0.0,
            sheen_tint: 0.5,
            clearcoat: 0.0,
            clearcoat_gloss: 1.0,
            ior_edge: [0.0; 3],
            emission: [0.0; 3],
        }
    }
}

/// Number of floats in the GPU layout of [`Params`]: five vec4s.
pub const GPU_FLOATS: usize = 20;
/// The BRDF's part of that layout, the first four vec4s: what `material.glsl` unpacks.
pub const BRDF_GPU_FLOATS: usize = 16;

/// [`Params`] as the GPU holds them: five vec4s, the first four as `unpack_material` in
/// `glsl/include/material.glsl` reads them (`p0.rgb` is bytes 0–11, `p0.a` 12–15, `p1.x` 16–19,
/// …), then emission, which `relight.comp` reads on its own.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuParams {
    base_color: [f32; 3],
    metallic: f32,
    subsurface: f32,
    specular: f32,
    specular_tint: f32,
    roughness: f32,
    anisotropic: f32,
    sheen: f32,
    sheen_tint: f32,
    clearcoat: f32,
    clearcoat_gloss: f32,
    ior_edge: [f32; 3],
    emission: [f32; 3],
    pad: f32,
}

crate::glsl_struct!(GpuParams as "unpack_material", 80 bytes {
    base_color @ 0,
    metallic @ 12,
    subsurface @ 16,
    specular @ 20,
    specular_tint @ 24,
    roughness @ 28,
    anisotropic @ 32,
    sheen @ 36,
    sheen_tint @ 40,
    clearcoat @ 44,
    clearcoat_gloss @ 48,
    ior_edge @ 52,
    emission @ 64,
    pad @ 76,
});

const _: () = assert!(std::mem::size_of::<GpuParams>() == 4 * GPU_FLOATS);
const _: () = assert!(std::mem::offset_of!(GpuParams, emission) == 4 * BRDF_GPU_FLOATS);

/// The BRDF's view of the parameters, unpacked from the GPU layout as the kernels unpack it.
impl From<&Params> for crate::shading::material::Material {
    fn from(params: &Params) -> Self {
        crate::shading::material::unpack_material(&params.brdf_gpu())
    }
}

/// The layout `unpack_material` (and, for emission, `relight.comp`) reads, by member name.
pub const GPU_LAYOUT: crate::gpu::GlslStruct = <GpuParams as crate::gpu::GlslLayout>::GLSL;

impl Params {
    pub fn get(&self, param: Param) -> Value {
        let g = self.to_gpu();
        let i = param.gpu_index();
        if param.is_color() {
            Value::Color([g[i], g[i + 1], g[i + 2]])
        } else {
            Value::Scalar(g[i])
        }
    }

    /// Sets a parameter after checking its kind and range. The error says what is wrong, without
    /// the file or line, which the caller adds.
    pub fn set(&mut self, param: Param, value: Value) -> Result<(), String> {
        check(param, value)?;
        let mut g = self.to_gpu();
        let i = param.gpu_index();
        match value {
            Value::Color(c) => g[i..i + 3].copy_from_slice(&c),
            Value::Scalar(v) => g[i] = v,
        }
        *self = Params::from_gpu(&g);
        Ok(())
    }

    /// The GPU layout: [`GpuParams`] as floats.
    pub fn to_gpu(&self) -> [f32; GPU_FLOATS] {
        bytemuck::cast(GpuParams {
            base_color: self.base_color,
            metallic: self.metallic,
            subsurface: self.subsurface,
            specular: self.specular,
            specular_tint: self.specular_tint,
            roughness: self.roughness,
            anisotropic: self.anisotropic,
            sheen: self.sheen,
            sheen_tint: self.sheen_tint,
            clearcoat: self.clearcoat,
            clearcoat_gloss: self.clearcoat_gloss,
            ior_edge: self.ior_edge,
            emission: self.emission,
            pad: 0.0,
        })
    }

    /// The BRDF's part of [`Params::to_gpu`], for kernels that evaluate only the BRDF.
    pub fn brdf_gpu(&self) -> [f32; BRDF_GPU_FLOATS] {
        let mut brdf = [0.0; BRDF_GPU_FLOATS];
        brdf.copy_from_slice(&self.to_gpu()[..BRDF_GPU_FLOATS]);
        brdf
    }

    pub fn from_gpu(v: &[f32; GPU_FLOATS]) -> Params {
        let p: GpuParams = bytemuck::cast(*v);
        Params {
            base_color: p.base_color,
            metallic: p.metallic,
            subsurface: p.subsurface,
            specular: p.specular,
            specular_tint: p.specular_tint,
            roughness: p.roughness,
            anisotropic: p.anisotropic,
            sheen: p.sheen,
            sheen_tint: p.sheen_tint,
            clearcoat: p.clearcoat,
            clearcoat_gloss: p.clearcoat_gloss,
            ior_edge: p.ior_edge,
            emission: p.emission,
        }
    }

    /// Per-parameter linear blend, `mix(self, other, w)`: the layer-stack rule of docs/formats.md.
    /// Written as `a·(1−w) + b·w`, as `resolve.comp` does, so that w = 1 gives `other` exactly.
    pub fn mix(&self, other: &Params, w: f32) -> Params {
        let a = self.to_gpu();
        let b = other.to_gpu();
        Params::from_gpu(&std::array::from_fn(|i| a[i] * (1.0 - w) + b[i] * w))
    }
}

/// Checks that `value` has the right kind for `param` and lies in its range.
pub fn check(param: Param, value: Value) -> Result<(), String> {
    let max = param.max();
    let in_range = |v: f32| v.is_finite() && (0.0..=max).contains(&v);
    match (param.is_color(), value) {
        (true, Value::Color(c)) => {
            if c.iter().all(|&v| in_range(v)) {
                Ok(())
            } else {
                Err(format!("{param} = {value} is out of range: each channel must be in [0, {max}] (linear)"))
            }
        }
        (false, Value::Scalar(v)) => {
            if in_range(v) {
                Ok(())
            } else {
                Err(format!("{param} = {v} is out of range [0, {max}]"))
            }
        }
        (true, Value::Scalar(_)) => Err(format!("{param} is a colour: give three numbers [r, g, b]")),
        (false, Value::Color(_)) => Err(format!("{param} is a number, not a colour")),
    }
}

/// Parses a command-line value: `0.25` for scalars; `r,g,b` or a single grey value for colours.
pub fn parse_value(param: Param, text: &str) -> Result<Value, String> {
    let numbers: Result<Vec<f32>, _> = text.split(',').map(|s| s.trim().parse::<f32>()).collect();
    let numbers = numbers.map_err(|_| format!("{param}: '{text}' is not a number"))?;
    let value = match (param.is_color(), numbers.as_slice()) {
        (true, [r, g, b]) => Value::Color([*r, *g, *b]),
        (true, [grey]) => Value::Color([*grey; 3]),
        (true, _) => return Err(format!("{param} takes r,g,b or one grey value, not '{text}'")),
        (false, [v]) => Value::Scalar(*v),
        (false, _) => return Err(format!("{param} takes one number, not '{text}'")),
    };
    check(param, value)?;
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grouping holds each parameter exactly once, so the panel shows every one and none
    /// twice; a parameter added to [`Param::ALL`] fails here until it has a group.
    #[test]
    fn every_parameter_is_in_exactly_one_group() {
        for param in Param::ALL {
            let homes: Vec<Group> =
                GROUPS.iter().filter(|(_, params)| params.contains(&param)).map(|(group, _)| *group).collect();
            assert_eq!(homes.len(), 1, "{param} is in {homes:?}");
            assert_eq!(param.group(), homes[0]);
            assert!(param.group().params().contains(&param));
        }
        let listed: usize = GROUPS.iter().map(|(_, params)| params.len()).sum();
        assert_eq!(listed, Param::ALL.len(), "a group lists a parameter twice");
    }

    #[test]
    fn values_for_people_drop_float_noise() {
        assert_eq!(Value::Scalar(0.9999996).short_text(), "1");
        assert_eq!(Value::Scalar(2.5e-7).short_text(), "0");
        assert_eq!(Value::Scalar(-1e-9).short_text(), "0");
        assert_eq!(Value::Scalar(0.05).short_text(), "0.05");
        assert_eq!(Value::Scalar(12.5).short_text(), "12.5");
        assert_eq!(Value::Color([0.8, 0.3 + 1e-7, 0.0]).short_text(), "[0.8, 0.3, 0]");
    }

    #[test]
    fn names_round_trip_and_gpu_layout_is_invertible() {
        for p in Param::ALL {
            assert_eq!(Param::from_name(p.name()), Some(p));
        }
        let params = Params {
            base_color: [0.1, 0.2, 0.3],
            clearcoat_gloss: 0.7,
            ior_edge: [0.2, 0.4, 0.6],
            emission: [2.0, 0.5, 0.0],
            ..Params::default()
        };
        assert_eq!(Params::from_gpu(&params.to_gpu()), params);
        assert_eq!(params.get(Param::Emission), Value::Color([2.0, 0.5, 0.0]));
        assert_eq!(params.get(Param::BaseColor), Value::Color([0.1, 0.2, 0.3]));
    }

    #[test]
    fn ranges_are_enforced() {
        let mut p = Params::default();
        assert!(p.set(Param::Roughness, Value::Scalar(1.01)).is_err());
        assert!(p.set(Param::Roughness, Value::Scalar(f32::NAN)).is_err());
        assert!(p.set(Param::Specular, Value::Scalar(2.0)).is_ok());
        assert!(p.set(Param::Specular, Value::Scalar(2.6)).is_err());
        assert!(p.set(Param::BaseColor, Value::Scalar(0.5)).is_err());
        assert!(p.set(Param::BaseColor, Value::Color([0.5, -0.1, 0.2])).is_err());
        assert!(p.set(Param::BaseColor, Value::Color([1.5, 0.1, 0.2])).is_err());
        assert!(p.set(Param::Emission, Value::Color([1.5, 20.0, 0.0])).is_ok());
        assert_eq!(p.emission, [1.5, 20.0, 0.0]);
        assert!(p.set(Param::Emission, Value::Color([70000.0, 0.0, 0.0])).is_err());
        assert!(p.set(Param::Emission, Value::Scalar(1.0)).is_err());
        assert_eq!(parse_value(Param::BaseColor, "0.9,0.6,0.3"), Ok(Value::Color([0.9, 0.6, 0.3])));
        assert_eq!(parse_value(Param::Metallic, "1"), Ok(Value::Scalar(1.0)));
        assert!(parse_value(Param::Metallic, "x").is_err());
    }

    #[test]
    fn mix_is_per_parameter() {
        let a = Params::default();
        let b = Params { roughness: 0.1, base_color: [1.0, 0.0, 0.0], ..Params::default() };
        let m = a.mix(&b, 0.5);
        assert!((m.roughness - 0.3).abs() < 1e-6);
        assert!((m.base_color[0] - 0.9).abs() < 1e-6 && (m.base_color[1] - 0.4).abs() < 1e-6);
        assert_eq!(a.mix(&b, 0.0), a);
        assert_eq!(a.mix(&b, 1.0), b);
    }
}
