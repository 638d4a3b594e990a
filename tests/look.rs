//! Looks and presets as a user writes them: parsing, defaults, errors with exact lines,
//! preset resolution and writing back.

use std::path::{Path, PathBuf};

use lookdev::environment::EnvironmentRef;
use lookdev::material::library::{self, Library};
use lookdev::material::look::Look;
use lookdev::material::params::{Param, Params, Value};
use lookdev::material::preset::Preset;
use lookdev::shading::tonemap::Tonemap;

/// A look that lives in a folder no test creates, so that names resolve to the built-ins.
const SHOT: &str = "looks/shot.toml";

/// A fresh, empty folder for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lookdev-look-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

/// Parses a look that must fail, and checks the error is one line of bad input.
fn error(text: &str) -> String {
    let e = Look::parse(text, Path::new(SHOT)).expect_err("the look should be rejected");
    let message = e.to_string();
    assert_eq!(message.lines().count(), 1, "not one line: {message}");
    assert_eq!(e.exit_code(), 2, "{message}");
    message
}

fn one_layer(set: &str) -> String {
    format!("[[object]]\n[[object.layer]]\npreset = \"gold\"\n[object.layer.set]\n{set}\n")
}

// ---- Errors: one line, FILE:LINE, the key named. ----

#[test]
fn toml_syntax_errors_carry_the_parsers_line() {
    assert_eq!(error("[render\nspp = 1\n"), "looks/shot.toml:1: TOML syntax error: unclosed table, expected `]`");
    let message = error("[render]\nspp = 4\nseed = = 3\n");
    assert!(message.starts_with("looks/shot.toml:3: TOML syntax error: "), "{message}");
    assert_eq!(error("[render]\nspp = 1\nspp = 2\n"), "looks/shot.toml:3: duplicate key 'spp'");
}

#[test]
fn unknown_keys_name_the_table_and_the_expected_keys() {
    assert_eq!(
        error("\n[render]\nsppp = 4\n"),
        "looks/shot.toml:3: unknown key 'sppp' in [render] (expected spp, seed, exposure, tonemap, aovs, noise_threshold, min_spp); did you mean 'spp'?"
    );
    assert_eq!(
        error("[environment]\nfile = \"a.exr\"\n\nrotaton = 3\n"),
        "looks/shot.toml:4: unknown key 'rotaton' in [environment] (expected file, builtin, rotation, intensity, background, background_blur, background_environment); \
         did you mean 'rotation'?"
    );
    assert_eq!(
        error("# a look\ncolour = 1\n"),
        "looks/shot.toml:2: unknown key 'colour' at the top level (expected environment, render, model, gbuffer, object)"
    );
    assert_eq!(
        error("[[object]]\nid = 1\n[[object.layer]]\npreset = \"gold\"\nmaks = \"stripes\"\n"),
        "looks/shot.toml:5: unknown key 'maks' in [[object.layer]] (expected name, preset, mask, mask_blur, mask_black, \
         mask_white, mask_gamma, invert, opacity, enabled, set, map); did you mean 'mask'?"
    );
    assert_eq!(
        error("[[object]]\nnmae = \"ball\"\n[[object.layer]]\n"),
        "looks/shot.toml:2: unknown key 'nmae' in [[object]] (expected id, name, shadow_catcher, layer); did you mean 'name'?"
    );
}

#[test]
fn unknown_parameters_suggest_the_closest() {
    let message = error(&one_layer("rougness = 0.2"));
    assert!(message
        .starts_with("looks/shot.toml:5: unknown parameter 'rougness' in [object.layer.set] (expected base_color, "));
    assert!(message.ends_with("; did you mean 'roughness'?"), "{message}");
    let message = error(&one_layer("shininess = 0.2"));
    assert!(!message.contains("did you mean"), "{message}");
}

#[test]
fn parameter_values_are_checked_for_range_finiteness_and_kind() {
    assert_eq!(error(&one_layer("roughness = 1.5")), "looks/shot.toml:5: roughness = 1.5 is out of range [0, 1]");
    assert_eq!(error(&one_layer("roughness = nan")), "looks/shot.toml:5: roughness = NaN is not a finite number");
    assert_eq!(error(&one_layer("specular = inf")), "looks/shot.toml:5: specular = inf is not a finite number");
    assert_eq!(error(&one_layer("clearcoat = 4.5")), "looks/shot.toml:5: clearcoat = 4.5 is out of range [0, 4]");
    assert_eq!(
        error(&one_layer("base_color = 0.5")),
        "looks/shot.toml:5: base_color must be a linear colour [r, g, b], not the number 0.5"
    );
    assert_eq!(
        error(&one_layer("base_color = [0.5, 0.5]")),
        "looks/shot.toml:5: base_color needs three numbers [r, g, b], not 2"
    );
    assert_eq!(
        error(&one_layer("base_color = [0.5, -nan, 0.5]")),
        "looks/shot.toml:5: base_color[1] = NaN is not a finite number"
    );
    assert_eq!(
        error(&one_layer("base_color = [0.5, 1.2, 0.5]")),
        "looks/shot.toml:5: base_color = [0.5, 1.2, 0.5] is out of range: each channel must be in [0, 1] (linear)"
    );
    assert_eq!(error(&one_layer("metallic = [1, 1, 1]")), "looks/shot.toml:5: metallic must be a number, not an array");
    assert_eq!(
        error(&one_layer("metallic = \"yes\"")),
        "looks/shot.toml:5: metallic must be a number, not the string \"yes\""
    );
}

