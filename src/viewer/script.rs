//! `--script FILE`: a list of interface actions, one per line, run one per frame through the
//! same code as the panels
//! (docs/commands.md#lookdev-view-looktoml---gbuffer-file---env-file---device-name).
//! The whole file is checked before the window opens; a line that fails while running stops the
//! viewer with the file and line named.

use super::action::{Action, Answer, Compare};
use super::compare::SnapshotView;
use crate::environment::backdrop::{self, Backdrop};
use crate::environment::EnvironmentRef;
use crate::material::mask::MaskAdjust;
use crate::material::params::{parse_value, Param, Value};
use crate::shading::tonemap::Tonemap;
use crate::viewer_state::{Edit, ObjectRef, Selection};
use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// A checked script.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Script {
    pub file: PathBuf,
    /// Each step with its 1-based line.
    pub steps: Vec<(usize, Step)>,
}

/// One line of a script.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// An action that needs nothing more.
    Do(Action),
    /// A change to the selected layer, made into an edit once the selection is known.
    Layer(LayerChange),
    /// Keep rendering until every pixel has this many samples.
    WaitSpp(u32),
}

/// A change to the selected layer.
#[derive(Clone, Debug, PartialEq)]
pub enum LayerChange {
    Set(Param, Value),
    Reset(Param),
    Remove,
    Duplicate,
    Move(usize),
    Enabled(bool),
    Invert(bool),
    Opacity(f32),
    MaskAdjust(MaskAdjust),
    Rename(Option<String>),
}

impl LayerChange {
    /// The edit this change makes to `layer` of `object`.
    pub fn edit(self, object: ObjectRef, layer: usize) -> Edit {
        match self {
            LayerChange::Set(param, value) => Edit::SetParam { object, layer, param, value },
            LayerChange::Reset(param) => Edit::ResetParam { object, layer, param },
            LayerChange::Remove => Edit::RemoveLayer { object, layer },
            LayerChange::Duplicate => Edit::DuplicateLayer { object, layer },
            LayerChange::Move(to) => Edit::MoveLayer { object, from: layer, to },
            LayerChange::Enabled(enabled) => Edit::SetEnabled { object, layer, enabled },
            LayerChange::Invert(invert) => Edit::SetInvert { object, layer, invert },
            LayerChange::Opacity(opacity) => Edit::SetOpacity { object, layer, opacity },
            LayerChange::MaskAdjust(adjust) => Edit::SetMaskAdjust { object, layer, adjust },
            LayerChange::Rename(name) => Edit::RenameLayer { object, layer, name },
        }
    }
}

/// The commands, for the error that names an unknown one.
const COMMANDS: &str = "select, set, reset, map, add, remove, duplicate, move, show, hide, mask, mask-adjust, invert, \
    opacity, rename, solo, overlay, \
    rotate, intensity, background, env, exposure, tonemap, spp, seed, undo, redo, pick, inspect, wait-spp, save-look, \
    save-preset, save-image, screenshot, open-look, quit, answer, compare, divider, key, zoom, view, clipping, probe, \
    snapshot, restore, delete-snapshot, denoise, visibility, catcher";

impl Script {
    pub fn load(path: &Path) -> Result<Script> {
        let text = crate::input::read_text(path, crate::input::Kind::Script)?;
        Script::parse(&text, path)
    }

    /// Parses a script; `file` names it in errors. Blank lines and `#` comments are skipped.
    pub fn parse(text: &str, file: &Path) -> Result<Script> {
        let mut steps = Vec::new();
        for (index, raw) in text.lines().enumerate() {
            let line = raw.split_once('#').map_or(raw, |(code, _)| code).trim();
            if line.is_empty() {
                continue;
            }
            let (command, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
            let step = parse_step(command, rest.trim())
                .map_err(|problem| Error::input_file(format!("{}:{}", file.display(), index + 1), problem))?;
            steps.push((index + 1, step));
        }
        Ok(Script { file: file.to_path_buf(), steps })
    }
}

/// Runs a script a step at a time.
pub struct ScriptRunner {
    script: Script,
    next: usize,
}

impl ScriptRunner {
    pub fn new(script: Script) -> ScriptRunner {
        ScriptRunner { script, next: 0 }
    }

