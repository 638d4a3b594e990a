//! Snapshots: the image on screen kept with the look and render settings that made it, to
//! compare the live image against and to go back to.
//!
//! They live beside the look file, in `<look stem>.snapshots/` (docs/formats.md#snapshots):
//! `NAME.toml` (the look, exactly, and when and at how many samples it was taken), `NAME.exr`
//! (linear radiance, with the metadata `lookdev render` writes) and `NAME.png` (the display
//! pixels). The TOML is written last and removed first, so a snapshot is listed only when its
//! images are there. A look without a file has nowhere to keep them: taking one is refused
//! until the look is saved.

use crate::material::toml_input::Source;
use crate::material::Look;
use crate::render::output;
use crate::render::settings::{Overrides, Settings};
use crate::{atomic_file, input, Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The longest snapshot name, in characters.
pub const MAX_NAME: usize = 64;

/// A snapshot: the state and the display pixels; its radiance stays on disk.
#[derive(Clone, Debug)]
pub struct Snapshot {
    pub name: String,
    /// The look and settings as the document held them (read back from disk: the look, and
    /// the settings it resolves to, which the document keeps its look's tables in step with).
    pub look: Look,
    pub settings: Settings,
    pub spp: u32,
    /// When it was taken, UTC, as `2026-12-02T10:31:07Z`.
    pub taken: String,
    pub width: u32,
    pub height: u32,
    /// RGBA8, sRGB-encoded, as the viewer showed them.
    pub display: Vec<u8>,
    /// Unique among the snapshots of this viewer run, so that a texture made for one is never
    /// shown for another of the same name.
    pub id: u64,
}

/// What the renderer gives for a snapshot: the image as `save-image` saves it.
pub struct Capture {
    pub radiance: Vec<[f32; 4]>,
    pub display: Vec<u8>,
    pub spp: u32,
    /// The EXR header attributes `lookdev render` writes.
    pub metadata: Vec<(String, String)>,
    pub background: bool,
}

/// The snapshots of one look file.
#[derive(Default)]
pub struct Snapshots {
    /// The look file they belong to; `None` for a look never saved.
    look: Option<PathBuf>,
    pub list: Vec<Snapshot>,
    next_id: u64,
}

/// `NAME.toml` as written.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SnapshotFile {
    snapshot: Header,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    name: String,
    spp: u32,
    taken: String,
    width: u32,
    height: u32,
    /// The look file's text, as saving the look would write it.
    look: String,
}

/// The folder a look's snapshots live in: `look.toml` → `look.snapshots/` beside it.
pub fn folder_for(look: &Path) -> PathBuf {
    let stem = look.file_stem().map_or("look".into(), |s| s.to_string_lossy().into_owned());
    look.with_file_name(format!("{stem}.snapshots"))
}

/// A snapshot name must be usable as a file stem anywhere: 1 to [`MAX_NAME`] ASCII letters,
/// digits, '-', '_' and '.', starting with a letter or digit.
pub fn check_name(name: &str) -> std::result::Result<(), String> {
    let allowed = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
    let problem = if name.is_empty() {
        "is empty".to_string()
    } else if name.chars().count() > MAX_NAME {
        format!("is longer than {MAX_NAME} characters")
    } else if let Some(c) = name.chars().find(|&c| !allowed(c)) {
        format!("has {c:?}, which a file name cannot safely hold")
    } else if !name.starts_with(|c: char| c.is_ascii_alphanumeric()) {
        "must start with a letter or a digit".to_string()
    } else {
        return Ok(());
    };
    Err(format!(
        "snapshot name '{}' {problem} (use letters, digits, '-', '_' and '.', e.g. before-gold)",
        crate::printable(name)
    ))
}

