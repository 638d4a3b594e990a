//! Mirror of `glsl/include/model.glsl`: the BRDF lab's model variants (docs/shading.md#brdf-models).
//!
//! A [`Model`] picks the diffuse term and the specular D, G and F. The kernels read it as
//! specialization constants ([`Model::specialization`]), so one kernel serves every model, and the
//! default is exactly the Disney 2012 model. Looks set it in a `[model]` table and the command
//! line with `--model KEY=VALUE`.

use std::fmt;

/// The diffuse term (seed 004's models).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Diffuse {
    /// Burley's 2012 retro-reflective diffuse.
    #[default]
    Burley2012,
    Lambert,
    /// Lagarde and de Rousiers' renormalised Burley diffuse (Frostbite, 2014).
    Frostbite,
    /// Oren and Nayar's full model (1994): Gaussian slopes, with interreflection.
    OrenNayar,
    /// Oren and Nayar's qualitative model.
    OrenNayarQualitative,
    /// Fujii's improved Oren–Nayar.
    OrenNayarFujii,
    /// Gotanda's Oren–Nayar for GGX+Smith microsurfaces (2014).
    Gotanda,
    /// Hammon's GGX+Smith diffuse approximation (2017).
    Hammon,
}

/// The specular normal distribution.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SpecularD {
    /// GTR with γ = 2: GGX (Trowbridge–Reitz), anisotropic.
    #[default]
    Gtr2,
    /// Beckmann, anisotropic.
    Beckmann,
    /// GTR with exponent `gtr_gamma`, isotropic.
    Gtr,
}

/// The specular masking-shadowing term.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SpecularG {
    /// Smith, G1(l)·G1(v).
    #[default]
    SmithSeparable,
    /// Smith, 1/(1 + Λ(l) + Λ(v)).
    SmithHeightCorrelated,
    /// Separable Smith with the 2012 notes' roughness remap α_g = (0.5 + roughness/2)².
    Burley2012,
}

/// The specular Fresnel term.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Fresnel {
    /// Schlick's approximation from F0.
    #[default]
    Schlick,
    /// The exact dielectric equations, for the real IOR whose F0 the material has.
    Dielectric,
    /// The exact conductor equations, for the complex IOR of the material (its preset's
    /// `ior_n` and `ior_k`; a dielectric's real IOR otherwise).
    Conductor,
}

/// A choice of every variant. `Model::default()` is the Disney 2012 model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Model {
    pub diffuse: Diffuse,
    pub specular_d: SpecularD,
    pub specular_g: SpecularG,
    pub fresnel: Fresnel,
    /// γ of `specular_d = gtr`.
    pub gtr_gamma: f32,
    /// Kulla–Conty multiple scattering for the specular lobe.
    pub energy_compensation: bool,
}

impl Default for Model {
    fn default() -> Self {
        Model {
            diffuse: Diffuse::default(),
            specular_d: SpecularD::default(),
            specular_g: SpecularG::default(),
            fresnel: Fresnel::default(),
            gtr_gamma: DEFAULT_GTR_GAMMA,
            energy_compensation: false,
        }
    }
}

/// γ of GTR when `gtr_gamma` is not given: 2, which is GGX.
pub const DEFAULT_GTR_GAMMA: f32 = 2.0;
/// The range of `gtr_gamma`: GTR is normalisable for any γ > 0; beyond 10 it is Beckmann-like.
pub const GTR_GAMMA_RANGE: (f32, f32) = (0.5, 10.0);

/// The keys of a `[model]` table and of `--model`, in the order of [`Model::specialization`].
pub const KEYS: [&str; 6] = ["diffuse", "specular_d", "specular_g", "fresnel", "gtr_gamma", "energy_compensation"];

impl Diffuse {
    pub const ALL: [Diffuse; 8] = [
        Diffuse::Burley2012,
        Diffuse::Lambert,
        Diffuse::Frostbite,
        Diffuse::OrenNayar,
        Diffuse::OrenNayarQualitative,
        Diffuse::OrenNayarFujii,
        Diffuse::Gotanda,
        Diffuse::Hammon,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Diffuse::Burley2012 => "burley2012",
            Diffuse::Lambert => "lambert",
            Diffuse::Frostbite => "frostbite",
            Diffuse::OrenNayar => "oren-nayar",
            Diffuse::OrenNayarQualitative => "oren-nayar-qualitative",
            Diffuse::OrenNayarFujii => "oren-nayar-fujii",
            Diffuse::Gotanda => "gotanda",
            Diffuse::Hammon => "hammon",
        }
    }
}

