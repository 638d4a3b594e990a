//! Saving: the look in the look format, and a layer as a preset in the user library.
//!
//! A look is saved only if its file reads back as the same look. Moving it to another folder
//! would change what its relative references mean, so they are rewritten first: the environment
//! file and preset paths become relative to the new folder, and a preset name that resolved to a
//! file beside the old look becomes a path to that file. A name the new folder would resolve to
//! another preset (a file there shadowing a built-in, say) is refused with the layer named.

use std::path::{Component, Path, PathBuf};

use super::edit::{check_layer, ObjectRef};
use super::Document;
use crate::environment::EnvironmentRef;
use crate::material::library::{self, looks_like_path, Library};
use crate::material::look::Look;
use crate::material::params::{Param, Params};
use crate::material::Preset;
use crate::{atomic_file, Error, Result};

impl Document {
    /// Saves the look to `path`, or to the file it came from, atomically (a temporary file renamed
    /// into place, so a failed save leaves any old file as it was). The file is in the look
    /// format, with the settings in its `[environment]` and `[render]` tables, and reads back as
    /// a look equal to [`Document::look`]: references are rewritten for a new folder (see the
    /// module documentation), and the environment path is written relative to the file's folder
    /// and then held as the file reads it back. Marks the document clean, makes `path` its file,
    /// and returns the path written.
    pub fn save(&mut self, path: Option<&Path>) -> Result<PathBuf> {
        let Some(file) = path.or(self.path.as_deref()).map(Path::to_path_buf) else {
            return Err(Error::input("the look has no file yet: say where to save it"));
        };
        let folder = folder_of(&file);
        let relocation = Relocation::between(self.library(), &self.folder(), folder);
        let mut look = self.state.look.clone();
        look.file = Some(file.clone());
        if let Some(relocation) = &relocation {
            relocation.apply(&mut look);
        }
        // Held as the saved file will give it back, so that the two compare equal.
        if let Some(EnvironmentRef::File(env)) = &mut look.environment.source {
            *env = folder.join(relative_path(env, folder));
        }
        let gbuffer = &mut look.gbuffer;
        for file in gbuffer.file.iter_mut().chain(gbuffer.source.occluders.iter_mut()) {
            *file = folder.join(relative_path(file, folder));
        }
        let text = look.to_toml();
        let reread = Look::parse(&text, &file).map_err(|e| Error::input(format!("not saved: {e}")))?;
        if reread != look {
            return Err(Error::input_file(&file, format!("not saved: {}", what_would_change(&look, &reread, &file))));
        }
        atomic_file::write(&file, text.as_bytes())?;

        // From here on the document is the file, and every state undo can return to belongs to
        // the new place too.
        self.state.settings.environment.clone_from(&reread.environment.source);
        self.state.look = reread;
        for state in self.history.states_mut() {
            if let Some(relocation) = &relocation {
                relocation.apply(&mut state.look);
            }
            state.look.file = Some(file.clone());
        }
        if relocation.is_some() {
            self.preset_cache().clear();
        }
        self.path = Some(file.clone());
        self.saved = self.state.clone();
        self.history.end_gesture();
        Ok(file)
    }

    /// A layer as a preset: its parameters (its preset's with its overrides), with those that
    /// differ from the defaults written, like `lookdev presets save --from-look`. The name must
    /// be lowercase letters, digits, '-' and '_', and tags must not be empty.
    pub fn layer_as_preset(
        &self,
        object: ObjectRef,
        layer: usize,
        name: &str,
        description: &str,
        tags: &[String],
    ) -> Result<Preset> {
        library::check_preset_name(name)?;
        if tags.iter().any(|t| t.trim().is_empty()) {
            return Err(Error::input("a preset's tags must not be empty"));
        }
        let count = self.stack(object).map_or(0, |s| s.layers.len());
        check_layer(object, layer, count).map_err(Error::input)?;
        // The eleven parameters only: a layer's complex IOR is its preset's, not the new one's.
        let params = self.layer(object, layer).map(|l| Params { ior_edge: [0.0; 3], ..l.params }).unwrap_or_default();
        let defaults = Params::default();
        Ok(Preset {
            name: name.to_string(),
            description: description.to_string(),
            tags: tags.to_vec(),
            params,
            set: Param::ALL.into_iter().filter(|&p| params.get(p) != defaults.get(p)).collect(),
            ior: None,
        })
    }

    /// Saves layer `layer` of the stack for `object` as a preset in the user library
    /// ([`library::user_library_dir`]), atomically; an existing preset of that name is refused
    /// unless `force`. Returns the file written.
    pub fn save_layer_as_preset(
        &self,
        object: ObjectRef,
        layer: usize,
        name: &str,
        description: &str,
        tags: &[String],
        force: bool,
    ) -> Result<PathBuf> {
        let preset = self.layer_as_preset(object, layer, name, description, tags)?;
        self.save_preset_in(&library::require_user_library_dir()?, &preset, force)
    }

    /// Saves a preset as `<dir>/<name>.toml`, atomically; an existing file is refused unless
    /// `force`. Layers of a preset by that name take their "reset to preset" values from the new
    /// file from now on.
    pub fn save_preset_in(&self, dir: &Path, preset: &Preset, force: bool) -> Result<PathBuf> {
        let path = library::save_preset(dir, preset, force)?;
        self.preset_cache().remove(&preset.name);
        Ok(path)
    }

