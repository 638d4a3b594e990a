//! A layer's mask adjustments (docs/formats.md#looks), as Substance Painter's mask
//! filters offer them: the mask channel is blurred (a Gaussian, in g-buffer pixels), then put
//! through levels (black and white points, then a gamma), and only then inverted and scaled by
//! the layer's opacity. `resolve.comp` applies the levels per pixel; a blurred mask is a channel
//! of its own, made from the g-buffer's when the stacks are uploaded ([`crate::gbuffer::blur`]).

/// The widest blur: a Gaussian's standard deviation, in g-buffer pixels. Its kernel reaches 3σ,
/// so this bounds the work per pixel at 2 × 97 taps.
pub const MAX_BLUR: f32 = 16.0;

/// The gamma range: 0.1 (darker midtones) to 10 (brighter), as Photoshop's levels.
pub const GAMMA_RANGE: std::ops::RangeInclusive<f32> = 0.1..=10.0;

/// The channel key of a blurred mask: `stripes@blur2.5` is `stripes` blurred with σ = 2.5.
pub const BLUR_SEPARATOR: &str = "@blur";

/// The adjustments of one layer's mask. The default changes nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaskAdjust {
    /// The mask value that maps to 0 (`mask_black`), in [0, 1), below `white`.
    pub black: f32,
    /// The mask value that maps to 1 (`mask_white`), in (0, 1].
    pub white: f32,
    /// The midtones' gamma (`mask_gamma`): the levelled value t becomes t^(1/gamma), so above 1
    /// widens the layer, below 1 narrows it. Within [`GAMMA_RANGE`].
    pub gamma: f32,
    /// The Gaussian blur's σ in g-buffer pixels (`mask_blur`), in [0, [`MAX_BLUR`]]; 0 is none.
    pub blur: f32,
}

impl Default for MaskAdjust {
    fn default() -> MaskAdjust {
        MaskAdjust { black: 0.0, white: 1.0, gamma: 1.0, blur: 0.0 }
    }
}

impl MaskAdjust {
    /// Whether the levels leave every value as it is (so the resolve skips them, and masks
    /// outside [0, 1] keep blending as they always have).
    pub fn levels_are_identity(&self) -> bool {
        self.black == 0.0 && self.white == 1.0 && self.gamma == 1.0
    }

    /// Why these adjustments cannot be used, naming the look keys.
    pub fn check(&self) -> Result<(), String> {
        let MaskAdjust { black, white, gamma, blur } = *self;
        if !(0.0..1.0).contains(&black) {
            return Err(format!("mask_black = {black} is out of range [0, 1)"));
        }
        if !(white > 0.0 && white <= 1.0) {
            return Err(format!("mask_white = {white} is out of range (0, 1]"));
        }
        if black >= white {
            return Err(format!("mask_black = {black} must be below mask_white = {white}"));
        }
        if !GAMMA_RANGE.contains(&gamma) {
            return Err(format!(
                "mask_gamma = {gamma} is out of range [{}, {}]",
                GAMMA_RANGE.start(),
                GAMMA_RANGE.end()
            ));
        }
        if !(0.0..=MAX_BLUR).contains(&blur) {
            return Err(format!("mask_blur = {blur} is out of range [0, {MAX_BLUR}] (pixels)"));
        }
        Ok(())
    }

    /// The levelled mask value, as `resolve.comp`'s `mask_levels` computes it.
    pub fn levels(&self, m: f32) -> f32 {
        if self.levels_are_identity() {
            return m;
        }
        let t = ((m - self.black) / (self.white - self.black)).clamp(0.0, 1.0);
        t.powf(1.0 / self.gamma)
    }

    /// The key of the channel a layer with mask `name` reads: the name itself, or the blurred
    /// mask's key ([`BLUR_SEPARATOR`]).
    pub fn channel_key(&self, name: &str) -> String {
        if self.blur > 0.0 {
            format!("{name}{BLUR_SEPARATOR}{}", self.blur)
        } else {
            name.to_string()
        }
    }
}

/// A blurred mask's key split into the mask's name and σ; `None` for a plain name.
pub fn parse_blurred(key: &str) -> Option<(&str, f32)> {
    let (name, sigma) = key.rsplit_once(BLUR_SEPARATOR)?;
    let sigma: f32 = sigma.parse().ok()?;
    (sigma > 0.0 && sigma <= MAX_BLUR).then_some((name, sigma))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_map_black_and_white_to_the_ends_and_gamma_bends_between() {
        let levels = MaskAdjust { black: 0.2, white: 0.6, ..MaskAdjust::default() };
        assert_eq!(levels.levels(0.1), 0.0);
        assert_eq!(levels.levels(0.2), 0.0);
        assert!((levels.levels(0.4) - 0.5).abs() < 1e-6);
        assert_eq!(levels.levels(0.9), 1.0);
        let brighter = MaskAdjust { gamma: 2.0, ..MaskAdjust::default() };
        assert!((brighter.levels(0.25) - 0.5).abs() < 1e-6, "t^(1/γ)");
        // The identity leaves even values outside [0, 1] alone, as before levels existed.
        assert_eq!(MaskAdjust::default().levels(1.5), 1.5);
    }

    #[test]
    fn bad_adjustments_name_their_key() {
        let bad = |adjust: MaskAdjust| adjust.check().unwrap_err();
        assert!(bad(MaskAdjust { black: 0.7, white: 0.5, ..Default::default() }).contains("below mask_white"));
        assert!(bad(MaskAdjust { gamma: 0.0, ..Default::default() }).contains("mask_gamma"));
        assert!(bad(MaskAdjust { blur: 17.0, ..Default::default() }).contains("mask_blur"));
        assert!(bad(MaskAdjust { white: f32::NAN, ..Default::default() }).contains("mask_white"));
        assert_eq!(MaskAdjust::default().check(), Ok(()));
    }

    #[test]
    fn a_blurred_mask_has_a_key_of_its_own_that_reads_back() {
        let blurred = MaskAdjust { blur: 2.5, ..MaskAdjust::default() };
        assert_eq!(blurred.channel_key("stripes"), "stripes@blur2.5");
        assert_eq!(parse_blurred("stripes@blur2.5"), Some(("stripes", 2.5)));
        assert_eq!(MaskAdjust::default().channel_key("stripes"), "stripes");
        assert_eq!(parse_blurred("stripes"), None);
        assert_eq!(parse_blurred("stripes@blur99"), None, "beyond the bound");
    }
}
