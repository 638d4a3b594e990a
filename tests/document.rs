//! The viewer's document: edits, undo and redo, merging, dirty state, revisions, saving looks
//! and presets.

use std::path::{Path, PathBuf};

use lookdev::environment::EnvironmentRef;
use lookdev::material::library;
use lookdev::material::look::Look;
use lookdev::material::params::{Param, Value};
use lookdev::material::preset::Preset;
use lookdev::render::settings::{Overrides, Settings};
use lookdev::shading::tonemap::Tonemap;
use lookdev::viewer_state::{Document, Edit, ObjectRef, Selection};

/// A default stack and a three-layer stack for object 1, the middle layer overriding roughness.
const LOOK: &str = r#"
[environment]
rotation = 15.0

[[object]]
[[object.layer]]
preset = "grey-card"

[[object]]
id = 1
[[object.layer]]
preset = "blue-rubber"
[[object.layer]]
preset = "gold"
mask = "stripes"
[object.layer.set]
roughness = 0.3
[[object.layer]]
preset = "grime"
mask = "grunge"
opacity = 0.7
"#;

const BALL: ObjectRef = ObjectRef::Id(1);

/// A look in a folder no test creates, so that its names resolve to the built-ins.
fn document() -> Document {
    opened(Look::parse(LOOK, Path::new("looks/shot.toml")).unwrap(), None)
}