#[test]
fn environment_and_render_values_are_checked() {
    assert_eq!(
        error("[environment]\nintensity = -1\n"),
        "looks/shot.toml:2: intensity = -1 must be a number from 0 to 1e6"
    );
    assert_eq!(error("[environment]\nintensity = inf\n"), "looks/shot.toml:2: intensity = inf is not a finite number");
    assert_eq!(error("[environment]\nrotation = nan\n"), "looks/shot.toml:2: rotation = NaN is not a finite number");
    assert_eq!(
        error("[environment]\nbackground = 1\n"),
        "looks/shot.toml:2: background must be true, false, \"blur\" or a linear colour [r, g, b], not the integer 1"
    );
    assert_eq!(error("[environment]\nfile = 3\n"), "looks/shot.toml:2: file must be a string, not the integer 3");
    assert_eq!(error("[render]\nspp = 0\n"), "looks/shot.toml:2: spp = 0 is out of range [1, 4294967295]");
    assert_eq!(error("[render]\nspp = \"4\"\n"), "looks/shot.toml:2: spp must be a whole number, not the string \"4\"");
    assert_eq!(error("[render]\nspp = 2.5\n"), "looks/shot.toml:2: spp must be a whole number, not the number 2.5");
    assert_eq!(error("[render]\nseed = -1\n"), "looks/shot.toml:2: seed = -1 is out of range [0, 4294967295]");
    assert_eq!(error("[render]\nexposure = -inf\n"), "looks/shot.toml:2: exposure = -inf is not a finite number");
    assert_eq!(
        error("[render]\nexposure = \"bright\"\n"),
        "looks/shot.toml:2: exposure must be a number, not the string \"bright\""
    );
    assert_eq!(
        error("[render]\ntonemap = \"filmic\"\n"),
        "looks/shot.toml:2: unknown tone map 'filmic' (expected linear, neutral, aces, agx)"
    );
    assert_eq!(
        error("[render]\ntonemap = \"agz\"\n"),
        "looks/shot.toml:2: unknown tone map 'agz' (expected linear, neutral, aces, agx); did you mean 'agx'?"
    );
    let unknown = error("[render]\naovs = [\"N\", \"speculr\"]\n");
    assert!(unknown.starts_with("looks/shot.toml:2: unknown AOV 'speculr'"), "{unknown}");
    assert!(unknown.ends_with("did you mean 'specular'?"), "{unknown}");
    assert_eq!(
        error("[render]\naovs = \"N\"\n"),
        "looks/shot.toml:2: aovs must be an array of strings, not the string \"N\""
    );
    assert_eq!(
        error("[render]\nnoise_threshold = 0\n"),
        "looks/shot.toml:2: noise_threshold = 0 must be above 0 and below 1000"
    );
    assert_eq!(
        error("[render]\nnoise_threshold = nan\n"),
        "looks/shot.toml:2: noise_threshold = NaN is not a finite number"
    );
    assert_eq!(error("[render]\nmin_spp = 1\n"), "looks/shot.toml:2: min_spp = 1 is out of range [2, 4294967295]");
}

#[test]
fn layer_values_are_checked() {
    let layer = |line: &str| format!("[[object]]\n[[object.layer]]\npreset = \"gold\"\n[[object.layer]]\n{line}\n");
    assert_eq!(error(&layer("opacity = 1.5")), "looks/shot.toml:5: opacity = 1.5 is out of range [0, 1]");
    assert_eq!(error(&layer("opacity = nan")), "looks/shot.toml:5: opacity = NaN is not a finite number");
    assert_eq!(
        error(&layer("invert = \"yes\"")),
        "looks/shot.toml:5: invert must be true or false, not the string \"yes\""
    );
    assert_eq!(error(&layer("mask = \"\"")), "looks/shot.toml:5: mask must not be empty");
    assert_eq!(error(&layer("enabled = 0")), "looks/shot.toml:5: enabled must be true or false, not the integer 0");
    assert_eq!(error(&layer("preset = 7")), "looks/shot.toml:5: preset must be a string, not the integer 7");
}

#[test]
fn map_bindings_are_checked() {
    let map = |body: &str| format!("[[object]]\n[[object.layer]]\npreset = \"gold\"\n[object.layer.map]\n{body}\n");
    assert_eq!(
        error(&map("rougness = \"r\"")),
        "looks/shot.toml:5: unknown parameter 'rougness' in [object.layer.map] (expected base_color, metallic, \
         subsurface, specular, specular_tint, roughness, anisotropic, sheen, sheen_tint, clearcoat, clearcoat_gloss, \
         emission); did you mean 'roughness'?"
    );
    assert_eq!(error(&map("roughness = 0.5")), "looks/shot.toml:5: roughness must be a string, not the number 0.5");
    assert_eq!(error(&map("roughness = \"\"")), "looks/shot.toml:5: roughness must not be empty");
    assert_eq!(
        error(&map("roughness = \"map.rough\"")),
        "looks/shot.toml:5: roughness = \"map.rough\": name the map without the channel prefix, as \"rough\""
    );
    assert_eq!(
        error(&map("roughness = \" rough\"")),
        "looks/shot.toml:5: roughness = \" rough\": a map's name has no spaces around it"
    );
    assert_eq!(
        error("[[object]]\n[[object.layer]]\n[object.layer.map]\nbase_color = \"a\"\nbase_color = \"b\"\n"),
        "looks/shot.toml:5: duplicate key 'base_color'"
    );
}

