//! Fuzzing every reader of hostile input, in-process and without a GPU: looks, presets,
//! g-buffers, environments (OpenEXR and Radiance), glTF assets and the command line.
//!
//! Each target starts from a corpus of valid files (`tests/data/fuzz/<target>/`), runs every
//! regression case (`tests/data/fuzz/regressions/<target>/`, one file per failure found, each
//! refused with an error unless its name starts with `ok-`), then
//! seeded mutations of the corpus: bit and byte flips, numeric edge values, truncation,
//! insertion, deletion, duplication and splicing, and for glTF mutations of the JSON's
//! structure. For every case it asserts:
//!
//! - no panic;
//! - a result, or an error whose one-line message names the file (the flag, for the command line);
//! - bounded allocation: the peak bytes allocated while the case runs, counted by this binary's
//!   global allocator, stay under [`CASE_BYTES`], and no single allocation may exceed
//!   [`ALLOCATION_CAP`] (one that would is refused, so the case aborts loudly, naming itself).
//!
//! `LOOKDEV_FUZZ_CASES` sets the cases per target (default 10000) and `LOOKDEV_FUZZ_SEED` the seed
//! (default 1); each target stops early at [`TARGET_SECONDS`] (`LOOKDEV_FUZZ_SECONDS`). `LOOKDEV_FUZZ_DUMP=DIR` writes
//! each case's input to `DIR/<target>-<case>.<ext>` before it runs, for a case that aborts. The corpus is rewritten by
//! `cargo test --release --test fuzz -- --ignored write_corpus`. The same functions have
//! `cargo fuzz` targets for long runs (`fuzz/`, see docs/development.md).

#[path = "common/gltf.rs"]
#[allow(dead_code)]
mod gltf_writer;

use lookdev::input::readers::Reader;
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicIsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

// ---- Counting allocation, per thread ----

/// The most a case may allocate at its peak, above what was live when it started.
const CASE_BYTES: usize = 256 << 20;
/// No single allocation while a case runs may be larger: one sized by a header would be.
const ALLOCATION_CAP: usize = 1 << 30;
/// Each target's share of the time bound.
const TARGET_SECONDS: u64 = 8;

struct Counting;

// Counted over every thread, since decoders may work on a pool's threads: the targets run one
// after another in one test, so nothing else allocates meanwhile.
static LIVE: AtomicIsize = AtomicIsize::new(0);
static PEAK: AtomicIsize = AtomicIsize::new(0);
static IN_CASE: AtomicBool = AtomicBool::new(false);
static CASE: Mutex<String> = Mutex::new(String::new());

