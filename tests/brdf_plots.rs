//! `lookdev brdf`: each plot's CSV holds what the lab's integrator and the Rust reference give,
//! the furnace's rendered values agree with the integrator, and bad input is one line with exit
//! code 2.

mod common;

use lookdev::lab::{directional_albedo, in_plane, slice_directions, Subject};
use lookdev::material::library;
use lookdev::shading::brdf::Shading;
use lookdev::shading::model::Model;
use std::path::Path;
use std::process::{Command, Output};

fn lookdev(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lookdev")).args(args).env("LOOKDEV_VALIDATION", "1").output().unwrap()
}

fn run_ok(args: &[&str]) {
    let output = lookdev(args);
    assert!(output.status.success(), "{args:?}: {}", String::from_utf8_lossy(&output.stderr));
}

/// The CSV's rows: the subject, then numbers.
fn csv(path: &Path) -> Vec<(String, Vec<f32>)> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .map(|line| {
            let (subject, rest) = if let Some(quoted) = line.strip_prefix('"') {
                let end = quoted.find('"').unwrap();
                (quoted[..end].to_string(), &quoted[end + 2..])
            } else {
                let (a, b) = line.split_once(',').unwrap();
                (a.to_string(), b)
            };
            (subject, rest.split(',').map(|x| x.parse().unwrap()).collect())
        })
        .collect()
}

/// The subjects of a CSV's rows, in order, each once.
fn subjects(rows: &[(String, Vec<f32>)]) -> Vec<String> {
    let mut labels: Vec<String> = Vec::new();
    for (label, _) in rows {
        if !labels.contains(label) {
            labels.push(label.clone());
        }
    }
    labels
}