#[test]
fn object_stacks_are_checked() {
    assert_eq!(
        error("[render]\nspp = 4\n\n[[object]]\nid = 3\n"),
        "looks/shot.toml:4: [[object]] has no layers; add at least one [[object.layer]]"
    );
    let twice = "[[object]]\nid = 1\n[[object.layer]]\n\n[[object]]\nid = 1\n[[object.layer]]\n";
    assert_eq!(error(twice), "looks/shot.toml:5: duplicate object id 1 (first at line 1)");
    let defaults = "[[object]]\n[[object.layer]]\n[[object]]\nid = 2\n[[object.layer]]\n[[object]]\n[[object.layer]]\n";
    assert_eq!(
        error(defaults),
        "looks/shot.toml:6: a second default stack ([[object]] without id; the first is at line 1)"
    );
    assert_eq!(error("[[object]]\nid = -1\n"), "looks/shot.toml:2: id = -1 is out of range [0, 4294967295]");
}

#[test]
fn unknown_presets_suggest_the_closest_names() {
    let message = error("[[object]]\n[[object.layer]]\npreset = \"golld\"\n");
    assert!(message.starts_with("looks/shot.toml:3: no preset named 'golld' (closest: gold, "), "{message}");
}

#[test]
fn a_missing_look_file_is_named() {
    let e = Look::load(Path::new("looks/missing.toml")).unwrap_err();
    assert_eq!(e.to_string(), "looks/missing.toml: file not found");
    assert_eq!(e.exit_code(), 2);
}

#[test]
fn a_preset_file_with_errors_is_named_with_its_line() {
    let dir = scratch("bad-preset");
    write(&dir.join("scuffed.toml"), "name = \"scuffed\"\nmetallic = 1\nroughness = 2\n");
    let look = dir.join("shot.toml");
    let text = "[[object]]\n[[object.layer]]\npreset = \"scuffed\"\n";
    let e = Look::parse(text, &look).unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "{}:3: preset 'scuffed': {}:3: roughness = 2 is out of range [0, 1]",
            look.display(),
            dir.join("scuffed.toml").display()
        )
    );
    let e = Look::parse("[[object]]\n[[object.layer]]\npreset = \"gone.toml\"\n", &look).unwrap_err().to_string();
    assert_eq!(
        e,
        format!("{}:3: preset 'gone.toml': {}: file not found", look.display(), dir.join("gone.toml").display())
    );
}

// ---- Presets ----

#[test]
fn preset_errors_name_the_key_and_line() {
    let file = Path::new("presets/mine.toml");
    let e = Preset::parse("name = \"mine\"\n\nmetalic = 1\n", file).unwrap_err().to_string();
    assert!(e.starts_with(
        "presets/mine.toml:3: unknown key 'metalic' at the top level (expected name, description, tags, base_color, "
    ));
    assert!(e.ends_with("; did you mean 'metallic'?"), "{e}");
    let e = Preset::parse("tags = \"metal\"\n", file).unwrap_err().to_string();
    assert_eq!(e, "presets/mine.toml:1: tags must be an array of strings, not the string \"metal\"");
    let e = Preset::parse("sheen = -0.1\n", file).unwrap_err().to_string();
    assert_eq!(e, "presets/mine.toml:1: sheen = -0.1 is out of range [0, 2]");
}

#[test]
fn preset_defaults_and_name_from_the_file() {
    let preset = Preset::parse("", Path::new("lib/plain-grey.toml")).unwrap();
    assert_eq!(preset.name, "plain-grey");
    assert_eq!(preset.description, "");
    assert!(preset.tags.is_empty() && preset.set.is_empty());
    assert_eq!(preset.params, Params::default());

    let preset =
        Preset::parse("name = \"Shiny\"\nroughness = 0\nbase_color = [1, 0, 0]\n", Path::new("x.toml")).unwrap();
    assert_eq!(preset.name, "Shiny");
    assert_eq!(preset.set, vec![Param::BaseColor, Param::Roughness]);
    assert_eq!(preset.params.base_color, [1.0, 0.0, 0.0]);
    assert_eq!(preset.params.roughness, 0.0);
    assert_eq!(preset.params.metallic, 0.0);
}

