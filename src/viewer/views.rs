//! The views the viewer shows instead of the beauty (docs/commands.md, "Views"): each light AOV,
//! albedo and each resolved parameter, N and V, the g-buffer's masks and maps, each layer's
//! weight, object ids, variance, and a false-colour EV view. Each is an AOV of
//! [`crate::render::aov`]; this module names them, parses names, and turns an AOV's values into
//! display pixels, a histogram and a clipping overlay.

use crate::gbuffer::GBuffer;
use crate::material::look::Look;
use crate::material::Param;
use crate::render::aov::{self, Aov};
use crate::render::renderer::Accumulate;
use crate::shading::tonemap::{self, Tonemap};
use glam::Vec3;

/// One view of the image.
#[derive(Clone, Debug, PartialEq)]
pub enum View {
    /// The render, as `lookdev render` shows it.
    Beauty,
    /// An AOV of one layer: a light, emission, albedo, a parameter, N, V, objectId, variance.
    Aov(Aov),
    /// A g-buffer mask, by name.
    Mask(String),
    /// A g-buffer map, by name (a colour map, or a scalar one).
    Map(String),
    /// A layer's share of its stack's blend, by its `layers` AOV layer name.
    Layer(String),
    /// The beauty's luminance after exposure, in stops about 18% grey, banded.
    FalseColour,
}

/// A change of view: by name (a script's `view NAME`, the View menu), or by hotkey.
#[derive(Clone, Debug, PartialEq)]
pub enum ViewChoice {
    Named(String),
    /// `C`: the next view in [`list`]'s order, after the last the first.
    Next,
    /// `Shift+C`: the previous view.
    Previous,
    /// `M`: back to the beauty.
    Beauty,
    /// `E`: the false-colour view, or back to the view before it.
    FalseColour,
}

/// How a view's values become display pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Exposure, tone map and sRGB, as the beauty.
    Radiance,
    /// A linear colour, clamped to [0, 1] and sRGB-encoded, as the product shows colours.
    Colour,
    /// A value in [0, 1] as grey: byte = round(255·v), so the pixel is the value.
    Value,
    /// A unit vector: each channel 0.5·(c + 1), by the value rule.
    Vector,
    /// Object ids as distinct colours ([`aov::id_colour`]).
    Ids,
    /// A variance as its square root (the standard error), by the value rule.
    Deviation,
    /// The band of [`FALSE_COLOURS`] the luminance falls in.
    FalseColour,
}

impl View {
    /// The view's name, as `view NAME` and the View menu give it.
    pub fn name(&self) -> String {
        match self {
            View::Beauty => "beauty".into(),
            View::Aov(Aov::Param(param)) if short_param(*param) => param.name().to_string(),
            View::Aov(aov) => aov.name(),
            View::Mask(name) => format!("mask.{name}"),
            View::Map(name) => format!("map.{name}"),
            View::Layer(name) => name.clone(),
            View::FalseColour => "falsecolor".into(),
        }
    }

    /// The group the View menu lists it under.
    pub fn group(&self) -> &'static str {
        match self {
            View::Beauty | View::FalseColour => "",
            View::Aov(Aov::Lobe(_) | Aov::Emission) => "Light",
            View::Aov(Aov::Albedo | Aov::Param(_)) => "Material",
            View::Aov(Aov::Variance) => "Error",
            View::Aov(_) => "Geometry",
            View::Mask(_) => "Masks",
            View::Map(_) => "Maps",
            View::Layer(_) => "Layers",
        }
    }

    /// How its values are shown; `channels` is how many its AOV layer has.
    pub fn encoding(&self, channels: usize) -> Encoding {
        match self {
            View::Beauty | View::Aov(Aov::Lobe(_) | Aov::Emission) => Encoding::Radiance,
            View::Aov(Aov::Albedo | Aov::Param(Param::BaseColor)) => Encoding::Colour,
            View::Aov(Aov::Normal | Aov::View) => Encoding::Vector,
            View::Aov(Aov::ObjectId) => Encoding::Ids,
            View::Aov(Aov::Variance) => Encoding::Deviation,
            View::Map(_) if channels == 3 => Encoding::Colour,
            View::FalseColour => Encoding::FalseColour,
            _ => Encoding::Value,
        }
    }

    /// Whether it changes as samples land (else only with edits).
    pub fn follows_samples(&self) -> bool {
        matches!(self, View::Beauty | View::FalseColour | View::Aov(Aov::Lobe(_) | Aov::Variance))
    }

    /// What the renderer must accumulate beside the total to show it: the light views need
    /// each lobe's share, the variance view the squared estimates; the rest nothing.
    pub fn accumulate(&self) -> Accumulate {
        match self {
            View::Aov(aov) => aov::accumulate(&[*aov]),
            _ => Accumulate::default(),
        }
    }

    /// Whether it is the radiance (its histogram is in stops), rather than a value.
    pub fn is_radiance(&self) -> bool {
        matches!(self.encoding(3), Encoding::Radiance | Encoding::FalseColour)
    }
}

