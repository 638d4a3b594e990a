//! The hotkey sheet (`?`, or Help ▸ Hotkeys): every key and mouse gesture the viewer answers,
//! from one table that docs/commands.md mirrors. A test reads the viewer's sources and fails
//! while a key they handle is missing here.

/// One line of the sheet.
#[derive(Clone, Copy, Debug)]
pub struct Hotkey {
    /// As typed: keys joined by `+`, alternatives by ` / ` (each key named as egui names it,
    /// or by its symbol).
    pub keys: &'static str,
    pub does: &'static str,
}

/// The keys, in the sheet's order.
pub const HOTKEYS: &[Hotkey] = &[
    Hotkey { keys: "Ctrl+Z", does: "Undo" },
    Hotkey { keys: "Ctrl+Shift+Z / Ctrl+Y", does: "Redo" },
    Hotkey { keys: "Ctrl+S", does: "Save the look (asks for a file if it has none)" },
    Hotkey { keys: "Ctrl+Shift+N", does: "Add a layer from the preset library" },
    Hotkey { keys: "Ctrl+J", does: "Duplicate the selected layer (the copy is selected)" },
    Hotkey { keys: "Delete", does: "Remove the selected layer" },
    Hotkey { keys: "Ctrl+Comma", does: "Hide or show the selected layer (Ctrl+, as in Photoshop)" },
    Hotkey { keys: "S", does: "Solo the selected layer (it alone fills its objects) or end the solo" },
    Hotkey { keys: "L", does: "Mask overlay on or off: the image tinted where the selected layer shows" },
    Hotkey { keys: "Ctrl+Q", does: "Quit (asks about unsaved edits)" },
    Hotkey { keys: "F", does: "Fit the image to the view" },
    Hotkey { keys: "1", does: "Show the image at 1:1 (one image pixel per screen pixel)" },
    Hotkey { keys: "H", does: "Hide or show the side panels, so that the image has the window's width" },
    Hotkey { keys: "C / Shift+C", does: "Next / previous view (beauty, light AOVs, parameters, N, V, masks, …)" },
    Hotkey { keys: "M", does: "Back to the beauty" },
    Hotkey { keys: "E", does: "False-colour EV view on or off" },
    Hotkey { keys: "X", does: "Clipping overlay on or off" },
    Hotkey { keys: "P", does: "Take a snapshot of the image and its look" },
    Hotkey {
        keys: "B",
        does: "Flip in place to the other image (the snapshot or B compared; else the last snapshot) and back",
    },
    Hotkey { keys: "ArrowLeft / ArrowRight", does: "Previous / next environment in the library (an undoable edit)" },
    Hotkey { keys: "D", does: "Denoised display on or off (a display filter: never in saved images)" },
    Hotkey { keys: "O", does: "Shadows (the g-buffer's visibility) on or off, for comparison" },
    Hotkey { keys: "?", does: "Show or hide this sheet" },
    Hotkey { keys: "Enter", does: "In a file dialog's name field: open or save that file" },
    Hotkey { keys: "Escape", does: "Close the preset library or the environments window" },
];

/// The mouse in the image and the panels.
pub const GESTURES: &[Hotkey] = &[
    Hotkey { keys: "Click", does: "Inspect the pixel and select its object" },
    Hotkey { keys: "Shift+drag", does: "Turn the light (environment rotation)" },
    Hotkey { keys: "Drag", does: "Pan the image; on the A/B divider, move the divider" },
    Hotkey { keys: "Wheel / pinch", does: "Zoom about the cursor" },
    Hotkey { keys: "Drag ☰", does: "Reorder a layer in the layer panel" },
    Hotkey { keys: "Click a snapshot in the strip", does: "Compare it with the live image" },
    Hotkey { keys: "Drag a panel's edge", does: "Resize the panel" },
];

/// Shows the sheet while `open`; its close button clears `open`. Anchored in the middle of the
/// window, over the image; it appears and goes at once (no fade), so a screenshot of the frame
/// after the key shows it whole or not at all.
pub fn show(ctx: &egui::Context, open: &mut bool) {
    // A closed window is not shown at all: egui would otherwise draw it on while its fade-out
    // animation runs, for a time rather than a number of frames.
    if !*open {
        return;
    }
    egui::Window::new("Hotkeys")
        .open(open)
        .collapsible(false)
        .resizable(false)
        // Wide enough for the longest description on one line: a narrower sheet cut them off.
        .min_width(720.0)
        .fade_in(false)
        .fade_out(false)
        .anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0])
        .show(ctx, |ui| {
            table(ui, "hotkeys", HOTKEYS);
            ui.separator();
            ui.strong("Mouse");
            table(ui, "gestures", GESTURES);
        });
}