    /// The folder the look's relative references start from.
    fn folder(&self) -> PathBuf {
        self.path.as_deref().map(folder_of).unwrap_or(Path::new("")).to_path_buf()
    }
}

/// The folder of a file, as [`Look::parse`] takes it: empty for a bare file name.
fn folder_of(file: &Path) -> &Path {
    file.parent().unwrap_or(Path::new(""))
}

/// Why a look saved as `file` would not read back as itself: the first layer whose preset would
/// resolve to another, and the file that would shadow it.
fn what_would_change(look: &Look, reread: &Look, file: &Path) -> String {
    for (stack, again) in look.objects.iter().zip(&reread.objects) {
        for (index, (layer, other)) in stack.layers.iter().zip(&again.layers).enumerate() {
            if layer.params == other.params {
                continue;
            }
            let object = stack.id.map_or(ObjectRef::Default, ObjectRef::Id);
            let preset = layer.preset.as_deref().unwrap_or_default();
            let instead = match Library::for_look(file).find(preset) {
                Some(shadow) => shadow.display().to_string(),
                None => "another preset".to_string(),
            };
            return format!(
                "preset '{preset}' (layer {index} of {object}) would read as {instead} from there; \
                 save elsewhere, or rename that preset"
            );
        }
    }
    "the file would not read back as the same look".to_string()
}

/// How preset references change when a look moves from one folder to another.
struct Relocation {
    /// The library of the look where it was, to find which names were its folder's files.
    library: Library,
    from: PathBuf,
    to: PathBuf,
}

impl Relocation {
    /// `None` when the two folders are the same, and nothing needs rewriting.
    fn between(library: Library, from: &Path, to: &Path) -> Option<Relocation> {
        (absolute(from) != absolute(to)).then(|| Relocation { library, from: from.to_path_buf(), to: to.to_path_buf() })
    }

    fn apply(&self, look: &mut Look) {
        for layer in look.objects.iter_mut().flat_map(|o| o.layers.iter_mut()) {
            if let Some(reference) = &layer.preset {
                layer.preset = Some(self.reference(reference));
            }
        }
    }

    /// A preset reference that means, from the new folder, what `reference` meant from the old.
    fn reference(&self, reference: &str) -> String {
        let file = if looks_like_path(reference) {
            let path = Path::new(reference);
            if path.is_absolute() {
                return reference.to_string();
            }
            self.from.join(path)
        } else {
            // Names resolve through the user library and the built-ins from anywhere; only a
            // file beside the old look has to be named by its path.
            match self.library.find(reference) {
                Some(file) if file.parent() == Some(self.from.as_path()) => file,
                _ => return reference.to_string(),
            }
        };
        let relative = relative_path(&file, &self.to).to_string_lossy().into_owned();
        // A path in the new folder itself must still read as a path, not as a name.
        if looks_like_path(&relative) {
            relative
        } else {
            format!("./{relative}")
        }
    }
}

/// `path` made absolute against the current directory, with `.` and `..` resolved by name.
fn absolute(path: &Path) -> PathBuf {
    let path = if path.as_os_str().is_empty() { Path::new(".") } else { path };
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut clean = PathBuf::new();
    for component in absolute.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                clean.pop();
            }
            other => clean.push(other),
        }
    }
    clean
}

/// `file` relative to `folder`, going up with `..` as needed. Absolute when they share no root
/// (two drives).
fn relative_path(file: &Path, folder: &Path) -> PathBuf {
    let file = absolute(file);
    let folder = absolute(folder);
    let shared = file.components().zip(folder.components()).take_while(|(a, b)| a == b).count();
    if shared == 0 {
        return file;
    }
    let mut relative = PathBuf::new();
    for _ in folder.components().skip(shared) {
        relative.push("..");
    }
    for component in file.components().skip(shared) {
        relative.push(component);
    }
    relative
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_go_up_and_down() {
        assert_eq!(relative_path(Path::new("/a/b/hdri/x.exr"), Path::new("/a/b/looks")), Path::new("../hdri/x.exr"));
        assert_eq!(relative_path(Path::new("/a/b/x.exr"), Path::new("/a/b")), Path::new("x.exr"));
        assert_eq!(relative_path(Path::new("/a/b/looks/../x.exr"), Path::new("/a/c/./d")), Path::new("../../b/x.exr"));
        assert_eq!(relative_path(Path::new("looks/x.exr"), Path::new("looks")), Path::new("x.exr"));
        assert_eq!(relative_path(Path::new("x.exr"), Path::new("")), Path::new("x.exr"));
    }

    #[test]
    fn references_are_rewritten_for_the_new_folder() {
        let relocation =
            Relocation { library: Library::builtin_only(), from: PathBuf::from("/s/old"), to: PathBuf::from("/s/new") };
        assert_eq!(relocation.reference("shelf/shiny.toml"), "../old/shelf/shiny.toml");
        assert_eq!(relocation.reference("../new/shiny.toml"), "shiny.toml");
        assert_eq!(relocation.reference("../new/shiny"), "./shiny", "a path must stay a path");
        assert_eq!(relocation.reference("/p/shiny.toml"), "/p/shiny.toml");
        assert_eq!(relocation.reference("gold"), "gold", "a built-in name means the same anywhere");
        assert!(Relocation::between(Library::builtin_only(), Path::new("a/../b"), Path::new("b")).is_none());
    }
}