/// A document as the viewer opens one: the look's settings with no command-line overrides.
fn opened(look: Look, path: Option<PathBuf>) -> Document {
    let settings = Settings::resolve(&look, &Overrides::default()).unwrap();
    Document::new(look, path, settings)
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

/// The names in a folder, sorted: what a save left behind.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

fn snapshot(doc: &Document) -> (Look, Settings) {
    (doc.look().clone(), doc.settings().clone())
}

fn scalar(doc: &Document, object: ObjectRef, layer: usize, param: Param) -> Value {
    doc.stack(object).unwrap().layers[layer].params.get(param)
}

fn every_kind_of_edit() -> Vec<Edit> {
    vec![
        Edit::SetParam { object: BALL, layer: 2, param: Param::Metallic, value: Value::Scalar(0.5) },
        Edit::SetParam { object: BALL, layer: 0, param: Param::BaseColor, value: Value::Color([0.1, 0.2, 0.3]) },
        Edit::ResetParam { object: BALL, layer: 1, param: Param::Roughness },
        Edit::AddLayer { object: BALL, preset: "chrome".into() },
        Edit::RemoveLayer { object: BALL, layer: 0 },
        Edit::MoveLayer { object: BALL, from: 0, to: 2 },
        Edit::DuplicateLayer { object: BALL, layer: 1 },
        Edit::SetEnabled { object: BALL, layer: 0, enabled: false },
        Edit::SetMask { object: BALL, layer: 1, mask: Some("grunge".into()) },
        Edit::SetMask { object: BALL, layer: 1, mask: None },
        Edit::SetMap { object: BALL, layer: 1, param: Param::BaseColor, map: Some("albedo".into()) },
        Edit::SetMap { object: BALL, layer: 1, param: Param::Roughness, map: Some("metalRough.G".into()) },
        Edit::SetMap { object: BALL, layer: 1, param: Param::BaseColor, map: None },
        Edit::SetInvert { object: BALL, layer: 2, invert: true },
        Edit::SetOpacity { object: BALL, layer: 2, opacity: 0.25 },
        Edit::SetParam { object: ObjectRef::Default, layer: 0, param: Param::Sheen, value: Value::Scalar(1.5) },
        Edit::CreateStack { id: 7 },
        Edit::SetParam { object: ObjectRef::Id(9), layer: 0, param: Param::Roughness, value: Value::Scalar(0.1) },
        Edit::SetRotation(-40.0),
        Edit::SetIntensity(2.5),
        Edit::SetBackground(false),
        Edit::SetEnvironment(Some(EnvironmentRef::File("hdri/courtyard.exr".into()))),
        Edit::SetExposure(1.5),
        Edit::SetTonemap(Tonemap::Agx),
        Edit::SetTargetSpp(64),
        Edit::SetSeed(9),
    ]
}

// ---- Applying, undoing and redoing. ----

#[test]
fn every_edit_applies_as_one_step_and_undoes_and_redoes_exactly() {
    let mut doc = document();
    let start = snapshot(&doc);
    for edit in every_kind_of_edit() {
        let before = snapshot(&doc);
        doc.apply(edit.clone()).unwrap_or_else(|e| panic!("{edit:?}: {e}"));
        let after = snapshot(&doc);
        assert_ne!(after, before, "{edit:?} changed nothing");
        assert!(doc.undo(), "{edit:?}");
        assert_eq!(snapshot(&doc), before, "undoing {edit:?}");
        assert!(doc.redo(), "{edit:?}");
        assert_eq!(snapshot(&doc), after, "redoing {edit:?}");
        assert!(!doc.can_redo());
    }
    let edits = every_kind_of_edit().len();
    for _ in 0..edits {
        assert!(doc.undo());
    }
    assert!(!doc.can_undo(), "one step per edit");
    assert_eq!(snapshot(&doc), start);
    assert!(!doc.is_dirty());
}

#[test]
fn map_bindings_keep_the_value_as_the_factor_and_refuse_empty_names() {
    let mut doc = document();
    let gold = |doc: &Document| doc.stack(BALL).unwrap().layers[1].clone();
    let before = gold(&doc);
    doc.apply(Edit::SetMap { object: BALL, layer: 1, param: Param::Metallic, map: Some("metal".into()) }).unwrap();
    let bound = gold(&doc);
    assert_eq!(bound.maps.get(&Param::Metallic).map(String::as_str), Some("metal"));
    assert_eq!(bound.params, before.params, "binding keeps the value, as the factor");
    assert!(doc.is_dirty());
    // Binding it again to the same map, and refused bindings, record nothing: one undo unbinds.
    doc.apply(Edit::SetMap { object: BALL, layer: 1, param: Param::Metallic, map: Some("metal".into()) }).unwrap();
    for bad in ["", " metal", "metal "] {
        let edit = Edit::SetMap { object: BALL, layer: 1, param: Param::Metallic, map: Some(bad.into()) };
        assert!(doc.apply(edit).is_err(), "{bad:?}");
        assert_eq!(gold(&doc), bound, "a refused binding changes nothing");
    }
    assert!(doc.undo());
    assert_eq!(gold(&doc), before);
    assert!(!doc.can_undo() && !doc.is_dirty(), "one step, and the look is as loaded");
    assert!(doc.redo());
    doc.apply(Edit::SetMap { object: BALL, layer: 1, param: Param::Metallic, map: None }).unwrap();
    assert_eq!(gold(&doc), before);
    assert!(!doc.is_dirty(), "unbound again, the look is as loaded");
}

#[test]
fn stack_edits_do_what_they_say() {
    let mut doc = document();
    let layers = |doc: &Document| doc.stack(BALL).unwrap().layers.clone();
    let original = layers(&doc);

    doc.apply(Edit::AddLayer { object: BALL, preset: "chrome".into() }).unwrap();
    let top = layers(&doc).pop().unwrap();
    assert_eq!(top.preset.as_deref(), Some("chrome"));
    assert_eq!(top.params, library::builtin("chrome").unwrap().params);
    assert!(top.enabled && top.opacity == 1.0 && top.mask.is_none() && !top.invert && top.overrides.is_empty());

    doc.apply(Edit::DuplicateLayer { object: BALL, layer: 1 }).unwrap();
    let now = layers(&doc);
    assert_eq!(now.len(), 5);
    assert_eq!(now[2], original[1], "the copy goes just above the original");
    assert_eq!(now[3], original[2]);

    doc.apply(Edit::MoveLayer { object: BALL, from: 0, to: 3 }).unwrap();
    assert_eq!(layers(&doc)[3], original[0], "the moved layer ends up at `to`");
    doc.apply(Edit::MoveLayer { object: BALL, from: 3, to: 0 }).unwrap();
    assert_eq!(layers(&doc)[0], original[0]);

    doc.apply(Edit::RemoveLayer { object: BALL, layer: 1 }).unwrap();
    assert_eq!(layers(&doc)[1], original[1], "the duplicate, above, is left");

    // Overrides are kept in Param::ALL order, whatever order they are set in.
    doc.apply(Edit::SetParam { object: BALL, layer: 1, param: Param::Metallic, value: Value::Scalar(0.5) }).unwrap();
    doc.apply(Edit::SetParam { object: BALL, layer: 1, param: Param::BaseColor, value: Value::Color([0.5; 3]) })
        .unwrap();
    assert_eq!(layers(&doc)[1].overrides, [Param::BaseColor, Param::Metallic, Param::Roughness]);
    assert!(doc.look().to_toml().contains("metallic = 0.5"), "an override is saved");

    doc.apply(Edit::SetEnabled { object: BALL, layer: 0, enabled: false }).unwrap();
    assert!(!layers(&doc)[0].enabled);
}

#[test]
fn failed_edits_change_nothing_and_record_nothing() {
    let mut doc = document();
    let bad = [
        Edit::SetParam { object: BALL, layer: 0, param: Param::Roughness, value: Value::Scalar(1.5) },
        Edit::SetParam { object: BALL, layer: 0, param: Param::Roughness, value: Value::Scalar(f32::NAN) },
        Edit::SetParam { object: BALL, layer: 0, param: Param::BaseColor, value: Value::Scalar(0.5) },
        Edit::SetParam { object: BALL, layer: 3, param: Param::Roughness, value: Value::Scalar(0.5) },
        // Aimed at an object without a stack: the stack it would have needed is not left behind.
        Edit::SetParam { object: ObjectRef::Id(5), layer: 0, param: Param::Specular, value: Value::Scalar(3.0) },
        Edit::ResetParam { object: BALL, layer: 9, param: Param::Roughness },
        Edit::AddLayer { object: BALL, preset: "golld".into() },
        Edit::AddLayer { object: BALL, preset: " ".into() },
        Edit::RemoveLayer { object: ObjectRef::Default, layer: 0 },
        Edit::RemoveLayer { object: BALL, layer: 3 },
        Edit::MoveLayer { object: BALL, from: 0, to: 3 },
        Edit::DuplicateLayer { object: BALL, layer: 3 },
        Edit::SetEnabled { object: BALL, layer: 3, enabled: false },
        Edit::SetMask { object: BALL, layer: 1, mask: Some(String::new()) },
        Edit::SetInvert { object: BALL, layer: 3, invert: true },
        Edit::SetOpacity { object: BALL, layer: 1, opacity: 1.5 },
        Edit::SetOpacity { object: BALL, layer: 1, opacity: f32::NAN },
        Edit::SetRotation(f32::INFINITY),
        Edit::SetIntensity(-1.0),
        Edit::SetIntensity(f32::NAN),
        Edit::SetEnvironment(Some(EnvironmentRef::File(PathBuf::new()))),
        Edit::SetExposure(64.5),
        Edit::SetExposure(f32::NAN),
        Edit::SetTargetSpp(0),
    ];
    let before = snapshot(&doc);
    for edit in bad {
        let error = doc.apply(edit.clone()).expect_err(&format!("{edit:?} should fail"));
        assert_eq!(error.lines().count(), 1, "{edit:?}: {error}");
        assert_eq!(snapshot(&doc), before, "{edit:?}");
        assert_eq!((doc.revision(), doc.material_revision()), (0, 0), "{edit:?}");
        assert!(!doc.can_undo() && !doc.is_dirty(), "{edit:?}");
    }
    let error = doc.apply(Edit::RemoveLayer { object: ObjectRef::Default, layer: 0 }).unwrap_err();
    assert!(error.contains("at least one"), "{error}");
    let error = doc.apply(Edit::AddLayer { object: BALL, preset: "golld".into() }).unwrap_err();
    assert!(error.contains("no preset named 'golld' (closest: gold"), "{error}");
    let error = doc.apply(Edit::MoveLayer { object: BALL, from: 0, to: 3 }).unwrap_err();
    assert_eq!(error, "object 1 has 3 layers; there is no layer 3 (layers count from 0 at the bottom)");
}

#[test]
fn edits_that_change_nothing_record_nothing() {
    let mut doc = document();
    let same = [
        Edit::SetRotation(15.0),
        Edit::SetEnabled { object: BALL, layer: 0, enabled: true },
        Edit::SetParam { object: BALL, layer: 1, param: Param::Roughness, value: Value::Scalar(0.3) },
        Edit::ResetParam { object: BALL, layer: 0, param: Param::Roughness },
        Edit::MoveLayer { object: BALL, from: 1, to: 1 },
        Edit::SetMask { object: BALL, layer: 1, mask: Some("stripes".into()) },
        // An object without a stack gets none for an edit that changes nothing.
        Edit::SetOpacity { object: ObjectRef::Id(5), layer: 0, opacity: 1.0 },
        Edit::CreateStack { id: 1 },
    ];
    let before = snapshot(&doc);
    for edit in same {
        doc.apply(edit.clone()).unwrap();
        assert_eq!(snapshot(&doc), before, "{edit:?}");
        assert!(!doc.can_undo(), "{edit:?} recorded a step");
        assert_eq!(doc.revision(), 0, "{edit:?}");
    }
}

// ---- Implicit stacks. ----

#[test]
fn an_edit_aimed_at_an_object_without_a_stack_gives_it_one_in_the_same_step() {
    let mut doc = document();
    let before = snapshot(&doc);
    let default = doc.stack(ObjectRef::Default).unwrap().clone();
    assert_eq!(doc.stack(ObjectRef::Id(5)), Some(&default), "an object without a stack shows the default");

    let edit =
        Edit::SetParam { object: ObjectRef::Id(5), layer: 0, param: Param::Roughness, value: Value::Scalar(0.1) };
    doc.apply(edit).unwrap();
    let own = doc.stack(ObjectRef::Id(5)).unwrap();
    assert_eq!(own.id, Some(5));
    assert_eq!(own.layers.len(), default.layers.len(), "a copy of the default stack");
    assert_eq!(own.layers[0].params.roughness, 0.1);
    assert_eq!(own.layers[0].preset, default.layers[0].preset);
    assert_eq!(doc.stack(ObjectRef::Default), Some(&default), "the default stack is not changed");

    assert!(doc.undo());
    assert_eq!(snapshot(&doc), before, "one undo takes away the edit and the stack");
    assert!(!doc.can_undo());

    // The explicit edit does the same.
    doc.apply(Edit::CreateStack { id: 5 }).unwrap();
    assert_eq!(doc.look().objects.last().unwrap().layers, default.layers);

    // Without a default stack, a copy is one layer of the default material, and an edit aimed at
    // the default stack adds one.
    let mut bare = opened(Look::parse("[[object]]\nid = 1\n[[object.layer]]\n", Path::new("x.toml")).unwrap(), None);
    bare.apply(Edit::SetEnabled { object: ObjectRef::Id(2), layer: 0, enabled: false }).unwrap();
    assert_eq!(bare.stack(ObjectRef::Id(2)).unwrap().layers.len(), 1);
    bare.apply(Edit::SetOpacity { object: ObjectRef::Default, layer: 0, opacity: 0.5 }).unwrap();
    let default = bare.look().objects.iter().find(|o| o.id.is_none()).unwrap();
    assert_eq!(default.layers[0].opacity, 0.5);
    assert_eq!(default.layers[0].preset, None);
}

// ---- Merging continuous edits. ----

#[test]
fn a_drag_is_one_undo_step_until_the_gesture_ends() {
    let mut doc = document();
    let start = snapshot(&doc);
    for degrees in [20.0, 30.0, 40.0] {
        doc.apply_merging(Edit::SetRotation(degrees)).unwrap();
    }
    assert_eq!(doc.settings().lighting.rotation_degrees, 40.0);
    assert_eq!(doc.revision(), 3, "each step of a drag is a change to render");
    doc.end_gesture();
    let dragged = snapshot(&doc);
    doc.apply_merging(Edit::SetRotation(50.0)).unwrap();
    assert!(doc.undo());
    assert_eq!(snapshot(&doc), dragged, "a new gesture is a new step");
    assert!(doc.undo());
    assert_eq!(snapshot(&doc), start, "the whole first drag undoes at once");
    assert!(!doc.can_undo());
}

#[test]
fn only_the_same_control_merges_and_only_until_something_else_happens() {
    let roughness =
        |v: f32| Edit::SetParam { object: BALL, layer: 1, param: Param::Roughness, value: Value::Scalar(v) };
    let mut doc = document();
    let start = snapshot(&doc);
    doc.apply_merging(roughness(0.4)).unwrap();
    doc.apply_merging(roughness(0.5)).unwrap();
    let after_drag = snapshot(&doc);
    // Another parameter of the same layer is another control.
    let metallic = Edit::SetParam { object: BALL, layer: 1, param: Param::Metallic, value: Value::Scalar(0.5) };
    doc.apply_merging(metallic).unwrap();
    // The same control after another edit came between is a new step.
    doc.apply_merging(roughness(0.6)).unwrap();
    // And apply() never merges.
    doc.apply(roughness(0.7)).unwrap();
    doc.apply(roughness(0.8)).unwrap();
    let mut steps = 0;
    while doc.undo() {
        steps += 1;
        if steps == 4 {
            assert_eq!(snapshot(&doc), after_drag);
        }
    }
    assert_eq!(steps, 5);
    assert_eq!(snapshot(&doc), start);

    // Undo closes a gesture: what follows is a step of its own.
    let mut doc = document();
    doc.apply_merging(Edit::SetExposure(1.0)).unwrap();
    doc.undo();
    doc.apply_merging(Edit::SetExposure(2.0)).unwrap();
    assert!(doc.undo());
    assert_eq!(doc.settings().exposure, 0.0);

    // So does saving.
    let dir = tempfile::tempdir().unwrap();
    doc.apply_merging(Edit::SetExposure(1.0)).unwrap();
    doc.save(Some(&dir.path().join("shot.toml"))).unwrap();
    doc.apply_merging(Edit::SetExposure(2.0)).unwrap();
    assert!(doc.undo());
    assert_eq!(doc.settings().exposure, 1.0);
}

#[test]
fn a_drag_back_to_where_it_started_leaves_nothing_to_undo() {
    let mut doc = document();
    doc.apply_merging(Edit::SetIntensity(2.0)).unwrap();
    doc.apply_merging(Edit::SetIntensity(1.0)).unwrap();
    assert!(!doc.can_undo());
    assert!(!doc.is_dirty());
}

// ---- Dirty state and revisions. ----

#[test]
fn dirty_means_different_from_what_was_loaded_or_saved() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("shot.toml");
    let mut doc = document();
    assert!(!doc.is_dirty());
    doc.apply(Edit::SetSeed(4)).unwrap();
    assert!(doc.is_dirty());
    doc.undo();
    assert!(!doc.is_dirty(), "undoing back to the loaded state is clean");
    doc.redo();
    assert!(doc.is_dirty());
    doc.save(Some(&path)).unwrap();
    assert!(!doc.is_dirty());
    doc.undo();
    assert!(doc.is_dirty(), "the saved state is the new reference");
    doc.redo();
    assert!(!doc.is_dirty());
    // Two edits that cancel out leave the document clean.
    doc.apply(Edit::SetSeed(5)).unwrap();
    doc.apply(Edit::SetSeed(4)).unwrap();
    assert!(!doc.is_dirty() && doc.can_undo());
}

