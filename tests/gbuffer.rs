//! G-buffer files: reading every sample type and compression, every error and fix-up, writing,
//! and the built-in shader ball.

use std::path::{Path, PathBuf};

use exr::prelude::*;
use lookdev::gbuffer::{stable_tangent, GBuffer, SourceOptions};
use lookdev::ErrorKind;

// ---------------------------------------------------------------------------------------------
// Helpers

/// A fresh path under the test's scratch folder.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("gbuffer-tests");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

/// One channel of a test file.
struct Channel {
    name: &'static str,
    samples: FlatSamples,
}

fn half(name: &'static str, values: impl IntoIterator<Item = f32>) -> Channel {
    Channel { name, samples: FlatSamples::F16(values.into_iter().map(f16::from_f32).collect()) }
}

fn float(name: &'static str, values: impl IntoIterator<Item = f32>) -> Channel {
    Channel { name, samples: FlatSamples::F32(values.into_iter().collect()) }
}

fn uint(name: &'static str, values: impl IntoIterator<Item = u32>) -> Channel {
    Channel { name, samples: FlatSamples::U32(values.into_iter().collect()) }
}

fn layer(
    size: (usize, usize),
    channels: Vec<Channel>,
    compression: Compression,
    attributes: &[(&str, AttributeValue)],
) -> Layer<AnyChannels<FlatSamples>> {
    let list: Vec<AnyChannel<FlatSamples>> = channels.into_iter().map(|c| AnyChannel::new(c.name, c.samples)).collect();
    let mut layer_attributes = LayerAttributes::default();
    for (name, value) in attributes {
        layer_attributes.other.insert(Text::from(*name), value.clone());
    }
    let encoding = Encoding { compression, blocks: Blocks::ScanLines, line_order: LineOrder::Increasing };
    Layer::new(size, layer_attributes, encoding, AnyChannels::sort(SmallVec::from_vec(list)))
}

fn write_exr(
    path: &Path,
    size: (usize, usize),
    channels: Vec<Channel>,
    compression: Compression,
    attributes: &[(&str, AttributeValue)],
) {
    Image::from_layer(layer(size, channels, compression, attributes)).write().to_file(path).unwrap();
}

/// A little scene: a disc of sphere normals on an empty background, `size` pixels wide.
struct Disc {
    width: usize,
    height: usize,
    normal: Vec<[f32; 3]>,
}

impl Disc {
    fn new(width: usize, height: usize) -> Disc {
        let mut normal = Vec::new();
        for y in 0..height {
            for x in 0..width {
                let u = (x as f32 + 0.5) / width as f32 * 2.0 - 1.0;
                let v = 1.0 - (y as f32 + 0.5) / height as f32 * 2.0;
                let r2 = u * u + v * v;
                normal.push(if r2 < 0.8 { [u, v, (1.0 - r2).sqrt()] } else { [0.0; 3] });
            }
        }
        Disc { width, height, normal }
    }

    fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    fn covered(&self, i: usize) -> bool {
        self.normal[i] != [0.0; 3]
    }

