//! `lookdev look default`: the built-in default look, written out to start a look from.

use crate::material::Look;
use crate::Result;
use clap::{Args, Subcommand};
use std::io::Write;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct LookArgs {
    #[command(subcommand)]
    pub command: LookCommand,
}

#[derive(Subcommand, Debug)]
pub enum LookCommand {
    /// Write the built-in default look (the one `lookdev render` shows without --look) to
    /// stdout, or to a file.
    Default {
        /// Write here (atomically) instead of to stdout; an existing file is kept unless --force.
        #[arg(long, value_name = "FILE.toml")]
        out: Option<PathBuf>,
        /// Replace an existing --out file.
        #[arg(long, requires = "out")]
        force: bool,
    },
}

pub fn run(args: LookArgs) -> Result<()> {
    let LookCommand::Default { out, force } = args.command;
    let text = Look::builtin_default_text();
    match out {
        Some(path) if force => crate::atomic_file::write(&path, text.as_bytes()),
        Some(path) => crate::atomic_file::write_new(&path, text.as_bytes()),
        None => {
            let mut stdout = std::io::stdout().lock();
            stdout
                .write_all(text.as_bytes())
                .and_then(|_| stdout.flush())
                .map_err(|e| crate::Error::io("stdout", format!("cannot write the look: {e}")))
        }
    }
}
