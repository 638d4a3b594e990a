//! The plots of `lookdev brdf`, and the CSV of the numbers each one shows. Line plots are SVG,
//! drawn with plotters; image slices are PNG.

use super::{directional_albedo, in_plane, luminance, slice_directions, Subject};
use crate::render::sheet;
use crate::Result;
use glam::Vec3;
use image::{Rgba, RgbaImage};
use plotters::coord::types::RangedCoordf32;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Once;

/// The CSV that goes beside a plot: the same path with the extension `csv`.
pub fn csv_path(plot: &Path) -> PathBuf {
    plot.with_extension("csv")
}

fn write_text(path: &Path, text: &str) -> Result<()> {
    crate::input::refuse_replacing_input(path)?;
    crate::atomic_file::write(path, text.as_bytes())
}

/// Angles 0°, step, … up to and including `last`.
pub fn degrees(step: f32, last: f32) -> Vec<f32> {
    let count = (last / step).round() as usize;
    (0..=count).map(|i| i as f32 * step).collect()
}

/// Directional albedo at each view angle (degrees), for each subject.
pub fn albedo_data(subjects: &[Subject], angles: &[f32]) -> Vec<Vec<Vec3>> {
    subjects.iter().map(|s| angles.iter().map(|a| directional_albedo(s, a.to_radians())).collect()).collect()
}

/// f in the plane of incidence, light at −θi, for outgoing angles θo (degrees, −90 to 90).
pub fn polar_data(subjects: &[Subject], theta_i: f32, angles: &[f32]) -> Vec<Vec<Vec3>> {
    let l = in_plane(-theta_i.to_radians());
    subjects.iter().map(|s| angles.iter().map(|a| s.brdf(l, in_plane(a.to_radians()))).collect()).collect()
}

/// f over BRDF Explorer's (θh, θd) slice at φd, one value per whole degree from 0 to 89 on each
/// axis, row-major with θd as the row.
pub fn slice_data(subject: &Subject, phi_d: f32) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(90 * 90);
    for theta_d in 0..90 {
        for theta_h in 0..90 {
            let (l, v) = slice_directions((theta_h as f32).to_radians(), (theta_d as f32).to_radians(), phi_d);
            out.push(subject.brdf(l, v));
        }
    }
    out
}

/// `label,angle,r,g,b,luminance` rows for a family of curves.
pub fn curves_csv(header: &str, subjects: &[Subject], angles: &[f32], data: &[Vec<Vec3>]) -> String {
    let mut text = format!("subject,{header},r,g,b,luminance\n");
    for (subject, values) in subjects.iter().zip(data) {
        for (angle, v) in angles.iter().zip(values) {
            let _ = writeln!(text, "{},{angle},{},{},{},{}", csv_field(&subject.label), v.x, v.y, v.z, luminance(*v));
        }
    }
    text
}

fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// Eight distinguishable line colours.
const PALETTE: [RGBColor; 8] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x17, 0xbe, 0xcf),
];

/// Guide lines (the polar plot's rings and spokes).
const GUIDE: RGBColor = RGBColor(0xd0, 0xd0, 0xd0);
/// The incident direction on the polar plot.
const LIGHT: RGBColor = RGBColor(0x55, 0x55, 0x55);

/// The family name the embedded font is registered under; the SVG names it too, so a viewer
/// shows the text in its own sans-serif face.
const FONT: &str = "sans-serif";
const TITLE_SIZE: f64 = 22.0;
const TEXT_SIZE: f64 = 16.0;

/// What drawing a plot into a string can fail with.
pub type DrawError = DrawingAreaErrorKind<std::io::Error>;

/// plotters lays text out with a font it is given: the sans-serif face the sheets use (Ubuntu
/// Light, embedded), so that no system font is needed.
fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let registered = plotters::style::register_font(FONT, FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
        assert!(registered.is_ok(), "the embedded font parses");
    });
}

/// The width of a legend of `labels`, which sits right of the axes so that it never covers a
/// curve.
fn legend_width(labels: &[&str]) -> u32 {
    let labeller = sheet::Labeller::default();
    let text = labels.iter().map(|l| labeller.width(l, TEXT_SIZE as f32)).fold(0.0, f32::max);
    // Margins of 12 either side, the frame's padding of 10, the line sample and the space after it.
    text.ceil() as u32 + 2 * 12 + 2 * 10 + 24 + 8
}