/// Counts `grow` more bytes; false if a case asks for more than the cap at once.
fn note(grow: isize, request: usize) -> bool {
    if request > ALLOCATION_CAP && IN_CASE.load(Ordering::Relaxed) {
        // Say which case it was before the allocation failure aborts the process.
        use std::io::Write;
        if let Ok(case) = CASE.try_lock() {
            let _ = writeln!(std::io::stderr(), "fuzz: a single allocation of {request} bytes in {case}");
        }
        return false;
    }
    let live = LIVE.fetch_add(grow, Ordering::Relaxed) + grow;
    PEAK.fetch_max(live, Ordering::Relaxed);
    true
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if !note(layout.size() as isize, layout.size()) {
            return std::ptr::null_mut();
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if !note(layout.size() as isize, layout.size()) {
            return std::ptr::null_mut();
        }
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        note(-(layout.size() as isize), 0);
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if !note(new_size as isize - layout.size() as isize, new_size) {
            return std::ptr::null_mut();
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

// ---- Mutations ----

/// SplitMix64: small, seedable, the same everywhere.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Numbers at the edges of what formats hold, as 32-bit patterns: sizes, indices, floats.
const EDGE_WORDS: [u32; 14] = [
    0,
    1,
    0xffff_ffff,
    0x7fff_ffff,
    0x8000_0000,
    0x0001_0000,
    0x0000_ffff,
    100_000,
    0x7f80_0000, // +inf
    0xff80_0000, // -inf
    0x7fc0_0000, // NaN
    0x7f7f_ffff, // f32::MAX
    0x0000_0001, // the smallest subnormal
    0x4780_0000, // 65536.0
];

/// Numbers at the edges of what text formats hold.
const EDGE_NUMBERS: [&str; 16] = [
    "0",
    "-1",
    "-0",
    "1e308",
    "1e39",
    "3.4e38",
    "nan",
    "inf",
    "-inf",
    "4294967296",
    "18446744073709551616",
    "1e-45",
    "99999999999999999999999",
    "0.5",
    "65536",
    "2147483648",
];

/// Bytes that break parsers in interesting ways.
const EDGE_BYTES: [u8; 9] = [0, 0xff, 0x7f, 0x80, 1, b'"', b'[', b'\n', 0x1b];

fn mutate(rng: &mut Rng, input: &[u8], corpus: &[Vec<u8>], text: bool) -> Vec<u8> {
    let mut out = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        let len = out.len();
        // Headers hold the sizes: bias binary edits towards the first KiB.
        let at = |rng: &mut Rng| if !text && rng.below(2) == 0 { rng.below(len.min(1024)) } else { rng.below(len) };
        match rng.below(9) {
            0 if len > 0 => {
                let i = at(rng);
                out[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = at(rng);
                out[i] = *rng.pick(&EDGE_BYTES);
            }
            2 if len > 0 => out.truncate(rng.below(len)),
            3 => {
                let i = rng.below(len + 1);
                let count = 1 + rng.below(16);
                let bytes: Vec<u8> = (0..count).map(|_| rng.next() as u8).collect();
                out.splice(i..i, bytes);
            }
            4 if len > 1 => {
                let start = rng.below(len);
                let end = (start + 1 + rng.below(64)).min(len);
                out.drain(start..end);
            }
            5 => {
                let other = rng.pick(corpus);
                if !other.is_empty() && len > 0 {
                    let from = rng.below(other.len());
                    let piece = &other[from..(from + 1 + rng.below(256)).min(other.len())];
                    let i = rng.below(len);
                    let end = (i + piece.len()).min(len);
                    out.splice(i..end, piece.iter().copied());
                }
            }
            6 if text => replace_number(rng, &mut out),
            6 if len >= 4 => {
                let i = at(rng).min(len - 4);
                out[i..i + 4].copy_from_slice(&rng.pick(&EDGE_WORDS).to_le_bytes());
            }
            7 if len > 1 => {
                let start = rng.below(len);
                let end = (start + 1 + rng.below(64)).min(len);
                let piece = out[start..end].to_vec();
                let i = rng.below(len);
                out.splice(i..i, piece);
            }
            _ if len >= 8 && !text => {
                // A whole 64-bit count or offset.
                let i = at(rng).min(len - 8);
                let word = *rng.pick(&[0u64, u64::MAX, 1 << 40, i64::MAX as u64, 1 << 31]);
                out[i..i + 8].copy_from_slice(&word.to_le_bytes());
            }
            _ => {}
        }
    }
    out
}

/// Replaces one number in a text with an edge value.
fn replace_number(rng: &mut Rng, text: &mut Vec<u8>) {
    let starts: Vec<usize> = (0..text.len())
        .filter(|&i| text[i].is_ascii_digit() && (i == 0 || !text[i - 1].is_ascii_alphanumeric()))
        .collect();
    if starts.is_empty() {
        return;
    }
    let start = *rng.pick(&starts);
    let end =
        (start..text.len()).find(|&i| !(text[i].is_ascii_digit() || b".eE+-".contains(&text[i]))).unwrap_or(text.len());
    text.splice(start..end, rng.pick(&EDGE_NUMBERS).bytes());
}

/// Edits one value of a JSON document: an edge number, an odd string, null, an empty or
/// grown container, or a removed key.
fn mutate_json(rng: &mut Rng, json: &mut serde_json::Value) {
    let mut paths = Vec::new();
    collect_paths(json, String::new(), &mut paths);
    let Some(path) = (!paths.is_empty()).then(|| rng.pick(&paths).clone()) else { return };
    let replacement = match rng.below(12) {
        0 => serde_json::json!(-1),
        1 => serde_json::json!(99),
        2 => serde_json::json!(4294967296u64),
        3 => serde_json::json!(1e30),
        4 => serde_json::json!(5126),
        5 => serde_json::json!("VEC2"),
        6 => serde_json::json!("3.0"),
        7 => serde_json::Value::Null,
        8 => serde_json::json!([]),
        9 => serde_json::json!({}),
        10 => serde_json::json!("/dev/zero"),
        _ => {
            // Remove the key, or grow the array it is in.
            let (parent, key) = path.rsplit_once('/').unwrap_or(("", &path));
            match json.pointer_mut(parent) {
                Some(serde_json::Value::Object(map)) => {
                    map.remove(key);
                }
                Some(serde_json::Value::Array(items)) if !items.is_empty() => {
                    let copy = items[rng.below(items.len())].clone();
                    items.push(copy);
                }
                _ => {}
            }
            return;
        }
    };
    if let Some(value) = json.pointer_mut(&path) {
        *value = replacement;
    }
}

fn collect_paths(value: &serde_json::Value, path: String, out: &mut Vec<String>) {
    if !path.is_empty() {
        out.push(path.clone());
    }
    match value {
        serde_json::Value::Object(map) => {
            for (key, child) in map {
                collect_paths(child, format!("{path}/{key}"), out);
            }
        }
        serde_json::Value::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                collect_paths(child, format!("{path}/{i}"), out);
            }
        }
        _ => {}
    }
}

/// A glTF mutation: the JSON's structure (of a `.gltf`, or the JSON chunk of a `.glb`, repacked
/// with its binary chunk) or its bytes.
fn mutate_gltf(rng: &mut Rng, input: &[u8], corpus: &[Vec<u8>]) -> Vec<u8> {
    if rng.below(2) == 0 {
        return mutate(rng, input, corpus, input.first() == Some(&b'{'));
    }
    let (json_bytes, bin) = match glb_chunks(input) {
        Some((json, bin)) => (json.to_vec(), Some(bin.to_vec())),
        None => (input.to_vec(), None),
    };
    let Ok(mut json) = serde_json::from_slice::<serde_json::Value>(&json_bytes) else {
        return mutate(rng, input, corpus, false);
    };
    for _ in 0..1 + rng.below(3) {
        mutate_json(rng, &mut json);
    }
    let text = serde_json::to_vec(&json).unwrap();
    match bin {
        Some(bin) => glb(&text, &bin),
        None => text,
    }
}

fn glb_chunks(bytes: &[u8]) -> Option<(&[u8], &[u8])> {
    if bytes.get(..4)? != b"glTF" {
        return None;
    }
    let json_len = u32::from_le_bytes(bytes.get(12..16)?.try_into().ok()?) as usize;
    let json = bytes.get(20..20 + json_len)?;
    let bin = bytes.get(20 + json_len + 8..).unwrap_or(&[]);
    Some((json, bin))
}

fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let mut json = json.to_vec();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

// ---- Targets ----

fn corpus_dir(target: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz").join(target)
}

fn regressions_dir(target: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz/regressions").join(target)
}

/// The files of a folder, sorted by name.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .flatten()
                .filter(|e| e.path().is_file())
                .map(|e| (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).unwrap()))
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