/// Whether a parameter's view is named by the parameter alone: where no light AOV has its name
/// (`specular` is the lobe; its parameter is `param_specular`).
fn short_param(param: Param) -> bool {
    Aov::parse(param.name()).is_ok_and(|a| a == [Aov::Param(param)])
}

/// Every view of a session, in the order `C` steps through them: the beauty, the light AOVs,
/// albedo and the parameters, N, V, object ids, variance, the masks, the maps, each layer's
/// weight, and false colour.
pub fn list(gbuffer: &GBuffer, look: &Look) -> Vec<View> {
    let mut views = vec![View::Beauty];
    let single = Aov::all().into_iter().filter(|a| !matches!(a, Aov::Layers | Aov::Masks | Aov::Maps));
    views.extend(single.map(View::Aov));
    views.extend(gbuffer.masks.keys().map(|m| View::Mask(m.clone())));
    views.extend(gbuffer.maps().into_iter().map(|m| View::Map(m.name)));
    views.extend(aov::layer_weight_names(gbuffer, look).into_iter().map(View::Layer));
    views.push(View::FalseColour);
    views
}

/// The view `name` names among `views`: its name, or a parameter by its AOV name
/// (`param_roughness`). Unknown names list the views and suggest the closest.
pub fn parse(name: &str, views: &[View]) -> Result<View, String> {
    let name = name.trim();
    if let Some(view) = views.iter().find(|v| v.name() == name) {
        return Ok(view.clone());
    }
    if let Some(view) = views.iter().find(|v| matches!(v, View::Aov(a) if a.name() == name)) {
        return Ok(view.clone());
    }
    let names: Vec<String> = views.iter().map(View::name).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    Err(crate::suggest::unknown("view", name, "", &names))
}