#[test]
fn presets_round_trip_through_toml() {
    for name in library::builtin_names() {
        let preset = library::builtin(name).unwrap();
        let text = preset.to_toml();
        assert_eq!(Preset::parse(&text, Path::new("elsewhere.toml")).unwrap(), preset, "{text}");
    }
    let odd = Preset {
        name: "it's \"odd\"".into(),
        description: "back\\slash\nnew line".into(),
        tags: vec![],
        params: Params { roughness: 0.1, ..Params::default() },
        set: vec![Param::Roughness],
        ior: None,
    };
    assert_eq!(Preset::parse(&odd.to_toml(), Path::new("odd.toml")).unwrap(), odd);
}

// ---- Looks ----

#[test]
fn unset_values_take_their_defaults() {
    let look = Look::parse("", Path::new(SHOT)).unwrap();
    assert_eq!(look.file.as_deref(), Some(Path::new(SHOT)));
    assert_eq!(look.environment, Default::default());
    assert_eq!(look.render, Default::default());
    assert!(look.objects.is_empty());

    let look =
        Look::parse("[[object]]\n[[object.layer]]\n\n[[object.layer]]\npreset = \"gold\"\n", Path::new(SHOT)).unwrap();
    let stack = &look.objects[0];
    assert_eq!(stack.id, None);
    let [bare, gold] = &stack.layers[..] else { panic!("two layers") };
    assert_eq!((bare.preset.as_deref(), bare.params), (None, Params::default()));
    assert_eq!(gold.preset.as_deref(), Some("gold"));
    assert_eq!(gold.params, library::builtin("gold").unwrap().params);
    assert!(gold.overrides.is_empty());
    assert_eq!((gold.mask.as_deref(), gold.invert, gold.opacity), (None, false, 1.0));
    assert_eq!((bare.line, gold.line), (2, 4));
}

#[test]
fn every_setting_is_read() {
    let text = r#"
[environment]
file = "../hdri/studio.exr"
rotation = -30
intensity = 2.5
background = false

[render]
spp = 64
seed = 4294967295
exposure = -1.5
tonemap = "agx"
noise_threshold = 0.05
min_spp = 8

[[object]]
id = 7
[[object.layer]]
preset = "blue-rubber"
[[object.layer]]
preset = "gold"
mask = "scratches"
invert = true
opacity = 0.25
[object.layer.set]
roughness = 0.125
base_color = [1, 0.5, 0]
"#;
    let look = Look::parse(text, Path::new(SHOT)).unwrap();
    assert_eq!(look.environment.source, Some(EnvironmentRef::File("looks/../hdri/studio.exr".into())));
    assert_eq!(look.environment.rotation, Some(-30.0));
    assert_eq!(look.environment.intensity, Some(2.5));
    assert_eq!(look.environment.background, Some(false));
    assert_eq!(look.render.spp, Some(64));
    assert_eq!(look.render.seed, Some(u32::MAX));
    assert_eq!(look.render.exposure, Some(-1.5));
    assert_eq!(look.render.tonemap, Some(Tonemap::Agx));
    assert_eq!(look.render.noise_threshold, Some(0.05));
    assert_eq!(look.render.min_spp, Some(8));
    let stack = look.stack_for(7).unwrap();
    let gold = &stack.layers[1];
    assert_eq!(gold.line, 20);
    assert_eq!(gold.mask.as_deref(), Some("scratches"));
    assert!(gold.invert);
    assert_eq!(gold.opacity, 0.25);
    assert_eq!(gold.overrides, vec![Param::BaseColor, Param::Roughness]);
    assert_eq!(gold.params.roughness, 0.125);
    assert_eq!(gold.params.base_color, [1.0, 0.5, 0.0]);
    assert_eq!(gold.params.metallic, 1.0, "the preset's own values stay under the overrides");
}

#[test]
fn looks_round_trip_through_toml() {
    let dir = scratch("round-trip");
    write(&dir.join("house/blue.toml"), "base_color = [0.1, 0.2, 0.9]\nroughness = 0.3\n");
    let path = dir.join("looks/shot.toml");
    let text = r#"
[environment]
file = "../hdri/studio.exr"
rotation = 12.5
background = true
[render]
seed = 3
tonemap = "aces"
aovs = ["light", "N"]
noise_threshold = 0.025
min_spp = 32
[[object]]
[[object.layer]]
[object.layer.set]
metallic = 1
[[object]]
id = 2
[[object.layer]]
preset = "../house/blue.toml"
mask = "base"
[[object.layer]]
preset = "gold"
mask = "stripes"
invert = true
opacity = 0.1
[object.layer.set]
base_color = [0.9, 0.1, 0.3]
clearcoat = 2.5
emission = [4.0, 2.0, 0.5]
[object.layer.map]
base_color = "albedo"
roughness = "metalRough.G"
emission = "glow"
"#;
    write(&path, text);
    let look = Look::load(&path).unwrap();
    let gold = &look.objects[1].layers[1];
    assert_eq!(gold.params.emission, [4.0, 2.0, 0.5]);
    let maps: Vec<(Param, &str)> = gold.maps.iter().map(|(p, m)| (*p, m.as_str())).collect();
    assert_eq!(maps, [(Param::BaseColor, "albedo"), (Param::Roughness, "metalRough.G"), (Param::Emission, "glow")]);
    assert_eq!(look.render.aovs.as_deref(), Some(&["light".to_string(), "N".to_string()][..]));
    let written = look.to_toml();
    assert!(written.contains("aovs = [\"light\", \"N\"]\nnoise_threshold = 0.025\nmin_spp = 32\n"), "{written}");
    assert!(written.contains("[object.layer.map]\nbase_color = \"albedo\"\nroughness = \"metalRough.G\""), "{written}");
    let again = Look::parse(&written, &path).unwrap();
    assert_eq!(again, look, "{written}");
    assert_eq!(again.to_toml(), written);
    let mut unbound = look.clone();
    unbound.objects[1].layers[1].maps.clear();
    assert_ne!(unbound, look, "bindings are part of what a look means");

    let builtin = Look::builtin_default();
    let mut again = Look::parse(&builtin.to_toml(), Path::new(SHOT)).unwrap();
    again.file = None;
    assert_eq!(again, builtin);
}

