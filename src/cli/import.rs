//! `lookdev import`: a glTF asset's materials as presets and a look.

use crate::asset::import::Import;
use crate::asset::Asset;
use crate::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ImportArgs {
    /// The asset: a .gltf (with its buffers and images) or a .glb.
    #[arg(value_name = "MODEL.gltf|.glb")]
    pub model: PathBuf,
    /// The folder the presets are written to, one `<material>.toml` each (created if needed).
    #[arg(long, value_name = "DIR")]
    pub presets: PathBuf,
    /// The look that layers the presets through the bake's masks.
    #[arg(long, value_name = "LOOK.toml")]
    pub look: PathBuf,
    /// The g-buffer baked from the same model (`lookdev bake`), recorded as the look's
    /// `[gbuffer] file`, relative to the look, so that the look opens on it.
    #[arg(long, value_name = "G.exr")]
    pub gbuffer: Option<PathBuf>,
    /// Replace presets and a look that already exist.
    #[arg(long)]
    pub force: bool,
    /// No summary.
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: ImportArgs) -> Result<()> {
    let asset = Asset::load_with(&args.model, crate::asset::Texels::Check)?;
    let import = Import::new(&asset)?;
    if !import.unsupported.is_empty() {
        crate::warn(format!(
            "{}: ignoring unsupported extensions: {}",
            args.model.display(),
            import.unsupported.join(", ")
        ));
    }
    if let Some(gbuffer) = args.gbuffer.as_deref().filter(|g| !g.is_file()) {
        crate::warn(format!("{}: not there yet; bake it before rendering the look", gbuffer.display()));
    }
    let written = import.write(&asset, &args.presets, &args.look, args.gbuffer.as_deref(), args.force)?;
    if !args.quiet {
        for material in &import.materials {
            let notes = if material.mapped.notes.is_empty() {
                String::new()
            } else {
                format!(": {}", material.mapped.notes.join("; "))
            };
            eprintln!(
                "lookdev: {}",
                crate::printable(&format!("'{}' -> preset {}{notes}", material.used.label, material.preset.name))
            );
        }
        eprintln!("lookdev: wrote {} files, the look {}", written.len(), args.look.display());
    }
    Ok(())
}
