//! Finding the preset a layer names.
//!
//! `preset = "..."` in a look layer is resolved like this:
//!
//! 1. If it looks like a path (it contains `/` or `\`, or ends with `.toml`), it is a preset file,
//!    relative to the look file's folder; absolute paths work too.
//! 2. Otherwise it is a name, looked up as `<folder>/<name>.toml` in the look file's folder, then
//!    in the user library ([`user_library_dir`]), then among the built-in presets.
//!
//! A user preset with the name of a built-in one shadows it; that is reported once per process.
//! The built-in presets are the files in `presets/`, compiled into the binary.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::preset::Preset;
use crate::suggest::{closest, edit_distance};

/// The user's preset library: `$LOOKDEV_PRESETS` if set, else `$XDG_DATA_HOME/lookdev/presets`,
/// else `~/.local/share/lookdev/presets`. None only without any of those variables.
pub fn user_library_dir() -> Option<PathBuf> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty()).map(PathBuf::from);
    var("LOOKDEV_PRESETS")
        .or_else(|| var("XDG_DATA_HOME").map(|d| d.join("lookdev").join("presets")))
        .or_else(|| var("HOME").map(|h| h.join(".local/share/lookdev/presets")))
}

/// The user library, or the error saying how to have one.
pub fn require_user_library_dir() -> crate::Result<PathBuf> {
    user_library_dir().ok_or_else(|| crate::Error::input("no user library: set LOOKDEV_PRESETS or HOME"))
}

/// The longest preset name, in bytes. The import names presets and masks after materials by the
/// same rule (`crate::asset::channel_name`), so it keeps `<name>.toml` and the g-buffer's
/// `mask.<name>` far within the 255 bytes file systems and OpenEXR allow.
pub const MAX_NAME_BYTES: usize = 64;

/// A name a preset may be saved under: lowercase letters, digits, '-' and '_', so that it is a
/// file name everywhere and never looks like a path.
pub fn check_preset_name(name: &str) -> crate::Result<()> {
    let valid =
        !name.is_empty() && name.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-' || c == '_');
    if !valid {
        return Err(crate::Error::input(format!(
            "'{name}' is not a preset name: use lowercase letters, digits, '-' and '_'"
        )));
    }
    if name.len() > MAX_NAME_BYTES {
        return Err(crate::Error::input(format!(
            "'{name}' is not a preset name: it has {} characters, and at most {MAX_NAME_BYTES} are allowed",
            name.len()
        )));
    }
    Ok(())
}

/// Writes `preset` as `<dir>/<name>.toml`, creating `dir` if needed, and returns the path. The
/// write is atomic; without `force` an existing preset is refused, and the check and the write
/// are one step.
pub fn save_preset(dir: &Path, preset: &Preset, force: bool) -> crate::Result<PathBuf> {
    check_preset_name(&preset.name)?;
    std::fs::create_dir_all(dir)
        .map_err(|e| crate::Error::io(dir, format!("cannot create the preset library: {e}")))?;
    let path = dir.join(format!("{}.toml", preset.name));
    let text = preset.to_toml();
    // What is saved must load: a file the library cannot read back would break every listing.
    Preset::parse(&text, &path).map_err(|e| crate::Error::input(format!("not saved: {e}")))?;
    if !force && shadows_builtin(dir, &preset.name) {
        return Err(shadowing_error(&preset.name));
    }
    if force {
        crate::atomic_file::write(&path, text.as_bytes())?;
    } else {
        crate::atomic_file::write_new(&path, text.as_bytes())?;
    }
    Ok(path)
}

/// Whether a preset `name` saved in `dir` would shadow a built-in preset: `dir` is the user
/// library, where every look finds it before the built-in one.
pub fn shadows_builtin(dir: &Path, name: &str) -> bool {
    let same_folder = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    };
    builtin(name).is_some() && user_library_dir().is_some_and(|library| same_folder(dir, &library))
}

/// The refusal to shadow the built-in preset `name` without being told to.
pub fn shadowing_error(name: &str) -> crate::Error {
    crate::Error::input(format!(
        "'{name}' would shadow the built-in preset '{name}' in every look that names it; choose another name, or --force to save it anyway"
    ))
}

