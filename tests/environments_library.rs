//! The environment library: the built-in environments, how looks, flags and scripts name them,
//! their thumbnails, the config file's folders and recent files, and stepping through the
//! library in the viewer (under Xvfb, validation on; see tests/viewer.rs).

mod common;

use lookdev::config::Config;
use lookdev::environment::builtin::{BUILTINS, DEFAULT};
use lookdev::environment::library;
use lookdev::environment::{Builtin, EnvironmentRef};
use lookdev::material::look::Look;
use std::path::Path;

/// The shipped maps, by name.
const SHIPPED: [&str; 5] = ["studio", "courtyard", "city", "interior", "sunrise"];

#[test]
fn every_builtin_loads_at_its_size_with_a_finite_positive_mean() {
    assert_eq!(BUILTINS.len(), SHIPPED.len());
    for name in SHIPPED {
        let builtin = Builtin::find(name).unwrap();
        let env = builtin.load();
        assert_eq!((env.width, env.height), (1024, 512), "{name}");
        let sum: f64 = env.texels.iter().flatten().map(|&v| v as f64).sum();
        let mean = sum / (env.texels.len() * 3) as f64;
        assert!(mean.is_finite() && mean > 0.0, "{name}: mean {mean}");
        assert!(env.texels.iter().flatten().all(|v| v.is_finite() && *v >= 0.0), "{name}");
        assert_eq!(env.source, format!("built-in {name}"));
        assert_eq!(env.content_hash, builtin.content_hash(), "{name}: renders record the embedded file's hash");
        assert!(!builtin.description.is_empty());
    }
    let hashes: std::collections::BTreeSet<u64> =
        SHIPPED.iter().map(|n| Builtin::find(n).unwrap().content_hash()).collect();
    assert_eq!(hashes.len(), SHIPPED.len(), "five different maps");
}

#[test]
fn the_library_lists_the_builtins_first() {
    let listing = library::list(&Config::default());
    let order = listing.order();
    assert_eq!(order, SHIPPED.map(EnvironmentRef::Builtin));
    assert!(listing.problems.is_empty());
}

#[test]
fn a_look_names_a_builtin_and_writes_it_back() {
    let file = Path::new("shots/a.toml");
    let look = Look::parse("[environment]\nbuiltin = \"courtyard\"\nrotation = 30\n", file).unwrap();
    assert_eq!(look.environment.source, Some(EnvironmentRef::Builtin("courtyard")));
    let text = look.to_toml();
    assert!(text.contains("builtin = \"courtyard\""), "{text}");
    assert_eq!(Look::parse(&text, file).unwrap(), look);

    let typo = Look::parse("[environment]\n\nbuiltin = \"courtyrad\"\n", file).unwrap_err();
    assert!(typo.message.starts_with("shots/a.toml:3:"), "{typo}");
    assert!(typo.message.contains("did you mean 'courtyard'?"), "{typo}");
    let both = Look::parse("[environment]\nfile = \"a.exr\"\nbuiltin = \"city\"\n", file).unwrap_err();
    assert!(both.message.contains("not both") && both.message.starts_with("shots/a.toml:3:"), "{both}");
}