#[test]
fn revisions_count_changes_and_material_revisions_count_stack_changes() {
    let mut doc = document();
    let revisions = |doc: &Document| (doc.revision(), doc.material_revision());
    assert_eq!(revisions(&doc), (0, 0));
    doc.apply(Edit::SetRotation(90.0)).unwrap();
    assert_eq!(revisions(&doc), (1, 0), "a rotation does not touch the materials");
    doc.apply(Edit::SetOpacity { object: BALL, layer: 2, opacity: 0.5 }).unwrap();
    assert_eq!(revisions(&doc), (2, 1));
    doc.undo();
    assert_eq!(revisions(&doc), (3, 2), "undoing a stack edit changes the materials back");
    doc.undo();
    assert_eq!(revisions(&doc), (4, 2));
    doc.redo();
    assert_eq!(revisions(&doc), (5, 2));
    doc.apply(Edit::SetRotation(90.0)).unwrap();
    assert_eq!(revisions(&doc), (5, 2), "no change, no revision");
    let _ = doc.apply(Edit::SetIntensity(-1.0));
    assert_eq!(revisions(&doc), (5, 2), "a failed edit is no change");
    doc.select(Selection { object: Some(BALL), layer: Some(1) });
    assert_eq!(revisions(&doc), (5, 2), "selecting is not editing");
    for edit in [
        Edit::SetEnabled { object: BALL, layer: 0, enabled: false },
        Edit::CreateStack { id: 3 },
        Edit::AddLayer { object: BALL, preset: "wax".into() },
    ] {
        let (r, m) = revisions(&doc);
        doc.apply(edit).unwrap();
        assert_eq!(revisions(&doc), (r + 1, m + 1));
    }
    for edit in [
        Edit::SetExposure(2.0),
        Edit::SetTonemap(Tonemap::Aces),
        Edit::SetEnvironment(Some(EnvironmentRef::File("sky.exr".into()))),
        Edit::SetIntensity(3.0),
        Edit::SetBackground(false),
        Edit::SetTargetSpp(16),
        Edit::SetSeed(1),
    ] {
        let (r, m) = revisions(&doc);
        doc.apply(edit.clone()).unwrap();
        assert_eq!(revisions(&doc), (r + 1, m), "{edit:?}");
    }
}