/// Names already reported as shadowing a built-in preset, so each is reported once.
static REPORTED_SHADOWS: Mutex<BTreeSet<String>> = Mutex::new(BTreeSet::new());

fn report_shadowing(name: &str, path: &Path) {
    if builtin(name).is_some() && REPORTED_SHADOWS.lock().is_ok_and(|mut seen| seen.insert(name.to_string())) {
        crate::warn(format!("{}: user preset '{name}' shadows the built-in one", path.display()));
    }
}

/// The built-in presets: every file in `presets/`, by name (the file name without `.toml`).
/// A test fails if this list and the folder disagree.
pub static BUILTIN: &[(&str, &str)] = &[
    ("aluminium", include_str!("../../presets/aluminium.toml")),
    ("black-plastic", include_str!("../../presets/black-plastic.toml")),
    ("blue-rubber", include_str!("../../presets/blue-rubber.toml")),
    ("brass", include_str!("../../presets/brass.toml")),
    ("brushed-aluminium", include_str!("../../presets/brushed-aluminium.toml")),
    ("brushed-steel", include_str!("../../presets/brushed-steel.toml")),
    ("car-paint", include_str!("../../presets/car-paint.toml")),
    ("charcoal", include_str!("../../presets/charcoal.toml")),
    ("chrome", include_str!("../../presets/chrome.toml")),
    ("cobalt", include_str!("../../presets/cobalt.toml")),
    ("concrete", include_str!("../../presets/concrete.toml")),
    ("copper", include_str!("../../presets/copper.toml")),
    ("cotton", include_str!("../../presets/cotton.toml")),
    ("fresh-snow", include_str!("../../presets/fresh-snow.toml")),
    ("gloss-enamel", include_str!("../../presets/gloss-enamel.toml")),
    ("gold", include_str!("../../presets/gold.toml")),
    ("granite", include_str!("../../presets/granite.toml")),
    ("grey-card", include_str!("../../presets/grey-card.toml")),
    ("grime", include_str!("../../presets/grime.toml")),
    ("iron", include_str!("../../presets/iron.toml")),
    ("lacquered-wood", include_str!("../../presets/lacquered-wood.toml")),
    ("limestone", include_str!("../../presets/limestone.toml")),
    ("marble", include_str!("../../presets/marble.toml")),
    ("matte-plastic", include_str!("../../presets/matte-plastic.toml")),
    ("matte-wall-paint", include_str!("../../presets/matte-wall-paint.toml")),
    ("nickel", include_str!("../../presets/nickel.toml")),
    ("palladium", include_str!("../../presets/palladium.toml")),
    ("platinum", include_str!("../../presets/platinum.toml")),
    ("red-plastic", include_str!("../../presets/red-plastic.toml")),
    ("silver", include_str!("../../presets/silver.toml")),
    ("skin", include_str!("../../presets/skin.toml")),
    ("stainless-steel", include_str!("../../presets/stainless-steel.toml")),
    ("titanium", include_str!("../../presets/titanium.toml")),
    ("tungsten", include_str!("../../presets/tungsten.toml")),
    ("velvet", include_str!("../../presets/velvet.toml")),
    ("wax", include_str!("../../presets/wax.toml")),
    ("white-ceramic", include_str!("../../presets/white-ceramic.toml")),
];

/// The built-in preset of this name, if there is one.
pub fn builtin(name: &str) -> Option<Preset> {
    let (name, text) = BUILTIN.iter().find(|(n, _)| *n == name)?;
    let file = PathBuf::from(format!("presets/{name}.toml"));
    // The built-in files are checked by the test suite; failing here is a build defect.
    Some(Preset::parse(text, &file).expect("built-in presets parse (tested)"))
}

/// The names of the built-in presets, sorted.
pub fn builtin_names() -> Vec<&'static str> {
    let mut names: Vec<&'static str> = BUILTIN.iter().map(|(n, _)| *n).collect();
    names.sort_unstable();
    names
}

/// Whether a layer's `preset` value is a file path rather than a library name.
pub fn looks_like_path(reference: &str) -> bool {
    reference.contains('/') || reference.contains('\\') || reference.ends_with(".toml")
}

