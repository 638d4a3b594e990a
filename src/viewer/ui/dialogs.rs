//! Windows that ask for something: a file to open or save, a preset's name, and what to do with
//! unsaved edits.

use super::super::action::{Action, Answer};
use super::super::session::Session;
use super::Pending;
use std::path::{Path, PathBuf};

/// What a file is being chosen for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilePurpose {
    OpenLook,
    SaveLook,
    SaveImage,
    OpenEnvironment,
    /// A look to show as B in the A/B split.
    CompareLook,
    /// A folder for the environment library: the folder shown, or the one named.
    AddEnvironmentFolder,
}

impl FilePurpose {
    fn title(self) -> &'static str {
        match self {
            FilePurpose::OpenLook => "Open look",
            FilePurpose::SaveLook => "Save look as",
            FilePurpose::SaveImage => "Save image",
            FilePurpose::OpenEnvironment => "Open environment",
            FilePurpose::CompareLook => "Compare with look",
            FilePurpose::AddEnvironmentFolder => "Add a folder of environments",
        }
    }

    /// The extensions listed, the first being what a bare name gets when saving.
    fn extensions(self) -> &'static [&'static str] {
        match self {
            FilePurpose::OpenLook | FilePurpose::SaveLook | FilePurpose::CompareLook => &["toml"],
            FilePurpose::SaveImage => &["png", "exr"],
            FilePurpose::OpenEnvironment | FilePurpose::AddEnvironmentFolder => &["exr", "hdr"],
        }
    }

    fn saving(self) -> bool {
        matches!(self, FilePurpose::SaveLook | FilePurpose::SaveImage)
    }

    fn action(self, path: PathBuf) -> Action {
        match self {
            FilePurpose::OpenLook => Action::OpenLook(path),
            FilePurpose::SaveLook => Action::SaveLook(Some(path)),
            FilePurpose::SaveImage => Action::SaveImage(path),
            FilePurpose::OpenEnvironment => {
                Action::OpenEnvironment(Some(crate::environment::EnvironmentRef::File(path)))
            }
            FilePurpose::CompareLook => Action::Compare(super::super::action::Compare::Look(path)),
            FilePurpose::AddEnvironmentFolder => Action::AddEnvironmentFolder(path),
        }
    }
}

/// A small file chooser: a folder's listing, filtered by extension, and a name field.
pub struct FileDialog {
    purpose: FilePurpose,
    dir: PathBuf,
    name: String,
    /// The folder's sub-folders and matching files, folders first.
    entries: Vec<(String, bool)>,
    problem: Option<String>,
    /// A save onto this existing file was asked for once; asking again replaces it.
    replace: Option<PathBuf>,
}

impl FileDialog {
    pub fn new(purpose: FilePurpose) -> FileDialog {
        let dir = std::env::current_dir().unwrap_or_else(|_| PathBuf::from("."));
        let mut dialog =
            FileDialog { purpose, dir, name: String::new(), entries: Vec::new(), problem: None, replace: None };
        dialog.list();
        dialog
    }

    fn list(&mut self) {
        let wanted = self.purpose.extensions();
        let mut entries: Vec<(String, bool)> = match std::fs::read_dir(&self.dir) {
            Ok(read) => read
                .flatten()
                .filter_map(|entry| {
                    let name = entry.file_name().to_string_lossy().into_owned();
                    let is_dir = entry.path().is_dir();
                    let matches = Path::new(&name)
                        .extension()
                        .and_then(|e| e.to_str())
                        .is_some_and(|e| wanted.contains(&e.to_ascii_lowercase().as_str()));
                    (!name.starts_with('.') && (is_dir || matches)).then_some((name, is_dir))
                })
                .collect(),
            Err(e) => {
                self.problem = Some(format!("{}: cannot list ({e})", self.dir.display()));
                Vec::new()
            }
        };
        entries.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        self.entries = entries;
    }

    fn enter(&mut self, dir: PathBuf) {
        self.dir = dir;
        self.problem = None;
        self.list();
    }

    /// The file the name field names, with the default extension added when saving.
    fn chosen(&self) -> Option<PathBuf> {
        let name = self.name.trim();
        if name.is_empty() {
            return None;
        }
        let mut path = self.dir.join(name);
        if self.purpose.saving() && path.extension().is_none() {
            path.set_extension(self.purpose.extensions()[0]);
        }
        Some(path)
    }