#[test]
fn a_shadow_catcher_is_kept_when_written_back_and_a_wrong_value_is_named() {
    let text = "[[object]]\nname = \"Ground\"\nshadow_catcher = true\n[[object.layer]]\npreset = \"gold\"\n\
                [[object]]\nid = 3\nshadow_catcher = false\n[[object.layer]]\npreset = \"wax\"\n";
    let look = Look::parse(text, Path::new(SHOT)).unwrap();
    let catchers: Vec<bool> = look.objects.iter().map(|o| o.shadow_catcher).collect();
    assert_eq!(catchers, [true, false]);
    let written = look.to_toml();
    assert_eq!(written.matches("shadow_catcher = true").count(), 1, "{written}");
    assert!(!written.contains("shadow_catcher = false"), "only the non-default value is written: {written}");
    assert_eq!(Look::parse(&written, Path::new(SHOT)).unwrap(), look);
    let mut none = look.clone();
    none.objects[0].shadow_catcher = false;
    assert_ne!(none, look, "catching shadows is part of what a stack means");

    let bad = "[[object]]\nid = 1\nshadow_catcher = \"yes\"\n[[object.layer]]\n";
    let message = Look::parse(bad, Path::new(SHOT)).unwrap_err().to_string();
    assert!(message.contains(&format!("{SHOT}:3")) && message.contains("shadow_catcher"), "{message}");
}

#[test]
fn layers_can_be_disabled_and_stay_so_when_written_back() {
    let text = "[[object]]\nid = 1\n[[object.layer]]\npreset = \"gold\"\n[[object.layer]]\npreset = \"grime\"\n\
                enabled = false\n[[object.layer]]\npreset = \"wax\"\nenabled = true\n";
    let look = Look::parse(text, Path::new(SHOT)).unwrap();
    let enabled: Vec<bool> = look.objects[0].layers.iter().map(|l| l.enabled).collect();
    assert_eq!(enabled, [true, false, true], "enabled defaults to true");

    let written = look.to_toml();
    assert_eq!(written.matches("enabled = false").count(), 1, "{written}");
    assert!(!written.contains("enabled = true"), "only the non-default value is written: {written}");
    assert_eq!(Look::parse(&written, Path::new(SHOT)).unwrap(), look);

    let mut enabled = look.clone();
    enabled.objects[0].layers[1].enabled = true;
    assert_ne!(enabled, look, "enabled is part of what a layer means");
}

#[test]
fn a_preset_beside_the_look_beats_the_builtin_of_that_name() {
    let dir = scratch("shadowing");
    write(
        &dir.join("gold.toml"),
        "name = \"studio gold\"\nbase_color = [0.5, 0.4, 0.1]\nmetallic = 1\nroughness = 0.9\n",
    );
    let look = Look::parse("[[object]]\n[[object.layer]]\npreset = \"gold\"\n", &dir.join("shot.toml")).unwrap();
    let params = look.objects[0].layers[0].params;
    assert_eq!((params.roughness, params.base_color), (0.9, [0.5, 0.4, 0.1]));

    // Without the look's folder, the same name is the built-in.
    let builtin = Library::builtin_only().resolve("gold").unwrap();
    assert_eq!(builtin, library::builtin("gold").unwrap());
}

#[test]
fn presets_can_be_given_by_path() {
    let dir = scratch("paths");
    write(&dir.join("shelf/shiny.toml"), "roughness = 0.05\n");
    let look_file = dir.join("shot.toml");
    let relative = Look::parse("[[object]]\n[[object.layer]]\npreset = \"shelf/shiny.toml\"\n", &look_file).unwrap();
    assert_eq!(relative.objects[0].layers[0].params.roughness, 0.05);

    let absolute = dir.join("shelf/shiny.toml");
    let text = format!("[[object]]\n[[object.layer]]\npreset = {:?}\n", absolute.to_string_lossy());
    let look = Look::parse(&text, Path::new("elsewhere/shot.toml")).unwrap();
    assert_eq!(look.objects[0].layers[0].params.roughness, 0.05);
}

#[test]
fn unknown_names_suggest_presets_beside_the_look_too() {
    let dir = scratch("suggest");
    write(&dir.join("goldleaf.toml"), "metallic = 1\n");
    let e = Look::parse("[[object]]\n[[object.layer]]\npreset = \"goldlef\"\n", &dir.join("shot.toml")).unwrap_err();
    let message = e.to_string();
    assert!(message.contains(":3: no preset named 'goldlef' (closest: goldleaf, gold, "), "{message}");
}