/// Where preset references are looked up.
#[derive(Clone, Debug, Default)]
pub struct Library {
    /// The folder relative preset paths start from: the look file's folder.
    base: PathBuf,
    /// Folders searched for `<name>.toml`, in order, before the built-ins.
    search: Vec<PathBuf>,
    /// The look file itself, which is never a preset even when its name matches one.
    look: Option<PathBuf>,
}

impl Library {
    /// Only the built-in presets; relative paths start from the current directory.
    pub fn builtin_only() -> Library {
        Library::default()
    }

    /// The user library, then the built-ins: what `lookdev presets` sees.
    pub fn standard() -> Library {
        Library { base: PathBuf::new(), search: user_library_dir().into_iter().collect(), look: None }
    }

    /// The library a look file sees: its own folder, then the user library, then the built-ins.
    pub fn for_look(look_file: &Path) -> Library {
        let folder = look_file.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut search = vec![folder.clone()];
        search.extend(user_library_dir().filter(|dir| *dir != folder));
        Library { base: folder, search, look: Some(look_file.to_path_buf()) }
    }

    /// Finds and loads the preset a layer names. The error is the problem alone, for the
    /// caller to place at the look's line; for a preset file with errors it carries that file's
    /// own `FILE:LINE`.
    pub fn resolve(&self, reference: &str) -> Result<Preset, String> {
        if looks_like_path(reference) {
            return load(reference, &self.base.join(reference));
        }
        if let Some(path) = self.find(reference) {
            if user_library_dir().is_some_and(|dir| path.parent() == Some(dir.as_path())) {
                report_shadowing(reference, &path);
            }
            return load(reference, &path);
        }
        builtin(reference).ok_or_else(|| self.unknown(reference))
    }

    /// The file a name resolves to in the search folders, if any.
    pub fn find(&self, name: &str) -> Option<PathBuf> {
        self.search
            .iter()
            .map(|dir| dir.join(format!("{name}.toml")))
            .find(|path| path.is_file() && self.look.as_deref() != Some(path.as_path()))
    }

    /// Every preset the library can resolve by name, with where it comes from: the search
    /// folders' files first (a name found earlier shadows later ones), then the built-ins not
    /// shadowed. Files that fail to load are returned as errors, not skipped.
    pub fn entries(&self) -> Vec<(String, Origin, Result<Preset, String>)> {
        let mut out: Vec<(String, Origin, Result<Preset, String>)> = Vec::new();
        for dir in &self.search {
            for name in toml_stems(dir) {
                if out.iter().any(|(n, _, _)| *n == name) {
                    continue;
                }
                let path = dir.join(format!("{name}.toml"));
                let preset = load(&name, &path);
                out.push((name, Origin::File(path), preset));
            }
        }
        for name in builtin_names() {
            if !out.iter().any(|(n, _, _)| n == name) {
                out.push((name.to_string(), Origin::Builtin, Ok(builtin(name).expect("listed"))));
            }
        }
        out.sort_by(|a, b| a.0.cmp(&b.0));
        out
    }

    fn unknown(&self, name: &str) -> String {
        let names = self.names();
        let nearest = closest(name, names.iter().map(String::as_str).filter(|n| *n != name));
        let shown: Vec<&str> = nearest.into_iter().take(3).collect();
        format!("no preset named '{name}' (closest: {})", shown.join(", "))
    }

    /// Every name the library can resolve: the `*.toml` files in the search folders that are
    /// presets (not the look itself, nor other looks beside it), and the built-ins. Used only
    /// to suggest names, so an unreadable folder or file is simply skipped.
    fn names(&self) -> Vec<String> {
        let mut names: Vec<String> = builtin_names().into_iter().map(String::from).collect();
        for dir in &self.search {
            names.extend(toml_stems(dir).into_iter().filter(|stem| {
                let path = dir.join(format!("{stem}.toml"));
                self.look.as_deref() != Some(path.as_path()) && Preset::load(&path).is_ok()
            }));
        }
        names.sort();
        names.dedup();
        names
    }
}

/// Where a preset comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Origin {
    File(PathBuf),
    Builtin,
}