    /// An error while a question that `line` raised is open (the unsaved-edits question of
    /// `quit`, `open-look` or a key), unless the script's next step answers it: a script cannot
    /// answer later, and nobody else may be there to, so waiting would hang.
    pub fn check_answerable(&self, line: usize) -> Result<()> {
        match self.script.steps.get(self.next) {
            Some((_, Step::Do(Action::Answer(_)))) => Ok(()),
            _ => Err(self.error_at(
                line,
                Error::input(
                    "this leaves the look's unsaved edits in question: answer on the next line \
                     (answer save, answer discard or answer cancel)",
                ),
            )),
        }
    }

    pub fn finished(&self) -> bool {
        self.next >= self.script.steps.len()
    }

    /// Whether the next step can run at `samples` of `target`: there is one, and it is not a
    /// wait for samples not yet taken (a wait that could never end is ready: to be refused).
    pub fn ready(&self, samples: u32, target: u32) -> bool {
        match self.script.steps.get(self.next) {
            None => false,
            Some((_, Step::WaitSpp(spp))) => samples >= *spp || *spp > target,
            Some(_) => true,
        }
    }

    /// The next step and its line; `None` when the script is done or waiting for samples. A
    /// wait for more samples than the target would never end, so it is an error, which names
    /// what sets the target: `--exit-after-spp` (`capped`), else the look's or `spp`'s.
    pub fn next(&mut self, samples: u32, target: u32, capped: bool) -> Result<Option<(usize, Step)>> {
        let Some((line, step)) = self.script.steps.get(self.next).cloned() else {
            return Ok(None);
        };
        if let Step::WaitSpp(spp) = step {
            if spp > target {
                let problem = if capped {
                    format!(
                        "wait-spp {spp} would never end: --exit-after-spp {target} stops the viewer at {target} spp \
                         (raise it to at least {spp})"
                    )
                } else {
                    format!("wait-spp {spp} would never end: the target is {target} spp (raise it with `spp {spp}`)")
                };
                return Err(self.error_at(line, Error::input(problem)));
            }
            if samples < spp {
                return Ok(None);
            }
        }
        self.next += 1;
        Ok(Some((line, step)))
    }