    fn normal_channels(&self, make: fn(&'static str, Vec<f32>) -> Channel) -> Vec<Channel> {
        ["N.X", "N.Y", "N.Z"]
            .into_iter()
            .enumerate()
            .map(|(axis, name)| make(name, self.normal.iter().map(|n| n[axis]).collect()))
            .collect()
    }

    fn half_normals(&self) -> Vec<Channel> {
        self.normal_channels(half)
    }

    fn float_normals(&self) -> Vec<Channel> {
        self.normal_channels(float)
    }

    fn coverage(&self) -> Vec<f32> {
        (0..self.normal.len()).map(|i| if self.covered(i) { 1.0 } else { 0.0 }).collect()
    }

    /// IDs 1 and 2 on the left and right halves of the disc.
    fn ids(&self) -> Vec<u32> {
        (0..self.normal.len())
            .map(|i| match (self.covered(i), i % self.width < self.width / 2) {
                (false, _) => 0,
                (true, true) => 1,
                (true, false) => 2,
            })
            .collect()
    }

    /// A smooth ramp in [0,1] across the image.
    fn ramp(&self) -> Vec<f32> {
        (0..self.normal.len()).map(|i| (i % self.width) as f32 / (self.width - 1) as f32).collect()
    }
}

fn read_ok(path: &Path) -> (GBuffer, Vec<String>) {
    match GBuffer::read_with_warnings(path) {
        Ok(result) => result,
        Err(e) => panic!("{}: unexpected error: {e}", path.display()),
    }
}

/// Reads a file that must fail, and checks the error is one input error line naming the file and
/// containing every one of `phrases`.
fn read_err(path: &Path, phrases: &[&str]) -> String {
    let error = match GBuffer::read_with_warnings(path) {
        Ok(_) => panic!("{} was accepted", path.display()),
        Err(e) => e,
    };
    let message = error.to_string();
    assert_eq!(error.kind, ErrorKind::Input, "{message}");
    assert_eq!(error.exit_code(), 2);
    assert!(!error.message.contains('\n'), "more than one line: {message:?}");
    assert!(message.starts_with(&format!("{}: ", path.display())), "file not named: {message}");
    for phrase in phrases {
        assert!(message.contains(phrase), "{message:?} lacks {phrase:?}");
    }
    message
}

fn assert_close(a: [f32; 3], b: [f32; 3], tolerance: f32, what: &str) {
    let distance = (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f32>().sqrt();
    assert!(distance <= tolerance, "{what}: {a:?} vs {b:?}");
}

fn assert_vectors_close(a: &[[f32; 3]], b: &[[f32; 3]], tolerance: f32, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    for (i, (a, b)) in a.iter().zip(b).enumerate() {
        assert_close(*a, *b, tolerance, &format!("{what} at pixel {i}"));
    }
}

fn length(v: [f32; 3]) -> f32 {
    v.iter().map(|c| c * c).sum::<f32>().sqrt()
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(v: [f32; 3]) -> [f32; 3] {
    let l = length(v);
    v.map(|c| c / l)
}

// ---------------------------------------------------------------------------------------------
// Sample types and compressions

const COMPRESSIONS: [Compression; 10] = [
    Compression::Uncompressed,
    Compression::RLE,
    Compression::ZIP1,
    Compression::ZIP16,
    Compression::PIZ,
    Compression::PXR24,
    Compression::B44,
    Compression::B44A,
    Compression::DWAA(None),
    Compression::DWAB(None),
];

/// How far a compression may move a half sample of a smooth image: B44 packs 4×4 blocks of
/// halves into 14 bytes; the others keep halves exactly (DWA's lossy DCT only takes channels
/// named like colours, and `A` is run-length coded).
fn half_tolerance(compression: Compression) -> f32 {
    match compression {
        Compression::B44 | Compression::B44A => 0.03,
        _ => 1e-3,
    }
}

/// How far a unit vector may move: DWA treats any channel ending in `.Y` as luminance and
/// quantises its DCT, so N.Y, V.Y and T.Y are lossy there, whatever their sample type.
fn vector_tolerance(compression: Compression, sample_tolerance: f32) -> f32 {
    match compression {
        Compression::DWAA(_) | Compression::DWAB(_) => sample_tolerance.max(0.01),
        _ => sample_tolerance,
    }
}

fn is_b44(compression: Compression) -> bool {
    matches!(compression, Compression::B44 | Compression::B44A)
}

#[test]
fn reads_half_normals_float_ids_and_masks_under_every_compression() {
    // Odd sizes put partial blocks at the right and bottom edges.
    let disc = Disc::new(37, 41);
    for compression in COMPRESSIONS {
        let path = scratch(&format!("half-{compression}.exr"));
        let mut channels = disc.half_normals();
        channels.push(half("A", disc.coverage()));
        channels.push(float("objectId", disc.ids().into_iter().map(|id| id as f32)));
        channels.push(half("mask.ramp", disc.ramp()));
        write_exr(&path, disc.size(), channels, compression, &[]);

        let (g, warnings) = read_ok(&path);
        assert_eq!((g.width, g.height), (37, 41), "{compression}");
        if !is_b44(compression) {
            assert!(warnings.is_empty(), "{compression}: {warnings:?}");
        }
        let tolerance = half_tolerance(compression);
        let normal_tolerance = vector_tolerance(compression, 2.0 * tolerance);
        for i in 0..g.pixel_count() {
            assert!((length(g.normal[i]) - 1.0).abs() < 1e-5, "{compression}: pixel {i}");
            if disc.covered(i) {
                assert_close(g.normal[i], unit(disc.normal[i]), normal_tolerance, &format!("{compression} N"));
            }
            assert!((g.coverage[i] - disc.coverage()[i]).abs() <= tolerance, "{compression} A");
            assert!((g.masks["ramp"][i] - disc.ramp()[i]).abs() <= tolerance, "{compression} mask");
        }
        assert_eq!(g.object_id, disc.ids(), "{compression}");
        assert!(!g.has_view && !g.has_tangent);
    }
}

#[test]
fn reads_float_normals_uint_ids_and_half_views_under_every_compression() {
    let disc = Disc::new(40, 33);
    let view: Vec<[f32; 3]> = disc.normal.iter().map(|n| unit([n[0] * 0.3, 0.2, 1.0])).collect();
    let tangent: Vec<[f32; 3]> = disc.normal.iter().map(|&n| stable_tangent(unit_or_z(n))).collect();
    for compression in COMPRESSIONS {
        let path = scratch(&format!("float-{compression}.exr"));
        let mut channels = disc.float_normals();
        channels.push(float("A", disc.coverage()));
        channels.push(uint("objectId", disc.ids()));
        for (axis, name) in ["V.X", "V.Y", "V.Z"].into_iter().enumerate() {
            channels.push(half(name, view.iter().map(|v| v[axis])));
        }
        for (axis, name) in ["T.X", "T.Y", "T.Z"].into_iter().enumerate() {
            channels.push(float(name, tangent.iter().map(|t| t[axis])));
        }
        write_exr(&path, disc.size(), channels, compression, &[]);

        let (g, _) = read_ok(&path);
        assert!(g.has_view && g.has_tangent, "{compression}");
        assert_eq!(g.object_id, disc.ids(), "{compression}");
        let view_tolerance = vector_tolerance(compression, 2.0 * half_tolerance(compression));
        // PXR24 keeps 24 of a float's 32 bits.
        let float_tolerance = vector_tolerance(compression, 1e-4);
        for i in 0..g.pixel_count() {
            if disc.covered(i) {
                assert_close(g.normal[i], unit(disc.normal[i]), float_tolerance, &format!("{compression} N"));
                assert_close(g.tangent[i], tangent[i], float_tolerance, &format!("{compression} T"));
            }
            assert_close(g.view[i], view[i], view_tolerance, &format!("{compression} V"));
            assert!(dot(g.tangent[i], g.normal[i]).abs() < 1e-5);
        }
    }
}

fn unit_or_z(n: [f32; 3]) -> [f32; 3] {
    if length(n) > 0.5 {
        unit(n)
    } else {
        [0.0, 0.0, 1.0]
    }
}

#[test]
fn tiled_files_read_like_scan_line_files() {
    let disc = Disc::new(70, 45);
    let path = scratch("tiled.exr");
    let channels: Vec<AnyChannel<FlatSamples>> =
        disc.half_normals().into_iter().map(|c| AnyChannel::new(c.name, c.samples)).collect();
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::Tiles(Vec2(16, 16)),
        line_order: LineOrder::Increasing,
    };
    let layer =
        Layer::new(disc.size(), LayerAttributes::default(), encoding, AnyChannels::sort(SmallVec::from_vec(channels)));
    Image::from_layer(layer).write().to_file(&path).unwrap();
    let (g, _) = read_ok(&path);
    for i in 0..g.pixel_count() {
        if disc.covered(i) {
            assert_close(g.normal[i], unit(disc.normal[i]), 2e-3, "tiled N");
        }
    }
}

/// The shared studio environment is a real DWAB file (RGB, not a g-buffer): it must decode and
/// then be refused for its missing normals, with the channels it does have listed.
#[test]
fn real_dwab_file_without_normals_is_refused_clearly() {
    let path = Path::new("/work/shared/hdri/studio.exr");
    if !path.exists() {
        eprintln!("skipped: {} is not on this machine", path.display());
        return;
    }
    let meta = MetaData::read_from_file(path, false).unwrap();
    assert!(matches!(meta.headers[0].compression, Compression::DWAB(_)));
    read_err(path, &["missing normal channels N.X, N.Y, N.Z", "channels found: ", "R", "G", "B"]);
}

// ---------------------------------------------------------------------------------------------
// Errors

#[test]
fn missing_file_is_an_input_error() {
    let path = scratch("does-not-exist.exr");
    read_err(&path, &["file not found"]);
}

#[test]
fn a_folder_is_not_a_file() {
    let path = scratch("a-folder.exr");
    let _ = std::fs::remove_dir(&path);
    std::fs::create_dir(&path).unwrap();
    read_err(&path, &["not a regular file (a folder)"]);
}

#[test]
fn garbage_and_truncated_files_are_errors_not_panics() {
    let garbage = scratch("garbage.exr");
    std::fs::write(&garbage, b"this is not an OpenEXR file\nsecond line\n").unwrap();
    read_err(&garbage, &["not a readable OpenEXR file ("]);

    let disc = Disc::new(64, 64);
    let whole = scratch("whole.exr");
    write_exr(&whole, disc.size(), disc.float_normals(), Compression::ZIP16, &[]);
    let bytes = std::fs::read(&whole).unwrap();
    for keep in [bytes.len() / 2, bytes.len() - 7, 40, 4] {
        let truncated = scratch(&format!("truncated-{keep}.exr"));
        std::fs::write(&truncated, &bytes[..keep]).unwrap();
        read_err(&truncated, &["not a readable OpenEXR file ("]);
    }
}

#[test]
fn multi_part_files_of_several_images_need_a_part_chosen() {
    let disc = Disc::new(8, 8);
    let path = scratch("two-parts.exr");
    let mut first = layer(disc.size(), disc.half_normals(), Compression::ZIP16, &[]);
    first.attributes.layer_name = Some(Text::from("one"));
    let mut second = layer(disc.size(), disc.half_normals(), Compression::ZIP16, &[]);
    second.attributes.layer_name = Some(Text::from("two"));
    Image::from_layers(ImageAttributes::new(IntegerBounds::from_dimensions(disc.size())), vec![first, second])
        .write()
        .to_file(&path)
        .unwrap();
    read_err(&path, &["several parts have the channel N.X", "choose a part with --gbuffer-layer (parts: one, two)"]);
    let options = SourceOptions { layer: Some("two".into()), ..SourceOptions::default() };
    let read = GBuffer::read_with(&path, &options).expect("--gbuffer-layer chooses a part");
    assert_eq!(read.detected.layer.as_deref(), Some("two"));
    assert_eq!(read.gbuffer.width, 8);
}

#[test]
fn missing_normals_name_what_is_missing_and_what_was_found() {
    let disc = Disc::new(8, 8);
    let path = scratch("no-nz.exr");
    let mut channels = disc.half_normals();
    channels.pop();
    channels.push(half("A", disc.coverage()));
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    read_err(&path, &["missing normal channel N.Z", "channels found: A, N.X, N.Y"]);
}

#[test]
fn partial_optional_triples_are_errors() {
    let disc = Disc::new(8, 8);
    for (prefix, what) in [("V", "view"), ("T", "tangent")] {
        let path = scratch(&format!("partial-{prefix}.exr"));
        let mut channels = disc.half_normals();
        let x: &'static str = if prefix == "V" { "V.X" } else { "T.X" };
        channels.push(half(x, vec![1.0; 64]));
        write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
        read_err(&path, &[&format!("incomplete {what} channels"), &format!("has {prefix}.X")]);
    }
}

#[test]
fn non_finite_normals_at_covered_pixels_are_counted_and_located() {
    let disc = Disc::new(10, 10);
    let mut normal = disc.normal.clone();
    normal[5 * 10 + 4] = [f32::NAN, 0.0, 1.0]; // covered: x = 4, y = 5
    normal[6 * 10 + 5] = [0.0, f32::INFINITY, 1.0]; // covered
    normal[0] = [f32::NAN; 3]; // background, since A = 0 there
    let mut coverage = disc.coverage();
    coverage[0] = 0.0;
    let path = scratch("nan-normals.exr");
    let mut channels: Vec<Channel> =
        (0..3).map(|axis| float(["N.X", "N.Y", "N.Z"][axis], normal.iter().map(|n| n[axis]))).collect();
    channels.push(half("A", coverage));
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    read_err(&path, &["NaN/Inf normals at 2 covered pixels", "first at x=4, y=5"]);

    // Without A, a NaN normal cannot be judged empty, so it is reported, not dropped.
    let path = scratch("nan-normals-no-a.exr");
    let channels: Vec<Channel> =
        (0..3).map(|axis| float(["N.X", "N.Y", "N.Z"][axis], normal.iter().map(|n| n[axis]))).collect();
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    read_err(&path, &["NaN/Inf normals at 3 pixels", "first at x=0, y=0"]);
}

#[test]
fn short_normals_where_a_says_covered_are_errors() {
    let disc = Disc::new(10, 10);
    let mut coverage = disc.coverage();
    coverage[0] = 0.5; // background pixel (zero normal) claimed as covered
    coverage[1] = 1.0;
    let path = scratch("short-normals.exr");
    let mut channels = disc.half_normals();
    channels.push(half("A", coverage));
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    read_err(&path, &["normals shorter than 0.5 where coverage A > 0, at 2 pixels", "x=0, y=0"]);
}

#[test]
fn bad_view_vectors_anywhere_are_errors() {
    let disc = Disc::new(10, 10);
    let mut view = vec![[0.0, 0.0, 1.0]; 100];
    view[99] = [0.0, 0.0, 0.0]; // background: V matters there too
    view[12] = [f32::NAN, 0.0, 1.0];
    let path = scratch("bad-views.exr");
    let mut channels = disc.half_normals();
    for (axis, name) in ["V.X", "V.Y", "V.Z"].into_iter().enumerate() {
        channels.push(float(name, view.iter().map(|v| v[axis])));
    }
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    read_err(&path, &["NaN/Inf or zero-length view vectors V at 2 pixels", "x=2, y=1"]);
}

#[test]
fn non_finite_coverage_and_masks_are_errors_naming_the_channel() {
    let disc = Disc::new(10, 10);
    let mut coverage = disc.coverage();
    coverage[3] = f32::NAN;
    let path = scratch("nan-coverage.exr");
    let mut channels = disc.half_normals();
    channels.push(float("A", coverage));
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    read_err(&path, &["channel A has 1 NaN/Inf value ", "x=3, y=0"]);

    let mut mask = disc.ramp();
    mask[50] = f32::INFINITY;
    mask[51] = f32::NEG_INFINITY;
    let path = scratch("nan-mask.exr");
    let mut channels = disc.half_normals();
    channels.push(half("mask.rust", mask));
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    read_err(&path, &["channel mask.rust has 2 NaN/Inf values", "x=0, y=5"]);
}

#[test]
fn maps_are_read_as_colour_and_scalar_maps_in_half_or_float() {
    let disc = Disc::new(10, 10);
    let ramp = disc.ramp();
    let mut channels = disc.half_normals();
    channels.push(half("map.baseColor.R", ramp.clone()));
    channels.push(float("map.baseColor.G", ramp.iter().map(|v| 1.0 - v)));
    channels.push(half("map.baseColor.B", vec![0.25; 100]));
    channels.push(float("map.rough", ramp.iter().map(|v| v * 0.5)));
    // Two channels of a trio are two scalar maps, not a colour map.
    channels.push(half("map.partial.R", vec![0.5; 100]));
    channels.push(half("map.partial.G", vec![0.5; 100]));
    let path = scratch("maps.exr");
    write_exr(&path, disc.size(), channels, Compression::PIZ, &[]);
    let (g, warnings) = read_ok(&path);
    assert!(warnings.is_empty(), "{warnings:?}");
    let names: Vec<String> = g.maps().iter().map(|m| m.to_string()).collect();
    assert_eq!(names, ["map.baseColor.R/G/B", "map.partial.G", "map.partial.R", "map.rough"]);
    assert!((g.maps["baseColor.R"][9] - 1.0).abs() < 1e-3 && g.maps["baseColor.G"][9].abs() < 1e-6);
    assert_eq!(g.maps["rough"][9], 0.5);
    use lookdev::gbuffer::MapSource;
    let trio = ["baseColor.R", "baseColor.G", "baseColor.B"].map(String::from);
    assert_eq!(g.map_source("baseColor"), Some(MapSource::Color(trio)));
    assert_eq!(g.map_source("baseColor.G"), Some(MapSource::Channel("baseColor.G".into())));
    assert_eq!(g.map_source("rough"), Some(MapSource::Channel("rough".into())));
    assert_eq!(g.map_source("partial"), None);
    assert_eq!(g.layer_channel("map.rough").map(|v| v[9]), Some(0.5));
    assert_eq!(g.map_list(), "map.baseColor.R/G/B, map.partial.G, map.partial.R, map.rough");
}

#[test]
fn maps_no_look_could_name_are_left_out_with_a_warning() {
    let disc = Disc::new(4, 4);
    let mut channels = disc.half_normals();
    channels.push(half("map.map.rough", vec![0.5; 16]));
    channels.push(half("map. padded", vec![0.5; 16]));
    channels.push(half("map.fine", vec![0.5; 16]));
    let path = scratch("odd-map-names.exr");
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    let (g, warnings) = read_ok(&path);
    assert_eq!(g.maps.keys().collect::<Vec<_>>(), ["fine"]);
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert!(warnings
        .iter()
        .any(|w| w.contains("ignored channel map.map.rough") && w.contains("without the channel prefix")));
    assert!(warnings.iter().any(|w| w.contains("ignored channel map. padded") && w.contains("spaces")));
}

#[test]
fn non_finite_maps_are_errors_and_out_of_range_maps_are_clamped_with_a_count() {
    let disc = Disc::new(10, 10);
    let mut map = disc.ramp();
    map[12] = f32::NAN;
    map[13] = f32::NAN;
    map[14] = f32::INFINITY;
    let path = scratch("nan-map.exr");
    let mut channels = disc.half_normals();
    channels.push(float("map.albedo.G", map));
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    read_err(&path, &["channel map.albedo.G has 3 NaN/Inf values", "x=2, y=1"]);

    let mut map = disc.ramp();
    map[0] = 1.5;
    map[1] = -0.5;
    map[2] = 7.0;
    let path = scratch("clamped-map.exr");
    let mut channels = disc.half_normals();
    channels.push(float("map.rough", map));
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    let (g, warnings) = read_ok(&path);
    assert_eq!(&g.maps["rough"][..3], &[1.0, 0.0, 1.0]);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("clamped 3 values of channel map.rough into [0,1]"), "{warnings:?}");
}

#[test]
fn object_ids_must_be_non_negative_integers() {
    let disc = Disc::new(10, 10);
    let mut ids: Vec<f32> = disc.ids().into_iter().map(|id| id as f32).collect();
    ids[7] = 1.5;
    ids[8] = -2.0;
    ids[9] = f32::NAN;
    for (name, channel) in [("float", float("objectId", ids.clone())), ("half", half("objectId", ids.clone()))] {
        let path = scratch(&format!("bad-ids-{name}.exr"));
        let mut channels = disc.half_normals();
        channels.push(channel);
        write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
        read_err(&path, &["objectId holds 3 values other than non-negative integers", "x=7, y=0"]);
    }
}

#[test]
fn empty_images_are_refused() {
    // The exr crate refuses to write an image without pixels, so make one by hand: a valid 1×1
    // file whose data window is rewritten to be empty (max < min). The crate reads such a window
    // with its corners swapped and then finds the pixel data inconsistent, so the file is refused
    // as unreadable; the g-buffer's own "empty image" check is unit-tested in `validate`.
    let path = scratch("empty.exr");
    write_exr(
        &path,
        (1, 1),
        vec![half("N.X", [0.0]), half("N.Y", [0.0]), half("N.Z", [1.0])],
        Compression::Uncompressed,
        &[],
    );
    let mut bytes = std::fs::read(&path).unwrap();
    let tag = b"dataWindow\0box2i\0";
    let at = bytes.windows(tag.len()).position(|w| w == tag).unwrap() + tag.len() + 4;
    // box2i: xMin, yMin, xMax, yMax (i32, little endian); xMax = -1 leaves no columns.
    bytes[at + 8..at + 12].copy_from_slice(&(-1i32).to_le_bytes());
    std::fs::write(&path, bytes).unwrap();
    let message = read_err(&path, &[]);
    assert!(message.contains("empty image") || message.contains("not a readable OpenEXR file"), "{message}");
}

// ---------------------------------------------------------------------------------------------
// Fix-ups and defaults

#[test]
fn off_length_normals_are_renormalised_with_one_warning() {
    let disc = Disc::new(12, 12);
    let mut normal = disc.normal.clone();
    let covered: Vec<usize> = (0..normal.len()).filter(|&i| disc.covered(i)).collect();
    for &i in &covered[..3] {
        normal[i] = normal[i].map(|c| c * 0.8);
    }
    normal[covered[3]] = normal[covered[3]].map(|c| c * 1.005); // within 1%: silent
    let path = scratch("renormalise.exr");
    let channels: Vec<Channel> =
        (0..3).map(|axis| float(["N.X", "N.Y", "N.Z"][axis], normal.iter().map(|n| n[axis]))).collect();
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    let (g, warnings) = read_ok(&path);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].starts_with(&format!("{}: ", path.display())));
    assert!(warnings[0].contains("renormalised 3 normals"), "{}", warnings[0]);
    for &i in &covered {
        assert!((length(g.normal[i]) - 1.0).abs() < 1e-6);
        assert_close(g.normal[i], unit(disc.normal[i]), 1e-6, "renormalised N");
    }
}