impl SpecularD {
    pub const ALL: [SpecularD; 3] = [SpecularD::Gtr2, SpecularD::Beckmann, SpecularD::Gtr];

    pub fn name(self) -> &'static str {
        match self {
            SpecularD::Gtr2 => "gtr2",
            SpecularD::Beckmann => "beckmann",
            SpecularD::Gtr => "gtr",
        }
    }
}

impl SpecularG {
    pub const ALL: [SpecularG; 3] =
        [SpecularG::SmithSeparable, SpecularG::SmithHeightCorrelated, SpecularG::Burley2012];

    pub fn name(self) -> &'static str {
        match self {
            SpecularG::SmithSeparable => "smith-separable",
            SpecularG::SmithHeightCorrelated => "smith-height-correlated",
            SpecularG::Burley2012 => "burley2012",
        }
    }
}

impl Fresnel {
    pub const ALL: [Fresnel; 3] = [Fresnel::Schlick, Fresnel::Dielectric, Fresnel::Conductor];

    pub fn name(self) -> &'static str {
        match self {
            Fresnel::Schlick => "schlick",
            Fresnel::Dielectric => "dielectric",
            Fresnel::Conductor => "conductor",
        }
    }
}

fn choose<T: Copy>(key: &str, value: &str, all: &[T], name: fn(T) -> &'static str) -> Result<T, String> {
    all.iter().copied().find(|v| name(*v) == value).ok_or_else(|| {
        let names: Vec<&str> = all.iter().map(|v| name(*v)).collect();
        let mut message = format!("{key} = '{value}' is not a model (expected {})", names.join(", "));
        if let Some(near) = crate::suggest::near_miss(value, &names) {
            message.push_str(&format!("; did you mean '{near}'?"));
        }
        message
    })
}

/// A value for one key, as TOML or the command line gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ModelValue<'a> {
    Text(&'a str),
    Number(f64),
    Bool(bool),
}

impl Model {
    /// Sets one key. The error names the key and the values it takes, without the file or line,
    /// which the caller adds.
    pub fn set(&mut self, key: &str, value: ModelValue) -> Result<(), String> {
        let text = |v: ModelValue| match v {
            ModelValue::Text(t) => Ok(t.to_string()),
            _ => Err(format!("{key} takes a name in quotes")),
        };
        match key {
            "diffuse" => self.diffuse = choose(key, &text(value)?, &Diffuse::ALL, Diffuse::name)?,
            "specular_d" => self.specular_d = choose(key, &text(value)?, &SpecularD::ALL, SpecularD::name)?,
            "specular_g" => self.specular_g = choose(key, &text(value)?, &SpecularG::ALL, SpecularG::name)?,
            "fresnel" => self.fresnel = choose(key, &text(value)?, &Fresnel::ALL, Fresnel::name)?,
            "gtr_gamma" => {
                let (lo, hi) = GTR_GAMMA_RANGE;
                let gamma = match value {
                    ModelValue::Number(x) => x as f32,
                    _ => return Err(format!("gtr_gamma takes a number in [{lo}, {hi}]")),
                };
                if !(gamma.is_finite() && (lo..=hi).contains(&gamma)) {
                    return Err(format!("gtr_gamma = {gamma} is out of range [{lo}, {hi}]"));
                }
                self.gtr_gamma = gamma;
            }
            "energy_compensation" => {
                self.energy_compensation = match value {
                    ModelValue::Bool(b) => b,
                    _ => return Err("energy_compensation takes true or false".to_string()),
                }
            }
            _ => return Err(crate::suggest::unknown("model key", key, "in [model]", &KEYS)),
        }
        Ok(())
    }

    /// Parses and applies `--model KEY=VALUE`: names bare, numbers and true/false as written.
    pub fn set_from_text(&mut self, text: &str) -> Result<(), String> {
        self.set_from_flag("--model", text)
    }