/// The value rule: v in [0, 1] as a byte, round(255·v).
pub fn value_byte(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// A linear colour as sRGB bytes, clamped to [0, 1].
fn srgb_bytes(v: [f32; 3]) -> [u8; 3] {
    v.map(|c| (tonemap::srgb_encode(c.clamp(0.0, 1.0)) * 255.0).round() as u8)
}

/// One pixel of a view: its linear value (a scalar in channel 0) as display RGB.
pub fn encode(encoding: Encoding, v: [f32; 3], exposure: f32, tonemap: Tonemap) -> [u8; 3] {
    match encoding {
        Encoding::Radiance => tonemap::display_pixel(Vec3::from(v), exposure, tonemap),
        Encoding::Colour => srgb_bytes(v),
        Encoding::Value => [value_byte(v[0]); 3],
        Encoding::Vector => v.map(|c| value_byte(0.5 * (c + 1.0))),
        Encoding::Ids => aov::id_colour(v[0].max(0.0) as u32),
        Encoding::Deviation => [value_byte(v[0].max(0.0).sqrt()); 3],
        Encoding::FalseColour => FALSE_COLOURS[band(stops(luminance(v), exposure))].0,
    }
}

/// Rec. 709 luminance.
pub fn luminance(v: [f32; 3]) -> f32 {
    crate::shading::common::luminance(Vec3::from(v))
}

/// Stops above 18% grey of a luminance after exposure; −∞ for black.
pub fn stops(luminance: f32, exposure: f32) -> f32 {
    (luminance * exposure.exp2() / 0.18).log2()
}

/// The false-colour bands, one stop wide, centred on −5 … +5 stops about 18% grey, with one
/// below and one above: each colour and its legend label.
pub const FALSE_COLOURS: [([u8; 3], &str); 13] = [
    ([60, 0, 90], "<−5"),
    ([40, 0, 200], "−5"),
    ([0, 70, 255], "−4"),
    ([0, 150, 255], "−3"),
    ([0, 200, 200], "−2"),
    ([60, 170, 90], "−1"),
    ([128, 128, 128], "0"),
    ([150, 210, 60], "+1"),
    ([255, 230, 0], "+2"),
    ([255, 170, 0], "+3"),
    ([255, 100, 0], "+4"),
    ([220, 0, 0], "+5"),
    ([255, 190, 255], ">+5"),
];

/// The band of [`FALSE_COLOURS`] a number of stops falls in: stops in [k − ½, k + ½) are band
/// k + 6; below −5.5 (black included) the first, from +5.5 the last.
pub fn band(stops: f32) -> usize {
    if stops.is_nan() || stops < -5.5 {
        0
    } else if stops >= 5.5 {
        FALSE_COLOURS.len() - 1
    } else {
        ((stops + 6.5).floor() as usize).min(FALSE_COLOURS.len() - 2)
    }
}

/// The clipping overlay's marks: a display value at 1 (255) in any channel, and one at 0 in
/// every channel.
pub const CLIPPED: [u8; 3] = [255, 0, 0];
pub const CRUSHED: [u8; 3] = [0, 80, 255];

/// The overlay's colour for a display pixel, if it clips or is crushed.
pub fn clip_mark(display: [u8; 3]) -> Option<[u8; 3]> {
    if display.contains(&255) {
        Some(CLIPPED)
    } else if display == [0; 3] {
        Some(CRUSHED)
    } else {
        None
    }
}

/// A histogram's horizontal axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Axis {
    /// Stops about 18% grey, after exposure, over [`STOPS`]; black and below in the first bin.
    Stops,
    /// Values in [0, 1], clamped.
    Unit,
}

/// The stops axis's range.
pub const STOPS: (f32, f32) = (-10.0, 10.0);
/// Bins: four a stop on the stops axis, 64 on the unit one.
const STOP_BINS: usize = 80;
const UNIT_BINS: usize = 64;

/// Counts of pixels per bin of a view's luminance.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    pub axis: Axis,
    pub bins: Vec<u32>,
    /// The pixels counted: every pixel of a radiance view with the background shown, else the
    /// covered ones.
    pub counted: usize,
}

