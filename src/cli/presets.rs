//! `lookdev presets list | show | save | sheet`: the preset library.

use super::inputs::{self, DisplayArgs, LightingArgs};
use super::progress::Progress;
use crate::material::library::{self, Library, Origin};
use crate::material::look::{Layer, Look};
use crate::material::params::{Param, Params};
use crate::material::Preset;
use crate::render::batch::{preset_on_ball, Batch};
use crate::render::scene::Scene;
use crate::render::sheet::{self, Cell};
use crate::{Error, Result};
use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct PresetsArgs {
    #[command(subcommand)]
    pub command: PresetsCommand,
}

#[derive(Subcommand, Debug)]
pub enum PresetsCommand {
    /// One line per preset: name, tags, and the first sentence of its description.
    List {
        /// Only presets with this tag.
        #[arg(long)]
        tag: Option<String>,
    },
    /// A preset's resolved values (every parameter) and where it comes from.
    Show { name: String },
    /// Save a preset to the user library, from a look's layer or from parameter values.
    Save(SaveArgs),
    /// Render every preset on the built-in ball under the same light, as a labelled grid.
    Sheet(SheetArgs),
}

#[derive(Args, Debug)]
pub struct SaveArgs {
    /// The preset's name: lowercase letters, digits, '-' and '_'.
    pub name: String,
    /// Take the parameters of a look's layer (with --object and --layer).
    #[arg(long, value_name = "FILE.toml", requires_all = ["object", "layer"], conflicts_with = "set")]
    pub from_look: Option<PathBuf>,
    /// The object whose stack holds the layer: its id, or "default" for the default stack.
    #[arg(long, value_name = "ID")]
    pub object: Option<String>,
    /// The layer, counted from 0 at the bottom of the stack.
    #[arg(long, value_name = "N")]
    pub layer: Option<usize>,
    /// Parameter values over the defaults, e.g. --set roughness=0.3.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    #[arg(long, default_value = "")]
    pub description: String,
    /// Comma-separated tags.
    #[arg(long, value_delimiter = ',')]
    pub tags: Vec<String>,
    /// Replace an existing preset of this name.
    #[arg(long)]
    pub force: bool,
}

#[derive(Args, Debug)]
pub struct SheetArgs {
    #[arg(long, value_name = "FILE.png")]
    pub out: PathBuf,
    /// Only presets with this tag.
    #[arg(long)]
    pub tag: Option<String>,
    #[command(flatten)]
    pub lighting: LightingArgs,
    #[command(flatten)]
    pub display: DisplayArgs,
    #[arg(long, default_value_t = 128)]
    pub spp: u32,
    /// Choose a BRDF model variant over the look's [model], as render's --model (repeatable).
    #[arg(long = "model", value_name = "KEY=VALUE")]
    pub model: Vec<String>,
    /// Side of each render in pixels.
    #[arg(long, default_value_t = 192)]
    pub size: u32,
    /// Columns of the grid (default: about square).
    #[arg(long)]
    pub columns: Option<usize>,
    #[arg(long, value_name = "NAME")]
    pub device: Option<String>,
    #[arg(long, short)]
    pub quiet: bool,
}

/// The most columns a sheet may have (`--columns`): 64 renders of 2048 pixels make a PNG
/// 131,072 pixels wide, PNG's practical limit.
const MAX_COLUMNS: usize = 64;

pub fn run(args: PresetsArgs) -> Result<()> {
    match args.command {
        PresetsCommand::List { tag } => list(tag.as_deref()),
        PresetsCommand::Show { name } => show(&name),
        PresetsCommand::Save(args) => save(args),
        PresetsCommand::Sheet(args) => sheet(args),
    }
}