#[test]
fn set_everywhere_overrides_every_layer_and_is_written_back() {
    let text = "[[object]]\n[[object.layer]]\npreset = \"gold\"\n[[object]]\nid = 1\n[[object.layer]]\n\
                [[object.layer]]\npreset = \"grime\"\n[object.layer.set]\nmetallic = 1\n";
    let mut look = Look::parse(text, Path::new(SHOT)).unwrap();
    look.set_everywhere(Param::Roughness, Value::Scalar(0.33)).unwrap();
    look.set_everywhere(Param::BaseColor, Value::Color([0.2, 0.3, 0.4])).unwrap();
    for layer in look.objects.iter().flat_map(|o| &o.layers) {
        assert_eq!(layer.params.roughness, 0.33);
        assert_eq!(layer.params.base_color, [0.2, 0.3, 0.4]);
        assert!(layer.overrides.contains(&Param::Roughness) && layer.overrides.contains(&Param::BaseColor));
    }
    assert_eq!(look.objects[1].layers[1].overrides, vec![Param::BaseColor, Param::Metallic, Param::Roughness]);
    assert_eq!(Look::parse(&look.to_toml(), Path::new(SHOT)).unwrap(), look);

    // A value that fails the range check changes nothing and says why.
    let before = look.clone();
    let error = look.set_everywhere(Param::Roughness, Value::Scalar(7.0)).unwrap_err();
    assert!(error.contains("roughness"), "{error}");
    assert_eq!(look, before);
}

#[test]
fn stacks_are_found_by_id_then_default() {
    let with_default =
        "[[object]]\nid = 1\n[[object.layer]]\npreset = \"gold\"\n[[object]]\n[[object.layer]]\npreset = \"wax\"\n";
    let look = Look::parse(with_default, Path::new(SHOT)).unwrap();
    assert_eq!(look.stack_for(1).unwrap().id, Some(1));
    assert_eq!(look.stack_for(0).unwrap().id, None);
    assert_eq!(look.stack_for(99).unwrap().layers[0].preset.as_deref(), Some("wax"));

    let without = "[[object]]\nid = 1\n[[object.layer]]\npreset = \"gold\"\n";
    let look = Look::parse(without, Path::new(SHOT)).unwrap();
    assert_eq!(look.stack_for(1).unwrap().id, Some(1));
    assert!(look.stack_for(2).is_none());
}

#[test]
fn the_builtin_default_look_shows_layering_on_the_shader_ball() {
    let look = Look::builtin_default();
    assert_eq!(look.file, None);
    assert_eq!(look.render.spp, Some(256));
    assert_eq!(look.environment.rotation, Some(-90.0));
    let ids: Vec<Option<u32>> = look.objects.iter().map(|o| o.id).collect();
    assert_eq!(ids, [None, Some(1), Some(2)]);

    let ball = &look.stack_for(1).unwrap().layers;
    let presets: Vec<_> = ball.iter().map(|l| l.preset.as_deref().unwrap()).collect();
    assert_eq!(presets, ["blue-rubber", "gold", "grime"]);
    assert_eq!(ball[0].overrides, [Param::Clearcoat, Param::ClearcoatGloss]);
    assert_eq!(ball[1].mask.as_deref(), Some("stripes"));
    assert_eq!(ball[1].params.roughness, 0.3);
    assert_eq!((ball[2].mask.as_deref(), ball[2].opacity), (Some("grunge"), 0.7));

    let pedestal = &look.stack_for(2).unwrap().layers;
    assert_eq!(pedestal[0].preset.as_deref(), Some("white-ceramic"));
    assert_eq!(pedestal[1].mask.as_deref(), Some("gradient"));
    assert_eq!(look.stack_for(0).unwrap().id, None);
}

#[test]
fn tables_of_the_wrong_shape_are_named() {
    assert_eq!(
        error("render = 3\n"),
        "looks/shot.toml:1: render: invalid type: integer `3`, expected a [render] table"
    );
    assert_eq!(
        error("[object]\nid = 1\n"),
        "looks/shot.toml:1: [object]: invalid type: map, expected a sequence (a list of tables is written [[name]])"
    );
}

// ---- The [model] table. ----