#[test]
fn the_selection_stays_within_its_stack() {
    let mut doc = document();
    doc.select(Selection { object: Some(BALL), layer: Some(7) });
    assert_eq!(doc.selection().layer, Some(2));
    doc.apply(Edit::RemoveLayer { object: BALL, layer: 2 }).unwrap();
    assert_eq!(doc.selection(), Selection { object: Some(BALL), layer: Some(1) });
    doc.undo();
    assert_eq!(doc.selection().layer, Some(1));
}

/// The selection is a layer, not an index: it follows its layer through duplicate, undo, redo
/// and moves, and a duplicate takes it. Once, `select 1 0`, `duplicate`, `undo`, `select 1 1`,
/// `redo`, `hide` hid the copy of blue-rubber, not the selected gold.
#[test]
fn the_selection_follows_its_layer_through_edits_undo_and_redo() {
    let mut doc = document();
    let selected = |doc: &Document| {
        let layer = doc.selection().layer.unwrap();
        doc.stack(BALL).unwrap().layers[layer].preset.clone().unwrap()
    };
    doc.select(Selection { object: Some(BALL), layer: Some(0) });
    doc.apply(Edit::DuplicateLayer { object: BALL, layer: 0 }).unwrap();
    assert_eq!(doc.selection().layer, Some(1), "the copy is selected");
    doc.undo();
    doc.select(Selection { object: Some(BALL), layer: Some(1) });
    assert_eq!(selected(&doc), "gold");
    doc.redo();
    assert_eq!(
        (doc.selection().layer, selected(&doc)),
        (Some(2), "gold".to_string()),
        "gold moved up; so did the selection"
    );
    let layer = doc.selection().layer.unwrap();
    doc.apply(Edit::SetEnabled { object: BALL, layer, enabled: false }).unwrap();
    let stack = doc.stack(BALL).unwrap();
    assert!(!stack.layers[2].enabled && stack.layers[..2].iter().all(|l| l.enabled), "gold is hidden, nothing else");
    doc.apply(Edit::MoveLayer { object: BALL, from: 2, to: 0 }).unwrap();
    assert_eq!((doc.selection().layer, selected(&doc)), (Some(0), "gold".to_string()), "a move takes it along");
    doc.undo();
    assert_eq!(selected(&doc), "gold");
}