#[test]
fn coverage_and_masks_outside_the_unit_interval_are_clamped_with_warnings() {
    let disc = Disc::new(10, 10);
    let mut coverage = disc.coverage();
    coverage[44] = 1.5;
    coverage[45] = -0.25;
    let mut mask = disc.ramp();
    mask[0] = 2.0;
    let path = scratch("clamp.exr");
    let mut channels = disc.half_normals();
    channels.push(half("A", coverage));
    channels.push(half("mask.dirt", mask));
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    let (g, warnings) = read_ok(&path);
    assert_eq!(g.coverage[44], 1.0);
    assert_eq!(g.coverage[45], 0.0);
    assert_eq!(g.masks["dirt"][0], 1.0);
    let joined = warnings.join("\n");
    assert!(joined.contains("clamped 2 values of channel A into [0,1]"), "{joined}");
    assert!(joined.contains("clamped 1 value of channel mask.dirt into [0,1]"), "{joined}");
    assert!(warnings.iter().all(|w| w.starts_with(&format!("{}: ", path.display())) && !w.contains('\n')));
}

#[test]
fn degenerate_tangents_take_the_stable_frame_and_others_are_made_orthogonal() {
    let disc = Disc::new(10, 10);
    let covered: Vec<usize> = (0..100).filter(|&i| disc.covered(i)).collect();
    // A tangent with a component along N, which Gram–Schmidt must remove.
    let mut tangent: Vec<[f32; 3]> = disc.normal.iter().map(|n| [1.0 + 0.3 * n[0], 0.3 * n[1], 0.3 * n[2]]).collect();
    tangent[covered[0]] = [0.0; 3];
    tangent[covered[1]] = [f32::NAN, 0.0, 0.0];
    tangent[covered[2]] = disc.normal[covered[2]].map(|c| -2.0 * c);
    tangent[0] = [0.0; 3]; // background: replaced, but not counted
    let path = scratch("tangents.exr");
    let mut channels = disc.float_normals();
    for (axis, name) in ["T.X", "T.Y", "T.Z"].into_iter().enumerate() {
        channels.push(float(name, tangent.iter().map(|t| t[axis])));
    }
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    let (g, warnings) = read_ok(&path);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("replaced 3 tangents"), "{}", warnings[0]);
    assert!(g.has_tangent);
    for i in 0..100 {
        let (n, t) = (g.normal[i], g.tangent[i]);
        assert!((length(t) - 1.0).abs() < 1e-5 && dot(n, t).abs() < 1e-5, "pixel {i}");
    }
    for &i in &covered[..3] {
        assert_eq!(g.tangent[i], stable_tangent(g.normal[i]));
    }
    let i = covered[10];
    let n = g.normal[i];
    let t = tangent[i];
    let expected = unit([0, 1, 2].map(|k| t[k] - dot(n, t) * n[k]));
    assert_close(g.tangent[i], expected, 1e-5, "Gram–Schmidt");
}