/// A legend at the top-left corner of `area`, `top` pixels down: a line sample in each entry's
/// colour and its label, in a frame.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    top: i32,
    entries: &[(&str, RGBColor)],
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let labels: Vec<&str> = entries.iter().map(|e| e.0).collect();
    let (left, right) = (12, legend_width(&labels) as i32 - 12);
    let row = TEXT_SIZE as i32 + 8;
    let bottom = top + 2 * 6 + row * entries.len() as i32;
    area.draw(&Rectangle::new([(left, top), (right, bottom)], BLACK.mix(0.3).stroke_width(1)))?;
    for (k, (label, colour)) in entries.iter().enumerate() {
        let y = top + 6 + row * k as i32 + row / 2;
        area.draw(&PathElement::new(vec![(left + 10, y), (left + 34, y)], colour.stroke_width(3)))?;
        let style = (FONT, TEXT_SIZE).into_font().color(&BLACK).pos(Pos::new(HPos::Left, VPos::Center));
        area.draw(&Text::new(label.to_string(), (left + 42, y), style))?;
    }
    Ok(())
}

/// A line plot on linear axes: x from `x_range`, y from 0 to the data's maximum (at least
/// `y_min_top`), one line per subject, with a legend.
#[allow(clippy::too_many_arguments)]
pub fn line_svg(
    title: &str,
    x_label: &str,
    y_label: &str,
    x_range: (f32, f32),
    y_min_top: f32,
    labels: &[String],
    xs: &[f32],
    ys: &[Vec<f32>],
) -> std::result::Result<String, DrawError> {
    register_font();
    let y_top = ys.iter().flatten().copied().filter(|v| v.is_finite()).fold(y_min_top, f32::max) * 1.05;
    let entries: Vec<(&str, RGBColor)> =
        labels.iter().enumerate().map(|(k, l)| (l.as_str(), PALETTE[k % PALETTE.len()])).collect();
    let legend = legend_width(&entries.iter().map(|e| e.0).collect::<Vec<_>>());
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (640 + legend, 480)).into_drawing_area();
        root.fill(&WHITE)?;
        let (plot_area, legend_area) = root.split_horizontally(640);
        let mut chart = ChartBuilder::on(&plot_area)
            .caption(title, (FONT, TITLE_SIZE))
            .margin(12)
            .x_label_area_size(48)
            .y_label_area_size(64)
            .build_cartesian_2d(x_range.0..x_range.1, 0f32..y_top)?;
        chart
            .configure_mesh()
            .x_labels(10)
            .y_labels(6)
            .x_label_formatter(&|x| format!("{}", x.round()))
            .y_label_formatter(&|y| format!("{y:.2}"))
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style((FONT, TEXT_SIZE))
            .axis_desc_style((FONT, TEXT_SIZE))
            .disable_x_mesh()
            .light_line_style(TRANSPARENT)
            .bold_line_style(GUIDE.mix(0.6))
            .draw()?;
        for ((_, colour), values) in entries.iter().zip(ys) {
            let points = xs.iter().zip(values).filter(|(_, y)| y.is_finite()).map(|(x, y)| (*x, *y));
            chart.draw_series(LineSeries::new(points, colour.stroke_width(2)))?;
        }
        draw_legend(&legend_area, chart.plotting_area().get_pixel_range().1.start, &entries)?;
        root.present()?;
    }
    Ok(svg)
}

/// A round step for `count` rings up to `top`: 1, 2, 2.5 or 5 times a power of ten.
fn ring_step(top: f32, count: f32) -> f32 {
    let raw = top / count;
    let power = 10f32.powf(raw.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0].into_iter().map(|m| m * power).find(|s| *s >= raw).unwrap_or(10.0 * power)
}

type PolarAxes = Cartesian2d<RangedCoordf32, RangedCoordf32>;

/// The polar plot's axes, x from −`half_width` to `half_width` and y from 0 to `height`.
fn polar_chart<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    half_width: f32,
    height: f32,
) -> std::result::Result<ChartContext<'a, DB, PolarAxes>, DrawingAreaErrorKind<DB::ErrorType>> {
    ChartBuilder::on(root)
        .caption(title, (FONT, TITLE_SIZE))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(-half_width..half_width, 0f32..height)
}

/// Enough decimals to write multiples of a `ring_step` exactly.
fn decimals(step: f32) -> usize {
    let power = step.log10().floor();
    let extra = usize::from((step / 10f32.powf(power) - 2.5).abs() < 1e-3);
    (-power).max(0.0) as usize + extra
}