#[test]
fn model_table_parses_reads_back_and_names_bad_values() {
    use lookdev::shading::model::{Diffuse, Fresnel, Model, SpecularD, SpecularG};
    let text = "[model]\ndiffuse = \"oren-nayar\"\nspecular_d = \"gtr\"\ngtr_gamma = 1.5\n\
                specular_g = \"smith-height-correlated\"\nfresnel = \"conductor\"\nenergy_compensation = true\n";
    let look = Look::parse(text, Path::new(SHOT)).unwrap();
    let model = look.model.unwrap();
    assert_eq!(model.diffuse, Diffuse::OrenNayar);
    assert_eq!(model.specular_d, SpecularD::Gtr);
    assert_eq!(model.specular_g, SpecularG::SmithHeightCorrelated);
    assert_eq!(model.fresnel, Fresnel::Conductor);
    assert_eq!(model.gtr_gamma, 1.5);
    assert!(model.energy_compensation);
    // Written back, it reads back equal.
    let again = Look::parse(&look.to_toml(), Path::new(SHOT)).unwrap();
    assert_eq!(again.model, Some(model));
    // No table: no model; an empty table: the default model.
    assert_eq!(Look::parse("", Path::new(SHOT)).unwrap().model, None);
    assert_eq!(Look::parse("[model]\n", Path::new(SHOT)).unwrap().model, Some(Model::default()));

    assert_eq!(
        error("[model]\n\ndiffuse = \"lambret\"\n"),
        "looks/shot.toml:3: diffuse = 'lambret' is not a model (expected burley2012, lambert, frostbite, oren-nayar, \
         oren-nayar-qualitative, oren-nayar-fujii, gotanda, hammon); did you mean 'lambert'?"
    );
    let message = error("[model]\nspecular = \"gtr\"\n");
    assert!(message.starts_with("looks/shot.toml:2: unknown model key 'specular'"), "{message}");
    assert_eq!(error("[model]\ngtr_gamma = 20\n"), "looks/shot.toml:2: gtr_gamma = 20 is out of range [0.5, 10]");
    assert_eq!(
        error("[model]\nenergy_compensation = 1\n"),
        "looks/shot.toml:2: energy_compensation takes true or false"
    );
    assert_eq!(error("[model]\nfresnel = 2\n"), "looks/shot.toml:2: fresnel takes a name in quotes");
}

#[test]
fn preset_complex_ior_must_match_its_base_color() {
    let file = Path::new("presets/metal.toml");
    let ok = "base_color = [0.9626, 0.8276, 0.4082]\nior_n = [0.14, 0.31, 1.38]\nior_k = [3.697, 2.34, 1.914]\n";
    let preset = Preset::parse(ok, file).unwrap();
    assert_eq!(preset.ior, Some(([0.14, 0.31, 1.38], [3.697, 2.34, 1.914])));
    assert!(preset.params.ior_edge.iter().all(|&e| e > 0.0 && e <= 1.0));
    assert_eq!(Preset::parse(&preset.to_toml(), file).unwrap(), preset);
    let bad = |text: &str| Preset::parse(text, file).unwrap_err().to_string();
    assert_eq!(bad("ior_n = [1, 1, 1]\n"), "presets/metal.toml:1: ior_n needs ior_k beside it");
    assert_eq!(
        bad("base_color = [0.5, 0.8276, 0.4082]\nior_n = [0.14, 0.31, 1.38]\nior_k = [3.697, 2.34, 1.914]\n"),
        "presets/metal.toml:2: base_color[0] = 0.5 is not the F0 0.9626 of ior_n and ior_k (within 0.005)"
    );
    assert_eq!(bad("ior_n = [0, 1, 1]\nior_k = [0, 0, 0]\n"), "presets/metal.toml:1: ior_n[0] = 0 must be in (0, 100]");
}

#[test]
fn gbuffer_tables_and_object_names_read_write_back_and_resolve() {
    let text = "[gbuffer]\nfile = \"shot.exr\"\nlayer = \"ViewLayer\"\nup = \"z\"\ncamera_position = [0.5, -7.0, 2.5]\n\
                occluders = \"shot.occluders.glb\"\nnormal = \"Nw\"\nposition = \"Pw\"\ncoverage = \"alpha\"\nid = \"objectIndex\"\nmasks = [\"matte_a\", \"matte_b\"]\n\n\
                [[object]]\nname = \"Sphere.001\"\n[[object.layer]]\npreset = \"gold\"\n\n\
                [[object]]\nid = 3\n[[object.layer]]\npreset = \"chrome\"\n";
    let look = Look::parse(text, Path::new(SHOT)).unwrap();
    let g = &look.gbuffer;
    assert_eq!(g.file.as_deref(), Some(Path::new("looks/shot.exr")), "relative to the look");
    assert_eq!(g.source.layer.as_deref(), Some("ViewLayer"));
    assert_eq!(g.source.up, Some(lookdev::gbuffer::Up::Z));
    assert_eq!(g.source.camera_position, Some(glam::Vec3::new(0.5, -7.0, 2.5)));
    assert_eq!(g.source.occluders.as_deref(), Some(Path::new("looks/shot.occluders.glb")), "relative to the look");
    assert_eq!(g.source.channels.normal.as_deref(), Some("Nw"));
    assert_eq!(g.source.channels.masks, ["matte_a", "matte_b"]);
    assert_eq!((look.objects[0].name.as_deref(), look.objects[0].id), (Some("Sphere.001"), None));
    assert!(!look.objects[0].is_default(), "a named stack is not the default stack");
    let again = Look::parse(&look.to_toml(), Path::new(SHOT)).unwrap();
    assert_eq!(again, look, "written back:\n{}", look.to_toml());

    // Names resolve through the g-buffer's object names; an unknown one lists them.
    let mut resolved = look.clone();
    let names = std::collections::BTreeMap::from([(2, "Sphere.001".to_string()), (3, "Cube".to_string())]);
    assert!(resolved.resolve_object_names(&names, Path::new("g.exr")).unwrap().is_empty());
    assert_eq!(resolved.objects[0].id, Some(2));
    assert!(resolved.to_toml().contains("name = \"Sphere.001\""), "the name is kept, not the id");
    let claimed = std::collections::BTreeMap::from([(3, "Sphere.001".to_string())]);
    let warnings = look.clone().resolve_object_names(&claimed, Path::new("g.exr")).unwrap();
    assert_eq!(warnings.len(), 1);
    assert!(
        warnings[0].contains(
            "looks/shot.toml:18: this stack claims object 3 'Sphere.001', which the stack at line 13 claims too"
        ),
        "{}",
        warnings[0]
    );
    let unknown = look.clone().resolve_object_names(
        &names.iter().filter(|(id, _)| **id == 3).map(|(k, v)| (*k, v.clone())).collect(),
        Path::new("g.exr"),
    );
    let message = unknown.unwrap_err().to_string();
    assert_eq!(message, "looks/shot.toml:13: no object named 'Sphere.001' in g.exr (it has Cube (3))");

    assert_eq!(error("[gbuffer]\nup = \"x\"\n"), "looks/shot.toml:2: up = 'x': expected \"y\" or \"z\"");
    assert_eq!(
        error("[gbuffer]\ncamera_position = [1, 2]\n"),
        "looks/shot.toml:2: camera_position must be a point [x, y, z], not an array"
    );
    assert!(error("[gbuffer]\nnormals = \"N\"\n").contains("unknown key 'normals' in [gbuffer]"));
    assert_eq!(
        error("[[object]]\nid = 2\nname = \"Cube\"\n[[object.layer]]\n"),
        "looks/shot.toml:3: an [[object]] has an id or a name, not both"
    );
}