/// The histogram of what a view shows: the luminance after exposure in stops for radiance, else
/// the value the encoding shows (the value, a colour's luminance, 0.5·(n + 1), the standard
/// error); `None` for object ids, which are not quantities. Counts the pixels `counted` allows.
pub fn histogram(
    encoding: Encoding,
    values: &[[f32; 3]],
    counted: impl Fn(usize) -> bool,
    exposure: f32,
) -> Option<Histogram> {
    let (axis, bins) = match encoding {
        Encoding::Ids => return None,
        Encoding::Radiance | Encoding::FalseColour => (Axis::Stops, STOP_BINS),
        _ => (Axis::Unit, UNIT_BINS),
    };
    let mut histogram = Histogram { axis, bins: vec![0; bins], counted: 0 };
    for v in values.iter().enumerate().filter(|(p, _)| counted(*p)).map(|(_, v)| v) {
        let x = match encoding {
            Encoding::Radiance | Encoding::FalseColour => {
                (stops(luminance(*v), exposure) - STOPS.0) / (STOPS.1 - STOPS.0)
            }
            Encoding::Colour => luminance(*v),
            Encoding::Vector => luminance(v.map(|c| 0.5 * (c + 1.0))),
            Encoding::Deviation => v[0].max(0.0).sqrt(),
            _ => v[0],
        };
        // NaN and −∞ (black in stops) land in the first bin.
        let bin = if x.is_nan() { 0 } else { ((x * bins as f32).max(0.0) as usize).min(bins - 1) };
        histogram.bins[bin] += 1;
    }
    histogram.counted = histogram.bins.iter().map(|&n| n as usize).sum();
    Some(histogram)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn views() -> Vec<View> {
        let mut gbuffer = GBuffer::shaderball(16, 16);
        gbuffer.maps.insert("rough".into(), vec![0.5; 256]);
        for c in ["R", "G", "B"] {
            gbuffer.maps.insert(format!("tex.{c}"), vec![0.25; 256]);
        }
        list(&gbuffer, &Look::builtin_default())
    }

    #[test]
    fn every_view_is_named_and_parses_back() {
        let views = views();
        let names: Vec<String> = views.iter().map(View::name).collect();
        for expected in [
            "beauty",
            "diffuse",
            "specular",
            "clearcoat",
            "sheen",
            "emission",
            "albedo",
            "base_color",
            "roughness",
            "param_specular",
            "specular_tint",
            "N",
            "V",
            "objectId",
            "variance",
            "mask.stripes",
            "map.tex",
            "map.rough",
            "falsecolor",
        ] {
            assert!(names.iter().any(|n| n == expected), "no view {expected} in {names:?}");
        }
        assert!(names.iter().any(|n| n.starts_with("layers_")), "{names:?}");
        let unique: std::collections::BTreeSet<&String> = names.iter().collect();
        assert_eq!(unique.len(), names.len(), "names are unique: {names:?}");
        for view in &views {
            assert_eq!(parse(&view.name(), &views).unwrap(), *view);
        }
        assert_eq!(parse("param_roughness", &views).unwrap(), View::Aov(Aov::Param(Param::Roughness)));
        assert_eq!(parse("specular", &views).unwrap(), View::Aov(Aov::Lobe(1)), "the lobe, not the parameter");
        let message = parse("roughnes", &views).unwrap_err();
        assert!(
            message.contains("unknown view 'roughnes'") && message.contains("did you mean 'roughness'?"),
            "{message}"
        );
        let message = parse("mask.stripe", &views).unwrap_err();
        assert!(message.contains("did you mean 'mask.stripes'?"), "{message}");
    }

    #[test]
    fn only_light_and_variance_views_accumulate_more() {
        let views = views();
        let accumulating: Vec<String> =
            views.iter().filter(|v| v.accumulate() != Accumulate::default()).map(View::name).collect();
        assert_eq!(accumulating, ["diffuse", "specular", "clearcoat", "sheen", "variance"]);
        assert_eq!(View::Beauty.accumulate(), Accumulate::default());
    }

    #[test]
    fn values_show_exactly_and_colours_as_colours() {
        let tonemap = Tonemap::Neutral;
        // The value rule is exact: the byte is round(255·v), whatever the exposure.
        assert_eq!(encode(Encoding::Value, [0.37, 0.0, 0.0], 3.0, tonemap), [94; 3]);
        assert_eq!(encode(Encoding::Value, [1.7, 0.0, 0.0], 0.0, tonemap), [255; 3]);
        assert_eq!(encode(Encoding::Value, [-0.2, 0.0, 0.0], 0.0, tonemap), [0; 3]);
        for k in 0..=255u8 {
            assert_eq!(encode(Encoding::Value, [k as f32 / 255.0; 3], 0.0, tonemap), [k; 3]);
        }
        // Colours are sRGB-encoded: linear 0.5 is sRGB 188, 0.2159 is 128.
        assert_eq!(encode(Encoding::Colour, [0.5, 0.2159, 0.0], 2.0, tonemap), [188, 128, 0]);
        assert_eq!(encode(Encoding::Vector, [0.0, 1.0, -1.0], 0.0, tonemap), [128, 255, 0]);
        assert_eq!(encode(Encoding::Deviation, [0.25, 0.0, 0.0], 0.0, tonemap), [128; 3]);
        // Radiance as the beauty shows it.
        let v = [0.3, 0.2, 0.1];
        assert_eq!(encode(Encoding::Radiance, v, 1.0, tonemap), tonemap::display_pixel(Vec3::from(v), 1.0, tonemap));
    }

    #[test]
    fn object_ids_have_stable_distinct_colours() {
        assert_eq!(encode(Encoding::Ids, [0.0; 3], 0.0, Tonemap::Neutral), [0; 3]);
        let colours: Vec<[u8; 3]> =
            (1..=64).map(|id| encode(Encoding::Ids, [id as f32; 3], 0.0, Tonemap::Linear)).collect();
        let unique: std::collections::BTreeSet<[u8; 3]> = colours.iter().copied().collect();
        assert_eq!(unique.len(), colours.len(), "distinct colours");
        assert_eq!(colours[0], aov::id_colour(1), "the same hash as render --aov-display");
        assert!(colours.iter().all(|c| c.iter().all(|&b| b >= 0x40)), "never near black, the background");
    }

    #[test]
    fn false_colour_bands_are_stops_about_mid_grey() {
        assert_eq!(band(stops(0.18, 0.0)), 6);
        assert_eq!(FALSE_COLOURS[band(stops(0.18, 0.0))].1, "0");
        assert_eq!(FALSE_COLOURS[band(stops(0.72, 0.0))].1, "+2");
        assert_eq!(FALSE_COLOURS[band(stops(0.72, 1.0))].1, "+3", "after exposure");
        assert_eq!(FALSE_COLOURS[band(stops(0.045, 0.0))].1, "−2");
        assert_eq!(band(stops(0.0, 0.0)), 0, "black is below the bands");
        assert_eq!(band(f32::NAN), 0);
        assert_eq!(band(40.0), 12);
        assert_eq!((band(-0.5), band(0.49), band(0.5)), (6, 6, 7), "a band is [k − ½, k + ½)");
        let colours: std::collections::BTreeSet<[u8; 3]> = FALSE_COLOURS.iter().map(|(c, _)| *c).collect();
        assert_eq!(colours.len(), FALSE_COLOURS.len(), "each band its own colour");
        assert!(!colours.contains(&CLIPPED) && !colours.contains(&CRUSHED), "the overlay's marks stand out");
        assert_eq!(encode(Encoding::FalseColour, [0.18; 3], 0.0, Tonemap::Neutral), FALSE_COLOURS[6].0);
    }

    #[test]
    fn clipping_marks_full_and_empty_display_values() {
        assert_eq!(clip_mark([255, 10, 10]), Some(CLIPPED));
        assert_eq!(clip_mark([0, 0, 0]), Some(CRUSHED));
        assert_eq!(clip_mark([0, 0, 1]), None);
        assert_eq!(clip_mark([254, 254, 254]), None);
    }

    #[test]
    fn a_histogram_counts_every_counted_pixel_once() {
        let values: Vec<[f32; 3]> =
            (0..1000).map(|i| [i as f32 / 500.0 - 0.5, f32::NAN.min(i as f32), (i % 7) as f32]).collect();
        let covered = |p: usize| p % 3 != 0;
        let expected = (0..1000).filter(|&p| covered(p)).count();
        for encoding in [Encoding::Value, Encoding::Colour, Encoding::Vector, Encoding::Deviation, Encoding::Radiance] {
            let h = histogram(encoding, &values, covered, 0.0).unwrap();
            assert_eq!(h.bins.iter().map(|&n| n as usize).sum::<usize>(), expected, "{encoding:?}");
            assert_eq!(h.counted, expected);
        }
        let all = histogram(Encoding::Radiance, &values, |_| true, 0.0).unwrap();
        assert_eq!((all.axis, all.counted), (Axis::Stops, 1000));
        // Black and negative radiance fall in the first bin; mid grey at the axis's middle.
        let grey = histogram(Encoding::Radiance, &[[0.18; 3], [0.0; 3]], |_| true, 0.0).unwrap();
        assert_eq!(grey.bins[0], 1);
        assert_eq!(grey.bins[STOP_BINS / 2], 1);
        assert!(histogram(Encoding::Ids, &values, |_| true, 0.0).is_none());
    }
}