/// The in-plane lobe as BRDF Explorer draws it: in the plane of incidence, the normal up and the
/// surface along the bottom, each curve the point f·(sinθo, cosθo) for outgoing angles θo (degrees),
/// so that its distance from the origin is f (luminance). Rings of equal f and spokes every 30°
/// stand in for polar axes; the incident direction, at −θi, is the dashed line.
pub fn polar_svg(
    title: &str,
    labels: &[String],
    angles: &[f32],
    values: &[Vec<f32>],
    theta_i: f32,
) -> std::result::Result<String, DrawError> {
    register_font();
    let top = values.iter().flatten().copied().filter(|v| v.is_finite()).fold(1e-6f32, f32::max);
    let step = ring_step(top, 4.0);
    let rings = (top / step).ceil().max(1.0);
    let outer = rings * step;
    let decimals = decimals(step);
    let light = format!("light, θi = {theta_i}°");
    let entries: Vec<(&str, RGBColor)> = std::iter::once((light.as_str(), LIGHT))
        .chain(labels.iter().enumerate().map(|(k, l)| (l.as_str(), PALETTE[k % PALETTE.len()])))
        .collect();
    let legend = legend_width(&entries.iter().map(|e| e.0).collect::<Vec<_>>());
    let size = (620 + legend, 420);
    // One unit of f is as long across as up: x covers ±`half_width` and y 0 to `height`, in the
    // proportions of the plotting area, which a first layout gives.
    let (w, h) = {
        let mut scratch = String::new();
        let root = SVGBackend::with_string(&mut scratch, size).into_drawing_area();
        let (plot_area, _) = root.split_horizontally(620);
        let chart = polar_chart(&plot_area, title, 1.0, 1.0)?;
        chart.plotting_area().dim_in_pixel()
    };
    let per_pixel = (2.0 * outer / w as f32).max(outer * 1.04 / h as f32);
    let (half_width, height) = (per_pixel * w as f32 / 2.0, per_pixel * h as f32);

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        let (plot_area, legend_area) = root.split_horizontally(620);
        let mut chart = polar_chart(&plot_area, title, half_width, height)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(9)
            .y_labels(5)
            .x_label_formatter(&|x| format!("{x:.*}", decimals))
            .y_label_formatter(&|y| format!("{y:.*}", decimals))
            .x_desc("f·sinθo")
            .y_desc("f·cosθo")
            .label_style((FONT, TEXT_SIZE))
            .axis_desc_style((FONT, TEXT_SIZE))
            .draw()?;
        let arc =
            |r: f32| (-90..=90).map(move |a| (r * (a as f32).to_radians().sin(), r * (a as f32).to_radians().cos()));
        for k in 1..=rings as u32 {
            let r = k as f32 * step;
            chart.draw_series(LineSeries::new(arc(r), GUIDE.stroke_width(1)))?;
            chart.draw_series(std::iter::once(Text::new(
                format!("{r:.*}", decimals),
                (r, 0.0),
                (FONT, TEXT_SIZE - 2.0).into_font().color(&LIGHT).pos(Pos::new(HPos::Right, VPos::Bottom)),
            )))?;
        }
        for a in (-60..=60).step_by(30) {
            let t = (a as f32).to_radians();
            chart.draw_series(LineSeries::new(
                [(0.0, 0.0), (outer * t.sin(), outer * t.cos())],
                GUIDE.stroke_width(1),
            ))?;
        }
        let t = theta_i.to_radians();
        chart.draw_series(DashedLineSeries::new(
            [(0.0, 0.0), (-outer * t.sin(), outer * t.cos())],
            8,
            5,
            LIGHT.stroke_width(2),
        ))?;
        for ((_, colour), vals) in entries[1..].iter().zip(values) {
            let points = angles.iter().zip(vals).filter(|(_, f)| f.is_finite()).map(|(a, f)| {
                let (t, f) = (a.to_radians(), f.max(0.0));
                (f * t.sin(), f * t.cos())
            });
            chart.draw_series(LineSeries::new(points, colour.stroke_width(2)))?;
        }
        draw_legend(&legend_area, chart.plotting_area().get_pixel_range().1.start, &entries)?;
        root.present()?;
    }
    Ok(svg)
}