#[test]
fn defaults_for_a_file_with_only_normals() {
    let disc = Disc::new(9, 7);
    let path = scratch("normals-only.exr");
    write_exr(&path, disc.size(), disc.half_normals(), Compression::ZIP16, &[]);
    let (g, warnings) = read_ok(&path);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!(!g.has_view && !g.has_tangent);
    assert!(g.masks.is_empty() && g.object_names.is_empty());
    assert_eq!(g.pixel_count(), 63);
    for i in 0..g.pixel_count() {
        assert_eq!(g.view[i], [0.0, 0.0, 1.0]);
        assert_eq!(g.object_id[i], 0);
        assert_eq!(g.coverage[i], if disc.covered(i) { 1.0 } else { 0.0 });
        assert_eq!(g.tangent[i], stable_tangent(g.normal[i]));
        if !disc.covered(i) {
            assert_eq!(g.normal[i], [0.0, 0.0, 1.0], "placeholder normal");
        }
    }
}

#[test]
fn unknown_channels_are_ignored() {
    let disc = Disc::new(6, 6);
    let path = scratch("extra-channels.exr");
    let mut channels = disc.half_normals();
    channels.push(half("R", vec![0.5; 36]));
    channels.push(float("depth.Z", vec![f32::NAN; 36]));
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
    let (g, warnings) = read_ok(&path);
    assert!(warnings.is_empty() && g.masks.is_empty());
}

