//! The viewer's test bench: a folder with the built-in shader ball as a g-buffer and a look, a
//! virtual X server, and runs of `lookdev view` on them at 1:1, with the image cut out of the
//! window's screenshot.

use super::display::{xvfb, XServer};
use image::RgbImage;
use lookdev::gbuffer::GBuffer;
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// G-buffer size and window size: small enough for a CPU driver, with the image at 1:1.
pub const SIZE: u32 = 160;
pub const WINDOW: [&str; 2] = ["960", "680"];
/// A viewer run that takes longer than this has hung.
pub const HANG: Duration = Duration::from_secs(300);

/// Ball (object 1): blue rubber with gold in the stripes; pedestal: the default stack.
pub const LOOK: &str = r#"
[environment]
rotation = -90.0

[[object]]
[[object.layer]]
preset = "white-ceramic"

[[object]]
id = 1
[[object.layer]]
preset = "blue-rubber"
[[object.layer]]
preset = "gold"
mask = "stripes"
[object.layer.set]
roughness = 0.3
"#;

/// A folder of inputs and outputs, and a display to open windows on.
pub struct Case {
    pub dir: tempfile::TempDir,
    pub x: XServer,
}

impl Case {
    /// Linear radiance of an EXR in the case's folder (one the viewer or `lookdev render`
    /// wrote), as bits, row by row.
    pub fn exr_bits(&self, name: &str) -> Vec<[u32; 4]> {
        super::cli::exr_bits(&self.path(name))
    }

    pub fn new() -> Option<Case> {
        let x = xvfb()?;
        let case = Case { dir: tempfile::tempdir().unwrap(), x };
        GBuffer::shaderball(SIZE, SIZE).write(&case.path("g.exr")).unwrap();
        std::fs::create_dir(case.path("presets")).unwrap();
        case.write("look.toml", LOOK);
        Some(case)
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    pub fn arg(&self, name: &str) -> String {
        self.path(name).to_string_lossy().into_owned()
    }

    pub fn write(&self, name: &str, text: &str) -> String {
        let path = self.path(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, text).unwrap();
        self.arg(name)
    }

    pub fn command(&self, args: &[&str]) -> Command {
        let mut command = Command::new(env!("CARGO_BIN_EXE_lookdev"));
        command
            .args(args)
            .current_dir(self.dir.path())
            .env("DISPLAY", &self.x.display)
            .env_remove("WAYLAND_DISPLAY")
            .env("LOOKDEV_VALIDATION", "1")
            .env("LOOKDEV_PRESETS", self.path("presets"))
            .env("XDG_CACHE_HOME", self.path("cache"))
            .env("XDG_CONFIG_HOME", self.path("config"));
        command
    }

    /// Runs the viewer on the case's g-buffer; a run past [`HANG`] is killed and fails.
    pub fn view(&self, args: &[&str]) -> Output {
        self.view_with_env(args, &[])
    }

    /// [`Case::view`] with the environment variables `env` set.
    pub fn view_with_env(&self, args: &[&str], env: &[(&str, &str)]) -> Output {
        let mut all = vec!["view", "--gbuffer", "g.exr", "--window-size", WINDOW[0], WINDOW[1], "--zoom", "1"];
        all.extend_from_slice(args);
        let mut command = self.command(&all);
        command.envs(env.iter().copied());
        let mut child = command.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
        let start = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if start.elapsed() > HANG {
                child.kill().unwrap();
                panic!("the viewer hung: {:?}", child.wait_with_output().unwrap());
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        child.wait_with_output().unwrap()
    }

    /// `lookdev render` of the case's g-buffer to a PNG.
    pub fn render(&self, look: &str, spp: u32, out: &str) -> RgbImage {
        let spp = spp.to_string();
        let args = ["render", "--gbuffer", "g.exr", "--look", look, "--spp", &spp, "--quiet", "--out", out];
        let output = self.command(&args).output().unwrap();
        assert_success(&output);
        image::open(self.path(out)).unwrap().into_rgb8()
    }

    /// The image part of a screenshot the viewer reported taking.
    pub fn screenshot_image(&self, output: &Output, name: &str) -> RgbImage {
        let Placement { x, y, width, height, scale } = placement(output, name);
        assert_eq!((width, height, scale), (SIZE as f32, SIZE as f32, 1.0), "the image is shown 1:1 in {name}");
        let window = image::open(self.path(name)).unwrap().into_rgb8();
        image::imageops::crop_imm(&window, x as u32, y as u32, SIZE, SIZE).to_image()
    }
}

/// Where a screenshot's report line says the image sits in the window, in window pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub x: f32,
    pub y: f32,
    pub width: f32,
    pub height: f32,
    pub scale: f32,
}

/// The placement the viewer reported for screenshot `name`:
/// `lookdev: screenshot NAME (… the image is at X,Y size WxH scale S; …)`.
pub fn placement(output: &Output, name: &str) -> Placement {
    let stdout = String::from_utf8_lossy(&output.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("lookdev: screenshot") && l.contains(name))
        .unwrap_or_else(|| panic!("no screenshot {name} reported: {stdout}"));
    let at = line.split("the image is at ").nth(1).expect("the placement is reported");
    let numbers: Vec<f32> = at
        .split([';', ')'])
        .next()
        .unwrap()
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect();
    let [x, y, width, height, scale] = numbers[..] else { panic!("bad placement: {line}") };
    Placement { x, y, width, height, scale }
}

pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

pub fn assert_success(output: &Output) {
    let text = stderr(output);
    assert!(output.status.success(), "failed ({:?}): {text}", output.status.code());
    assert!(!text.contains("validation error") && !text.contains("panicked"), "{text}");
}

/// Largest and mean absolute difference of two images, in 8-bit steps.
pub fn difference(a: &RgbImage, b: &RgbImage) -> (u8, f64) {
    assert_eq!(a.dimensions(), b.dimensions());
    let diffs: Vec<u8> = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| x.abs_diff(*y)).collect();
    let mean = diffs.iter().map(|&d| d as f64).sum::<f64>() / diffs.len() as f64;
    (*diffs.iter().max().unwrap(), mean)
}

/// The screenshot shows what `lookdev render` makes: the display image is sampled through an
/// sRGB view and drawn into an sRGB window, a round trip that may move a channel by one step on some devices.
pub fn assert_matches_render(shot: &RgbImage, render: &RgbImage) {
    let (max, mean) = difference(shot, render);
    assert!(max <= 1 && mean < 0.05, "screenshot differs from lookdev render: max {max}, mean {mean:.3}");
}

pub fn assert_differs(a: &RgbImage, b: &RgbImage, what: &str) {
    let (_, mean) = difference(a, b);
    assert!(mean > 2.0, "{what}: the images should differ, mean difference {mean:.3}");
}