/// sRGB byte of a linear value through x/(1 + x), so that every value of f shows.
fn slice_byte(x: f32) -> u8 {
    let t = (x.max(0.0) / (1.0 + x.max(0.0))).clamp(0.0, 1.0);
    let s = if t <= 0.0031308 { 12.92 * t } else { 1.055 * t.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0 + 0.5) as u8
}

/// One slice as an image, θh to the right and θd down, each degree `scale` pixels.
pub fn slice_image(data: &[Vec3], scale: u32) -> RgbaImage {
    RgbaImage::from_fn(90 * scale, 90 * scale, |x, y| {
        let v = data[(y / scale * 90 + x / scale) as usize];
        Rgba([slice_byte(v.x), slice_byte(v.y), slice_byte(v.z), 255])
    })
}

/// Writes a plot and its CSV.
pub fn write_plot(out: &Path, plot: PlotFile, csv: &str) -> Result<()> {
    match plot {
        PlotFile::Svg(text) => write_text(out, &text)?,
        PlotFile::Png(image) => crate::render::output::write_png_image(out, &image)?,
    }
    write_text(&csv_path(out), csv)
}

pub enum PlotFile {
    Svg(String),
    Png(RgbaImage),
}

/// Slices side by side, labelled.
pub fn slices_sheet(title: &str, cells: Vec<(String, RgbaImage)>) -> RgbaImage {
    sheet::rows(&[(title.to_string(), cells)])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The value of attribute `name` in one tag's text.
    fn attr<'a>(tag: &'a str, name: &str) -> &'a str {
        let key = format!(" {name}=\"");
        let start = tag.find(&key).unwrap_or_else(|| panic!("no {name} in {tag}")) + key.len();
        &tag[start..start + tag[start..].find('"').unwrap()]
    }

    /// A `<polyline>`'s stroke colour, stroke width and points.
    type Polyline = (String, String, Vec<(f32, f32)>);

    fn polylines(svg: &str) -> Vec<Polyline> {
        svg.split("<polyline")
            .skip(1)
            .map(|rest| {
                let tag = &rest[..rest.find("/>").unwrap()];
                let points = attr(tag, "points")
                    .split_whitespace()
                    .map(|p| {
                        let (x, y) = p.split_once(',').unwrap();
                        (x.parse().unwrap(), y.parse().unwrap())
                    })
                    .collect();
                (attr(tag, "stroke").to_string(), attr(tag, "stroke-width").to_string(), points)
            })
            .collect()
    }

    /// The text of each `<text>` element, unescaped.
    fn texts(svg: &str) -> Vec<String> {
        svg.split("<text")
            .skip(1)
            .map(|rest| {
                let body = &rest[rest.find('>').unwrap() + 1..rest.find("</text>").unwrap()];
                body.trim()
                    .replace("&lt;", "<")
                    .replace("&gt;", ">")
                    .replace("&quot;", "\"")
                    .replace("&apos;", "'")
                    .replace("&amp;", "&")
            })
            .collect()
    }

    fn hex(colour: RGBColor) -> String {
        format!("#{:02X}{:02X}{:02X}", colour.0, colour.1, colour.2)
    }

    /// The point counts of the polylines drawn in `colour` at `width`, in order.
    fn lines_in(svg: &str, colour: RGBColor, width: &str) -> Vec<usize> {
        polylines(svg)
            .into_iter()
            .filter(|(c, w, _)| *c == hex(colour) && w == width)
            .map(|(_, _, p)| p.len())
            .collect()
    }

    fn labels() -> Vec<String> {
        vec!["red-plastic".to_string(), "gold · ggx, conductor".to_string(), "<odd> & \"quoted\"".to_string()]
    }

    #[test]
    fn line_plot_has_one_curve_and_one_legend_entry_per_subject() {
        let xs = degrees(2.0, 88.0);
        let ys: Vec<Vec<f32>> = (0..3).map(|k| xs.iter().map(|x| 0.3 * k as f32 + x / 180.0).collect()).collect();
        let svg = line_svg("Directional albedo", "view angle θv (°)", "albedo", (0.0, 90.0), 1.0, &labels(), &xs, &ys)
            .unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{svg}");
        let texts = texts(&svg);
        for title in ["Directional albedo", "view angle θv (°)", "albedo", "0", "90"] {
            assert!(texts.iter().any(|t| t == title), "{title:?} missing from {texts:?}");
        }
        for (k, label) in labels().iter().enumerate() {
            // The curve, every point of it, then the legend's sample.
            assert_eq!(lines_in(&svg, PALETTE[k], "2"), [xs.len()], "{label}");
            assert_eq!(lines_in(&svg, PALETTE[k], "3"), [2], "{label}");
            assert!(texts.contains(label), "{label:?} missing from {texts:?}");
        }
        // Higher values are drawn higher up: SVG's y grows downwards.
        let curve =
            |k: usize| polylines(&svg).into_iter().find(|(c, w, _)| *c == hex(PALETTE[k]) && w == "2").unwrap().2;
        assert!(curve(2)[0].1 < curve(0)[0].1);
        assert!(curve(0)[0].0 < curve(0)[xs.len() - 1].0);
    }

    #[test]
    fn polar_plot_has_each_lobe_the_light_and_a_legend() {
        let angles: Vec<f32> = (0..=178).map(|i| -89.0 + i as f32).collect();
        // Lobes around the mirror direction (30°) of different widths and heights.
        let values: Vec<Vec<f32>> = (0..3)
            .map(|k| {
                angles
                    .iter()
                    .map(|a| (1.0 + k as f32) * (-((a - 30.0) / (10.0 + 10.0 * k as f32)).powi(2)).exp())
                    .collect()
            })
            .collect();
        let svg = polar_svg("In-plane lobe, θi = 30°", &labels(), &angles, &values, 30.0).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{svg}");
        let texts = texts(&svg);
        for text in ["In-plane lobe, θi = 30°", "light, θi = 30°", "f·sinθo", "f·cosθo"] {
            assert!(texts.iter().any(|t| t == text), "{text:?} missing from {texts:?}");
        }
        for (k, label) in labels().iter().enumerate() {
            assert_eq!(lines_in(&svg, PALETTE[k], "2"), [angles.len()], "{label}");
            assert_eq!(lines_in(&svg, PALETTE[k], "3"), [2], "{label}");
            assert!(texts.contains(label), "{label:?} missing from {texts:?}");
        }
        // The light: dashes from the origin up and to the left, and its legend sample.
        let dashes = lines_in(&svg, LIGHT, "2");
        assert!(dashes.len() > 3 && dashes.iter().all(|n| *n == 2), "{dashes:?}");
        assert_eq!(lines_in(&svg, LIGHT, "3"), [2]);

        // One unit of f is as long across as up: the outer ring is a semicircle, twice as wide
        // as it is high, and the lobes peak on the mirror ray, 30° right of the normal.
        let rings: Vec<Vec<(f32, f32)>> = polylines(&svg)
            .into_iter()
            .filter(|(c, _, p)| *c == hex(GUIDE) && p.len() > 2)
            .map(|(_, _, p)| p)
            .collect();
        let outer = rings.last().unwrap();
        let (x0, x1) = (outer.first().unwrap().0, outer.last().unwrap().0);
        let origin = ((x0 + x1) / 2.0, outer[0].1);
        let radius = (x1 - x0) / 2.0;
        let top = outer.iter().map(|p| p.1).fold(f32::MAX, f32::min);
        assert!((origin.1 - top - radius).abs() <= 2.0, "ring {radius} wide, {} high", origin.1 - top);
        let curve = polylines(&svg).into_iter().find(|(c, w, _)| *c == hex(PALETTE[2]) && w == "2").unwrap().2;
        let peak = curve
            .iter()
            .map(|(x, y)| (x - origin.0, origin.1 - y))
            .max_by(|a, b| a.0.hypot(a.1).total_cmp(&b.0.hypot(b.1)))
            .unwrap();
        let angle = peak.0.atan2(peak.1).to_degrees();
        assert!((angle - 30.0).abs() < 2.0, "peak at {angle}°");
        // The highest lobe reaches the outer ring or nearly.
        assert!(peak.0.hypot(peak.1) > 0.7 * radius && peak.0.hypot(peak.1) <= radius + 2.0);
    }

    #[test]
    fn ring_steps_are_round_and_written_exactly() {
        for (top, step) in [(1.0, 0.25), (3.0, 1.0), (70.0, 20.0), (0.9, 0.25), (1e3, 250.0)] {
            assert!((ring_step(top, 4.0) / step - 1.0).abs() < 1e-5, "{top}: {}", ring_step(top, 4.0));
        }
        assert_eq!(decimals(0.25), 2);
        assert_eq!(decimals(2.5), 1);
        assert_eq!(decimals(20.0), 0);
        assert_eq!(decimals(0.05), 2);
    }
}