fn table(ui: &mut egui::Ui, id: &str, rows: &[Hotkey]) {
    egui::Grid::new(id).num_columns(2).striped(true).show(ui, |ui| {
        for row in rows {
            ui.label(egui::RichText::new(row.keys).monospace().strong());
            ui.label(row.does);
            ui.end_row();
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    /// Calls that take a key the viewer answers.
    const KEY_CALLS: [&str; 4] = ["consume_key(", "consume_shortcut(", "KeyboardShortcut::new(", "key_pressed("];

    fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                rust_files(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }

    /// The text of the call whose opening parenthesis ends `text[..start]`, to its closing one.
    fn call_arguments(text: &str, start: usize) -> &str {
        let mut depth = 1;
        for (offset, c) in text[start..].char_indices() {
            match c {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth == 0 {
                        return &text[start..start + offset];
                    }
                }
                _ => {}
            }
        }
        &text[start..]
    }

    /// Every `Key::Name` in the arguments of a key call in the viewer's sources, with its file.
    fn handled_keys() -> Vec<(String, String)> {
        let viewer = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/viewer");
        let mut files = Vec::new();
        rust_files(&viewer, &mut files);
        let mut keys = Vec::new();
        for file in files.iter().filter(|f| !f.ends_with("hotkeys.rs")) {
            let text = std::fs::read_to_string(file).unwrap();
            for call in KEY_CALLS {
                for (at, _) in text.match_indices(call) {
                    let arguments = call_arguments(&text, at + call.len());
                    for (key_at, _) in arguments.match_indices("Key::") {
                        let name: String = arguments[key_at + 5..]
                            .chars()
                            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                            .collect();
                        keys.push((name, file.strip_prefix(&viewer).unwrap().display().to_string()));
                    }
                }
            }
        }
        keys
    }

    /// The egui key of a `Key::` variant name.
    fn key_of(variant: &str) -> Option<egui::Key> {
        egui::Key::ALL.iter().copied().find(|k| format!("{k:?}") == variant)
    }

    /// Whether a sheet entry's keys name `key` (by egui's name, its symbol or its variant).
    fn names(keys: &str, key: egui::Key) -> bool {
        let variant = format!("{key:?}");
        keys.split(['+', '/', ',', ' ']).filter(|t| !t.is_empty()).any(|token| {
            token.eq_ignore_ascii_case(key.name())
                || token == key.symbol_or_name()
                || token.eq_ignore_ascii_case(&variant)
        })
    }

    /// A key the viewer handles and the sheet does not list fails here, naming the file.
    #[test]
    fn the_sheet_lists_every_key_the_viewer_handles() {
        let handled = handled_keys();
        // The scan itself works: it finds the keys this module's own sheet starts with.
        for known in ["Z", "Y", "S", "Q", "F", "Num1", "Questionmark"] {
            assert!(handled.iter().any(|(k, _)| k == known), "the scan misses Key::{known}: {handled:?}");
        }
        let mut missing = Vec::new();
        for (variant, file) in &handled {
            let key = key_of(variant).unwrap_or_else(|| panic!("{file}: Key::{variant} is not an egui key"));
            if !HOTKEYS.iter().any(|h| names(h.keys, key)) {
                missing.push(format!("{file}: Key::{variant} ('{}')", key.symbol_or_name()));
            }
        }
        assert!(missing.is_empty(), "keys missing from HOTKEYS in src/viewer/ui/hotkeys.rs:\n{}", missing.join("\n"));
    }

    /// docs/commands.md shows the same table, row for row.
    #[test]
    fn the_docs_mirror_the_sheet() {
        let docs = include_str!("../../../docs/commands.md");
        for row in HOTKEYS.iter().chain(GESTURES) {
            let line = format!("| `{}` | {} |", row.keys, row.does);
            assert!(docs.contains(&line), "docs/commands.md lacks the row:\n{line}");
        }
    }

    #[test]
    fn names_match_keys_by_name_symbol_or_variant() {
        assert!(names("Ctrl+Shift+Z / Ctrl+Y", egui::Key::Y));
        assert!(names("?", egui::Key::Questionmark));
        assert!(names("1", egui::Key::Num1));
        assert!(names("Shift+Right", egui::Key::ArrowRight));
        assert!(!names("Ctrl+S", egui::Key::C));
    }
}