/// `[gbuffer] size` keeps the built-in scene's size with the look: it reads back as written,
/// each side is 1 to 8192 whole pixels, and a file beside it is refused, since a file has its
/// own size.
#[test]
fn the_built_in_scenes_size_is_kept_and_checked() {
    let look = Look::parse("[gbuffer]\nsize = [320, 200]\n", Path::new(SHOT)).unwrap();
    assert_eq!(look.gbuffer.size, Some((320, 200)));
    assert!(look.to_toml().contains("[gbuffer]\nsize = [320, 200]\n"), "{}", look.to_toml());
    assert_eq!(Look::parse(&look.to_toml(), Path::new(SHOT)).unwrap(), look);
    for (size, problem) in
        [("[0, 5]", "each side"), ("[9000, 5]", "each side"), ("[1.5, 5]", "each side"), ("640", "[width, height]")]
    {
        let message = error(&format!("[gbuffer]\nsize = {size}\n"));
        assert!(message.contains(":2:") && message.contains(problem), "{size}: {message}");
    }
    let message = error("[gbuffer]\nfile = \"g.exr\"\nsize = [64, 64]\n");
    assert!(message.contains(":3:") && message.contains("its own size"), "{message}");
}

#[test]
fn layer_names_and_mask_adjustments_are_read_written_back_and_checked() {
    let text = "[[object]]\nid = 1\n[[object.layer]]\npreset = \"gold\"\n[[object.layer]]\nname = \"Worn edges\"\n\
                preset = \"grime\"\nmask = \"grunge\"\nmask_blur = 2.5\nmask_black = 0.1\nmask_white = 0.8\n\
                mask_gamma = 1.5\n";
    let look = Look::parse(text, Path::new(SHOT)).unwrap();
    let layer = &look.objects[0].layers[1];
    assert_eq!(layer.name.as_deref(), Some("Worn edges"));
    let adjust = layer.mask_adjust;
    assert_eq!((adjust.blur, adjust.black, adjust.white, adjust.gamma), (2.5, 0.1, 0.8, 1.5));
    assert_eq!(look.objects[0].layers[0].mask_adjust, Default::default(), "unset: no adjustment");

    let written = look.to_toml();
    assert!(written.contains("name = \"Worn edges\"") && written.contains("mask_gamma = 1.5"), "{written}");
    assert!(!written.contains("mask_blur = 0"), "only adjustments that change something are written: {written}");
    assert_eq!(Look::parse(&written, Path::new(SHOT)).unwrap(), look);
    let mut renamed = look.clone();
    renamed.objects[0].layers[1].name = None;
    assert_ne!(renamed, look, "a layer's name is part of the look");

    let layer = |line: &str| format!("[[object]]\n[[object.layer]]\npreset = \"gold\"\n[[object.layer]]\n{line}\n");
    assert_eq!(
        error(&layer("mask_black = 0.6\nmask_white = 0.4")),
        "looks/shot.toml:5: mask_black = 0.6 must be below mask_white = 0.4"
    );
    assert_eq!(error(&layer("mask_gamma = 0")), "looks/shot.toml:5: mask_gamma = 0 is out of range [0.1, 10]");
    assert_eq!(error(&layer("mask_blur = 40")), "looks/shot.toml:5: mask_blur = 40 is out of range [0, 16] (pixels)");
    assert_eq!(error(&layer("name = 3")), "looks/shot.toml:5: name must be a string, not the integer 3");
}