/// Every preset the standard library resolves, optionally with a tag. A user preset that
/// fails to load is skipped with a warning naming its file, so one broken file never hides the
/// rest of the library.
fn presets_with_tag(tag: Option<&str>) -> Result<Vec<(Preset, Origin)>> {
    let mut out = Vec::new();
    let mut all_tags = std::collections::BTreeSet::new();
    for (_, origin, preset) in Library::standard().entries() {
        let preset = match preset {
            Ok(preset) => preset,
            Err(problem) => {
                crate::warn(format!("{problem}; skipped"));
                continue;
            }
        };
        all_tags.extend(preset.tags.clone());
        if tag.is_none_or(|t| preset.tags.iter().any(|p| p == t)) {
            out.push((preset, origin));
        }
    }
    if let (Some(tag), true) = (tag, out.is_empty()) {
        let tags: Vec<&str> = all_tags.iter().map(String::as_str).collect();
        let hint = crate::suggest::near_miss(tag, &tags).map(|t| format!("; did you mean '{t}'?")).unwrap_or_default();
        return Err(Error::input(format!("--tag {tag}: no preset has this tag (the tags: {}){hint}", tags.join(", "))));
    }
    Ok(out)
}

/// The first sentence of a description, for one-line listings.
fn first_sentence(text: &str) -> &str {
    let text = text.trim();
    match text.find(". ") {
        Some(end) => &text[..=end],
        None => text,
    }
}

fn list(tag: Option<&str>) -> Result<()> {
    let presets = presets_with_tag(tag)?;
    let width = presets.iter().map(|(p, _)| p.name.len()).max().unwrap_or(0);
    for (preset, origin) in presets {
        let mark = if origin == Origin::Builtin { "" } else { " (user)" };
        println!("{:width$}  [{}]{mark}  {}", preset.name, preset.tags.join(", "), first_sentence(&preset.description));
    }
    Ok(())
}

fn show(name: &str) -> Result<()> {
    let library = Library::standard();
    let preset = library.resolve(name).map_err(Error::input)?;
    let origin = if library::looks_like_path(name) {
        name.to_string()
    } else {
        library.find(name).map(|path| path.display().to_string()).unwrap_or_else(|| "built-in".to_string())
    };
    println!("name = {}", preset.name);
    println!("source = {origin}");
    println!("tags = [{}]", preset.tags.join(", "));
    println!("description = {}", preset.description.trim());
    for param in Param::ALL {
        let mark = if preset.set.contains(&param) { "" } else { "  # default" };
        println!("{param} = {}{mark}", preset.params.get(param));
    }
    if let Some((n, k)) = preset.ior {
        println!("ior_n = {n:?}");
        println!("ior_k = {k:?}");
    }
    Ok(())
}

/// The flags' values, before anything is read.
pub fn check(args: &PresetsArgs) -> Result<()> {
    match &args.command {
        PresetsCommand::Save(save) => {
            library::check_preset_name(&save.name)?;
            tags(&save.tags).map(|_| ())
        }
        _ => Ok(()),
    }
}

/// `--tags`, trimmed; an empty tag is refused, since a preset file cannot hold one.
fn tags(given: &[String]) -> Result<Vec<String>> {
    let tags: Vec<String> = given.iter().map(|t| t.trim().to_string()).collect();
    if tags.iter().any(String::is_empty) {
        return Err(Error::input(format!("--tags {}: a tag must not be empty", given.join(","))));
    }
    Ok(tags)
}

fn save(args: SaveArgs) -> Result<()> {
    let tags = tags(&args.tags)?;
    let dir = library::require_user_library_dir()?;
    let (params, set) = match &args.from_look {
        Some(look) => layer_params(look, args.object.as_deref().unwrap_or_default(), args.layer.unwrap_or(0))?,
        None if args.set.is_empty() => {
            return Err(Error::input("presets save needs --from-look FILE --object ID --layer N, or --set NAME=VALUE"))
        }
        None => {
            let mut params = Params::default();
            let mut set = Vec::new();
            for text in &args.set {
                let (param, value) = super::parse_set(text)?;
                params.set(param, value).map_err(Error::input)?;
                set.push(param);
            }
            (params, set)
        }
    };
    let mut set: Vec<Param> = Param::ALL.into_iter().filter(|p| set.contains(p)).collect();
    set.dedup();
    // The eleven parameters only: a look's complex IOR belongs to the preset it came from.
    let params = Params { ior_edge: [0.0; 3], ..params };
    let preset = Preset { name: args.name, description: args.description, tags, params, set, ior: None };
    let path = library::save_preset(&dir, &preset, args.force)?;
    println!("{}", path.display());
    Ok(())
}