#[test]
fn object_names_come_from_header_attributes() {
    let disc = Disc::new(6, 6);
    let path = scratch("names.exr");
    let utf8 = Text::from_slice_unchecked("théière".as_bytes());
    let attributes = [
        ("objectName.1", AttributeValue::Text(Text::from("ball"))),
        ("objectName.42", AttributeValue::Text(utf8)),
        ("objectName.x", AttributeValue::Text(Text::from("nope"))),
        ("objectName.3", AttributeValue::I32(3)),
        ("owner.note", AttributeValue::Text(Text::from("unrelated"))),
    ];
    let mut channels = disc.half_normals();
    channels.push(uint("objectId", disc.ids()));
    write_exr(&path, disc.size(), channels, Compression::ZIP16, &attributes);
    let (g, warnings) = read_ok(&path);
    assert_eq!(g.object_names.len(), 2);
    assert_eq!(g.object_names[&1], "ball");
    assert_eq!(g.object_names[&42], "théière");
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert!(warnings.iter().any(|w| w.contains("objectName.x")));
    assert!(warnings.iter().any(|w| w.contains("objectName.3") && w.contains("not a text")));
}

// ---------------------------------------------------------------------------------------------
// Writing

#[test]
fn write_then_read_reproduces_the_shaderball() {
    let original = GBuffer::shaderball(64, 48);
    let path = scratch("round-trip.exr");
    original.write(&path).unwrap();
    let (g, warnings) = read_ok(&path);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!((g.width, g.height), (64, 48));
    // Float channels come back exactly; reading renormalises, which may move the last bit.
    assert_vectors_close(&g.normal, &original.normal, 1e-6, "N");
    assert_vectors_close(&g.view, &original.view, 1e-6, "V");
    assert_vectors_close(&g.tangent, &original.tangent, 1e-6, "T");
    assert_eq!(g.object_id, original.object_id);
    assert_eq!(g.object_names, original.object_names);
    assert_eq!((g.has_view, g.has_tangent), (true, true));
    // A and masks are stored as half: 11 significant bits.
    let close = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 5e-4);
    assert!(close(&g.coverage, &original.coverage));
    assert_eq!(g.masks.keys().collect::<Vec<_>>(), original.masks.keys().collect::<Vec<_>>());
    for (name, mask) in &original.masks {
        assert!(close(&g.masks[name], mask), "mask {name}");
    }
    assert!(g.maps.is_empty());
    let meta = MetaData::read_from_file(&path, false).unwrap();
    assert_eq!(meta.headers.len(), 1);
    assert_eq!(meta.headers[0].compression, Compression::ZIP16);
}