impl Snapshots {
    /// The snapshots kept beside `look` (none for a look without a file). A snapshot that
    /// cannot be read is left out with a warning naming its file; the rest are listed, oldest
    /// first.
    pub fn open(look: Option<&Path>) -> (Snapshots, Vec<String>) {
        let mut snapshots = Snapshots { look: look.map(Path::to_path_buf), ..Snapshots::default() };
        let mut warnings = Vec::new();
        let Some(look) = look else { return (snapshots, warnings) };
        let folder = folder_for(look);
        let Ok(entries) = std::fs::read_dir(&folder) else { return (snapshots, warnings) };
        let mut files: Vec<PathBuf> = entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .filter(|p| !p.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.')))
            .collect();
        files.sort();
        for file in files {
            match read(&file, look, snapshots.next_id) {
                Ok(snapshot) => {
                    snapshots.next_id += 1;
                    snapshots.list.push(snapshot);
                }
                Err(e) => warnings.push(format!("{e}; this snapshot is skipped")),
            }
        }
        snapshots.list.sort_by(|a, b| (&a.taken, &a.name).cmp(&(&b.taken, &b.name)));
        (snapshots, warnings)
    }

    /// The look file these belong to.
    pub fn look_file(&self) -> Option<&Path> {
        self.look.as_deref()
    }

    /// `snapshot-N`, one past the highest such number in use.
    pub fn default_name(&self) -> String {
        let highest = self
            .list
            .iter()
            .filter_map(|s| s.name.strip_prefix("snapshot-").and_then(|n| n.parse::<u64>().ok()))
            .max()
            .unwrap_or(0);
        format!("snapshot-{}", highest + 1)
    }

    /// The snapshot called `name`, or an error listing those there are.
    pub fn get(&self, name: &str) -> Result<&Snapshot> {
        self.list.iter().find(|s| s.name == name).ok_or_else(|| {
            let names: Vec<&str> = self.list.iter().map(|s| s.name.as_str()).collect();
            let has = if names.is_empty() {
                "there are none".to_string()
            } else {
                format!("there are: {}", names.join(", "))
            };
            let hint =
                crate::suggest::near_miss(name, &names).map_or(String::new(), |n| format!(" (did you mean '{n}'?)"));
            Error::input(format!("no snapshot named '{}'{hint}; {has}", crate::printable(name)))
        })
    }

    /// Checks a name for a new snapshot: safe as a file stem, not taken, and a look file to
    /// keep it beside. `None` takes the next default name.
    pub fn name_for_new(&self, name: Option<&str>) -> Result<String> {
        if self.look.is_none() {
            return Err(Error::input(
                "snapshot: the look has no file yet, and snapshots are kept beside it (in LOOK.snapshots/): save the look first",
            ));
        }
        let name = name.map_or_else(|| self.default_name(), str::to_string);
        check_name(&name).map_err(Error::input)?;
        if self.list.iter().any(|s| s.name == name) {
            return Err(Error::input(format!(
                "a snapshot named '{name}' already exists (delete it, or choose another name)"
            )));
        }
        Ok(name)
    }

    /// Writes a snapshot of `capture` under `name` (from [`Snapshots::name_for_new`]), with the
    /// look and settings that made it, and lists it.
    pub fn add(
        &mut self,
        name: String,
        look: &Look,
        settings: &Settings,
        capture: Capture,
        size: (u32, u32),
    ) -> Result<&Snapshot> {
        let look_file = self.look.clone().ok_or_else(|| Error::input("snapshot: the look has no file yet"))?;
        let folder = folder_for(&look_file);
        std::fs::create_dir_all(&folder)
            .map_err(|e| Error::io(&folder, format!("cannot create the snapshot folder ({e})")))?;
        let (width, height) = size;
        let path = |ext: &str| folder.join(format!("{name}.{ext}"));
        output::write_exr_with(
            &path("exr"),
            width,
            height,
            &capture.radiance,
            capture.background,
            Vec::new(),
            &capture.metadata,
        )?;
        output::write_png(&path("png"), width, height, &capture.display, !capture.background)?;
        // The look as saving it would write it: relative references stay relative to its folder.
        let mut stored = look.clone();
        stored.file = Some(look_file.clone());
        let taken = utc_now();
        let header = Header {
            name: name.clone(),
            spp: capture.spp,
            taken: taken.clone(),
            width,
            height,
            look: stored.to_toml(),
        };
        let text = toml::to_string(&SnapshotFile { snapshot: header })
            .map_err(|e| Error::io(path("toml"), format!("cannot encode the snapshot ({e})")))?;
        let text = format!("# A lookdev viewer snapshot (docs/formats.md#snapshots).\n{text}");
        atomic_file::write(&path("toml"), text.as_bytes())?;
        let id = self.next_id;
        self.next_id += 1;
        self.list.push(Snapshot {
            name,
            look: stored,
            settings: settings.clone(),
            spp: capture.spp,
            taken,
            width,
            height,
            display: capture.display,
            id,
        });
        Ok(self.list.last().expect("just pushed"))
    }

    /// Removes a snapshot and its files.
    pub fn delete(&mut self, name: &str) -> Result<()> {
        self.get(name)?;
        let look = self.look.as_deref().ok_or_else(|| Error::input("the look has no file"))?;
        let folder = folder_for(look);
        // The TOML first: without it, what is left is never listed.
        for ext in ["toml", "exr", "png"] {
            let file = folder.join(format!("{name}.{ext}"));
            match std::fs::remove_file(&file) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => return Err(Error::io(&file, format!("cannot delete the snapshot ({e})"))),
            }
        }
        self.list.retain(|s| s.name != name);
        Ok(())
    }
}