#[test]
fn the_env_flag_takes_a_builtin_name_and_renders_record_it() {
    let dir = tempfile::tempdir().unwrap();
    let gbuffer = dir.path().join("g.exr");
    lookdev::gbuffer::GBuffer::shaderball(32, 32).write(&gbuffer).unwrap();
    let g = gbuffer.to_str().unwrap();

    let typo = common::cli::lookdev(&["render", "--gbuffer", g, "--env", "courtyrad", "--out", "x.png"]);
    let text = common::cli::stderr(&typo);
    assert!(text.contains("did you mean 'courtyard'?") && !text.contains("panicked"), "{text}");
    assert_eq!(typo.status.code(), Some(2), "{text}");

    for (flag, name) in [("builtin:city", "city"), ("sunrise", "sunrise")] {
        let out = dir.path().join(format!("{name}.exr"));
        let rendered = common::cli::lookdev(&[
            "render",
            "--gbuffer",
            g,
            "--env",
            flag,
            "--spp",
            "1",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        common::cli::assert_success(&rendered);
        let meta = exr::meta::MetaData::read_from_file(&out, false).unwrap();
        let text = |key: &str| {
            meta.headers[0].own_attributes.other.iter().find_map(|(k, v)| match v {
                exr::meta::attribute::AttributeValue::Text(t) if k == key => Some(t.to_string()),
                _ => None,
            })
        };
        assert_eq!(text("lookdev/environment"), Some(format!("built-in {name}")));
        let hash = format!("{:016x}", Builtin::find(name).unwrap().content_hash());
        assert_eq!(text("lookdev/environmentHash"), Some(hash));
    }
}

#[test]
fn environment_thumbnails_render_once_and_are_kept_on_disk() {
    use lookdev::viewer::thumbnails::{self, Thumbnails};
    let ctx = common::gpu::context();
    let dir = tempfile::tempdir().unwrap();
    let references = SHIPPED.map(EnvironmentRef::Builtin);
    let mut first = Vec::new();
    {
        let mut thumbnails = Thumbnails::new(&ctx, Some(dir.path().to_path_buf())).unwrap();
        for reference in &references {
            let mut may_render = true;
            let image = thumbnails.environment(reference, &mut may_render).unwrap().expect("rendered").clone();
            assert!(!may_render, "rendering one uses the frame's allowance");
            first.push(image);
        }
    }
    let kept = || cached_files(dir.path());
    let before = kept();
    assert_eq!(before.len(), SHIPPED.len(), "one file each: {before:?}");
    let (w, h) = thumbnails::ENVIRONMENT_SIZE;
    for (image, name) in first.iter().zip(SHIPPED) {
        assert_eq!(image.dimensions(), (w, h));
        // The three panels: lat-long, chrome ball, grey ball; each is lit, and the balls differ.
        let panel = |x0: u32, width: u32| {
            let view = image::imageops::crop_imm(image, x0, 0, width, h).to_image();
            view.pixels().map(|p| p.0[..3].iter().map(|&c| c as f64).sum::<f64>()).sum::<f64>() / (3 * width * h) as f64
        };
        let size = thumbnails::SIZE;
        let (sky, chrome, grey) = (panel(0, 2 * size), panel(2 * size, size), panel(3 * size, size));
        assert!(sky > 10.0 && grey > 10.0 && chrome > 10.0, "{name}: panels' mean levels {sky} {chrome} {grey}");
        let ball = |x0: u32| image.get_pixel(x0 + size / 2, h * 2 / 5).0;
        assert_ne!(ball(2 * size), ball(3 * size), "{name}: the chrome and the grey ball differ");
    }
    assert_ne!(first[0], first[1]);

    // A new session reads them all back without rendering any.
    let mut thumbnails = Thumbnails::new(&ctx, Some(dir.path().to_path_buf())).unwrap();
    for (reference, image) in references.iter().zip(&first) {
        let mut may_render = false;
        assert_eq!(thumbnails.environment(reference, &mut may_render).unwrap(), Some(image));
    }
    assert_eq!(kept(), before, "nothing rendered or written again");
    drop(thumbnails);
    common::gpu::finish(ctx);
}

#[cfg(feature = "viewer")]
/// The files in a thumbnail cache with their modification times, by name: what a session that
/// renders nothing leaves as it was.
fn cached_files(dir: &Path) -> Vec<(std::ffi::OsString, std::time::SystemTime)> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (e.file_name(), e.metadata().unwrap().modified().unwrap())
        })
        .collect();
    files.sort();
    files
}

mod viewer {
    use super::common::viewer::*;
    use super::*;

    /// Writes a small sky-over-ground map as Radiance `.hdr`.
    fn write_map(path: &std::path::Path) {
        let pixels: Vec<image::Rgb<f32>> = (0..64 * 32)
            .map(|i| if i < 64 * 16 { image::Rgb([0.6, 0.8, 1.2]) } else { image::Rgb([0.3, 0.2, 0.1]) })
            .collect();
        let file = std::fs::File::create(path).unwrap();
        image::codecs::hdr::HdrEncoder::new(file).encode(&pixels, 64, 32).unwrap();
    }

    /// A case whose config names a folder holding one map.
    fn case_with_a_folder() -> Option<Case> {
        let case = Case::new()?;
        let maps = case.path("maps");
        std::fs::create_dir_all(&maps).unwrap();
        write_map(&maps.join("mine.hdr"));
        // Listed before mine.hdr, and not a map: stepping passes over it.
        std::fs::write(maps.join("broken.hdr"), b"not a map").unwrap();
        write_map(&case.path("other.hdr"));
        let config = Config { environment_folders: vec![maps], recent_environments: Vec::new() };
        config.save(&case.path("config/lookdev/config.toml")).unwrap();
        Some(case)
    }

    fn environment_of(case: &Case, look: &str) -> Option<EnvironmentRef> {
        Look::load(&case.path(look)).unwrap().environment.source
    }

