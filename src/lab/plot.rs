//! The plots of `lookdev brdf`, and the CSV of the numbers each one shows. Line plots are SVG,
//! written as text; image slices are PNG.

use super::{directional_albedo, in_plane, luminance, slice_directions, Subject};
use crate::render::sheet;
use crate::Result;
use glam::Vec3;
use image::{Rgba, RgbaImage};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The CSV that goes beside a plot: the same path with the extension `csv`.
pub fn csv_path(plot: &Path) -> PathBuf {
    plot.with_extension("csv")
}

fn write_text(path: &Path, text: &str) -> Result<()> {
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
const PALETTE: [&str; 8] = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"];

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A line plot on linear axes: x from `x_range`, y from 0 to the data's maximum (at least
/// `y_min_top`), one polyline per subject, with a legend.
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
) -> String {
    let (w, h, left, right, top, bottom) = (720.0f32, 480.0f32, 70.0f32, 20.0f32, 40.0f32, 60.0f32);
    let y_top = ys.iter().flatten().copied().filter(|v| v.is_finite()).fold(y_min_top, f32::max) * 1.05;
    let px = |x: f32| left + (x - x_range.0) / (x_range.1 - x_range.0) * (w - left - right);
    let py = |y: f32| h - bottom - y / y_top * (h - top - bottom);
    let mut s = String::new();
    let _ = writeln!(s, r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">"#);
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="24" font-family="sans-serif" font-size="16" text-anchor="middle">{}</text>"#,
        w / 2.0,
        escape(title)
    );
    // Axes and ticks.
    let _ = writeln!(
        s,
        r#"<path d="M{l} {t} L{l} {b} L{r} {b}" stroke="black" fill="none"/>"#,
        l = left,
        t = top,
        b = h - bottom,
        r = w - right
    );
    for i in 0..=6 {
        let x = x_range.0 + (x_range.1 - x_range.0) * i as f32 / 6.0;
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" font-family="sans-serif" font-size="12" text-anchor="middle">{}</text>"#,
            px(x),
            h - bottom + 18.0,
            x.round()
        );
    }
    for i in 0..=5 {
        let y = y_top / 1.05 * i as f32 / 5.0;
        let _ = writeln!(
            s,
            r##"<line x1="{l}" x2="{r}" y1="{y:.1}" y2="{y:.1}" stroke="#ddd"/><text x="{tx}" y="{ty:.1}" font-family="sans-serif" font-size="12" text-anchor="end">{v:.3}</text>"##,
            l = left,
            r = w - right,
            y = py(y),
            tx = left - 6.0,
            ty = py(y) + 4.0,
            v = y
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" font-family="sans-serif" font-size="13" text-anchor="middle">{}</text>"#,
        (left + w - right) / 2.0,
        h - 18.0,
        escape(x_label)
    );
    let _ = writeln!(
        s,
        r#"<text x="18" y="{}" font-family="sans-serif" font-size="13" text-anchor="middle" transform="rotate(-90 18 {})">{}</text>"#,
        (top + h - bottom) / 2.0,
        (top + h - bottom) / 2.0,
        escape(y_label)
    );
    for (k, (label, values)) in labels.iter().zip(ys).enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let points: Vec<String> = xs.iter().zip(values).map(|(x, y)| format!("{:.2},{:.2}", px(*x), py(*y))).collect();
        let _ =
            writeln!(s, r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="2"/>"#, points.join(" "));
        let ly = top + 12.0 + 18.0 * k as f32;
        let _ = writeln!(
            s,
            r#"<line x1="{x1}" x2="{x2}" y1="{ly}" y2="{ly}" stroke="{colour}" stroke-width="3"/><text x="{tx}" y="{ty}" font-family="sans-serif" font-size="12">{label}</text>"#,
            x1 = w - right - 250.0,
            x2 = w - right - 226.0,
            tx = w - right - 220.0,
            ty = ly + 4.0,
            label = escape(label)
        );
    }
    s.push_str("</svg>\n");
    s
}

/// The in-plane lobe as a polar plot: radius f (luminance), angle θo from the normal (up).
pub fn polar_svg(title: &str, labels: &[String], angles: &[f32], values: &[Vec<f32>], theta_i: f32) -> String {
    let (w, h) = (640.0f32, 420.0f32);
    let (cx, cy, radius) = (w / 2.0, h - 50.0, 300.0f32);
    let top = values.iter().flatten().copied().filter(|v| v.is_finite()).fold(1e-6f32, f32::max);
    let point = |theta: f32, r: f32| {
        let t = theta.to_radians();
        (cx + r / top * radius * t.sin(), cy - r / top * radius * t.cos())
    };
    let mut s = String::new();
    let _ = writeln!(s, r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">"#);
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="24" font-family="sans-serif" font-size="16" text-anchor="middle">{}</text>"#,
        w / 2.0,
        escape(title)
    );
    for k in 1..=4 {
        let r = radius * k as f32 / 4.0;
        let _ = writeln!(
            s,
            r##"<path d="M{} {cy} A{r} {r} 0 0 1 {} {cy}" fill="none" stroke="#ddd"/><text x="{}" y="{}" font-family="sans-serif" font-size="11">{:.3}</text>"##,
            cx - r,
            cx + r,
            cx + r + 2.0,
            cy + 14.0,
            top * k as f32 / 4.0
        );
    }
    let _ = writeln!(s, r#"<line x1="{}" x2="{}" y1="{cy}" y2="{cy}" stroke="black"/>"#, cx - radius, cx + radius);
    let _ = writeln!(s, r##"<line x1="{cx}" x2="{cx}" y1="{cy}" y2="{}" stroke="#999"/>"##, cy - radius);
    // The incident direction, drawn from the centre.
    let (lx, ly) = point(-theta_i, top);
    let _ =
        writeln!(s, r#"<line x1="{cx}" y1="{cy}" x2="{lx:.1}" y2="{ly:.1}" stroke="orange" stroke-dasharray="6 4"/>"#);
    for (k, (label, vals)) in labels.iter().zip(values).enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let points: Vec<String> = angles
            .iter()
            .zip(vals)
            .map(|(a, v)| {
                let (x, y) = point(*a, v.max(0.0));
                format!("{x:.2},{y:.2}")
            })
            .collect();
        let _ =
            writeln!(s, r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="2"/>"#, points.join(" "));
        let ly = 44.0 + 18.0 * k as f32;
        let _ = writeln!(
            s,
            r#"<line x1="12" x2="36" y1="{ly}" y2="{ly}" stroke="{colour}" stroke-width="3"/><text x="42" y="{}" font-family="sans-serif" font-size="12">{}</text>"#,
            ly + 4.0,
            escape(label)
        );
    }
    s.push_str("</svg>\n");
    s
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