#[test]
fn maps_are_written_as_half_and_read_back() {
    let mut original = GBuffer::shaderball(32, 32);
    let pixels = original.pixel_count();
    let ramp: Vec<f32> = (0..pixels).map(|i| i as f32 / (pixels - 1) as f32).collect();
    for (k, channel) in ["R", "G", "B"].into_iter().enumerate() {
        original.maps.insert(format!("tex.{channel}"), ramp.iter().map(|v| (v + k as f32 * 0.25) % 1.0).collect());
    }
    original.maps.insert("rough".into(), ramp.iter().map(|v| 1.0 - v).collect());
    let path = scratch("maps-round-trip.exr");
    original.write(&path).unwrap();
    let (g, warnings) = read_ok(&path);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(g.maps.keys().collect::<Vec<_>>(), original.maps.keys().collect::<Vec<_>>());
    for (name, map) in &original.maps {
        assert!(g.maps[name].iter().zip(map).all(|(a, b)| (a - b).abs() <= 5e-4), "map {name}");
    }
    let meta = MetaData::read_from_file(&path, false).unwrap();
    let channels = &meta.headers[0].channels.list;
    let rough = channels.iter().find(|c| c.name.eq("map.rough")).expect("map.rough written");
    assert_eq!(rough.sample_type, SampleType::F16);
    assert!(channels.iter().any(|c| c.name.eq("map.tex.G")));
}

#[test]
fn write_leaves_out_view_and_tangent_when_absent_and_replaces_atomically() {
    let disc = Disc::new(8, 8);
    let source = scratch("minimal-source.exr");
    write_exr(&source, disc.size(), disc.half_normals(), Compression::ZIP16, &[]);
    let (mut g, _) = read_ok(&source);
    g.object_names.insert(5, "thing".to_string());
    g.masks.insert("ramp".to_string(), disc.ramp());

    let path = scratch("minimal.exr");
    std::fs::write(&path, b"an older file to be replaced").unwrap();
    g.write(&path).unwrap();
    let meta = MetaData::read_from_file(&path, false).unwrap();
    let names: Vec<String> = meta.headers[0].channels.list.iter().map(|c| c.name.to_string()).collect();
    assert_eq!(names, ["A", "N.X", "N.Y", "N.Z", "mask.ramp", "objectId"]);
    let (back, _) = read_ok(&path);
    assert_vectors_close(&back.normal, &g.normal, 1e-6, "N");
    assert_eq!(back.object_names, g.object_names);
    assert!(!back.has_view && !back.has_tangent);

    // No temporary file is left beside it.
    let folder = path.parent().unwrap();
    let leftovers: Vec<_> = std::fs::read_dir(folder)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with(".minimal.exr"))
        .collect();
    assert!(leftovers.is_empty());
}

#[test]
fn write_failures_are_io_errors_naming_the_file() {
    let g = GBuffer::shaderball(8, 8);
    let path = scratch("no-such-folder").join("out.exr");
    let error = g.write(&path).unwrap_err();
    assert_eq!(error.kind, ErrorKind::Io);
    assert!(error.to_string().starts_with(&path.display().to_string()), "{error}");

    let mut broken = g.clone();
    broken.coverage.pop();
    let error = broken.write(&scratch("broken.exr")).unwrap_err();
    assert!(error.to_string().contains("coverage has 63 entries for 8x8 pixels"), "{error}");
}

// ---------------------------------------------------------------------------------------------
// The shader ball

const SIZE: u32 = 255; // odd, so one pixel sits on the optical axis

fn shaderball() -> GBuffer {
    GBuffer::shaderball(SIZE, SIZE)
}