/// Why a preset matched a search (docs/commands.md#lookdev-view-looktoml---gbuffer-file---env-file---device-name).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MatchedBy {
    /// The name is the query, starts with it or contains it.
    Name,
    /// This tag is the query or contains it.
    Tag(String),
    /// Only the description contains the query.
    Description,
    /// Nothing contains the query, but it is a likely typo of this word of the name or of a
    /// tag (see [`near_word`]).
    Near(String),
}

impl std::fmt::Display for MatchedBy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MatchedBy::Name => write!(f, "name"),
            MatchedBy::Tag(tag) => write!(f, "tag: {tag}"),
            MatchedBy::Description => write!(f, "in description"),
            MatchedBy::Near(word) => write!(f, "close to: {word}"),
        }
    }
}

/// How well a preset (its name, tags and description) matches `query`, case-insensitively:
/// a rank (lower is better) and why; `None` when it does not match. The ranks: the name is the
/// query, the name starts with it, the name contains it, a tag is the query, a tag contains it,
/// the description contains it; then, when none of those, the query is a likely typo of a word
/// of the name, then of a tag ([`near_word`]), so that "metl" finds the metals.
pub fn search_match(query: &str, name: &str, tags: &[String], description: &str) -> Option<(u8, MatchedBy)> {
    exact_match(query, name, tags, description).or_else(|| near_match(query, name, tags))
}

/// [`search_match`] without typos: the query is the name or a tag, or is part of one of them or
/// of the description.
fn exact_match(query: &str, name: &str, tags: &[String], description: &str) -> Option<(u8, MatchedBy)> {
    let query = query.trim().to_lowercase();
    let name = name.to_lowercase();
    if query.is_empty() || name == query {
        return Some((0, MatchedBy::Name));
    }
    if name.starts_with(&query) {
        return Some((1, MatchedBy::Name));
    }
    if name.contains(&query) {
        return Some((2, MatchedBy::Name));
    }
    if let Some(tag) = tags.iter().find(|t| t.to_lowercase() == query) {
        return Some((3, MatchedBy::Tag(tag.clone())));
    }
    if let Some(tag) = tags.iter().find(|t| t.to_lowercase().contains(&query)) {
        return Some((4, MatchedBy::Tag(tag.clone())));
    }
    description.to_lowercase().contains(&query).then_some((5, MatchedBy::Description))
}

/// The typo ranks of [`search_match`]: 6 when the query is near a word of the name, 7 when
/// near a tag or a word of one; why names the word (the whole tag, for a tag).
fn near_match(query: &str, name: &str, tags: &[String]) -> Option<(u8, MatchedBy)> {
    let query = query.trim().to_lowercase();
    let name = name.to_lowercase();
    if let Some(word) = words(&name).find(|word| near_word(&query, word)) {
        return Some((6, MatchedBy::Near(word.to_string())));
    }
    let tag = tags.iter().find(|tag| words(&tag.to_lowercase()).any(|word| near_word(&query, word)))?;
    Some((7, MatchedBy::Near(tag.clone())))
}

/// The words of a name or tag: "brushed-aluminium" is "brushed" and "aluminium".
fn words(text: &str) -> impl Iterator<Item = &str> {
    text.split(['-', '_', ' ']).filter(|word| !word.is_empty())
}

/// Whether `query` (lowercase) is likely a typo of `word`: within one edit (a letter left out,
/// added, changed, or two neighbours swapped) for a query of 3 to 5 letters, two for a longer
/// one; or, from 4 letters, within one edit of the word's beginning, so that a typo in a word
/// not typed out yet ("alumn") finds it too. Queries under 3 letters are too short to tell a
/// typo from another word.
pub fn near_word(query: &str, word: &str) -> bool {
    let length = query.chars().count();
    if length < 3 {
        return false;
    }
    let limit = if length <= 5 { 1 } else { 2 };
    if edit_distance(query, word) <= limit {
        return true;
    }
    // The beginnings of the word a letter shorter or longer than the query, as well as its own
    // length: the typo may have dropped or doubled a letter.
    let letters: Vec<char> = word.chars().collect();
    length >= 4
        && (length - 1..=(length + 1).min(letters.len()))
            .any(|end| edit_distance(query, &letters[..end].iter().collect::<String>()) <= 1)
}

