//! The command line: `lookdev render | gbuffer | bake | import | presets | wedge | turntable | view | lint | brdf |
//! bench | devices`.

mod bake;
mod bench;
mod brdf;
mod gbuffer;
mod import;
mod inputs;
mod lint;
mod presets;
mod progress;
mod render;
mod turntable;
mod view;
mod wedge;

use crate::gpu::ContextOptions;
use crate::material::params::{parse_value, Param, Value};
use crate::{Error, Result};
use clap::{Parser, Subcommand};

/// lookdev: relight stored g-buffers with Disney principled layer stacks under image-based light.
#[derive(Parser, Debug)]
#[command(name = "lookdev", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a g-buffer (the built-in shader ball by default) to a PNG or EXR.
    Render(render::RenderArgs),
    /// Write the built-in look-dev g-buffer to an EXR.
    Gbuffer(gbuffer::GbufferArgs),
    /// Rasterize a glTF asset into a g-buffer: normals, tangents, view vectors, ids, masks, and
    /// maps of its textures.
    Bake(bake::BakeArgs),
    /// Write a glTF asset's materials as presets, and a look that layers them through the
    /// bake's masks and binds its maps.
    Import(import::ImportArgs),
    /// The preset library: list, show, save, and a contact sheet of every preset.
    Presets(presets::PresetsArgs),
    /// Render a look once per value of a parameter, as labelled rows.
    Wedge(wedge::WedgeArgs),
    /// Render the look with the environment turning through 360°, one image per frame.
    Turntable(turntable::TurntableArgs),
    /// Open the interactive viewer: edit layer stacks and turn the light while it renders.
    View(view::ViewArgs),
    /// Check a look's materials for implausible values.
    Lint(lint::LintArgs),
    /// BRDF Explorer-style plots of materials under BRDF models: slice, albedo, polar, furnace.
    Brdf(brdf::BrdfArgs),
    /// Measure relighting throughput on the built-in scene.
    Bench(bench::BenchArgs),
    /// List the Vulkan devices lookdev can use, best first.
    Devices,
}

/// Parses the arguments and runs the command; the caller turns the error into an exit code.
pub fn run(args: impl IntoIterator<Item = std::ffi::OsString>) -> Result<()> {
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e)
            if matches!(
                e.kind(),
                clap::error::ErrorKind::DisplayHelp
                    | clap::error::ErrorKind::DisplayVersion
                    | clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) =>
        {
            e.exit()
        }
        Err(e) => return Err(Error::input(format!("{} (see lookdev --help)", clap_problem(&e)))),
    };
    match cli.command {
        Command::Render(args) => render::run(args),
        Command::Gbuffer(args) => gbuffer::run(args),
        Command::Bake(args) => bake::run(args),
        Command::Import(args) => import::run(args),
        Command::Presets(args) => presets::run(args),
        Command::Wedge(args) => wedge::run(args),
        Command::Turntable(args) => turntable::run(args),
        Command::View(args) => view::run(args),
        Command::Lint(args) => lint::run(args),
        Command::Brdf(args) => brdf::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Devices => list_devices(),
    }
}

/// clap's error on one line: its first line, the arguments it lists on the lines below (the
/// missing required ones), and its suggestion for a misspelled flag, subcommand or value.
fn clap_problem(e: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue};
    let text = e.render().to_string();
    let first = text.lines().next().unwrap_or("invalid arguments").trim_start_matches("error: ");
    let mut problem = match (e.kind(), e.get(ContextKind::InvalidArg)) {
        (clap::error::ErrorKind::MissingRequiredArgument, Some(ContextValue::Strings(missing))) => {
            format!("the following required arguments were not provided: {}", missing.join(", "))
        }
        _ => first.to_string(),
    };
    let suggested = [ContextKind::SuggestedArg, ContextKind::SuggestedSubcommand, ContextKind::SuggestedValue]
        .into_iter()
        .find_map(|kind| match e.get(kind) {
            Some(ContextValue::String(s)) => Some(s.clone()),
            Some(ContextValue::Strings(s)) if !s.is_empty() => Some(s.join("' or '")),
            _ => None,
        });
    if let Some(suggested) = suggested {
        problem.push_str(&format!("; did you mean '{suggested}'?"));
    }
    problem
}

fn list_devices() -> Result<()> {
    for (name, kind) in crate::gpu::context::list_devices()? {
        println!("{name} ({kind})");
    }
    Ok(())
}

/// Parses `NAME=VALUE` for `--set`.
pub fn parse_set(text: &str) -> Result<(Param, Value)> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| Error::input(format!("--set {text}: expected NAME=VALUE, e.g. roughness=0.3")))?;
    let param = Param::from_name(name.trim()).ok_or_else(|| {
        let names = Param::ALL.map(Param::name);
        Error::input(format!("--set {text}: {}", crate::material::unknown_key("parameter", name.trim(), "", &names)))
    })?;
    let value = parse_value(param, value).map_err(|e| Error::input(format!("--set {text}: {e}")))?;
    Ok((param, value))
}

/// A Vulkan context for a command, validated when `LOOKDEV_VALIDATION=1`.
fn context(device: Option<String>) -> Result<crate::gpu::Context> {
    crate::gpu::Context::new(&ContextOptions::from_env(device))
}

/// After a command's GPU work is dropped: with validation on, any validation error fails it.
fn check_validation(counter: &crate::gpu::context::ValidationCounter) -> Result<()> {
    match counter.errors() {
        0 => Ok(()),
        n => Err(Error::gpu(format!("Vulkan validation reported {n} error(s); see above"))),
    }
}
