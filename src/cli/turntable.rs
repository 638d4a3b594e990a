//! `lookdev turntable`: the environment rotated through 360°, one image per frame.
//!
//! Frames are numbered from 1; frame f of N turns the environment by (f − 1)·360°/N on top of
//! the look's rotation. Every frame is rendered from scratch with the same seed, so frames from
//! different machines with the same device and driver (and any `--range` split) match a single
//! run bit for bit.

use super::inputs::SceneArgs;
use super::progress::Progress;
use crate::gpu::{Context, ContextOptions};
use crate::render::aov;
use crate::render::batch::Batch;
use crate::render::output::{self, Metadata, OutputFormat};
use crate::render::renderer::{KernelSource, Specialization};
use crate::render::scene::Scene;
use crate::render::startup::{self, Started};
use crate::{Error, Result};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct TurntableArgs {
    #[arg(long, value_name = "FILE.toml")]
    pub look: Option<PathBuf>,
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Frames in the full turn, 1 to 10800.
    #[arg(long)]
    pub frames: u32,
    /// Write an AOV beside the beauty in EXR frames (repeatable), as `render --aov` does.
    #[arg(long = "aov", value_name = "NAME")]
    pub aovs: Vec<String>,
    /// The frames to render, A-B inclusive or one frame A, numbered from 1 (default: all).
    #[arg(long, value_name = "A-B|A")]
    pub range: Option<String>,
    #[arg(long, value_name = "NAME")]
    pub device: Option<String>,
    #[arg(long, short)]
    pub quiet: bool,
    /// Output path with a frame-number pattern, e.g. out/turn_%04d.png (or .exr).
    #[arg(long, value_name = "DIR/NAME_%04d.png")]
    pub out: String,
    #[command(flatten)]
    pub adaptive: super::render::AdaptiveArgs,
}

/// The most frames a turntable has: a frame a degree at 1/30 of a degree, far beyond any real
/// turn, and a bound on the loop over them.
pub const MAX_FRAMES: u32 = 10_800;

/// A printf-style frame pattern: the text around one `%d` or `%0Nd`.
#[derive(Debug, PartialEq)]
pub struct FramePattern {
    prefix: String,
    width: usize,
    suffix: String,
}

impl FramePattern {
    pub fn parse(text: &str) -> Result<FramePattern> {
        let bad = || Error::input(format!("--out {text}: needs one frame number pattern such as %04d"));
        let start = text.find('%').ok_or_else(bad)?;
        let rest = &text[start + 1..];
        let end = rest.find('d').ok_or_else(bad)?;
        let digits = &rest[..end];
        let width = if digits.is_empty() { 0 } else { digits.parse::<usize>().map_err(|_| bad())? };
        let suffix = &rest[end + 1..];
        if suffix.contains('%') || width > 12 {
            return Err(bad());
        }
        Ok(FramePattern { prefix: text[..start].to_string(), width, suffix: suffix.to_string() })
    }

    pub fn path(&self, frame: u32) -> PathBuf {
        PathBuf::from(format!("{}{:0width$}{}", self.prefix, frame, self.suffix, width = self.width))
    }
}

/// Parses `A-B` (inclusive, 1-based), or a single frame `A`, against `frames`.
pub fn parse_range(text: &str, frames: u32) -> Result<(u32, u32)> {
    let bad = || Error::input(format!("--range {text}: expected A-B with 1 <= A <= B <= {frames}, or one frame A"));
    let (a, b) = text.split_once('-').unwrap_or((text, text));
    let (a, b): (u32, u32) = (a.trim().parse().map_err(|_| bad())?, b.trim().parse().map_err(|_| bad())?);
    if a < 1 || a > b || b > frames {
        return Err(bad());
    }
    Ok((a, b))
}