/// Reads `NAME.toml` and the display pixels of `NAME.png` beside it.
fn read(file: &Path, look_file: &Path, id: u64) -> Result<Snapshot> {
    let text = input::read_text(file, input::Kind::Toml)?;
    let header = Source { file, text: &text }.decode::<SnapshotFile>()?.snapshot;
    let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    check_name(&stem).map_err(|problem| Error::input_file(file, problem))?;
    if header.name != stem {
        return Err(Error::input_file(
            file,
            format!("names the snapshot '{}', but the file is {stem}.toml", crate::printable(&header.name)),
        ));
    }
    let side = input::exr::MAX_SIDE as u32;
    if header.width == 0 || header.height == 0 || header.width > side || header.height > side {
        return Err(Error::input_file(
            file,
            format!("the size {}x{} is not an image size", header.width, header.height),
        ));
    }
    if header.spp == 0 {
        return Err(Error::input_file(file, "spp = 0: a snapshot has at least one sample"));
    }
    let look = Look::parse(&header.look, look_file).map_err(|e| Error::input_file(file, format!("its look: {e}")))?;
    let settings = Settings::resolve(&look, &Overrides::default())
        .map_err(|e| Error::input_file(file, format!("its look: {e}")))?;
    let exr = file.with_extension("exr");
    if !std::fs::metadata(&exr).is_ok_and(|m| m.is_file()) {
        return Err(Error::input_file(&exr, "missing: the snapshot's radiance is not there"));
    }
    let png = file.with_extension("png");
    let bytes = input::read(&png, input::Kind::SnapshotImage)?;
    let image = input::image::decode(&bytes, side).map_err(|problem| Error::input_file(&png, problem))?;
    if (image.width(), image.height()) != (header.width, header.height) {
        return Err(Error::input_file(
            &png,
            format!(
                "is {}x{}, but the snapshot says {}x{}",
                image.width(),
                image.height(),
                header.width,
                header.height
            ),
        ));
    }
    Ok(Snapshot {
        name: header.name,
        look,
        settings,
        spp: header.spp,
        taken: crate::printable(&header.taken),
        width: header.width,
        height: header.height,
        display: image.into_rgba8().into_raw(),
        id,
    })
}

/// Now, UTC, as `2026-12-02T10:31:07Z`.
fn utc_now() -> String {
    let seconds = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    utc_text(seconds)
}

/// Seconds since 1970 as an ISO 8601 UTC time.
fn utc_text(seconds: u64) -> String {
    let (days, rest) = ((seconds / 86_400) as i64, seconds % 86_400);
    // Days to a civil date in the proleptic Gregorian calendar, by 400-year eras.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let day_of_era = z - era * 146_097;
    let year_of_era = (day_of_era - day_of_era / 1460 + day_of_era / 36_524 - day_of_era / 146_096) / 365;
    let day_of_year = day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
    let mp = (5 * day_of_year + 2) / 153;
    let day = day_of_year - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = year_of_era + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z", rest / 3600, rest % 3600 / 60, rest % 60)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_must_be_safe_file_stems() {
        for good in ["snapshot-1", "before_gold", "v2.1", "A", &"x".repeat(MAX_NAME)] {
            assert_eq!(check_name(good), Ok(()), "{good}");
        }
        for (bad, problem) in [
            ("", "is empty"),
            ("../escape", "has '/'"),
            ("a/b", "has '/'"),
            ("a b", "has ' '"),
            ("-flag", "must start with a letter or a digit"),
            (".hidden", "must start with a letter or a digit"),
            ("naïve", "has 'ï'"),
            ("con\u{7}", "has '\\u{7}'"),
            (&"x".repeat(MAX_NAME + 1), "is longer than 64"),
        ] {
            let message = check_name(bad).unwrap_err();
            assert!(message.contains(problem), "{bad:?}: {message}");
        }
    }

    #[test]
    fn the_folder_sits_beside_the_look() {
        assert_eq!(folder_for(Path::new("/work/shots/look.toml")), Path::new("/work/shots/look.snapshots"));
        assert_eq!(folder_for(Path::new("a.b.toml")), Path::new("a.b.snapshots"));
    }

    #[test]
    fn default_names_count_up_past_those_in_use() {
        let mut snapshots = Snapshots::default();
        assert_eq!(snapshots.default_name(), "snapshot-1");
        let blank = |name: &str| Snapshot {
            name: name.into(),
            look: Look::default_material(),
            settings: Settings::resolve(&Look::default_material(), &Overrides::default()).unwrap(),
            spp: 1,
            taken: String::new(),
            width: 1,
            height: 1,
            display: vec![0; 4],
            id: 0,
        };
        snapshots.list = vec![blank("snapshot-1"), blank("snapshot-7"), blank("mine")];
        assert_eq!(snapshots.default_name(), "snapshot-8");
        let missing = snapshots.get("snapshot-2").unwrap_err().to_string();
        assert!(
            missing.contains("no snapshot named 'snapshot-2'") && missing.contains("snapshot-1, snapshot-7, mine"),
            "{missing}"
        );
        let refused = snapshots.name_for_new(None).unwrap_err().to_string();
        assert!(refused.contains("the look has no file yet"), "{refused}");
    }

    #[test]
    fn times_are_written_as_utc() {
        assert_eq!(utc_text(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc_text(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc_text(1_798_886_227), "2027-01-02T10:37:07Z");
    }
}