/// A click on the object already selected keeps its layer (the next slider edit once went to
/// the top layer instead); a click on another object selects that object's top layer.
#[test]
fn picking_the_selected_object_keeps_its_layer() {
    let mut doc = document();
    doc.select(Selection { object: Some(BALL), layer: Some(0) });
    doc.select_object(BALL);
    assert_eq!(doc.selection(), Selection { object: Some(BALL), layer: Some(0) });
    doc.select_object(ObjectRef::Id(2));
    assert_eq!(
        doc.selection(),
        Selection { object: Some(ObjectRef::Id(2)), layer: Some(0) },
        "the default stack's top"
    );
    doc.select_object(BALL);
    assert_eq!(doc.selection(), Selection { object: Some(BALL), layer: Some(2) }, "another object: its top layer");
}

// ---- Presets: resolution, overrides, reset. ----

#[test]
fn added_layers_resolve_presets_beside_the_look_before_the_builtins() {
    let dir = tempfile::tempdir().unwrap();
    write(&dir.path().join("gold.toml"), "name = \"house gold\"\nmetallic = 1\nroughness = 0.9\n");
    write(&dir.path().join("shelf/shiny.toml"), "roughness = 0.05\n");
    let path = dir.path().join("shot.toml");
    write(&path, LOOK);
    let mut doc = opened(Look::load(&path).unwrap(), Some(path.clone()));
    doc.apply(Edit::AddLayer { object: BALL, preset: "gold".into() }).unwrap();
    doc.apply(Edit::AddLayer { object: BALL, preset: "shelf/shiny.toml".into() }).unwrap();
    let layers = &doc.stack(BALL).unwrap().layers;
    assert_eq!(layers[3].params.roughness, 0.9, "the look folder's gold, not the built-in");
    assert_eq!(layers[4].params.roughness, 0.05, "a path starts from the look's folder");

    // A look that has no file sees the built-in.
    let mut doc = document();
    doc.apply(Edit::AddLayer { object: BALL, preset: "gold".into() }).unwrap();
    assert_eq!(doc.stack(BALL).unwrap().layers[3].params, library::builtin("gold").unwrap().params);
}

