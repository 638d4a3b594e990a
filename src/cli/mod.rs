//! The command line: `lookdev render | gbuffer | bake | import | presets | wedge | turntable | view | lint | brdf |
//! bench | devices | look`.

mod bake;
mod bench;
mod bench_adaptive;
mod bench_convergence;
mod bench_interactive;
mod brdf;
mod gbuffer;
mod import;
mod inputs;
mod lint;
mod look;
mod presets;
pub(crate) mod progress;
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
    /// Looks: `lookdev look default` writes the built-in default look out, to start one from.
    Look(look::LookArgs),
}

/// The command line, parsed: a command to run, or text clap prints (help, the version).
pub enum Parsed {
    Run(Box<Cli>),
    Print(clap::Error),
}

/// Parses the arguments without running anything: the command with its flags' values checked
/// ([`check`]), help or version text, or the one-line error.
pub fn parse(args: impl IntoIterator<Item = std::ffi::OsString>) -> Result<Parsed> {
    let args: Vec<std::ffi::OsString> = args.into_iter().collect();
    let cli = match Cli::try_parse_from(&args) {
        Ok(cli) => cli,
        Err(e)
            if matches!(
                e.kind(),
                clap::error::ErrorKind::DisplayHelp
                    | clap::error::ErrorKind::DisplayVersion
                    | clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) =>
        {
            return Ok(Parsed::Print(e))
        }
        Err(e) if e.kind() == clap::error::ErrorKind::InvalidUtf8 => {
            // clap does not say which; name it, as the shell would show it.
            let (index, arg) = args.iter().enumerate().find(|(_, a)| a.to_str().is_none()).unwrap_or((0, &args[0]));
            return Err(Error::input(format!("argument {index} '{}' is not valid UTF-8", arg.to_string_lossy())));
        }
        Err(e) => return Err(Error::input(format!("{} (see lookdev --help)", clap_problem(&e)))),
    };
    check(&cli.command)?;
    Ok(Parsed::Run(Box::new(cli)))
}

/// Checks the values of a command's flags that need no file and no device, so that a bad one is
/// refused before anything is read or started.
pub fn check(command: &Command) -> Result<()> {
    match command {
        Command::Render(a) => a.scene.check(&a.aovs),
        Command::Turntable(a) => a.scene.check(&a.aovs),
        Command::View(a) => a.scene.check(&[]),
        Command::Bake(a) => bake::check(a),
        Command::Presets(a) => presets::check(a),
        _ => Ok(()),
    }
}

/// Runs `run`, turning a panic into an [`ErrorKind::Internal`](crate::ErrorKind) error: every
/// input is validated before use, so a panic is a defect, and even a defect ends in one line.
/// `place` gives where the panic happened, when a panic hook recorded it.
pub fn catching_panics(run: impl FnOnce() -> Result<()>, place: impl FnOnce() -> Option<String>) -> Result<()> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)) {
        Ok(result) => result,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic".to_string());
            Err(Error::internal(match place() {
                Some(place) => format!("{what} at {place}"),
                None => what,
            }))
        }
    }
}

/// Parses the arguments and runs the command; the caller turns the error into an exit code.
pub fn run(args: impl IntoIterator<Item = std::ffi::OsString>) -> Result<()> {
    let cli = match parse(args)? {
        Parsed::Run(cli) => cli,
        Parsed::Print(text) => text.exit(),
    };
    // This process is one command: what it reads are its inputs, which no output may replace.
    crate::input::track_inputs();
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
        Command::Look(args) => look::run(args),
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
    let param = Param::parse(name.trim()).map_err(|e| Error::input(format!("--set {text}: {e}")))?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_one_line_naming_it_a_defect() {
        let error = catching_panics(|| panic!("index out of bounds"), || Some("src/x.rs:3".into())).unwrap_err();
        assert_eq!(error.exit_code(), 1);
        assert_eq!(
            error.to_string(),
            "internal error (index out of bounds at src/x.rs:3); this is a defect of lookdev, please report it"
        );
        assert_eq!(catching_panics(|| Err(Error::input("bad")), || None).unwrap_err().exit_code(), 2);
    }

    /// No two of a command's flags share a long name: a flattened group of flags would
    /// otherwise shadow another silently (clap checks this only in debug builds).
    #[test]
    fn no_two_flags_of_a_command_share_a_name() {
        fn check(command: &clap::Command, path: &str) {
            let mut seen = std::collections::HashSet::new();
            for long in command.get_arguments().filter_map(|a| a.get_long()) {
                assert!(seen.insert(long), "{path}: --{long} is declared twice");
            }
            for sub in command.get_subcommands() {
                check(sub, &format!("{path} {}", sub.get_name()));
            }
        }
        use clap::CommandFactory;
        check(&Cli::command(), "lookdev");
    }
}