/// What a case gave: nothing to report, or the error's message.
type Outcome = Result<(), String>;

/// Runs one case under the checks: no panic, bounded allocation, and an error on one line that
/// `names` accepts (it names the file, or the argument).
fn run_case(label: &str, names: &dyn Fn(&str) -> bool, case: impl FnOnce() -> Outcome) -> Result<(), String> {
    *CASE.lock().unwrap() = label.to_string();
    let start = LIVE.load(Ordering::Relaxed);
    PEAK.store(start, Ordering::Relaxed);
    IN_CASE.store(true, Ordering::Relaxed);
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(case));
    IN_CASE.store(false, Ordering::Relaxed);
    let grown = PEAK.load(Ordering::Relaxed) - start;
    match outcome {
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            return Err(format!("{label}: panicked: {what}"));
        }
        Ok(Err(message)) if !names(&message) => {
            return Err(format!("{label}: the error does not name what it is about: {message}"));
        }
        Ok(Err(message)) if message.lines().count() != 1 => {
            return Err(format!("{label}: the error is not one line: {message}"));
        }
        Ok(_) => {}
    }
    if grown > CASE_BYTES as isize {
        return Err(format!("{label}: allocated {grown} bytes at its peak"));
    }
    Ok(())
}

/// Fuzzes one reader of files: its regressions, then mutations of its corpus. `run` reads the
/// bytes as the file at the path it is given, and its errors must name that file.
fn fuzz(target: &str, extension: &str, text: bool, run: impl Fn(&[u8], &Path) -> Outcome) {
    fuzz_with(target, extension, text, run, |message, _, path| message.contains(&path.display().to_string()));
}