#[test]
fn reset_restores_the_presets_value_and_clears_the_override() {
    let gold = library::builtin("gold").unwrap().params;
    let mut doc = document();
    // Layer 1 is gold with roughness 0.3 set in the file.
    assert!(doc.is_overridden(BALL, 1, Param::Roughness));
    assert!(!doc.is_overridden(BALL, 1, Param::Metallic));
    assert_eq!(doc.preset_value(BALL, 1, Param::Roughness), gold.get(Param::Roughness));
    assert_ne!(scalar(&doc, BALL, 1, Param::Roughness), gold.get(Param::Roughness));

    doc.apply(Edit::ResetParam { object: BALL, layer: 1, param: Param::Roughness }).unwrap();
    assert_eq!(scalar(&doc, BALL, 1, Param::Roughness), gold.get(Param::Roughness));
    assert!(!doc.is_overridden(BALL, 1, Param::Roughness));
    assert!(!doc.look().to_toml().contains("roughness"), "no longer written");

    let metallic = Edit::SetParam { object: BALL, layer: 1, param: Param::Metallic, value: Value::Scalar(0.25) };
    doc.apply(metallic).unwrap();
    assert!(doc.is_overridden(BALL, 1, Param::Metallic));
    assert_eq!(doc.preset_value(BALL, 1, Param::Metallic), Value::Scalar(1.0), "gold's, not the override");
    doc.apply(Edit::ResetParam { object: BALL, layer: 1, param: Param::Metallic }).unwrap();
    assert_eq!(scalar(&doc, BALL, 1, Param::Metallic), Value::Scalar(1.0));

    // A layer without a preset resets to the defaults.
    let mut doc = opened(
        Look::parse("[[object]]\n[[object.layer]]\n[object.layer.set]\nsheen = 1\n", Path::new("x.toml")).unwrap(),
        None,
    );
    assert_eq!(doc.preset_value(ObjectRef::Default, 0, Param::Sheen), Value::Scalar(0.0));
    doc.apply(Edit::ResetParam { object: ObjectRef::Default, layer: 0, param: Param::Sheen }).unwrap();
    assert_eq!(scalar(&doc, ObjectRef::Default, 0, Param::Sheen), Value::Scalar(0.0));
    assert!(!doc.is_overridden(ObjectRef::Default, 0, Param::Sheen));

    // An object without a stack shows the default stack's values; there is no layer 5.
    let doc = document();
    let grey_card = library::builtin("grey-card").unwrap().params;
    assert_eq!(doc.preset_value(ObjectRef::Id(8), 0, Param::BaseColor), grey_card.get(Param::BaseColor));
    assert!(!doc.is_overridden(BALL, 5, Param::Roughness));
}

// ---- Saving looks. ----

#[test]
fn a_saved_look_reads_back_equal_with_its_settings_and_leaves_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let looks = dir.path().join("looks");
    let path = looks.join("shot.toml");
    write(&path, LOOK);
    let mut doc = opened(Look::load(&path).unwrap(), Some(path.clone()));
    for edit in every_kind_of_edit() {
        doc.apply(edit).unwrap();
    }
    doc.apply(Edit::SetEnvironment(Some(EnvironmentRef::File(dir.path().join("hdri/courtyard.exr"))))).unwrap();
    assert!(doc.is_dirty());

    assert_eq!(doc.save(None).unwrap(), path);
    assert!(!doc.is_dirty());
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("file = \"../hdri/courtyard.exr\""), "relative to the look's folder: {text}");
    for line in ["rotation = -40.0", "intensity = 2.5", "background = false", "spp = 64", "seed = 9"] {
        assert!(text.contains(line), "{line}: {text}");
    }
    assert!(text.contains("exposure = 1.5") && text.contains("tonemap = \"agx\""), "{text}");
    assert!(text.contains("enabled = false"), "{text}");

    let reopened = Look::load(&path).unwrap();
    assert_eq!(&reopened, doc.look());
    assert_eq!(&Settings::resolve(&reopened, &Overrides::default()).unwrap(), doc.settings());
    assert_eq!(listing(&looks), ["shot.toml"], "no temporary file is left");
}