/// A line plot is an SVG document with one curve per subject (a 2-pixel polyline through every
/// one of its `points`), each subject's label as legend text, and the title.
fn assert_plot(path: &Path, title: &str, labels: &[String], points: usize) {
    let svg = std::fs::read_to_string(path).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{}", path.display());
    let curves = svg
        .split("<polyline")
        .skip(1)
        .map(|rest| &rest[..rest.find("/>").unwrap()])
        .filter(|tag| tag.contains(r#" stroke-width="2""#))
        .filter(|tag| {
            let start = tag.find(r#" points=""#).unwrap() + 9;
            tag[start..start + tag[start..].find('"').unwrap()].split_whitespace().count() == points
        })
        .count();
    assert_eq!(curves, labels.len(), "{}: curves", path.display());
    let texts: Vec<String> = svg
        .split("<text")
        .skip(1)
        .map(|rest| rest[rest.find('>').unwrap() + 1..rest.find("</text>").unwrap()].trim().replace("&amp;", "&"))
        .collect();
    for text in labels.iter().map(String::as_str).chain([title]) {
        assert!(texts.iter().any(|t| t == text), "{}: {text:?} not among {texts:?}", path.display());
    }
}

fn subject(preset: &str, text: &str) -> Subject {
    let mut model = Model::default();
    for part in text.split(',').filter(|p| !p.is_empty()) {
        model.set_from_text(part).unwrap();
    }
    let params = library::builtin(preset).unwrap().params;
    Subject { label: String::new(), params, shading: Shading::new(model, None) }
}

#[test]
fn albedo_and_polar_csvs_are_the_integrator_and_the_reference() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("albedo.svg");
    run_ok(&[
        "brdf",
        "albedo",
        "--preset",
        "red-plastic",
        "--preset",
        "gold",
        "--vs",
        "diffuse=oren-nayar,specular_d=beckmann",
        "--out",
        out.to_str().unwrap(),
    ]);
    let rows = csv(&dir.path().join("albedo.csv"));
    assert_eq!(rows.len(), 4 * 45);
    let labels = subjects(&rows);
    assert_eq!(labels.len(), 4);
    assert_plot(&out, "Directional albedo", &labels, 45);
    for (label, values) in rows.iter().step_by(7) {
        let preset = if label.starts_with("gold") { "gold" } else { "red-plastic" };
        let model = if label.contains("oren-nayar") { "diffuse=oren-nayar,specular_d=beckmann" } else { "" };
        let s = subject(preset, model);
        let theta = values[0].to_radians();
        let expected = directional_albedo(&s, theta);
        for c in 0..3 {
            assert!(
                (values[1 + c] - expected[c]).abs() <= 1e-6 * expected[c].max(1.0),
                "{label} {values:?} vs {expected}"
            );
        }
        // And an independent quadrature of the same BRDF.
        let reference = common::albedo::directional_albedo_with(&s.params, &s.shading, theta as f64);
        for c in 0..3 {
            let error = (values[1 + c] as f64 - reference[c]).abs() / reference[c].max(0.05);
            assert!(error < 3e-3, "{label} at {}°: {} vs quadrature {}", values[0], values[1 + c], reference[c]);
        }
    }

    let out = dir.path().join("polar.svg");
    run_ok(&[
        "brdf",
        "polar",
        "--preset",
        "gold",
        "--theta-i",
        "30",
        "--model",
        "fresnel=conductor",
        "--out",
        out.to_str().unwrap(),
    ]);
    let rows = csv(&dir.path().join("polar.csv"));
    assert_eq!(rows.len(), 179);
    assert_plot(&out, "In-plane lobe, θi = 30°", &subjects(&rows), 179);
    let s = subject("gold", "fresnel=conductor");
    let l = in_plane(-30f32.to_radians());
    let mut peak = (0.0f32, 0.0f32);
    for (_, values) in &rows {
        let f = s.brdf(l, in_plane(values[0].to_radians()));
        assert_eq!([values[1], values[2], values[3]], f.to_array(), "θo {}", values[0]);
        if values[4] > peak.1 {
            peak = (values[0], values[4]);
        }
    }
    // The lobe peaks in the mirror direction.
    assert!((peak.0 - 30.0).abs() <= 1.0, "peak at {}°", peak.0);
}

#[test]
fn slice_csv_is_the_reference_at_brdf_explorer_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("slice.png");
    run_ok(&[
        "brdf",
        "slice",
        "--preset",
        "gold",
        "--phi-d",
        "60",
        "--vs",
        "specular_g=burley2012",
        "--out",
        out.to_str().unwrap(),
    ]);
    let image = image::open(&out).unwrap();
    assert!(image.width() > 2 * 180 && image.height() >= 180);
    let rows = csv(&dir.path().join("slice.csv"));
    assert_eq!(rows.len(), 2 * 90 * 90);
    for (i, (label, values)) in rows.iter().enumerate().step_by(37) {
        let s = subject("gold", if label.contains("burley2012") { "specular_g=burley2012" } else { "" });
        let (l, v) = slice_directions(values[0].to_radians(), values[1].to_radians(), 60f32.to_radians());
        assert_eq!([values[2], values[3], values[4]], s.brdf(l, v).to_array(), "row {i}");
        // θh and θd are the angles of h and of l about h.
        let h = (l + v).normalize();
        let (theta_h, theta_d) = (h.z.min(1.0).acos().to_degrees(), l.dot(h).min(1.0).acos().to_degrees());
        assert!(
            (theta_h - values[0]).abs() < 0.1 && (theta_d - values[1]).abs() < 0.1,
            "row {i}: θh {theta_h} θd {theta_d} vs {values:?}"
        );
    }
}

#[test]
fn furnace_csv_rendered_matches_integrated() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("furnace.png");
    run_ok(&[
        "brdf",
        "furnace",
        "--set",
        "base_color=1",
        "--model",
        "energy_compensation=true",
        "--columns",
        "3",
        "--metallic",
        "0,1",
        "--size",
        "32",
        "--spp",
        "256",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(image::open(&out).is_ok());
    let text = std::fs::read_to_string(dir.path().join("furnace.csv")).unwrap();
    let rows: Vec<Vec<f32>> =
        text.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 6);
    for row in &rows {
        for c in 0..3 {
            let (rendered, integrated) = (row[2 + c], row[5 + c]);
            assert!((rendered - integrated).abs() < 0.03 * integrated, "{row:?}");
        }
        // A compensated white metal vanishes: it reflects 1.
        if row[1] == 1.0 {
            assert!((row[5] - 1.0).abs() < 0.01, "{row:?}");
        }
    }
}

#[test]
fn bad_plot_input_is_one_line_with_exit_code_2() {
    for (args, needle) in [
        (vec!["brdf", "albedo", "--out", "x.png"], "--out x.png: albedo plots are written as .svg"),
        (vec!["brdf", "slice", "--vs", "diffuse=lambret", "--out", "x.png"], "did you mean 'lambert'"),
        (vec!["brdf", "polar", "--theta-i", "95", "--out", "x.svg"], "--theta-i 95: must be in [0, 90)"),
        (vec!["brdf", "albedo", "--preset", "no-such", "--out", "x.svg"], "--preset no-such: no preset named"),
        (vec!["brdf", "furnace", "--metallic", "2", "--out", "x.png"], "--metallic: values must be in [0, 1]"),
        (vec!["brdf", "albedo", "--model", "gtr_gamma=99", "--out", "x.svg"], "out of range"),
        (
            vec!["render", "--model", "fresnel=exact", "--out", "x.png"],
            "--model fresnel=exact: fresnel = 'exact' is not a model",
        ),
        (vec!["render", "--model", "energy_compensation", "--out", "x.png"], "expected KEY=VALUE"),
    ] {
        let output = lookdev(&args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
}