    /// [`Model::set_from_text`] for another flag or command that takes the same `KEY=VALUE`,
    /// which its errors name (`--compare-model`, a script's `compare model`).
    pub fn set_from_flag(&mut self, flag: &str, text: &str) -> Result<(), String> {
        let (key, value) =
            text.split_once('=').ok_or_else(|| format!("{flag} {text}: expected KEY=VALUE, e.g. diffuse=lambert"))?;
        let (key, value) = (key.trim(), value.trim());
        let parsed = match key {
            "gtr_gamma" => ModelValue::Number(
                value.parse::<f64>().map_err(|_| format!("{flag} {text}: gtr_gamma takes a number"))?,
            ),
            "energy_compensation" => match value {
                "true" | "on" | "1" => ModelValue::Bool(true),
                "false" | "off" | "0" => ModelValue::Bool(false),
                _ => return Err(format!("{flag} {text}: energy_compensation takes true or false")),
            },
            _ => ModelValue::Text(value),
        };
        self.set(key, parsed).map_err(|e| format!("{flag} {text}: {e}"))
    }

    /// The value of every key, as a `[model]` table would write it.
    pub fn entries(&self) -> Vec<(&'static str, String)> {
        vec![
            ("diffuse", format!("\"{}\"", self.diffuse.name())),
            ("specular_d", format!("\"{}\"", self.specular_d.name())),
            ("specular_g", format!("\"{}\"", self.specular_g.name())),
            ("fresnel", format!("\"{}\"", self.fresnel.name())),
            ("gtr_gamma", format!("{}", self.gtr_gamma)),
            ("energy_compensation", format!("{}", self.energy_compensation)),
        ]
    }

    /// The specialization constants of model.glsl, constant ids 0 to 5, as 32-bit words.
    pub fn specialization(&self) -> [u32; 6] {
        let index = |i: usize| i as u32;
        [
            index(Diffuse::ALL.iter().position(|d| *d == self.diffuse).unwrap_or(0)),
            index(SpecularD::ALL.iter().position(|d| *d == self.specular_d).unwrap_or(0)),
            index(SpecularG::ALL.iter().position(|g| *g == self.specular_g).unwrap_or(0)),
            index(Fresnel::ALL.iter().position(|f| *f == self.fresnel).unwrap_or(0)),
            self.gtr_gamma.to_bits(),
            self.energy_compensation as u32,
        ]
    }

    /// A short label naming what differs from the default, e.g. `diffuse=lambert fresnel=conductor`,
    /// or `default` (for plot legends and comparisons).
    pub fn label(&self) -> String {
        let default = Model::default();
        let mine = self.entries();
        let parts: Vec<String> = mine
            .iter()
            .zip(default.entries())
            .filter(|(a, b)| a.1 != b.1 && !(a.0 == "gtr_gamma" && self.specular_d != SpecularD::Gtr))
            .map(|(a, _)| format!("{}={}", a.0, a.1.trim_matches('"')))
            .collect();
        if parts.is_empty() {
            "default".to_string()
        } else {
            parts.join(" ")
        }
    }
}

impl fmt::Display for Model {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.label())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_parse_and_reject() {
        let mut m = Model::default();
        assert_eq!(m.specialization(), [0, 0, 0, 0, 2.0f32.to_bits(), 0]);
        m.set_from_text("diffuse=oren-nayar").unwrap();
        m.set_from_text("specular_d = gtr").unwrap();
        m.set_from_text("gtr_gamma=1.5").unwrap();
        m.set_from_text("energy_compensation=true").unwrap();
        assert_eq!(m.diffuse, Diffuse::OrenNayar);
        assert_eq!(m.specialization(), [3, 2, 0, 0, 1.5f32.to_bits(), 1]);
        assert_eq!(m.label(), "diffuse=oren-nayar specular_d=gtr gtr_gamma=1.5 energy_compensation=true");
        let e = m.set_from_text("diffuse=lambret").unwrap_err();
        assert!(e.contains("did you mean 'lambert'"), "{e}");
        assert!(m.set_from_text("gtr_gamma=0").is_err());
        assert!(m.set_from_text("gtr_gamma=nan").is_err());
        assert!(m.set_from_text("colour=red").unwrap_err().contains("unknown model key"));
        assert!(m.set_from_text("diffuse").is_err());
        assert!(m.set("diffuse", ModelValue::Number(1.0)).is_err());
        assert_eq!(Model::default().label(), "default");
    }
}