    #[test]
    fn the_arrow_keys_step_through_the_library_as_undoable_edits() {
        let Some(case) = case_with_a_folder() else { return };
        // A key reaches the interface in the frame after its line, so a line follows each.
        case.write(
            "step.script",
            "wait-spp 2\nscreenshot before.png\nkey ArrowRight\nwait-spp 2\nscreenshot stepped.png\n\
             save-look stepped.toml\nundo\nwait-spp 2\nscreenshot undone.png\nsave-look undone.toml\n\
             key ArrowLeft\nwait-spp 1\nsave-look left.toml\nenv studio\nkey ArrowLeft\nwait-spp 1\nsave-look wrapped.toml\nenv next\n\
             save-look next.toml\nenv prev\nenv prev\nsave-look prev.toml\nenv sunrise\nsave-look named.toml\n\
             key ArrowRight\nwait-spp 1\nsave-look passed.toml\nenv other.hdr\n",
        );
        let output = case.view(&["look.toml", "--script", "step.script", "--exit-after-spp", "2"]);
        assert_success(&output);
        // The bench's look names no environment: the default built-in. The library lists the
        // built-ins, then the folder's map.
        let at = BUILTINS.iter().position(|b| b.name == DEFAULT).unwrap();
        let builtin = |i: usize| Some(EnvironmentRef::Builtin(BUILTINS[i].name));
        assert_eq!(environment_of(&case, "undone.toml"), None, "undo restores the look's own");
        assert_eq!(environment_of(&case, "stepped.toml"), builtin(at + 1));
        assert_eq!(environment_of(&case, "left.toml"), builtin(at - 1));
        let mine = EnvironmentRef::File(case.path("maps/mine.hdr"));
        assert_eq!(environment_of(&case, "wrapped.toml"), Some(mine), "← from the first wraps to the last");
        assert_eq!(environment_of(&case, "next.toml"), builtin(0));
        assert_eq!(environment_of(&case, "prev.toml"), builtin(BUILTINS.len() - 1));
        assert_eq!(environment_of(&case, "named.toml"), Some(EnvironmentRef::Builtin("sunrise")));
        assert_eq!(
            environment_of(&case, "passed.toml"),
            Some(EnvironmentRef::File(case.path("maps/mine.hdr"))),
            "→ passes over the map that does not load"
        );
        let saved = std::fs::read_to_string(case.path("stepped.toml")).unwrap();
        assert!(saved.contains(&format!("builtin = \"{}\"", BUILTINS[at + 1].name)), "{saved}");

        // The image followed: the step changed it, and undo brought back the same pixels.
        let shot = |name: &str| case.screenshot_image(&output, name);
        let (_, changed) = difference(&shot("before.png"), &shot("stepped.png"));
        assert!(changed > 5.0, "stepping changed the image by only {changed}");
        let (_, undone) = difference(&shot("before.png"), &shot("undone.png"));
        assert!(undone < 0.5, "undo left the image {undone} off");

        // The file opened by name became a recent file in the config, which reads back.
        let config = Config::load(&case.path("config/lookdev/config.toml")).unwrap();
        assert_eq!(config.environment_folders, [case.path("maps")]);
        assert_eq!(config.recent_environments, [case.path("other.hdr")]);
    }

    #[test]
    fn a_misspelt_builtin_in_a_script_is_named_with_a_suggestion() {
        let Some(case) = Case::new() else { return };
        case.write("typo.script", "env courtyrad\n");
        let output = case.view(&["look.toml", "--script", "typo.script", "--exit-after-spp", "1"]);
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{text}");
        assert!(text.contains("typo.script:1:") && text.contains("did you mean 'courtyard'?"), "{text}");
    }

    #[test]
    fn a_bad_config_file_is_a_warning_and_left_as_it_is() {
        let Some(case) = Case::new() else { return };
        let config = case.path("config/lookdev/config.toml");
        std::fs::create_dir_all(config.parent().unwrap()).unwrap();
        std::fs::write(&config, "[environments]\nfolders = 3\n").unwrap();
        write_map(&case.path("o.hdr"));
        case.write("open.script", "env o.hdr\nkey ArrowRight\nwait-spp 1\nsave-look stepped.toml\n");
        let output = case.view(&["look.toml", "--script", "open.script", "--exit-after-spp", "1"]);
        assert_success(&output);
        let text = stderr(&output);
        assert!(text.contains("warning") && text.contains(&format!("{}:2:", config.display())), "{text}");
        assert_eq!(std::fs::read_to_string(&config).unwrap(), "[environments]\nfolders = 3\n");
        // The library still steps through the built-ins.
        let stepped = environment_of(&case, "stepped.toml");
        assert!(matches!(stepped, Some(EnvironmentRef::Builtin(_))), "{stepped:?}");
    }

    #[test]
    fn the_browser_keeps_its_thumbnails_in_the_cache() {
        let Some(case) = Case::new() else { return };
        case.write("browse.script", "environments\nwait-spp 16\nscreenshot browser.png\n");
        let run = || {
            let output =
                case.view(&["look.toml", "--script", "browse.script", "--spp", "16", "--exit-after-spp", "16"]);
            assert_success(&output);
            super::cached_files(&case.path("cache/lookdev/thumbnails"))
        };
        let first = run();
        assert!(!first.is_empty(), "the open browser rendered thumbnails into the cache");
        let second = run();
        for file in &first {
            assert!(second.contains(file), "{file:?} was rendered again: {second:?}");
        }
    }
}