    /// An error placed at a line of the script.
    pub fn error_at(&self, line: usize, error: Error) -> Error {
        Error { kind: error.kind, message: format!("{}:{line}: {}", self.script.file.display(), error.message) }
    }
}

fn parse_step(command: &str, rest: &str) -> std::result::Result<Step, String> {
    let args: Vec<&str> = rest.split_whitespace().collect();
    let arity = |n: usize| {
        if args.len() == n {
            Ok(())
        } else {
            Err(format!("'{command}' takes {n} argument{}, not {}", if n == 1 { "" } else { "s" }, args.len()))
        }
    };
    let path = || if rest.is_empty() { Err(format!("'{command}' needs a file")) } else { Ok(PathBuf::from(rest)) };
    let edit = |edit: Edit| Ok(Step::Do(Action::Edit(edit)));
    let layer = |change: LayerChange| Ok(Step::Layer(change));
    match command {
        "select" => {
            if args.is_empty() || args.len() > 2 {
                return Err("'select' takes an object (an id or `default`) and optionally a layer".into());
            }
            let object = match args[0] {
                "default" => ObjectRef::Default,
                id => ObjectRef::Id(number(id, "object id")?),
            };
            let layer = args.get(1).map(|l| number(l, "layer")).transpose()?;
            Ok(Step::Do(Action::Select(Selection { object: Some(object), layer })))
        }
        "set" => {
            let (name, value) = rest.split_once(char::is_whitespace).ok_or("'set' takes a parameter and a value")?;
            let param = parameter(name)?;
            let value = parse_value(param, value.trim())?;
            layer(LayerChange::Set(param, value))
        }
        "reset" => {
            arity(1)?;
            layer(LayerChange::Reset(parameter(args[0])?))
        }
        "add" => {
            arity(1)?;
            Ok(Step::Do(Action::AddPresetLayer(args[0].to_string())))
        }
        "remove" | "duplicate" | "show" | "hide" => {
            arity(0)?;
            layer(match command {
                "remove" => LayerChange::Remove,
                "duplicate" => LayerChange::Duplicate,
                "show" => LayerChange::Enabled(true),
                _ => LayerChange::Enabled(false),
            })
        }
        "move" => {
            arity(1)?;
            layer(LayerChange::Move(number(args[0], "layer")?))
        }
        "map" => {
            arity(2)?;
            let map = if args[1] == "none" { None } else { Some(args[1].to_string()) };
            Ok(Step::Do(Action::SetMap { param: parameter(args[0])?, map }))
        }
        "mask" => {
            arity(1)?;
            Ok(Step::Do(Action::SetMask(if args[0] == "none" { None } else { Some(args[0].to_string()) })))
        }
        "invert" => {
            arity(1)?;
            layer(LayerChange::Invert(switch(args[0])?))
        }
        "opacity" => {
            arity(1)?;
            layer(LayerChange::Opacity(float(args[0])?))
        }
        "mask-adjust" => {
            arity(4)?;
            let [black, white, gamma, blur] = [args[0], args[1], args[2], args[3]].map(float);
            layer(LayerChange::MaskAdjust(MaskAdjust { black: black?, white: white?, gamma: gamma?, blur: blur? }))
        }
        "rename" => match rest {
            "" => Err("'rename' needs a name ('rename none' goes back to the preset's)".to_string()),
            "none" => layer(LayerChange::Rename(None)),
            name => layer(LayerChange::Rename(Some(name.to_string()))),
        },
        "solo" => {
            arity(1)?;
            Ok(Step::Do(Action::Solo(switch(args[0])?)))
        }
        "overlay" => {
            arity(1)?;
            Ok(Step::Do(Action::MaskOverlay(Some(switch(args[0])?))))
        }
        "rotate" => {
            arity(1)?;
            edit(Edit::SetRotation(float(args[0])?))
        }
        "intensity" => {
            arity(1)?;
            edit(Edit::SetIntensity(float(args[0])?))
        }
        "background" => edit(background(&args, rest)?),
        "environments" => {
            arity(0)?;
            Ok(Step::Do(Action::ShowEnvironments))
        }
        "env" => Ok(Step::Do(match rest {
            "next" => Action::StepEnvironment(1),
            "prev" => Action::StepEnvironment(-1),
            "default" => Action::OpenEnvironment(None),
            _ => {
                path()?;
                Action::OpenEnvironment(Some(EnvironmentRef::parse(rest)?))
            }
        })),
        "exposure" => {
            arity(1)?;
            edit(Edit::SetExposure(float(args[0])?))
        }
        "tonemap" => {
            arity(1)?;
            let tonemap = Tonemap::parse(args[0])?;
            edit(Edit::SetTonemap(tonemap))
        }
        "spp" => {
            arity(1)?;
            edit(Edit::SetTargetSpp(number(args[0], "spp")?))
        }
        "seed" => {
            arity(1)?;
            edit(Edit::SetSeed(number(args[0], "seed")?))
        }
        "undo" | "redo" | "quit" => {
            arity(0)?;
            Ok(Step::Do(match command {
                "undo" => Action::Undo,
                "redo" => Action::Redo,
                _ => Action::Quit,
            }))
        }
        "pick" => {
            arity(2)?;
            Ok(Step::Do(Action::Pick { x: number(args[0], "x")?, y: number(args[1], "y")? }))
        }
        "inspect" => {
            arity(0)?;
            Ok(Step::Do(Action::ShowInspection))
        }
        "wait-spp" => {
            arity(1)?;
            let spp = number(args[0], "spp")?;
            if spp == 0 {
                return Err("'wait-spp' needs at least 1 sample".into());
            }
            Ok(Step::WaitSpp(spp))
        }
        "save-look" => Ok(Step::Do(Action::SaveLook(if rest.is_empty() { None } else { Some(path()?) }))),
        "save-preset" => {
            let force = args.contains(&"--force");
            let names: Vec<&&str> = args.iter().filter(|a| **a != "--force").collect();
            if names.len() != 1 {
                return Err("'save-preset' takes a name and optionally --force".into());
            }
            Ok(Step::Do(Action::SaveLayerAsPreset {
                name: names[0].to_string(),
                description: String::new(),
                tags: Vec::new(),
                force,
            }))
        }
        "save-image" => Ok(Step::Do(Action::SaveImage(path()?))),
        "screenshot" => Ok(Step::Do(Action::Screenshot(path()?))),
        "open-look" => Ok(Step::Do(Action::OpenLook(path()?))),
        "answer" => {
            arity(1)?;
            let answer = match args[0] {
                "save" => Answer::Save,
                "discard" => Answer::Discard,
                "cancel" => Answer::Cancel,
                other => return Err(format!("unknown answer '{other}' (expected save, discard or cancel)")),
            };
            Ok(Step::Do(Action::Answer(answer)))
        }
        "compare" => {
            let usage =
                "'compare' takes `model KEY=VALUE...`, `look FILE`, `snapshot NAME [split|side|delta-e]`, `swap` \
                or `off`";
            let (what, more) = rest.split_once(char::is_whitespace).unwrap_or((rest, ""));
            let more = more.trim();
            let compare = match what {
                "model" => {
                    let keys: Vec<String> = more.split_whitespace().map(str::to_string).collect();
                    if keys.is_empty() {
                        return Err("'compare model' takes KEY=VALUE changes, e.g. diffuse=lambert".into());
                    }
                    // Checked now, so that a bad key is a parse error naming its line.
                    let mut model = crate::shading::model::Model::default();
                    for key in &keys {
                        model.set_from_flag("compare model", key)?;
                    }
                    Compare::Model(keys)
                }
                "look" if !more.is_empty() => Compare::Look(PathBuf::from(more)),
                "look" => return Err("'compare look' needs a file".into()),
                "snapshot" => {
                    let words: Vec<&str> = more.split_whitespace().collect();
                    let (name, view) = match words[..] {
                        [name] => (name, SnapshotView::Split),
                        [name, view] => (name, SnapshotView::parse(view)?),
                        _ => return Err("'compare snapshot' takes a name and optionally split, side or delta-e".into()),
                    };
                    crate::viewer::snapshots::check_name(name)?;
                    Compare::Snapshot(name.to_string(), view)
                }
                "swap" | "off" if more.is_empty() => {
                    if what == "swap" {
                        Compare::Swap
                    } else {
                        Compare::Off
                    }
                }
                _ => return Err(usage.into()),
            };
            Ok(Step::Do(Action::Compare(compare)))
        }
        "divider" => {
            arity(1)?;
            let at = float(args[0])?;
            if !(0.0..=1.0).contains(&at) {
                return Err(format!("divider {at} is outside [0, 1] (a fraction of the image's width)"));
            }
            Ok(Step::Do(Action::Divider(at)))
        }
        "key" => {
            arity(1)?;
            let (key, modifiers) = key_press(args[0])?;
            Ok(Step::Do(Action::Key(key, modifiers)))
        }
        "zoom" => {
            arity(1)?;
            Ok(Step::Do(Action::Zoom(zoom(args[0])?)))
        }
        // The view's name is checked when the line runs, against the session's views.
        "view" => {
            arity(1)?;
            Ok(Step::Do(Action::View(super::views::ViewChoice::Named(args[0].to_string()))))
        }
        "clipping" => {
            arity(1)?;
            Ok(Step::Do(Action::Clipping(Some(switch(args[0])?))))
        }
        "probe" => {
            arity(2)?;
            Ok(Step::Do(Action::Probe { x: number(args[0], "x")?, y: number(args[1], "y")? }))
        }
        "snapshot" => {
            if args.len() > 1 {
                return Err("'snapshot' takes at most a name".into());
            }
            let name = args.first().map(|name| crate::viewer::snapshots::check_name(name).map(|()| name.to_string()));
            Ok(Step::Do(Action::Snapshot(name.transpose()?)))
        }
        "restore" | "delete-snapshot" => {
            arity(1)?;
            crate::viewer::snapshots::check_name(args[0])?;
            let name = args[0].to_string();
            Ok(Step::Do(if command == "restore" {
                Action::RestoreSnapshot(name)
            } else {
                Action::DeleteSnapshot(name)
            }))
        }
        "denoise" => {
            arity(1)?;
            Ok(Step::Do(Action::Denoise(switch(args[0])?)))
        }
        "visibility" => {
            arity(1)?;
            Ok(Step::Do(Action::Visibility(switch(args[0])?)))
        }
        "catcher" => {
            arity(1)?;
            Ok(Step::Do(Action::SetShadowCatcher(switch(args[0])?)))
        }
        other => Err(format!("unknown command '{other}' (expected one of: {COMMANDS})")),
    }
}

/// `C`, `ArrowRight`, `?`, `shift+C`, `ctrl+Z`: a key as egui names it, after any modifiers.
fn key_press(text: &str) -> std::result::Result<(egui::Key, egui::Modifiers), String> {
    let mut modifiers = egui::Modifiers::NONE;
    let mut parts: Vec<&str> = text.split('+').collect();
    // `+` itself is a key: `key +` or `key shift++`.
    if text.ends_with("++") || text == "+" {
        parts.retain(|p| !p.is_empty());
        parts.push("+");
    }
    let name = parts.pop().unwrap_or_default();
    for modifier in parts {
        match modifier.to_ascii_lowercase().as_str() {
            "shift" => modifiers.shift = true,
            "ctrl" | "command" | "cmd" => modifiers |= egui::Modifiers::COMMAND,
            "alt" => modifiers.alt = true,
            other => return Err(format!("unknown modifier '{other}' in '{text}' (expected shift, ctrl or alt)")),
        }
    }
    let key = egui::Key::from_name(name).ok_or_else(|| {
        format!("unknown key '{name}' (keys are named as egui names them: A, Num1, ArrowLeft, Escape, ?, …)")
    })?;
    Ok((key, modifiers))
}

/// `fit`, or a scale in window pixels per image pixel (`1`, `2`, `0.5`).
pub fn zoom(text: &str) -> std::result::Result<Option<f32>, String> {
    if text == "fit" {
        return Ok(None);
    }
    match text.parse::<f32>() {
        Ok(scale) if (super::ui::MIN_SCALE..=super::ui::MAX_SCALE).contains(&scale) => Ok(Some(scale)),
        _ => Err(format!(
            "zoom '{text}' is neither 'fit' nor a scale from {} to {}",
            super::ui::MIN_SCALE,
            super::ui::MAX_SCALE
        )),
    }
}

fn parameter(name: &str) -> std::result::Result<Param, String> {
    Param::parse(name)
}

fn number<T: std::str::FromStr>(text: &str, what: &str) -> std::result::Result<T, String> {
    text.parse().map_err(|_| format!("{what} '{text}' is not a whole number ≥ 0"))
}

fn float(text: &str) -> std::result::Result<f32, String> {
    text.parse::<f32>().ok().filter(|v| v.is_finite()).ok_or_else(|| format!("'{text}' is not a finite number"))
}

/// `background on|off|environment|blur [DEG]|colour R G B|env NAME|FILE`: `rest` is the
/// whole of the arguments, `args` split at spaces.
fn background(args: &[&str], rest: &str) -> std::result::Result<Edit, String> {
    let takes = |n: usize, form: &str| {
        if args.len() == n {
            Ok(())
        } else {
            Err(format!("'background {form}' takes {} value{}", n - 1, if n == 2 { "" } else { "s" }))
        }
    };
    match args.first().copied() {
        Some("environment") => takes(1, "environment").map(|()| Edit::SetBackdrop(Backdrop::Environment)),
        Some("blur") if args.len() == 1 => Ok(Edit::SetBackdrop(Backdrop::Blurred(backdrop::DEFAULT_BLUR_DEGREES))),
        Some("blur") => takes(2, "blur DEG").and(float(args[1])).map(|d| Edit::SetBackdrop(Backdrop::Blurred(d))),
        Some("colour" | "color") => {
            takes(4, "colour R G B")?;
            let [r, g, b] = [args[1], args[2], args[3]].map(float);
            Ok(Edit::SetBackdrop(Backdrop::Colour([r?, g?, b?])))
        }
        Some("env") => {
            let name = rest["env".len()..].trim();
            if name.is_empty() {
                return Err("'background env' needs an environment file or a built-in's name".to_string());
            }
            Ok(Edit::SetBackdrop(Backdrop::Other(EnvironmentRef::parse(name)?)))
        }
        Some(word) if args.len() == 1 => switch(word)
            .map(Edit::SetBackground)
            .map_err(|_| format!("'{word}' is not on or off, environment, blur [DEG], colour R G B or env NAME|FILE")),
        _ => Err("'background' takes on, off, environment, blur [DEG], colour R G B or env NAME|FILE".to_string()),
    }
}

fn switch(text: &str) -> std::result::Result<bool, String> {
    match text {
        "on" | "true" => Ok(true),
        "off" | "false" => Ok(false),
        _ => Err(format!("'{text}' is not on or off")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Script> {
        Script::parse(text, Path::new("edit.script"))
    }

    #[test]
    fn every_command_parses_to_its_action() {
        let script = parse(
            "# a comment\n\nselect 1 0\nset roughness 0.25\nset base_color 0.8, 0.1, 0.1  # red\nadd gold\n\
             mask stripes\nrotate -45\nenv studio\nwait-spp 4\nsave-look out/look.toml\nanswer discard\n",
        )
        .unwrap();
        let steps: Vec<&Step> = script.steps.iter().map(|(_, s)| s).collect();
        assert_eq!(script.steps[0].0, 3, "lines count from 1, comments and blanks included");
        assert_eq!(*steps[0], Step::Do(Action::Select(Selection { object: Some(ObjectRef::Id(1)), layer: Some(0) })));
        assert_eq!(*steps[1], Step::Layer(LayerChange::Set(Param::Roughness, Value::Scalar(0.25))));
        assert_eq!(*steps[2], Step::Layer(LayerChange::Set(Param::BaseColor, Value::Color([0.8, 0.1, 0.1]))));
        assert_eq!(*steps[3], Step::Do(Action::AddPresetLayer("gold".into())));
        assert_eq!(*steps[4], Step::Do(Action::SetMask(Some("stripes".into()))));
        assert_eq!(*steps[5], Step::Do(Action::Edit(Edit::SetRotation(-45.0))));
        assert_eq!(*steps[6], Step::Do(Action::OpenEnvironment(Some(EnvironmentRef::Builtin("studio")))));
        assert_eq!(*steps[7], Step::WaitSpp(4));
        assert_eq!(*steps[8], Step::Do(Action::SaveLook(Some(PathBuf::from("out/look.toml")))));
        assert_eq!(*steps[9], Step::Do(Action::Answer(Answer::Discard)));
    }

    #[test]
    fn every_background_parses_to_its_edit() {
        let script = parse(
            "background off\nbackground environment\nbackground blur\nbackground blur 12\n\
             background colour 0.1 0.2 0.3\nbackground env builtin:city\n",
        )
        .unwrap();
        let edits: Vec<Edit> = script
            .steps
            .iter()
            .map(|(_, step)| match step {
                Step::Do(Action::Edit(edit)) => edit.clone(),
                other => panic!("{other:?} is not an edit"),
            })
            .collect();
        assert_eq!(
            edits,
            [
                Edit::SetBackground(false),
                Edit::SetBackdrop(Backdrop::Environment),
                Edit::SetBackdrop(Backdrop::Blurred(backdrop::DEFAULT_BLUR_DEGREES)),
                Edit::SetBackdrop(Backdrop::Blurred(12.0)),
                Edit::SetBackdrop(Backdrop::Colour([0.1, 0.2, 0.3])),
                Edit::SetBackdrop(Backdrop::Other(EnvironmentRef::Builtin("city"))),
            ]
        );
        for (text, expected) in [
            ("background colour 1 2\n", "'background colour R G B' takes 3 values"),
            ("background blur soft\n", "'soft' is not a finite number"),
            ("background env\n", "needs an environment file or a built-in's name"),
            ("background\n", "'background' takes on, off"),
        ] {
            let message = parse(text).unwrap_err().to_string();
            assert!(message.contains(expected), "{text:?}: {message}");
        }
    }

    #[test]
    fn a_bad_line_is_named_with_its_problem() {
        let cases = [
            ("frobnicate\n", "edit.script:1: unknown command 'frobnicate'"),
            ("\nset shininess 3\n", "edit.script:2: unknown parameter 'shininess'"),
            ("set roughness lots\n", "edit.script:1:"),
            ("rotate nan\n", "'nan' is not a finite number"),
            ("select\n", "'select' takes an object"),
            ("wait-spp 0\n", "at least 1 sample"),
            ("background maybe\n", "'maybe' is not on or off"),
            ("undo now\n", "'undo' takes 0 arguments, not 1"),
            ("compare model diffuse=lamber\n", "compare model diffuse=lamber: diffuse = 'lamber' is not a model"),
            ("compare model\n", "'compare model' takes KEY=VALUE"),
            ("compare look\n", "'compare look' needs a file"),
            ("compare sideways\n", "'compare' takes"),
            ("divider 1.5\n", "divider 1.5 is outside [0, 1]"),
        ];
        for (text, expected) in cases {
            let message = parse(text).unwrap_err().to_string();
            assert!(message.contains(expected), "{text:?}: {message}");
        }
    }

    #[test]
    fn compare_and_divider_parse_to_their_actions() {
        let script = parse(
            "compare model diffuse=lambert fresnel=dielectric\ncompare look b.toml\ncompare swap\ncompare off\n\
             divider 0.25\n",
        )
        .unwrap();
        let steps: Vec<&Step> = script.steps.iter().map(|(_, s)| s).collect();
        let keys = vec!["diffuse=lambert".to_string(), "fresnel=dielectric".to_string()];
        assert_eq!(*steps[0], Step::Do(Action::Compare(Compare::Model(keys))));
        assert_eq!(*steps[1], Step::Do(Action::Compare(Compare::Look(PathBuf::from("b.toml")))));
        assert_eq!(*steps[2], Step::Do(Action::Compare(Compare::Swap)));
        assert_eq!(*steps[3], Step::Do(Action::Compare(Compare::Off)));
        assert_eq!(*steps[4], Step::Do(Action::Divider(0.25)));
    }

    #[test]
    fn keys_and_zoom_parse_to_their_actions() {
        let script = parse("key C\nkey shift+ArrowRight\nkey ?\nkey ctrl+Z\nzoom fit\nzoom 2\n").unwrap();
        let steps: Vec<&Step> = script.steps.iter().map(|(_, s)| s).collect();
        let shift = egui::Modifiers::SHIFT;
        assert_eq!(*steps[0], Step::Do(Action::Key(egui::Key::C, egui::Modifiers::NONE)));
        assert_eq!(*steps[1], Step::Do(Action::Key(egui::Key::ArrowRight, shift)));
        assert_eq!(*steps[2], Step::Do(Action::Key(egui::Key::Questionmark, egui::Modifiers::NONE)));
        assert_eq!(*steps[3], Step::Do(Action::Key(egui::Key::Z, egui::Modifiers::COMMAND)));
        assert_eq!(*steps[4], Step::Do(Action::Zoom(None)));
        assert_eq!(*steps[5], Step::Do(Action::Zoom(Some(2.0))));
        for (line, problem) in [
            ("key Banana", "unknown key 'Banana'"),
            ("key super+C", "unknown modifier 'super'"),
            ("zoom 100", "zoom '100' is neither 'fit' nor a scale"),
            ("zoom", "'zoom' takes 1 argument"),
        ] {
            let message = parse(line).unwrap_err().to_string();
            assert!(message.contains(problem), "{line}: {message}");
        }
    }

    #[test]
    fn view_clipping_and_probe_parse_to_their_actions() {
        use crate::viewer::views::ViewChoice;
        let script = parse("view mask.stripes\nclipping on\nclipping off\nprobe 3 4\n").unwrap();
        let steps: Vec<&Step> = script.steps.iter().map(|(_, s)| s).collect();
        assert_eq!(*steps[0], Step::Do(Action::View(ViewChoice::Named("mask.stripes".into()))));
        assert_eq!(*steps[1], Step::Do(Action::Clipping(Some(true))));
        assert_eq!(*steps[2], Step::Do(Action::Clipping(Some(false))));
        assert_eq!(*steps[3], Step::Do(Action::Probe { x: 3, y: 4 }));
        for (line, problem) in [
            ("view", "'view' takes 1 argument, not 0"),
            ("clipping maybe", "'maybe' is not on or off"),
            ("probe 1", "'probe' takes 2 arguments"),
            ("probe -1 2", "x '-1' is not a whole number"),
        ] {
            let message = parse(line).unwrap_err().to_string();
            assert!(message.contains(problem), "{line}: {message}");
        }
    }

    #[test]
    fn snapshot_commands_parse_and_bad_names_are_refused_at_their_line() {
        let script = parse(
            "snapshot\nsnapshot before\nrestore before\ncompare snapshot before delta-e\ncompare snapshot a side\n\
                   compare snapshot b\ndelete-snapshot b\n",
        )
        .unwrap();
        let steps: Vec<&Step> = script.steps.iter().map(|(_, s)| s).collect();
        assert_eq!(*steps[0], Step::Do(Action::Snapshot(None)));
        assert_eq!(*steps[1], Step::Do(Action::Snapshot(Some("before".into()))));
        assert_eq!(*steps[2], Step::Do(Action::RestoreSnapshot("before".into())));
        assert_eq!(*steps[3], Step::Do(Action::Compare(Compare::Snapshot("before".into(), SnapshotView::DeltaE))));
        assert_eq!(*steps[4], Step::Do(Action::Compare(Compare::Snapshot("a".into(), SnapshotView::Side))));
        assert_eq!(*steps[5], Step::Do(Action::Compare(Compare::Snapshot("b".into(), SnapshotView::Split))));
        assert_eq!(*steps[6], Step::Do(Action::DeleteSnapshot("b".into())));
        for (line, problem) in [
            ("snapshot ../up", "edit.script:1: snapshot name '../up' has '/'"),
            ("snapshot a b", "'snapshot' takes at most a name"),
            ("restore", "'restore' takes 1 argument"),
            ("restore -x", "must start with a letter or a digit"),
            ("compare snapshot", "'compare snapshot' takes a name"),
            ("compare snapshot a wipe", "unknown snapshot view 'wipe' (expected split, side or delta-e)"),
        ] {
            let message = parse(line).unwrap_err().to_string();
            assert!(message.contains(problem), "{line}: {message}");
        }
    }

    #[test]
    fn layer_changes_become_edits_of_the_selected_layer() {
        let object = ObjectRef::Id(2);
        assert_eq!(LayerChange::Move(0).edit(object, 3), Edit::MoveLayer { object, from: 3, to: 0 });
        assert_eq!(
            LayerChange::Reset(Param::Sheen).edit(object, 1),
            Edit::ResetParam { object, layer: 1, param: Param::Sheen }
        );
    }

    #[test]
    fn denoise_parses_to_the_display_filter_switch() {
        let script = parse("denoise on\ndenoise off\n").unwrap();
        assert_eq!(script.steps[0].1, Step::Do(Action::Denoise(true)));
        assert_eq!(script.steps[1].1, Step::Do(Action::Denoise(false)));
        for (line, problem) in
            [("denoise", "'denoise' takes 1 argument"), ("denoise maybe", "'maybe' is not on or off")]
        {
            let message = parse(line).unwrap_err().to_string();
            assert!(message.contains(problem), "{line}: {message}");
        }
    }
}
