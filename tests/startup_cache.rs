//! The start-up caches (docs/formats.md#caches): a second run takes the pipeline cache, the
//! environment's sampling tables and the decoded built-in map from `$XDG_CACHE_HOME/lookdev`,
//! and renders the same image, bit for bit, as a run without any cache; damaged cache files and
//! a cache folder that cannot be written never fail a render. Every run here has its own
//! temporary cache folder, so the user's is never touched.

mod common;

use common::cli::{assert_success, stderr};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A temporary folder for one test: its cache folder and its renders.
struct Case {
    dir: tempfile::TempDir,
}

impl Case {
    fn new() -> Case {
        Case { dir: tempfile::tempdir().unwrap() }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn cache(&self) -> PathBuf {
        self.path("cache")
    }

    /// `lookdev render` of the built-in ball at 64², 1 spp, to `out`, with timings (which say
    /// what came from the cache) and validation on. `cache` is `$XDG_CACHE_HOME`; None runs
    /// with neither it nor `$HOME`, so there is no cache folder at all.
    fn render(&self, cache: Option<&Path>, out: &str, extra: &[&str]) -> Output {
        let out = self.path(out);
        let mut args = vec!["render", "--size", "64", "64", "--spp", "1", "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let mut command = Command::new(env!("CARGO_BIN_EXE_lookdev"));
        command.args(&args).env("LOOKDEV_VALIDATION", "1").env("LOOKDEV_TIMINGS", "1");
        match cache {
            Some(cache) => command.env("XDG_CACHE_HOME", cache),
            None => command.env_remove("XDG_CACHE_HOME").env_remove("HOME"),
        };
        let output = command.output().unwrap();
        assert_success(&output);
        output
    }

    /// The files of one cache folder (`pipelines`, `environments`), by name.
    fn files(&self, folder: &str) -> Vec<PathBuf> {
        let Ok(entries) = std::fs::read_dir(self.cache().join("lookdev").join(folder)) else { return Vec::new() };
        let mut files: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).collect();
        files.sort();
        files
    }

    /// The one file in `folder` whose name ends with `suffix`.
    fn file(&self, folder: &str, suffix: &str) -> PathBuf {
        let found: Vec<PathBuf> =
            self.files(folder).into_iter().filter(|p| p.to_string_lossy().ends_with(suffix)).collect();
        assert_eq!(found.len(), 1, "one {suffix} in {folder}: {found:?}");
        found[0].clone()
    }

    /// The render's pixels, every channel of every layer.
    fn pixels(&self, name: &str) -> Vec<(String, Vec<u32>)> {
        use exr::prelude::*;
        let image = read_all_flat_layers_from_file(self.path(name)).unwrap();
        let mut channels = Vec::new();
        for layer in &image.layer_data {
            for channel in &layer.channel_data.list {
                let values = channel.sample_data.values_as_f32().map(f32::to_bits).collect();
                channels.push((format!("{:?}.{}", layer.attributes.layer_name, channel.name), values));
            }
        }
        channels
    }
}

/// What the timings say came from the cache.
fn loaded(output: &Output) -> (bool, bool, bool) {
    let text = stderr(output);
    (
        text.contains("pipeline cache: loaded"),
        text.contains("environment tables: loaded from"),
        text.contains("environment: built-in city loaded from"),
    )
}

fn warnings(output: &Output) -> Vec<String> {
    stderr(output).lines().filter(|l| l.starts_with("lookdev: warning:")).map(str::to_string).collect()
}

#[test]
fn a_second_run_starts_from_the_cache_and_renders_the_same_image_as_no_cache() {
    let case = Case::new();
    let cold = case.render(Some(&case.cache()), "cold.exr", &[]);
    assert_eq!(loaded(&cold), (false, false, false), "a cold cache has nothing: {}", stderr(&cold));
    assert!(stderr(&cold).contains("pipeline cache: starting empty"), "{}", stderr(&cold));
    let pipelines = case.file("pipelines", ".bin");
    let tables = case.file("environments", ".tables");
    let builtin = case.file("environments", ".texels");
    assert!(builtin.file_name().unwrap().to_string_lossy().starts_with("builtin-city-"), "{builtin:?}");

    let warm = case.render(Some(&case.cache()), "warm.exr", &[]);
    assert_eq!(loaded(&warm), (true, true, true), "a warm cache is used: {}", stderr(&warm));
    assert!(warnings(&warm).is_empty(), "{:?}", warnings(&warm));
    let mut cached = vec![tables, builtin];
    cached.sort();
    assert_eq!(case.files("environments"), cached, "nothing new is cached");
    assert_eq!(case.files("pipelines"), vec![pipelines]);

    let none = case.render(None, "none.exr", &[]);
    assert_eq!(loaded(&none), (false, false, false));
    let reference = case.pixels("none.exr");
    assert!(reference.len() >= 3 && reference[0].1.iter().any(|&v| v != 0), "a real image");
    assert!(case.pixels("cold.exr") == reference, "the cold-cache render differs from one without a cache");
    assert!(case.pixels("warm.exr") == reference, "the warm-cache render differs from one without a cache");
}

#[test]
fn a_map_with_other_texels_gets_its_own_tables() {
    let case = Case::new();
    let write_map = |name: &str, sun: f32| {
        let pixels: Vec<image::Rgb<f32>> =
            (0..64 * 32).map(|i| image::Rgb(if i == 300 { [sun; 3] } else { [0.5, 0.6, 0.7] })).collect();
        let file = std::fs::File::create(case.path(name)).unwrap();
        image::codecs::hdr::HdrEncoder::new(file).encode(&pixels, 64, 32).unwrap();
    };
    write_map("a.hdr", 50.0);
    write_map("b.hdr", 400.0);
    let env = |name: &str| case.path(name).to_str().unwrap().to_string();
    let (a, b) = (env("a.hdr"), env("b.hdr"));
    case.render(Some(&case.cache()), "a1.exr", &["--env", &a]);
    let first = case.files("environments");
    assert_eq!(first.len(), 1, "one map's tables: {first:?}");
    let second = case.render(Some(&case.cache()), "b1.exr", &["--env", &b]);
    assert!(!loaded(&second).1, "another map's tables are not reused: {}", stderr(&second));
    assert_eq!(case.files("environments").len(), 2);
    // The same texels under another name share the tables.
    std::fs::copy(case.path("a.hdr"), case.path("copy.hdr")).unwrap();
    let copy = case.render(Some(&case.cache()), "copy.exr", &["--env", &env("copy.hdr")]);
    assert!(loaded(&copy).1, "the copy's tables come from the cache: {}", stderr(&copy));
    assert!(case.pixels("copy.exr") == case.pixels("a1.exr"));
    assert!(case.pixels("a1.exr") != case.pixels("b1.exr"));
}

#[test]
fn damaged_cache_files_are_ignored_and_made_again() {
    let case = Case::new();
    case.render(Some(&case.cache()), "reference.exr", &[]);
    let reference = case.pixels("reference.exr");
    let files =
        [case.file("pipelines", ".bin"), case.file("environments", ".tables"), case.file("environments", ".texels")];
    type Damage = fn(&Path);
    let damages: [(&str, Damage); 5] = [
        ("truncated", |p| {
            let len = std::fs::metadata(p).unwrap().len();
            std::fs::OpenOptions::new().write(true).open(p).unwrap().set_len(len / 2).unwrap();
        }),
        ("a flipped byte", |p| {
            let mut bytes = std::fs::read(p).unwrap();
            let at = bytes.len() - 5;
            bytes[at] ^= 0x40;
            std::fs::write(p, bytes).unwrap();
        }),
        ("empty", |p| std::fs::write(p, b"").unwrap()),
        ("not a cache file", |p| std::fs::write(p, b"P6\n1 1\n255\n\0\0\0").unwrap()),
        // Sparse, so the test writes nothing: larger than any cache file may be.
        ("oversized", |p| std::fs::OpenOptions::new().write(true).open(p).unwrap().set_len(600 << 20).unwrap()),
    ];
    for (what, damage) in damages {
        for file in &files {
            damage(file);
        }
        let output = case.render(Some(&case.cache()), &format!("{}.exr", what.replace(' ', "_")), &[]);
        assert!(case.pixels(&format!("{}.exr", what.replace(' ', "_"))) == reference, "{what}: the image changed");
        let warned = warnings(&output);
        assert!(warned.len() <= 1, "{what}: one warning at most: {warned:?}");
        assert!(warned.iter().all(|w| w.contains("ignoring the cache file")), "{what}: {warned:?}");
        assert_eq!(loaded(&output), (false, false, false), "{what}: damaged files are not used: {}", stderr(&output));
        // Written again, whole: the next run takes all three from the cache.
        let again = case.render(Some(&case.cache()), "again.exr", &[]);
        assert_eq!(loaded(&again), (true, true, true), "{what}: made again: {}", stderr(&again));
        assert!(warnings(&again).is_empty(), "{what}: {:?}", warnings(&again));
    }
}

/// An entry whose payload hash is right is still checked as strictly as the input it stands
/// for: NaN in a table once rendered another image, and NaN texels once made lookdev blame the
/// intact environment file.
#[test]
fn crafted_entries_with_a_right_hash_are_checked_like_their_input() {
    let case = Case::new();
    let env = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/environment/sunrise.exr");
    let env = env.to_str().unwrap();
    // Its few negative texels (from lossy compression) are clamped, on every load.
    case.render(Some(&case.cache()), "reference.exr", &["--env", env, "--env-clamp"]);
    let reference = case.pixels("reference.exr");
    // Replaces the payload's 4 bytes at `at` (from its end) with `value` and fixes the hash.
    let craft = |file: &Path, from_end: usize, value: f32| {
        let mut bytes = std::fs::read(file).unwrap();
        let key = u32::from_le_bytes(bytes[20..24].try_into().unwrap()) as usize;
        let at = bytes.len() - from_end;
        bytes[at..at + 4].copy_from_slice(&value.to_le_bytes());
        let hash = lookdev::cache::hash128(&bytes[48 + key..]);
        bytes[32..48].copy_from_slice(&hash);
        std::fs::write(file, bytes).unwrap();
    };
    let tables = case.file("environments", ".tables");
    let texels = case.file("environments", ".texels");
    assert!(texels.file_name().unwrap().to_string_lossy().starts_with("file-"), "{texels:?}");
    // The last cell's pdf, and a texel near the end.
    craft(&tables, 4, f32::NAN);
    craft(&texels, 40, f32::NAN);
    let output = case.render(Some(&case.cache()), "crafted.exr", &["--env", env, "--env-clamp"]);
    assert!(case.pixels("crafted.exr") == reference, "the crafted entries changed the image");
    assert!(!loaded(&output).1, "the crafted tables are not used: {}", stderr(&output));
    assert!(!stderr(&output).contains("loaded from"), "nothing crafted is used: {}", stderr(&output));
    assert!(!stderr(&output).contains("error"), "{}", stderr(&output));
}

#[test]
fn a_cache_folder_that_cannot_be_written_does_not_fail_the_render() {
    let case = Case::new();
    // A file where the folder should be: nothing can be created under it, whoever runs this.
    std::fs::write(case.path("not-a-folder"), b"").unwrap();
    let blocked = case.render(Some(&case.path("not-a-folder")), "blocked.exr", &[]);
    assert!(warnings(&blocked).is_empty(), "{:?}", warnings(&blocked));
    assert!(stderr(&blocked).contains("cache: cannot write"), "timings say why: {}", stderr(&blocked));
    assert!(stderr(&blocked).contains("driver shader cache off"), "{}", stderr(&blocked));
    assert_only_lookdev_speaks(&blocked);
    let none = case.render(None, "none.exr", &[]);
    assert_only_lookdev_speaks(&none);
    assert!(case.pixels("blocked.exr") == case.pixels("none.exr"));
}

/// Every line on stderr is lookdev's own: the driver's ("… for shader cache (not a
/// directory)---disabling") once reached it where the docs promise silence.
fn assert_only_lookdev_speaks(output: &Output) {
    let text = stderr(output);
    assert!(text.lines().all(|l| l.starts_with("lookdev: ")), "a line that is not lookdev's:\n{text}");
}

/// A cache folder on a full file system: the driver's shader cache, which maps its files into
/// memory, once killed every command there with SIGBUS (exit 135, no message). Needs a tmpfs,
/// so root (as CI runs); elsewhere it says so and passes.
#[test]
fn a_full_cache_file_system_does_not_fail_the_render() {
    let case = Case::new();
    let full = case.path("full");
    std::fs::create_dir(&full).unwrap();
    let mounted = Command::new("mount").args(["-t", "tmpfs", "-o", "size=512k", "tmpfs"]).arg(&full).output();
    if !mounted.is_ok_and(|o| o.status.success()) {
        assert!(
            std::env::var_os("CI").is_none() || unsafe { libc::geteuid() } != 0,
            "CI runs as root: mount must work"
        );
        eprintln!("skipped: cannot mount a tmpfs here");
        return;
    }
    struct Unmount(PathBuf);
    impl Drop for Unmount {
        fn drop(&mut self) {
            let _ = Command::new("umount").arg(&self.0).status();
        }
    }
    let _unmount = Unmount(full.clone());
    // Fill it to the last byte.
    let mut filler = std::fs::File::create(full.join("filler")).unwrap();
    let block = vec![0u8; 4096];
    while std::io::Write::write_all(&mut filler, &block).is_ok() {}
    let _ = std::io::Write::write_all(&mut filler, &[0]);
    drop(filler);
    let output = case.render(Some(&full), "full.exr", &[]);
    assert!(stderr(&output).contains("driver shader cache off"), "{}", stderr(&output));
    assert_only_lookdev_speaks(&output);
}