/// [`fuzz`], with `names` judging whether an error message names what it is about.
fn fuzz_with(
    target: &str,
    extension: &str,
    text: bool,
    run: impl Fn(&[u8], &Path) -> Outcome,
    names: impl Fn(&str, &[u8], &Path) -> bool,
) {
    let corpus = files(&corpus_dir(target));
    assert!(!corpus.is_empty(), "no corpus for {target}");
    let scratch = tempfile::tempdir().unwrap();
    let path = scratch.path().join(format!("case.{extension}"));
    let mut failures = Vec::new();
    for (file, bytes) in &corpus {
        let label = format!("{target} {file}");
        if let Err(failure) = run_case(&label, &|m| names(m, bytes, &path), || run(bytes, &path)) {
            failures.push(failure);
        }
    }
    // A regression case is refused with an error, unless its name says it reads ("ok-...").
    for (file, bytes) in files(&regressions_dir(target)) {
        let label = format!("{target} regression {file}");
        let expect_error = !file.starts_with("ok-");
        let outcome = run_case(&label, &|m| names(m, &bytes, &path), || match run(&bytes, &path) {
            Ok(()) if expect_error => Err(format!("was read without an error {}", path.display())),
            outcome => outcome,
        });
        if let Err(failure) = outcome {
            failures.push(failure);
        }
    }
    let seed: u64 = std::env::var("LOOKDEV_FUZZ_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    let cases: usize = std::env::var("LOOKDEV_FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(10_000);
    let bytes: Vec<Vec<u8>> = corpus.iter().map(|(_, b)| b.clone()).collect();
    let mut rng = Rng(seed ^ target.bytes().fold(0u64, |h, b| h.wrapping_mul(31).wrapping_add(b as u64)));
    let seconds = std::env::var("LOOKDEV_FUZZ_SECONDS").ok().and_then(|s| s.parse().ok()).unwrap_or(TARGET_SECONDS);
    let deadline = Instant::now() + Duration::from_secs(seconds);
    let mut ran = 0;
    while ran < cases && Instant::now() < deadline {
        let which = rng.below(corpus.len());
        let input = if target == "gltf" {
            mutate_gltf(&mut rng, &bytes[which], &bytes)
        } else {
            mutate(&mut rng, &bytes[which], &bytes, text)
        };
        let label = format!("{target} case {ran} (seed {seed}, from {})", corpus[which].0);
        if let Some(dump) = std::env::var_os("LOOKDEV_FUZZ_DUMP") {
            // For a case that aborts the process: its input, written before it runs.
            std::fs::write(Path::new(&dump).join(format!("{target}-{ran}.{extension}")), &input).unwrap();
        }
        if let Err(failure) = run_case(&label, &|m| names(m, &input, &path), || run(&input, &path)) {
            let kept = scratch.path().join(format!("failure-{ran}.{extension}"));
            std::fs::write(&kept, &input).unwrap();
            failures.push(format!("{failure} (input kept at {})", kept.display()));
            if failures.len() >= 10 {
                break;
            }
        }
        ran += 1;
    }
    let regressions = files(&regressions_dir(target)).len();
    eprintln!("fuzz {target}: {} corpus files, {regressions} regressions, {ran} mutated cases", corpus.len());
    if !failures.is_empty() {
        // Keep the failing inputs for a reproducer: the scratch folder outlives the test.
        let kept = scratch.keep();
        let report = format!("{} failures (inputs in {}):\n{}", failures.len(), kept.display(), failures.join("\n"));
        eprintln!("fuzz {target}: {report}");
        panic!("{report}");
    }
}

/// A reader of [`Reader::ALL`], with its corpus folder, file extension and whether it is text.
fn target(reader: Reader) -> (&'static str, &'static str, bool) {
    match reader {
        Reader::Look => ("look", "toml", true),
        Reader::Preset => ("preset", "toml", true),
        Reader::GBuffer => ("gbuffer", "exr", false),
        Reader::ExrEnvironment => ("environment", "exr", false),
        Reader::HdrEnvironment => ("hdr", "hdr", false),
        Reader::Gltf => ("gltf", "glb", false),
        Reader::CommandLine => ("cli", "args", true),
    }
}

/// Every reader, one after another (see [`Counting`]), with a silent panic hook: a panic is
/// reported as the case's failure.
#[test]
fn every_reader_survives_mutated_input() {
    let quiet = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(|| {
        for reader in Reader::ALL {
            let (name, extension, text) = target(reader);
            let run = |bytes: &[u8], path: &Path| reader.read(bytes, path).map_err(|e| e.to_string());
            if reader == Reader::CommandLine {
                // A command-line error names no file: clap quotes what it refuses (dropping
                // control characters from it), and lookdev names the flag.
                fuzz_with(name, extension, text, run, |message, _, _| {
                    message.matches('\'').count() >= 2 || message.contains("--")
                });
            } else {
                fuzz(name, extension, text, run);
            }
        }
    });
    std::panic::set_hook(quiet);
    if let Err(payload) = result {
        std::panic::resume_unwind(payload);
    }
}

// ---- The corpus, written by code so that its origin is on record ----

#[test]
#[ignore = "rewrites the committed corpus"]
fn write_corpus() {
    corpus::write_all();
}

mod corpus {
    use super::corpus_dir;
    use super::gltf_writer::{cube, uv_sphere, Gltf};
    use lookdev::gbuffer::GBuffer;
    use serde_json::json;
    use std::path::Path;

    pub fn write_all() {
        looks();
        presets();
        gbuffers();
        environments();
        hdrs();
        gltfs();
        command_lines();
    }

    fn write(target: &str, name: &str, bytes: &[u8]) {
        let dir = corpus_dir(target);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(name), bytes).unwrap();
    }

    fn looks() {
        write("look", "default.toml", include_bytes!("../src/material/default_look.toml"));
        write(
            "look",
            "everything.toml",
            br#"[environment]
file = "studio.exr"
rotation = 30.0
intensity = 1.5
background = false

[model]
diffuse = "lambert"
specular_g = "smith-height-correlated"
energy_compensation = true

[render]
spp = 64
seed = 7
exposure = -0.5
tonemap = "agx"

[[object]]
id = 1
[[object.layer]]
preset = "blue-rubber"
[[object.layer]]
preset = "gold"
mask = "stripes"
invert = true
opacity = 0.75
[object.layer.set]
roughness = 0.25
base_color = [0.9, 0.5, 0.1]
[object.layer.map]
base_color = "baseColor"
metallic = "metalRough.B"

[[object]]
[[object.layer]]
enabled = false
[object.layer.set]
emission = [1.0, 0.5, 0.0]
"#,
        );
        write("look", "paths.toml", b"[[object]]\nid = 4\n[[object.layer]]\npreset = \"presets/mine.toml\"\n");
    }

    fn presets() {
        for name in ["gold", "car-paint", "velvet", "white-ceramic"] {
            let text = lookdev::material::library::BUILTIN.iter().find(|(n, _)| *n == name).unwrap().1;
            write("preset", &format!("{name}.toml"), text.as_bytes());
        }
    }

    fn small_gbuffer() -> GBuffer {
        let mut g = GBuffer::shaderball(12, 10);
        let pixels = g.normal.len();
        g.maps.insert("rough".into(), (0..pixels).map(|i| i as f32 / pixels as f32).collect());
        for c in ["R", "G", "B"] {
            g.maps.insert(format!("tint.{c}"), vec![0.5; pixels]);
        }
        g.mask_names.insert("stripes".into(), "Stripes, painted".into());
        g
    }

    fn gbuffers() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.exr");
        small_gbuffer().write(&path).unwrap();
        write("gbuffer", "shaderball-zip.exr", &std::fs::read(&path).unwrap());
        for (name, compression) in [
            ("rle", exr::compression::Compression::RLE),
            ("piz", exr::compression::Compression::PIZ),
            ("none", exr::compression::Compression::Uncompressed),
            ("pxr24", exr::compression::Compression::PXR24),
        ] {
            write("gbuffer", &format!("shaderball-{name}.exr"), &recompress(&path, compression, false));
        }
        write("gbuffer", "shaderball-tiled.exr", &recompress(&path, exr::compression::Compression::ZIP16, true));
        write(
            "gbuffer",
            "blender-multilayer.exr",
            &renderer_aovs(&["ViewLayer."], "Normal", "Position", "CryptoObject", false, 0),
        );
        // A manifest far longer than the image shows, and a copied view layer beside its
        // original (Blender names it `ViewLayer.002`; read as it is, the two are ambiguous).
        write(
            "gbuffer",
            "blender-long-manifest.exr",
            &renderer_aovs(&["ViewLayer."], "Normal", "Position", "CryptoObject", false, 2000),
        );
        write(
            "gbuffer",
            "blender-copied-view-layer.exr",
            &renderer_aovs(&["ViewLayer.", "ViewLayer.002."], "Normal", "Position", "CryptoObject", false, 0),
        );
        write("gbuffer", "arnold-multipart.exr", &renderer_aovs(&[""], "N", "P", "crypto_object", true, 0));
    }

    /// A 12×10 disc as a renderer writes it: normals, positions, a Cryptomatte object layer
    /// with its manifest (the disc, then `more` names no pixel shows), and the camera (as
    /// lookdev's Blender note, or Arnold's worldToCamera); Blender-style (one part, each view
    /// layer's passes under its prefix) or Arnold-style (an AOV a part, one empty prefix).
    fn renderer_aovs(
        prefixes: &[&str],
        normal: &str,
        position: &str,
        crypto: &str,
        parts: bool,
        more: usize,
    ) -> Vec<u8> {
        use exr::prelude::*;
        use lookdev::gbuffer::source::cryptomatte::{hash_to_float, murmur3_32};
        let (w, h) = (12usize, 10usize);
        let inside = |p: usize| {
            let (x, y) = ((p % w) as f32 - 5.5, (p / w) as f32 - 4.5);
            x * x + y * y < 16.0
        };
        // Facing the camera: Blender's at −Y (Z up), Arnold's at +Z (Y up).
        let toward = if parts { [0.0, 0.0, 1.0] } else { [0.0, -1.0, 0.0] };
        let n: Vec<[f32; 3]> = (0..w * h).map(|p| if inside(p) { toward } else { [0.0; 3] }).collect();
        let points: Vec<[f32; 3]> =
            (0..w * h).map(|p| if inside(p) { [p as f32 * 0.01, 0.0, 1.0] } else { [0.0; 3] }).collect();
        let id = hash_to_float(murmur3_32(b"disc"));
        let mut manifest = vec![format!("\"disc\":\"{:08x}\"", murmur3_32(b"disc"))];
        manifest.extend(
            (0..more).map(|i| format!("\"object{i}\":\"{:08x}\"", murmur3_32(format!("object{i}").as_bytes()))),
        );
        let manifest = format!("{{{}}}", manifest.join(","));
        let suffixes = if parts { ["R", "G", "B"] } else { ["X", "Y", "Z"] };
        let mut attributes = LayerAttributes::default();
        let mut groups = Vec::new();
        for prefix in prefixes {
            let vector = |layer: &str, v: &[[f32; 3]]| -> Vec<AnyChannel<FlatSamples>> {
                (0..3)
                    .map(|k| {
                        AnyChannel::new(
                            Text::from(format!("{prefix}{layer}.{}", suffixes[k]).as_str()),
                            FlatSamples::F32(v.iter().map(|x| x[k]).collect()),
                        )
                    })
                    .collect()
            };
            let rank: Vec<AnyChannel<FlatSamples>> = [
                (0..w * h).map(|p| if inside(p) { id } else { 0.0 }).collect::<Vec<f32>>(),
                (0..w * h).map(|p| if inside(p) { 1.0 } else { 0.0 }).collect(),
                vec![0.0; w * h],
                vec![0.0; w * h],
            ]
            .into_iter()
            .zip(["r", "g", "b", "a"])
            .map(|(values, c)| {
                AnyChannel::new(Text::from(format!("{prefix}{crypto}00.{c}").as_str()), FlatSamples::F32(values))
            })
            .collect();
            let layer_name = format!("{prefix}{crypto}");
            let key = &format!("{:08x}", murmur3_32(layer_name.as_bytes()))[..7];
            for (field, value) in [
                ("name", layer_name.clone()),
                ("hash", "MurmurHash3_32".into()),
                ("conversion", "uint32_to_float32".into()),
                ("manifest", manifest.clone()),
            ] {
                attributes.other.insert(
                    Text::from(format!("cryptomatte/{key}/{field}").as_str()),
                    AttributeValue::Text(Text::from(value.as_str())),
                );
            }
            groups.push((normal, vector(normal, &n)));
            groups.push((position, vector(position, &points)));
            groups.push((crypto, rank));
        }
        if parts {
            attributes.world_to_camera = Some([1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., -5., 1.]);
        } else {
            let note = "lookdev.camera position=0,-5,0 forward=0,1,0 projection=perspective";
            attributes.other.insert(Text::from("Note"), AttributeValue::Text(Text::from(note)));
        }
        let layer = |name: Option<&str>, channels: Vec<AnyChannel<FlatSamples>>| {
            let attributes = LayerAttributes { layer_name: name.map(Text::from), ..attributes.clone() };
            Layer::new((w, h), attributes, Encoding::SMALL_LOSSLESS, AnyChannels::sort(channels.into()))
        };
        let layers: Vec<_> = if parts {
            groups.into_iter().map(|(name, channels)| layer(Some(name), channels)).collect()
        } else {
            vec![layer(None, groups.into_iter().flat_map(|(_, c)| c).collect())]
        };
        let mut bytes = std::io::Cursor::new(Vec::new());
        Image::from_layers(ImageAttributes::new(IntegerBounds::from_dimensions((w, h))), layers)
            .write()
            .non_parallel()
            .to_buffered(&mut bytes)
            .unwrap();
        bytes.into_inner()
    }

    /// The file at `path` written again with another compression, or as 8×8 tiles.
    fn recompress(path: &Path, compression: exr::compression::Compression, tiled: bool) -> Vec<u8> {
        use exr::prelude::*;
        let mut image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .from_file(path)
            .unwrap();
        for layer in &mut image.layer_data {
            layer.encoding.compression = compression;
            if tiled {
                layer.encoding.blocks = Blocks::Tiles(Vec2(8, 8));
            }
        }
        let mut bytes = std::io::Cursor::new(Vec::new());
        image.write().non_parallel().to_buffered(&mut bytes).unwrap();
        bytes.into_inner()
    }

    /// A 32×16 sky: blue above, brown below, a sun.
    fn sky(x: usize, y: usize) -> (f32, f32, f32) {
        if (x, y) == (20, 4) {
            return (500.0, 450.0, 400.0);
        }
        if y < 8 {
            (0.3, 0.5, 1.0 - y as f32 * 0.05)
        } else {
            (0.2, 0.15, 0.1)
        }
    }

    fn environments() {
        use exr::prelude::*;
        for (name, compression, tiled) in [
            ("zip", Compression::ZIP16, false),
            ("rle", Compression::RLE, false),
            ("piz", Compression::PIZ, false),
            ("b44", Compression::B44, false),
            ("tiled", Compression::ZIP1, true),
        ] {
            let pixels = SpecificChannels::rgb(|p: Vec2<usize>| {
                let (r, g, b) = sky(p.x(), p.y());
                (f16::from_f32(r), f16::from_f32(g), f16::from_f32(b))
            });
            let blocks = if tiled { Blocks::Tiles(Vec2(8, 8)) } else { Blocks::ScanLines };
            let encoding = Encoding { compression, blocks, line_order: LineOrder::Increasing };
            let layer = Layer::new((32, 16), LayerAttributes::default(), encoding, pixels);
            let mut bytes = std::io::Cursor::new(Vec::new());
            Image::from_layer(layer).write().non_parallel().to_buffered(&mut bytes).unwrap();
            write("environment", &format!("sky-{name}.exr"), &bytes.into_inner());
        }
    }

    fn hdrs() {
        // Wide enough (8 or more) that the encoder run-length encodes its scan lines.
        let pixels: Vec<image::Rgb<f32>> = (0..16 * 32)
            .map(|i| {
                let (r, g, b) = sky(i % 32, i / 32);
                image::Rgb([r, g, b])
            })
            .collect();
        let mut bytes = Vec::new();
        image::codecs::hdr::HdrEncoder::new(&mut bytes).encode(&pixels, 32, 16).unwrap();
        write("hdr", "sky-rle.hdr", &bytes);
        // Flat scan lines, as narrow images are stored.
        let mut flat = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n".to_vec();
        for i in 0..8u8 {
            flat.extend([100 + i, 90, 80, 129]);
        }
        write("hdr", "flat.hdr", &flat);
    }

    fn gltfs() {
        let dir = tempfile::tempdir().unwrap();
        let mut gltf = Gltf::new();
        let texture =
            gltf.texture(&image::RgbaImage::from_fn(4, 4, |x, y| image::Rgba([x as u8 * 60, y as u8 * 60, 128, 255])));
        let painted = gltf.material(json!({
            "name": "painted",
            "pbrMetallicRoughness": {
                "baseColorTexture": { "index": texture, "extensions": { "KHR_texture_transform": { "scale": [2.0, 2.0] } } },
                "metallicFactor": 0.0, "roughnessFactor": 0.4
            },
            "extensions": { "KHR_materials_clearcoat": { "clearcoatFactor": 0.5 }, "KHR_materials_sheen": { "sheenColorFactor": [0.2, 0.1, 0.0] } }
        }));
        let metal = gltf.material(json!({ "name": "metal", "pbrMetallicRoughness": { "metallicFactor": 1.0 } }));
        gltf.uses_extension("KHR_texture_transform");
        gltf.uses_extension("KHR_materials_clearcoat");
        gltf.uses_extension("KHR_materials_sheen");
        let ball = gltf.mesh("ball", &[(&uv_sphere(1.0, 8, 6), Some(painted))]);
        let box_mesh = gltf.mesh("box", &[(&cube(0.5), Some(metal))]);
        let child = gltf.node(
            json!({ "name": "box", "mesh": box_mesh, "translation": [2.0, 0.0, 0.0], "scale": [1.0, -1.0, 1.0] }),
        );
        gltf.node(json!({ "name": "ball", "mesh": ball, "children": [child], "rotation": [0.0, 0.38, 0.0, 0.92] }));
        let path = gltf.write_glb(dir.path(), "scene");
        write("gltf", "scene.glb", &std::fs::read(path).unwrap());

        // The same as JSON with its buffer embedded.
        let path = gltf.write_gltf(dir.path(), "scene");
        let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
        use base64::Engine;
        let bin = std::fs::read(dir.path().join("scene.bin")).unwrap();
        let data = base64::engine::general_purpose::STANDARD.encode(bin);
        json["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{data}"));
        write("gltf", "scene.gltf", serde_json::to_string(&json).unwrap().as_bytes());
    }

    fn command_lines() {
        let lines: [&[&str]; 9] = [
            &["render", "--out", "x.png", "--spp", "4", "--seed", "2", "--set", "roughness=0.3", "--tonemap", "agx"],
            &[
                "render",
                "--gbuffer",
                "g.exr",
                "--look",
                "l.toml",
                "--out",
                "x.exr",
                "--intensity",
                "2",
                "--rotation",
                "90",
                "--exposure",
                "1",
            ],
            &["render", "--out", "x.png", "--model", "diffuse=lambert", "--compare"],
            &["turntable", "--frames", "8", "--range", "2-4", "--out", "f_####.png", "--no-background"],
            &[
                "bake",
                "m.glb",
                "--out",
                "g.exr",
                "--size",
                "64",
                "48",
                "--samples",
                "4",
                "--auto-camera",
                "--yaw",
                "30",
                "--pitch",
                "10",
                "--fov",
                "40",
            ],
            &["import", "m.glb", "--presets", "p", "--look", "l.toml", "--force"],
            &["presets", "save", "mine", "--set", "metallic=1", "--tags", "metal,warm", "--description", "A metal"],
            &["wedge", "--param", "roughness", "--values", "0,0.5,1", "--out", "w.png", "--size", "64"],
            &["view", "l.toml", "--gbuffer", "g.exr", "--window-size", "800", "600", "--exit-after-spp", "4"],
        ];
        for (i, line) in lines.iter().enumerate() {
            write("cli", &format!("{i}-{}.args", line[0]), line.join("\n").as_bytes());
        }
    }
}