/// The presets among `items` that match `query`, best first (see [`search_match`]), in their
/// given order within a rank, each with why it matched. `fields` gives an item's name, tags and
/// description. An empty query matches everything, by name.
pub fn search<'a, T>(
    items: &'a [T],
    query: &str,
    fields: impl Fn(&T) -> (&str, &[String], &str),
) -> Vec<(&'a T, MatchedBy)> {
    let mut found: Vec<(u8, &T, MatchedBy)> = items
        .iter()
        .filter_map(|item| {
            let (name, tags, description) = fields(item);
            search_match(query, name, tags, description).map(|(rank, why)| (rank, item, why))
        })
        .collect();
    found.sort_by_key(|(rank, _, _)| *rank);
    found.into_iter().map(|(_, item, why)| (item, why)).collect()
}

/// The stems of the `*.toml` files in a folder, sorted; an unreadable folder has none.
fn toml_stems(dir: &Path) -> Vec<String> {
    // A look given as a bare file name has the empty path as its folder.
    let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
    let mut stems: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .flatten()
                .map(|e| e.path())
                .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "toml"))
                .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
                .collect()
        })
        .unwrap_or_default();
    stems.sort();
    stems
}

fn load(reference: &str, path: &Path) -> Result<Preset, String> {
    Preset::load(path).map_err(|e| format!("preset '{reference}': {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::params::Param;
    use std::collections::BTreeSet;

    fn presets_folder() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("presets")
    }

    /// The built-in presets as the browser lists them.
    fn builtins() -> Vec<Preset> {
        builtin_names().into_iter().map(|name| builtin(name).unwrap()).collect()
    }

    fn fields(p: &Preset) -> (&str, &[String], &str) {
        (&p.name, &p.tags, &p.description)
    }

    #[test]
    fn search_ranks_names_then_tags_then_descriptions_and_says_why() {
        let presets = builtins();
        let found = search(&presets, "rough", fields);
        // Every description mentions roughness, so everything matches; the tagged ones lead.
        assert_eq!(found.len(), presets.len());
        let tagged: BTreeSet<&str> =
            presets.iter().filter(|p| p.tags.iter().any(|t| t == "rough")).map(|p| p.name.as_str()).collect();
        assert!(!tagged.is_empty());
        let first: BTreeSet<&str> = found[..tagged.len()].iter().map(|(p, _)| p.name.as_str()).collect();
        assert_eq!(first, tagged, "the presets tagged rough come first");
        for (preset, why) in &found {
            if tagged.contains(preset.name.as_str()) {
                assert_eq!(*why, MatchedBy::Tag("rough".into()), "{}", preset.name);
            } else {
                assert_eq!(*why, MatchedBy::Description, "{}", preset.name);
                assert!(preset.description.to_lowercase().contains("rough"), "{}", preset.name);
            }
        }
        assert_eq!(MatchedBy::Tag("rough".into()).to_string(), "tag: rough");
        assert_eq!(MatchedBy::Description.to_string(), "in description");

        // The exact name, then names that start with the query, then names that contain it,
        // then tags.
        let found = search(&presets, "Aluminium", fields);
        let names: Vec<&str> = found.iter().map(|(p, _)| p.name.as_str()).collect();
        assert_eq!(names[..2], ["aluminium", "brushed-aluminium"]);
        assert!(found[..2].iter().all(|(_, why)| *why == MatchedBy::Name));
        let found = search(&presets, "metal", fields);
        let tag_at = found.iter().position(|(_, why)| matches!(why, MatchedBy::Tag(_))).unwrap();
        assert!(found[..tag_at].iter().all(|(_, why)| *why == MatchedBy::Name), "{found:?}");
        assert!(found[tag_at..].iter().all(|(_, why)| *why != MatchedBy::Name), "{found:?}");
        let description_at = found.iter().position(|(_, why)| *why == MatchedBy::Description);
        if let Some(at) = description_at {
            assert!(found[at..].iter().all(|(_, why)| *why == MatchedBy::Description), "{found:?}");
        }
    }

    #[test]
    fn search_finds_words_only_descriptions_use() {
        let presets = builtins();
        // A word from a description that no name or tag has.
        let word = presets
            .iter()
            .flat_map(|p| p.description.split(|c: char| !c.is_alphabetic()))
            .filter(|w| w.len() > 4)
            .map(str::to_lowercase)
            .find(|w| {
                presets.iter().all(|p| !p.name.contains(w.as_str()) && p.tags.iter().all(|t| !t.contains(w.as_str())))
            })
            .expect("some description has a word of its own");
        let found = search(&presets, &word, fields);
        assert!(!found.is_empty(), "{word}");
        assert!(found
            .iter()
            .all(|(p, why)| *why == MatchedBy::Description && p.description.to_lowercase().contains(&word)));
        assert!(search(&presets, "no-preset-says-this", fields).is_empty());
        assert_eq!(search(&presets, "", fields).len(), presets.len(), "an empty query lists everything");
    }

    /// A typo finds what it meant, after every preset the query itself matches, and says so.
    #[test]
    fn search_tolerates_a_typo() {
        let presets = builtins();
        let metals: BTreeSet<&str> =
            presets.iter().filter(|p| p.tags.iter().any(|t| t == "metal")).map(|p| p.name.as_str()).collect();
        assert!(metals.len() > 3);
        let found = search(&presets, "metl", fields);
        let names: BTreeSet<&str> = found.iter().map(|(p, _)| p.name.as_str()).collect();
        assert_eq!(names, metals, "'metl' finds the metals, and only them");
        assert!(found.iter().all(|(_, why)| *why == MatchedBy::Near("metal".into())), "{found:?}");
        assert_eq!(MatchedBy::Near("metal".into()).to_string(), "close to: metal");
        // Swapped letters, a letter left out of a long word, a word of a name not typed out.
        for (typo, meant) in [
            ("glod", "gold"),
            ("cpoper", "copper"),
            ("alumnium", "aluminium"),
            ("alumn", "aluminium"),
            ("stainels", "stainless-steel"),
        ] {
            let found = search(&presets, typo, fields);
            assert!(found.iter().any(|(p, _)| p.name == meant), "'{typo}' does not find {meant}: {found:?}");
        }
    }

    /// Presets the query matches as typed come before any it is only close to.
    #[test]
    fn typos_rank_after_name_and_tag_matches() {
        let item = |name: &str, tags: &[&str], description: &str| {
            (name.to_string(), tags.iter().map(|t| t.to_string()).collect::<Vec<String>>(), description.to_string())
        };
        let items = [
            item("x", &["glod"], ""),
            item("gould", &[], ""),
            item("leaf", &[], "gold leaf"),
            item("cobalt", &["golden"], ""),
            item("old-gild", &["gold"], ""),
            item("gold", &[], ""),
            item("silver", &["metal"], "not yellow"),
        ];
        let found = search(&items, "gold", |(name, tags, description)| (name, tags, description));
        let order: Vec<(&str, String)> = found.iter().map(|(item, why)| (item.0.as_str(), why.to_string())).collect();
        let expected = [
            ("gold", "name"),
            ("old-gild", "tag: gold"),
            ("cobalt", "tag: golden"),
            ("leaf", "in description"),
            ("gould", "close to: gould"),
            ("x", "close to: glod"),
        ];
        assert_eq!(order, expected.map(|(name, why)| (name, why.to_string())));
        // A name one edit from the query ranks above a tag one edit from it.
        let tags = ["glossy".to_string()];
        let by_name = search_match("golb", "gold", &[], "").unwrap();
        let by_tag = search_match("glosy", "other", &tags, "").unwrap();
        assert_eq!(by_name.1, MatchedBy::Near("gold".into()));
        assert_eq!(by_tag.1, MatchedBy::Near("glossy".into()));
        assert!(by_name.0 < by_tag.0);
        let exact = search_match("glossy", "other", &tags, "").unwrap();
        let described = search_match("glossy", "other", &[], "a glossy coat").unwrap();
        assert!(exact.0 < by_name.0 && described.0 < by_name.0);
    }

    #[test]
    fn nonsense_and_short_queries_find_no_typos() {
        let presets = builtins();
        for query in ["qzxv", "xyz", "wolfram-zebra", "qj"] {
            assert!(search(&presets, query, fields).is_empty(), "{query}: {:?}", search(&presets, query, fields));
        }
        assert!(!near_word("go", "gold"), "two letters are too few to call a typo");
        assert!(near_word("gld", "gold"));
        assert!(!near_word("glx", "gold"));
        assert!(near_word("brsuhed", "brushed"), "two edits in a longer word");
    }

    #[test]
    fn builtin_list_matches_the_presets_folder() {
        let on_disk: BTreeSet<String> = std::fs::read_dir(presets_folder())
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
            .collect();
        let listed: BTreeSet<String> = BUILTIN.iter().map(|(n, _)| n.to_string()).collect();
        assert_eq!(listed, on_disk, "BUILTIN and presets/ disagree");
        assert_eq!(listed.len(), BUILTIN.len(), "a name is listed twice");
        for (name, text) in BUILTIN {
            let file = std::fs::read_to_string(presets_folder().join(format!("{name}.toml"))).unwrap();
            assert_eq!(*text, file, "BUILTIN '{name}' embeds another file");
        }
    }

    #[test]
    fn every_builtin_parses_in_range_and_is_described() {
        for name in builtin_names() {
            let preset = builtin(name).unwrap();
            assert_eq!(preset.name, name);
            assert!(preset.description.len() > 40, "{name}: describe what it models and its sources");
            assert!(!preset.tags.is_empty(), "{name}: no tags");
            for param in Param::ALL {
                assert!(crate::material::params::check(param, preset.params.get(param)).is_ok(), "{name}: {param}");
            }
            let m = preset.params.metallic;
            assert!(m == 0.0 || m == 1.0, "{name}: metallic is {m}; a surface is a metal or it is not");
            if m == 0.0 {
                let [r, g, b] = preset.params.base_color;
                let luminance = 0.2126 * r + 0.7152 * g + 0.0722 * b;
                assert!((0.02..=0.9).contains(&luminance), "{name}: implausible albedo {luminance}");
            }
        }
    }

    /// F0 = ((n−1)² + k²) / ((n+1)² + k²), the normal-incidence reflectance of a conductor.
    fn f0(n: f64, k: f64) -> f64 {
        ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
    }

    /// The (n, k) behind each metal's base_color, for R, G and B, as cited in its description.
    #[test]
    fn metal_base_colors_are_f0_of_the_cited_complex_ior() {
        let metals: [(&str, [(f64, f64); 3]); 5] = [
            // Johnson & Christy 1972 at 659.5 nm and 450.9 nm; Ogaki and Ishiyama's 546.1 nm value for G.
            ("gold", [(0.14, 3.697), (0.31, 2.34), (1.38, 1.914)]),
            ("silver", [(0.05, 4.483), (0.05, 3.54), (0.04, 2.657)]),
            ("copper", [(0.22, 3.747), (0.84, 2.41), (1.24, 2.397)]),
            // Rakić et al. 1998 Lorentz-Drude model at 650, 546.1 and 450 nm.
            ("chrome", [(3.535, 4.348), (2.873, 4.222), (2.145, 3.862)]),
            ("brushed-aluminium", [(1.420, 7.467), (0.949, 6.416), (0.590, 5.311)]),
        ];
        for (name, nk) in metals {
            let preset = builtin(name).unwrap();
            assert_eq!(preset.params.metallic, 1.0, "{name}");
            for (channel, (n, k)) in nk.into_iter().enumerate() {
                let stored = preset.params.base_color[channel] as f64;
                assert!((stored - f0(n, k)).abs() < 1e-4, "{name} channel {channel}: {stored} vs {}", f0(n, k));
            }
        }
    }

    #[test]
    fn paths_and_names_are_told_apart() {
        assert!(looks_like_path("mine/gold.toml"));
        assert!(looks_like_path("gold.toml"));
        assert!(looks_like_path("C:\\presets\\gold"));
        assert!(!looks_like_path("gold"));
        assert!(!looks_like_path("brushed-aluminium"));
    }

    #[test]
    fn unknown_names_suggest_the_closest() {
        let error = Library::builtin_only().resolve("golld").unwrap_err();
        assert!(error.starts_with("no preset named 'golld' (closest: gold, "), "{error}");
    }
}