#[test]
fn settings_left_at_their_defaults_add_no_tables() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plain.toml");
    let mut doc = opened(Look::parse("[[object]]\n[[object.layer]]\npreset = \"wax\"\n", &path).unwrap(), None);
    doc.save(Some(&path)).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "[[object]]\n[[object.layer]]\npreset = \"wax\"\n");
    assert_eq!(doc.path(), Some(path.as_path()));
    // A setting changed and changed back leaves the look as it was.
    doc.apply(Edit::SetTargetSpp(32)).unwrap();
    doc.apply(Edit::SetTargetSpp(256)).unwrap();
    assert!(!doc.is_dirty());
    // Once saved with a value, the look keeps saying it, even at the default.
    doc.apply(Edit::SetTargetSpp(32)).unwrap();
    doc.save(None).unwrap();
    doc.apply(Edit::SetTargetSpp(256)).unwrap();
    doc.save(None).unwrap();
    assert!(std::fs::read_to_string(&path).unwrap().starts_with("[render]\nspp = 256\n"));
}

#[test]
fn a_noise_threshold_given_on_the_command_line_is_saved_with_the_look() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("adaptive.toml");
    let look = Look::parse("[render]\nspp = 128\n[[object]]\n[[object.layer]]\npreset = \"wax\"\n", &path).unwrap();
    let overrides = Overrides { noise_threshold: Some(0.05), ..Overrides::default() };
    let settings = Settings::resolve(&look, &overrides).unwrap();
    let mut doc = Document::new(look, Some(path.clone()), settings);
    doc.save(None).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.starts_with("[render]\nspp = 128\nnoise_threshold = 0.05\n"), "{text}");
    assert!(!text.contains("min_spp"), "the default minimum is left out: {text}");
    let reopened = Look::load(&path).unwrap();
    assert_eq!(&Settings::resolve(&reopened, &Overrides::default()).unwrap(), doc.settings());
}

#[test]
fn saving_elsewhere_keeps_what_references_mean_and_undo_follows() {
    let dir = tempfile::tempdir().unwrap();
    let old = dir.path().join("old/shot.toml");
    write(&dir.path().join("old/house.toml"), "metallic = 1\nroughness = 0.8\n");
    write(&dir.path().join("shared/shiny.toml"), "roughness = 0.05\n");
    let text = "[environment]\nfile = \"../hdri/studio.exr\"\n[[object]]\n[[object.layer]]\npreset = \"house\"\n\
                [[object.layer]]\npreset = \"../shared/shiny.toml\"\nopacity = 0.5\n";
    write(&old, text);
    let mut doc = opened(Look::load(&old).unwrap(), Some(old.clone()));
    doc.apply(Edit::SetSeed(2)).unwrap();

    let new = dir.path().join("new/deeper/shot.toml");
    std::fs::create_dir_all(new.parent().unwrap()).unwrap();
    doc.save(Some(&new)).unwrap();
    let written = std::fs::read_to_string(&new).unwrap();
    assert!(written.contains("file = \"../../hdri/studio.exr\""), "{written}");
    assert!(written.contains("preset = \"../../old/house.toml\""), "a name from the old folder: {written}");
    assert!(written.contains("preset = \"../../shared/shiny.toml\""), "{written}");
    assert_eq!(&Look::load(&new).unwrap(), doc.look());
    assert_eq!(doc.path(), Some(new.as_path()));
    assert_eq!(std::fs::read_to_string(&old).unwrap(), text, "the old file is left alone");

    // A state from before the move means the same from the new folder.
    assert!(doc.undo());
    assert_eq!(doc.look().objects[0].layers[0].preset.as_deref(), Some("../../old/house.toml"));
    assert_eq!(doc.look().file.as_deref(), Some(new.as_path()));
    doc.apply(Edit::AddLayer { object: ObjectRef::Default, preset: "../../old/house.toml".into() }).unwrap();
    doc.save(None).unwrap();
    assert_eq!(&Look::load(&new).unwrap(), doc.look());
    assert_eq!(doc.preset_value(ObjectRef::Default, 0, Param::Roughness), Value::Scalar(0.8));
}

#[test]
fn a_failed_save_leaves_every_file_and_the_document_as_they_were() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("shot.toml");
    write(&path, LOOK);
    let mut doc = opened(Look::load(&path).unwrap(), Some(path.clone()));
    doc.apply(Edit::SetSeed(8)).unwrap();

    let missing = dir.path().join("no/such/folder/shot.toml");
    let error = doc.save(Some(&missing)).unwrap_err();
    assert_eq!(error.to_string().lines().count(), 1, "{error}");
    assert!(error.to_string().contains("cannot write"), "{error}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), LOOK);
    assert_eq!(doc.path(), Some(path.as_path()));
    assert!(doc.is_dirty());
    assert_eq!(listing(dir.path()), ["shot.toml"]);

    // A folder where a preset name means another preset would not read back: refused, and the
    // file already there is untouched.
    let elsewhere = dir.path().join("elsewhere");
    write(&elsewhere.join("gold.toml"), "metallic = 1\nroughness = 1\n");
    write(&elsewhere.join("shot.toml"), "# theirs\n");
    let error = doc.save(Some(&elsewhere.join("shot.toml"))).unwrap_err().to_string();
    assert!(error.contains("'gold'") && error.contains("not saved"), "{error}");
    assert_eq!(std::fs::read_to_string(elsewhere.join("shot.toml")).unwrap(), "# theirs\n");
    assert_eq!(listing(&elsewhere), ["gold.toml", "shot.toml"]);
    assert!(doc.is_dirty());

    // A look never saved needs a path.
    let mut new = document();
    assert!(new.save(None).is_err());
}