#[test]
fn shaderball_fills_the_frame_with_two_named_objects() {
    let g = shaderball();
    let n = g.pixel_count() as f32;
    let coverage: f32 = g.coverage.iter().sum::<f32>() / n;
    assert!(coverage > 0.4 && coverage < 0.6, "coverage {coverage}");
    let count = |id| g.object_id.iter().filter(|&&i| i == id).count() as f32 / n;
    assert!(count(1) > 0.3, "ball {}", count(1));
    assert!(count(2) > 0.03, "pedestal {}", count(2));
    assert_eq!(g.object_names.get(&1).map(String::as_str), Some("ball"));
    assert_eq!(g.object_names.get(&2).map(String::as_str), Some("pedestal"));
    assert!(g.has_view && g.has_tangent);
    for i in 0..g.pixel_count() {
        // Background is object 0; every covered pixel belongs to an object.
        assert_eq!(g.coverage[i] == 0.0, g.object_id[i] == 0, "pixel {i}");
    }
}

#[test]
fn shaderball_directions_are_unit_and_tangents_orthogonal() {
    let g = shaderball();
    for i in 0..g.pixel_count() {
        let (n, t, v) = (g.normal[i], g.tangent[i], g.view[i]);
        assert!((length(n) - 1.0).abs() < 1e-5, "N at {i}");
        assert!((length(t) - 1.0).abs() < 1e-5, "T at {i}");
        assert!((length(v) - 1.0).abs() < 1e-5, "V at {i}");
        assert!(dot(n, t).abs() < 1e-5, "T.N at {i}");
        if g.coverage[i] == 1.0 {
            assert!(dot(n, v) > -1e-3, "back-facing normal at {i}");
        }
    }
}

/// The pedestal is cylinders and their flat caps, so every normal below the ball is horizontal
/// (a side) or vertical (a cap). A pixel where two surfaces meet (the crease of the neck and the
/// foot's top, the neck's silhouette against the foot) takes one surface's normal: an average
/// of the two is a surface that is not there, and at 1024² it lit a bright one-pixel seam along
/// row 910 and specks at (368–370, 887–889).
#[test]
fn shaderball_pedestal_normals_are_its_surfaces_even_at_creases() {
    for size in [SIZE, 1024] {
        let g = GBuffer::shaderball(size, size);
        let width = size as usize;
        // Rows from the first one without the ball down: only the pedestal and background.
        let first = (0..width)
            .rev()
            .find(|&y| g.object_id[y * width..(y + 1) * width].contains(&lookdev::gbuffer::BALL_ID))
            .unwrap()
            + 1;
        let mut bad = Vec::new();
        for i in first * width..g.pixel_count() {
            let n = g.normal[i];
            let side = n[1].abs() < 1e-4;
            let cap = (n[1].abs() - 1.0).abs() < 1e-4;
            if g.coverage[i] > 0.0 && !side && !cap {
                bad.push((i % width, i / width, n));
            }
        }
        assert!(
            bad.is_empty(),
            "{size}²: {} pedestal normals between surfaces, e.g. {:?}",
            bad.len(),
            &bad[..bad.len().min(4)]
        );
    }
}

/// The default look turns the pedestal from ceramic to copper through `gradient`: the mask
/// must rise over the pedestal itself (it was 0.02–0.14 there when it ran over the whole
/// scene), and over the ball.
#[test]
fn shaderball_gradient_spans_each_object() {
    let g = shaderball();
    let gradient = &g.masks["gradient"];
    for (object, name) in [(1, "ball"), (2, "pedestal")] {
        let values: Vec<f32> = (0..g.pixel_count())
            .filter(|&i| g.object_id[i] == object && g.coverage[i] == 1.0)
            .map(|i| gradient[i])
            .collect();
        let low = values.iter().copied().fold(f32::MAX, f32::min);
        let high = values.iter().copied().fold(f32::MIN, f32::max);
        assert!(low < 0.2 && high > 0.8, "{name}: gradient {low}..{high}");
    }
}

#[test]
fn shaderball_masks_are_bounded_and_non_trivial() {
    let g = shaderball();
    assert_eq!(g.masks.keys().collect::<Vec<_>>(), ["gradient", "grunge", "stripes"]);
    for (name, mask) in &g.masks {
        let covered: Vec<f32> = mask.iter().zip(&g.coverage).filter(|(_, &a)| a > 0.0).map(|(&m, _)| m).collect();
        assert!(mask.iter().all(|m| (0.0..=1.0).contains(m)), "{name} out of [0,1]");
        let low = covered.iter().filter(|&&m| m < 0.05).count();
        let high = covered.iter().filter(|&&m| m > 0.95).count();
        assert!(low > 20 && high > 20, "{name}: {low} low, {high} high");
        // Antialiased: plenty of values in between, not a binary pattern.
        let between = covered.iter().filter(|&&m| m > 0.1 && m < 0.9).count();
        assert!(between > 50, "{name}: {between} in-between values");
    }
}

#[test]
fn shaderball_masks_have_no_hard_steps() {
    // Antialiased at any resolution: between neighbouring covered pixels of the ball a mask
    // never steps straight from "off" to "on"; every edge passes through intermediate values.
    // (Not the pedestal: at small sizes its top is a pixel tall, and one pixel there spans
    // surfaces far apart in the world, so a step is the right answer.)
    for size in [97, SIZE, 600] {
        let g = GBuffer::shaderball(size, size);
        let width = size as usize;
        for (name, mask) in &g.masks {
            let mut steps = Vec::new();
            for i in 0..g.pixel_count() {
                for j in [i + 1, i + width] {
                    let inside = j < g.pixel_count() && g.coverage[i] == 1.0 && g.coverage[j] == 1.0;
                    let ball = inside && g.object_id[i] == 1 && g.object_id[j] == 1;
                    if ball && (mask[i] - mask[j]).abs() > 0.9 {
                        steps.push((i % width, i / width));
                    }
                }
            }
            assert!(steps.is_empty(), "{name} at {size}x{size} has hard steps at {steps:?}");
        }
    }
}

#[test]
fn shaderball_has_antialiased_silhouettes() {
    let g = shaderball();
    let fractional = g.coverage.iter().filter(|&&a| a > 0.0 && a < 1.0).count();
    // Roughly the perimeter of the ball and pedestal, in pixels.
    assert!(fractional > 300, "{fractional} fractional pixels");
    assert!(g.coverage.iter().all(|a| (0.0..=1.0).contains(a)));
}