/// The resolved parameters of one layer of a look (its preset with its overrides), and which
/// parameters differ from the defaults.
fn layer_params(look_path: &Path, object: &str, layer: usize) -> Result<(Params, Vec<Param>)> {
    let look = Look::load(look_path)?;
    let id = match object {
        "default" => None,
        text => Some(
            text.parse::<u32>()
                .map_err(|_| Error::input(format!("--object {text}: expected an object id or \"default\"")))?,
        ),
    };
    let stack = look
        .objects
        .iter()
        .find(|o| o.id == id)
        .ok_or_else(|| Error::input_file(look_path, format!("no stack for object {object}")))?;
    let chosen: &Layer = stack.layers.get(layer).ok_or_else(|| {
        Error::input_file(
            look_path,
            format!("object {object} has {} layers; --layer {layer} is not one", stack.layers.len()),
        )
    })?;
    let defaults = Params::default();
    let set = Param::ALL.into_iter().filter(|p| chosen.params.get(*p) != defaults.get(*p)).collect();
    // A preset holds constants: a bound parameter keeps its factor, and the map is left behind.
    if !chosen.maps.is_empty() {
        let bound: Vec<String> = chosen.maps.iter().map(|(param, map)| format!("{param} (map '{map}')")).collect();
        crate::warn(format!(
            "{}:{}: the preset keeps constants only; dropped the maps of {}, whose values are their factors",
            look_path.display(),
            chosen.line,
            bound.join(", ")
        ));
    }
    Ok((chosen.params, set))
}

fn sheet(args: SheetArgs) -> Result<()> {
    crate::render::output::require_png(&args.out)?;
    if args.spp == 0 {
        return Err(Error::input("--spp 0: the sample count must be at least 1"));
    }
    if !(16..=2048).contains(&args.size) {
        return Err(Error::input(format!("--size {}: renders must be 16 to 2048 pixels", args.size)));
    }
    if let Some(columns) = args.columns.filter(|c| !(1..=MAX_COLUMNS).contains(c)) {
        return Err(Error::input(format!("--columns {columns}: a sheet has 1 to {MAX_COLUMNS} columns")));
    }
    let presets = presets_with_tag(args.tag.as_deref())?;
    // The default look's light, unless another environment is given.
    let mut base = Look::builtin_default();
    if args.lighting.env.is_some() {
        base.environment = Default::default();
    }
    let Scene { gbuffer, gbuffer_name, environment, settings, .. } =
        Scene::load(&inputs::ball_spec(base, &args.lighting, &args.display, args.spp, &args.model, args.size))?;
    let ctx = super::context(args.device.clone())?;
    let counter = ctx.validation_counter();
    let cells = {
        let mut batch = Batch::new(&ctx, &gbuffer, &gbuffer_name, &environment)?;
        let mut progress = Progress::new(presets.len() as u64, "presets", args.quiet);
        let mut cells = Vec::new();
        for (i, (preset, origin)) in presets.iter().enumerate() {
            batch.render(&preset_on_ball(&preset.params), &settings, |_| {})?;
            let pixels = batch.display(&settings)?;
            let image = image::RgbaImage::from_raw(args.size, args.size, pixels).expect("size matches");
            let mut caption = preset.tags.join(", ");
            if *origin != Origin::Builtin {
                caption = format!("user · {caption}");
            }
            cells.push(Cell { image, title: preset.name.clone(), caption });
            progress.update(i as u64 + 1);
        }
        progress.finish();
        cells
    };
    drop(ctx);
    super::check_validation(&counter)?;
    let columns = args.columns.unwrap_or_else(|| (cells.len() as f64).sqrt().ceil() as usize).clamp(1, MAX_COLUMNS);
    let image = sheet::grid(&cells, columns);
    crate::render::output::write_png_image(&args.out, &image)?;
    if !args.quiet {
        eprintln!(
            "lookdev: wrote {} ({} presets in {columns} columns, {}x{})",
            args.out.display(),
            cells.len(),
            image.width(),
            image.height()
        );
    }
    Ok(())
}