pub fn run(args: TurntableArgs) -> Result<()> {
    if args.frames == 0 || args.frames > MAX_FRAMES {
        return Err(Error::input(format!("--frames {}: a turntable has 1 to {MAX_FRAMES} frames", args.frames)));
    }
    let pattern = FramePattern::parse(&args.out)?;
    let format = OutputFormat::from_path(&pattern.path(1))?;
    let (first, last) = match &args.range {
        Some(text) => parse_range(text, args.frames)?,
        None => (1, args.frames),
    };
    if let Some(dir) = pattern.path(1).parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, format!("cannot create the output folder: {e}")))?;
    }
    let mut spec = args.scene.spec(args.look.as_deref(), &args.aovs, args.quiet)?;
    args.adaptive.apply(&mut spec.overrides);
    // The device opens while the scene loads, and the kernels compile while the scene uploads
    // (crate::render::startup).
    let options = ContextOptions::from_env(args.device.clone());
    std::thread::scope(|threads| {
        let specialize = |scene: &Scene| Specialization::of_render(scene, aov::accumulate(&scene.settings.aovs));
        let Started { scene, ctx, kernels } = startup::start(threads, &spec, options, specialize)?;
        // Every input is read by now: refuse before the first frame, not at one.
        for frame in first..=last {
            crate::input::refuse_replacing_input(&pattern.path(frame))?;
        }
        let counter = ctx.validation_counter();
        scene.check_device(ctx.info())?;
        render_frames(&args, &scene, &ctx, KernelSource::Pending(kernels), &pattern, format, (first, last))?;
        drop(ctx);
        super::check_validation(&counter)
    })
}

/// Renders and writes the frames `first..=last` of `scene`.
fn render_frames(
    args: &TurntableArgs,
    scene: &Scene,
    ctx: &Context,
    kernels: KernelSource,
    pattern: &FramePattern,
    format: OutputFormat,
    (first, last): (u32, u32),
) -> Result<()> {
    {
        let (gbuffer_name, sampling) = (Path::new(&scene.gbuffer_name), scene.settings.sampling);
        let mut batch = Batch::with_kernels(ctx, &scene.gbuffer, gbuffer_name, &scene.environment, sampling, kernels)?;
        batch.set_backdrop(&scene.backdrop)?;
        let (width, height) = (batch.width(), batch.height());
        for frame in first..=last {
            let mut settings = scene.settings.clone();
            settings.lighting.rotation_degrees += (frame - 1) as f32 * 360.0 / args.frames as f32;
            let label = format!("frame {frame}/{}", args.frames);
            let mut progress = Progress::new(settings.spp as u64, label.clone(), args.quiet);
            batch.render(&scene.look, &settings, |done| progress.update(done as u64))?;
            progress.finish();
            let path = pattern.path(frame);
            match format {
                OutputFormat::Exr => {
                    let metadata = Metadata::of_render(&scene.look, &settings, &scene.environment, &scene.recorded);
                    let aovs = batch.aovs(&scene.look, &settings)?;
                    let radiance = batch.radiance()?;
                    let background = settings.lighting.background;
                    output::write_exr_with(&path, width, height, &radiance, background, aovs, &metadata.entries)?
                }
                OutputFormat::Png => {
                    output::check_finite(&path, &batch.radiance()?)?;
                    output::write_png(&path, width, height, &batch.display(&settings)?, !settings.lighting.background)?
                }
            }
            if !args.quiet {
                eprintln!("lookdev: {label}: wrote {}", path.display());
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_patterns_and_ranges() {
        let p = FramePattern::parse("out/turn_%04d.png").unwrap();
        assert_eq!(p.path(7), PathBuf::from("out/turn_0007.png"));
        assert_eq!(FramePattern::parse("f%d.exr").unwrap().path(12), PathBuf::from("f12.exr"));
        assert!(FramePattern::parse("no_pattern.png").is_err());
        assert!(FramePattern::parse("a%04d_%04d.png").is_err());
        assert_eq!(parse_range("3-5", 10).unwrap(), (3, 5));
        assert_eq!(parse_range("3", 10).unwrap(), (3, 3));
        assert!(parse_range("11", 10).is_err());
        assert!(parse_range("0-5", 10).is_err());
        assert!(parse_range("5-3", 10).is_err());
        assert!(parse_range("5-11", 10).is_err());
    }
}