#[test]
fn shaderball_centre_looks_down_minus_z_at_the_ball_head_on() {
    let g = shaderball();
    let centre = (SIZE as usize / 2) * SIZE as usize + SIZE as usize / 2;
    assert_eq!(g.object_id[centre], 1);
    assert_eq!(g.coverage[centre], 1.0);
    assert_close(g.normal[centre], [0.0, 0.0, 1.0], 1e-3, "centre N");
    assert_close(g.tangent[centre], [1.0, 0.0, 0.0], 1e-3, "centre T");
    // The eye looks along −V: at the centre that is −Z.
    assert_close(g.view[centre], [0.0, 0.0, 1.0], 1e-4, "centre V");
}

#[test]
fn shaderball_background_view_is_the_reversed_camera_ray() {
    let g = shaderball();
    let tan_half = (15.0f32).to_radians().tan();
    for (x, y) in [(0usize, 0usize), (SIZE as usize - 1, 3), (10, SIZE as usize / 2)] {
        let i = y * SIZE as usize + x;
        assert_eq!(g.coverage[i], 0.0);
        let ndc_x = (x as f32 + 0.5) / SIZE as f32 * 2.0 - 1.0;
        let ndc_y = 1.0 - (y as f32 + 0.5) / SIZE as f32 * 2.0;
        let ray = unit([ndc_x * tan_half, ndc_y * tan_half, -1.0]);
        assert_close(g.view[i], ray.map(|c| -c), 1e-4, &format!("background V at ({x}, {y})"));
    }
}

#[test]
fn shaderball_keeps_the_ball_round_at_any_aspect() {
    // A wide frame: the horizontal field of view grows, the ball stays a circle in the middle.
    let g = GBuffer::shaderball(300, 150);
    let ball = |x: usize, y: usize| g.object_id[y * 300 + x] == 1 && g.coverage[y * 300 + x] > 0.5;
    let row_width = (0..300).filter(|&x| ball(x, 75)).count();
    let column_height = (0..150).filter(|&y| ball(150, y)).count();
    assert!((row_width as i32 - column_height as i32).abs() <= 2, "{row_width} vs {column_height}");
    assert!(ball(150, 75) && !ball(5, 75) && !ball(294, 75));
}

#[test]
fn shaderball_is_deterministic() {
    assert_eq!(GBuffer::shaderball(97, 61), GBuffer::shaderball(97, 61));
}

fn with_views(disc: &Disc, view: &[[f32; 3]]) -> Vec<Channel> {
    let mut channels = disc.half_normals();
    for (axis, name) in ["V.X", "V.Y", "V.Z"].into_iter().enumerate() {
        channels.push(float(name, view.iter().map(|v| v[axis])));
    }
    channels
}

#[test]
fn reversed_view_vectors_are_an_error_not_a_black_image() {
    // V written as the camera ray (eye to surface) makes every covered normal face away.
    let disc = Disc::new(10, 10);
    let path = scratch("reversed-views.exr");
    write_exr(&path, disc.size(), with_views(&disc, &vec![[0.0, 0.0, -1.0]; 100]), Compression::ZIP16, &[]);
    read_err(&path, &["faces away from the view vector", "camera ray reversed"]);
}

#[test]
fn a_few_normals_facing_away_shade_black_with_a_warning() {
    let disc = Disc::new(10, 10);
    let mut view = vec![[0.0, 0.0, 1.0]; 100];
    let covered: Vec<usize> = (0..100).filter(|&i| disc.covered(i)).collect();
    view[covered[0]] = [0.0, 0.0, -1.0];
    view[covered[1]] = [0.0, 0.0, -1.0];
    let path = scratch("few-away.exr");
    write_exr(&path, disc.size(), with_views(&disc, &view), Compression::ZIP16, &[]);
    let (_, warnings) = read_ok(&path);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("at 2 pixels of") && warnings[0].contains("shade black"), "{}", warnings[0]);
}

// ---------------------------------------------------------------------------------------------
// Visibility channels (docs/formats.md#visibility)

#[test]
fn visibility_channels_round_trip_word_for_word() {
    use lookdev::visibility::{Grid, Visibility};
    let mut g = GBuffer::sphere(8, 8);
    let grid = Grid::new(16).unwrap();
    let words = (0..g.pixel_count() * grid.words()).map(|i| (i as u32).wrapping_mul(2_654_435_761)).collect();
    g.visibility = Some(Visibility { grid, words });
    let path = scratch("visibility-round-trip.exr");
    g.write(&path).unwrap();
    let (read, warnings) = read_ok(&path);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(read.visibility, g.visibility);
    // Every word is its own uint channel.
    let names: Vec<String> = read_channel_names(&path);
    assert!((0..8).all(|w| names.contains(&format!("visibility.{w}"))), "{names:?}");
}

fn read_channel_names(path: &Path) -> Vec<String> {
    let image = read_all_flat_layers_from_file(path).unwrap();
    image.layer_data[0].channel_data.list.iter().map(|c| c.name.to_string()).collect()
}

#[test]
fn bad_visibility_channels_are_named_errors() {
    let disc = Disc::new(4, 4);
    let words = |name: &'static str| uint(name, (0..16).map(|i| i * 7));
    let with = |extra: Vec<Channel>| {
        let mut channels = disc.half_normals();
        channels.extend(extra);
        channels
    };
    let cases: Vec<(&str, Vec<Channel>, Vec<&str>)> = vec![
        (
            "half",
            with(vec![words("visibility.0"), half("visibility.1", (0..16).map(|_| 1.0))]),
            vec!["channel visibility.1 is not uint"],
        ),
        (
            "three words",
            with(vec![words("visibility.0"), words("visibility.1"), words("visibility.2")]),
            vec!["found 3 with indices 0, 1, 2", "K = 2, 8, 32, 128"],
        ),
        ("a gap", with(vec![words("visibility.0"), words("visibility.2")]), vec!["found 2 with indices 0, 2"]),
        (
            "a name",
            with(vec![words("visibility.sun"), words("visibility.1")]),
            vec!["channel visibility.sun: a visibility channel is named by its word's index"],
        ),
        ("padded", with(vec![words("visibility.00"), words("visibility.1")]), vec!["channel visibility.00"]),
    ];
    for (what, channels, phrases) in cases {
        let path = scratch(&format!("visibility-{}.exr", what.replace(' ', "-")));
        write_exr(&path, disc.size(), channels, Compression::ZIP16, &[]);
        read_err(&path, &phrases);
    }
}