    /// Shows the window; false once it is done (chosen or cancelled).
    pub fn show(&mut self, ctx: &egui::Context, actions: &mut Vec<Action>) -> bool {
        let mut keep = true;
        let mut confirm = false;
        egui::Window::new(self.purpose.title()).collapsible(false).default_size([480.0, 420.0]).show(ctx, |ui| {
            ui.horizontal(|ui| {
                if ui.button("⬆").on_hover_text("Parent folder").clicked() {
                    if let Some(parent) = self.dir.parent().map(Path::to_path_buf) {
                        self.enter(parent);
                    }
                }
                ui.label(self.dir.display().to_string());
            });
            ui.separator();
            let mut enter = None;
            egui::ScrollArea::vertical().max_height(260.0).show(ui, |ui| {
                for (name, is_dir) in &self.entries {
                    let label = if *is_dir { format!("📁 {name}") } else { name.clone() };
                    let response = ui.selectable_label(!*is_dir && self.name == *name, label);
                    if response.clicked() {
                        if *is_dir {
                            enter = Some(self.dir.join(name));
                        } else {
                            self.name = name.clone();
                        }
                    }
                    if response.double_clicked() && !*is_dir {
                        confirm = true;
                    }
                }
            });
            if let Some(dir) = enter {
                self.enter(dir);
            }
            ui.separator();
            ui.horizontal(|ui| {
                ui.label("File");
                let field = ui.text_edit_singleline(&mut self.name);
                if field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                    confirm = true;
                }
                ui.label(egui::RichText::new(format!("(.{})", self.purpose.extensions().join(", ."))).weak());
            });
            if let Some(problem) = &self.problem {
                ui.colored_label(ui.visuals().error_fg_color, problem);
            }
            ui.horizontal(|ui| {
                let verb = match self.purpose {
                    FilePurpose::AddEnvironmentFolder => "Add this folder",
                    _ if self.purpose.saving() => "Save",
                    _ => "Open",
                };
                if ui.button(verb).clicked() {
                    confirm = true;
                }
                if ui.button("Cancel").clicked() {
                    keep = false;
                }
            });
        });
        if confirm && self.purpose == FilePurpose::AddEnvironmentFolder {
            // The folder shown, or a sub-folder named in the field.
            let folder = self.chosen().filter(|p| p.is_dir()).unwrap_or_else(|| self.dir.clone());
            actions.push(self.purpose.action(folder));
            keep = false;
        } else if confirm {
            match self.chosen() {
                None => self.problem = Some("type a file name, or pick one".into()),
                Some(path) if !self.purpose.saving() && !path.is_file() => {
                    self.problem = Some(format!("{}: no such file", path.display()));
                }
                Some(path) if self.purpose.saving() && path.exists() && self.replace.as_ref() != Some(&path) => {
                    self.problem = Some(format!("{} exists: {} again to replace it", path.display(), "Save"));
                    self.replace = Some(path);
                }
                Some(path) => {
                    actions.push(self.purpose.action(path));
                    keep = false;
                }
            }
        }
        keep
    }
}

/// The fields of "save layer as preset".
#[derive(Default)]
pub struct SavePresetForm {
    name: String,
    description: String,
    tags: String,
    force: bool,
}

impl SavePresetForm {
    /// Shows the window; false once it is done.
    pub fn show(&mut self, ctx: &egui::Context, actions: &mut Vec<Action>) -> bool {
        let mut keep = true;
        egui::Window::new("Save layer as preset").collapsible(false).show(ctx, |ui| {
            egui::Grid::new("preset form").num_columns(2).show(ui, |ui| {
                ui.label("Name");
                ui.text_edit_singleline(&mut self.name).on_hover_text("lowercase letters, digits, - and _");
                ui.end_row();
                ui.label("Description");
                ui.text_edit_multiline(&mut self.description);
                ui.end_row();
                ui.label("Tags");
                ui.text_edit_singleline(&mut self.tags).on_hover_text("comma-separated, e.g. metal, brushed");
                ui.end_row();
                ui.label("");
                ui.checkbox(&mut self.force, "replace a preset of that name");
                ui.end_row();
            });
            let folder = crate::material::library::user_library_dir()
                .map_or("(no user library: set LOOKDEV_PRESETS or HOME)".to_string(), |d| d.display().to_string());
            ui.label(egui::RichText::new(format!("Saved to {folder}")).weak());
            ui.horizontal(|ui| {
                if ui.button("Save").clicked() {
                    let tags = self.tags.split(',').map(|t| t.trim().to_string()).filter(|t| !t.is_empty()).collect();
                    actions.push(Action::SaveLayerAsPreset {
                        name: self.name.trim().to_string(),
                        description: self.description.trim().to_string(),
                        tags,
                        force: self.force,
                    });
                    keep = false;
                }
                if ui.button("Cancel").clicked() {
                    keep = false;
                }
            });
        });
        keep
    }
}

/// The question asked before unsaved edits would be lost.
pub fn unsaved_question(ctx: &egui::Context, session: &Session, pending: &Pending, actions: &mut Vec<Action>) {
    let name = session.document.path().map_or("the look".to_string(), |p| p.display().to_string());
    let then = match pending {
        Pending::Quit => "closing".to_string(),
        Pending::Open(path) => format!("opening {}", path.display()),
    };
    egui::Modal::new(egui::Id::new("unsaved edits")).show(ctx, |ui| {
        ui.heading("Unsaved edits");
        ui.label(format!("{name} has edits that are not saved. Save them before {then}?"));
        ui.horizontal(|ui| {
            for (answer, label) in
                [(Answer::Save, "Save"), (Answer::Discard, "Discard edits"), (Answer::Cancel, "Cancel")]
            {
                if ui.button(label).clicked() {
                    actions.push(Action::Answer(answer));
                }
            }
        });
    });
}