// ---- Saving layers as presets. ----

#[test]
fn a_layer_saved_as_a_preset_loads_back_and_is_not_overwritten_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let library = dir.path().join("presets");
    let doc = document();
    let tags = vec!["metal".to_string(), "mine".to_string()];
    let preset = doc.layer_as_preset(BALL, 1, "rough-gold", "Gold, roughened.", &tags).unwrap();
    let path = doc.save_preset_in(&library, &preset, false).unwrap();
    assert_eq!(path, library.join("rough-gold.toml"));
    let loaded = Preset::load(&path).unwrap();
    assert_eq!(loaded, preset);
    // The eleven parameters, overrides included; a preset's complex IOR is not one of them.
    let layer = doc.stack(BALL).unwrap().layers[1].params;
    for param in Param::ALL {
        assert_eq!(loaded.params.get(param), layer.get(param), "{param}: the layer's values, overrides included");
    }
    assert_eq!((loaded.ior, loaded.params.ior_edge), (None, [0.0; 3]));
    assert_eq!(loaded.params.roughness, 0.3);

    let other = doc.layer_as_preset(BALL, 0, "rough-gold", "", &[]).unwrap();
    let error = doc.save_preset_in(&library, &other, false).unwrap_err();
    assert!(error.to_string().contains("already exists"), "{error}");
    assert_eq!(Preset::load(&path).unwrap(), preset, "refused without force");
    doc.save_preset_in(&library, &other, true).unwrap();
    assert_eq!(Preset::load(&path).unwrap(), other);
    assert_eq!(listing(&library), ["rough-gold.toml"], "no temporary file is left");

    assert!(doc.layer_as_preset(BALL, 1, "Rough Gold", "", &[]).is_err(), "not a preset name");
    assert!(doc.layer_as_preset(BALL, 3, "x", "", &[]).is_err(), "no such layer");
    assert!(doc.layer_as_preset(BALL, 1, "x", "", &[String::new()]).is_err(), "an empty tag");
}

#[test]
fn a_preset_saved_over_one_a_layer_uses_becomes_what_it_resets_to() {
    let dir = tempfile::tempdir().unwrap();
    write(&dir.path().join("house.toml"), "roughness = 0.8\n");
    let path = dir.path().join("shot.toml");
    write(&path, "[[object]]\n[[object.layer]]\npreset = \"house\"\n[object.layer.set]\nroughness = 0.2\n");
    let doc = opened(Look::load(&path).unwrap(), Some(path.clone()));
    assert_eq!(doc.preset_value(ObjectRef::Default, 0, Param::Roughness), Value::Scalar(0.8));
    let preset = doc.layer_as_preset(ObjectRef::Default, 0, "house", "", &[]).unwrap();
    doc.save_preset_in(dir.path(), &preset, true).unwrap();
    assert_eq!(doc.preset_value(ObjectRef::Default, 0, Param::Roughness), Value::Scalar(0.2));
}

/// A layer inserted into the stack (a preset dropped between two layers) goes at its index, the
/// others keeping their order, as one undo step; an index past the top is refused.
#[test]
fn an_inserted_layer_goes_at_its_index() {
    let mut doc = document();
    let layers = |doc: &Document| doc.stack(BALL).unwrap().layers.clone();
    let original = layers(&doc);

    doc.apply(Edit::InsertLayer { object: BALL, preset: "chrome".into(), at: 1 }).unwrap();
    let now = layers(&doc);
    assert_eq!(now.len(), 4);
    assert_eq!(now[0], original[0]);
    assert_eq!(now[2..], original[1..], "the layers above move up one");
    assert_eq!(now[1].preset.as_deref(), Some("chrome"));
    assert_eq!(now[1].params, library::builtin("chrome").unwrap().params);
    doc.apply(Edit::InsertLayer { object: BALL, preset: "wax".into(), at: 4 }).unwrap();
    assert_eq!(layers(&doc)[4].preset.as_deref(), Some("wax"), "at the number of layers is on top");

    assert!(doc.undo());
    assert_eq!(layers(&doc), now);
    assert!(doc.undo());
    assert_eq!(layers(&doc), original);
    assert!(!doc.can_undo(), "each insert is one step");

    let error = doc.apply(Edit::InsertLayer { object: BALL, preset: "chrome".into(), at: 4 }).unwrap_err();
    assert_eq!(error, "object 1 has 3 layers; a new layer goes at 0 to 3 (on top)");
    let error = doc.apply(Edit::InsertLayer { object: BALL, preset: "golld".into(), at: 0 }).unwrap_err();
    assert!(error.contains("no preset named 'golld'"), "{error}");
    assert_eq!(layers(&doc), original);
    assert!(!doc.can_undo());
}
