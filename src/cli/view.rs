//! `lookdev view`: the interactive viewer.

use super::inputs::SceneArgs;
use crate::{Error, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ViewArgs {
    /// The look to open (default: the built-in default look on the built-in shader ball, or the
    /// default material on a g-buffer).
    #[arg(value_name = "LOOK.toml")]
    pub look: Option<PathBuf>,
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Vulkan device to use: part of its name (lavapipe is "llvmpipe").
    #[arg(long, value_name = "NAME")]
    pub device: Option<String>,
    /// The window's size in logical pixels.
    #[arg(long, num_args = 2, value_names = ["W", "H"])]
    pub window_size: Option<Vec<u32>>,
    /// The zoom the image opens at: `fit` (the default; magnifies a small image) or window pixels
    /// per image pixel (`1` for 1:1).
    #[arg(long, value_name = "fit|SCALE")]
    pub zoom: Option<String>,
    /// Save the window as a PNG once --exit-after-spp is reached.
    #[arg(long, value_name = "FILE.png", requires = "exit_after_spp")]
    pub screenshot: Option<PathBuf>,
    /// Render until every pixel has N samples (after the script, if any), then exit. N becomes
    /// the target spp.
    #[arg(long, value_name = "N")]
    pub exit_after_spp: Option<u32>,
    /// Run interface actions from a file, one per line (see docs/commands.md).
    #[arg(long, value_name = "FILE")]
    pub script: Option<PathBuf>,
    /// Open with an A/B split: B is the look under its model with KEY=VALUE changed (the keys of
    /// --model; repeatable).
    #[arg(long = "compare-model", value_name = "KEY=VALUE", conflicts_with = "compare_look")]
    pub compare_model: Vec<String>,
    /// Open with an A/B split: B is this look (its stacks and model, A's lighting and settings).
    #[arg(long, value_name = "B.toml")]
    pub compare_look: Option<PathBuf>,
    /// Adaptive sampling as the accumulation's target: it stops once every pixel's estimated
    /// relative error is below --noise-threshold (or at the target spp).
    #[command(flatten)]
    pub adaptive: super::render::AdaptiveArgs,
}

pub fn run(args: ViewArgs) -> Result<()> {
    if args.exit_after_spp == Some(0) {
        return Err(Error::input("--exit-after-spp 0: the sample count must be at least 1"));
    }
    if let Some(path) = &args.screenshot {
        crate::render::output::OutputFormat::from_path(path)
            .ok()
            .filter(|f| *f == crate::render::output::OutputFormat::Png)
            .ok_or_else(|| Error::input_file(path, "a screenshot is a .png file"))?;
    }
    let window_size = match args.window_size.as_deref() {
        None => DEFAULT_WINDOW_SIZE,
        Some(&[w, h]) if (320..=16384).contains(&w) && (240..=16384).contains(&h) => (w, h),
        Some(size) => {
            return Err(Error::input(format!("--window-size {size:?}: the window must be 320x240 to 16384x16384")));
        }
    };
    #[cfg(feature = "viewer")]
    if let Some(zoom) = &args.zoom {
        crate::viewer::zoom(zoom).map_err(|problem| Error::input(format!("--zoom: {problem}")))?;
    }
    let mut model = crate::shading::model::Model::default();
    for key in &args.compare_model {
        model.set_from_flag("--compare-model", key).map_err(Error::input)?;
    }
    let mut scene = args.scene.spec(args.look.as_deref(), &[], false)?;
    args.adaptive.apply(&mut scene.overrides);
    open(args, scene, window_size)
}

#[cfg(feature = "viewer")]
const DEFAULT_WINDOW_SIZE: (u32, u32) = crate::viewer::DEFAULT_WINDOW_SIZE;
#[cfg(not(feature = "viewer"))]
const DEFAULT_WINDOW_SIZE: (u32, u32) = (1600, 960);

#[cfg(feature = "viewer")]
fn open(args: ViewArgs, scene: crate::render::scene::SceneSpec, window_size: (u32, u32)) -> Result<()> {
    let script = args.script.as_deref().map(crate::viewer::Script::load).transpose()?;
    crate::viewer::run(crate::viewer::ViewOptions {
        scene,
        device: args.device,
        window_size,
        zoom: args.zoom.as_deref().map(crate::viewer::zoom).transpose().map_err(Error::input)?.flatten(),
        screenshot: args.screenshot,
        exit_after_spp: args.exit_after_spp,
        script,
        compare_model: args.compare_model,
        compare_look: args.compare_look,
    })
}

#[cfg(not(feature = "viewer"))]
fn open(_args: ViewArgs, _scene: crate::render::scene::SceneSpec, _window_size: (u32, u32)) -> Result<()> {
    Err(Error::input("this lookdev was built without the viewer: rebuild with the default `viewer` feature"))
}
