//! Display transforms: exposure, tone map and the sRGB OETF.

use std::fmt;

/// The tone map applied to PNG output and the viewer, after exposure and before sRGB encoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Tonemap {
    /// Clamp to [0, 1].
    Linear,
    /// Khronos PBR Neutral: hue-preserving, base colours reproduced under unit white light.
    #[default]
    Neutral,
    /// ACES 1.0 RRT+ODT (sRGB), Stephen Hill's fit.
    Aces,
    /// Troy Sobotka's AgX base look.
    Agx,
}

impl Tonemap {
    pub const ALL: [Tonemap; 4] = [Tonemap::Linear, Tonemap::Neutral, Tonemap::Aces, Tonemap::Agx];

    pub fn name(self) -> &'static str {
        match self {
            Tonemap::Linear => "linear",
            Tonemap::Neutral => "neutral",
            Tonemap::Aces => "aces",
            Tonemap::Agx => "agx",
        }
    }

    pub fn from_name(name: &str) -> Option<Tonemap> {
        Tonemap::ALL.into_iter().find(|t| t.name() == name)
    }

    /// The id the display kernel switches on.
    pub fn gpu_id(self) -> u32 {
        self as u32
    }
}

impl fmt::Display for Tonemap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
