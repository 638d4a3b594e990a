//! The built-in preset library: every file parses and names itself, metals carry the F0 of
//! the complex IORs their descriptions cite, dielectric albedos are plausible, and the
//! library covers the material families docs/formats.md lists.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use lookdev::material::library::{self, BUILTIN};
use lookdev::material::preset::Preset;

fn presets_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("presets")
}

/// Every built-in preset, parsed.
fn all() -> Vec<Preset> {
    library::builtin_names().into_iter().map(|name| library::builtin(name).unwrap()).collect()
}

fn get(name: &str) -> Preset {
    library::builtin(name).unwrap_or_else(|| panic!("no built-in preset '{name}'"))
}

/// Rec.709 luminance of a linear colour.
fn luminance([r, g, b]: [f32; 3]) -> f64 {
    0.2126 * r as f64 + 0.7152 * g as f64 + 0.0722 * b as f64
}

/// Normal-incidence reflectance of a conductor with complex IOR n + ik.
fn f0(n: f64, k: f64) -> f64 {
    ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
}

fn has_tag(preset: &Preset, tag: &str) -> bool {
    preset.tags.iter().any(|t| t == tag)
}

/// The tags presets may use. A new tag joins this list deliberately, not by a typo.
const VOCABULARY: &[&str] = &[
    // What the surface is.
    "metal",
    "dielectric",
    // Where the numbers come from.
    "measured",
    "reference",
    // Material classes.
    "plastic",
    "rubber",
    "ceramic",
    "paint",
    "stone",
    "wood",
    "fabric",
    "organic",
    "dirt",
    // Finish.
    "polished",
    "glossy",
    "matte",
    "rough",
    "translucent",
    // Use.
    "layer",
    // Lobes beyond the base diffuse and specular.
    "clearcoat",
    "sheen",
    "subsurface",
    "anisotropic",
    // A dielectric whose IOR puts specular above 1 (none yet).
    "high-ior",
];

#[test]
fn every_preset_file_parses_names_itself_and_round_trips() {
    let mut stems = BTreeSet::new();
    for entry in std::fs::read_dir(presets_folder()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let preset = Preset::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(preset.name, stem, "{}: `name` must be the file name", path.display());
        let well_formed = !stem.is_empty()
            && stem.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
            && !stem.starts_with('-')
            && !stem.ends_with('-')
            && !stem.contains("--");
        assert!(well_formed, "{stem}: names are lowercase words joined by hyphens");
        assert!(!preset.description.trim().is_empty(), "{stem}: no description");
        assert!(!preset.tags.is_empty(), "{stem}: no tags");
        let text = preset.to_toml();
        assert_eq!(Preset::parse(&text, Path::new("elsewhere.toml")).unwrap(), preset, "{stem}: {text}");
        assert_eq!(library::builtin(&stem).as_ref(), Some(&preset), "{stem}: not built in, or built in differently");
        stems.insert(stem);
    }
    let listed: BTreeSet<String> = BUILTIN.iter().map(|(name, _)| name.to_string()).collect();
    assert_eq!(listed, stems, "BUILTIN and presets/ disagree");
    let names: Vec<&str> = BUILTIN.iter().map(|(name, _)| *name).collect();
    let mut sorted = names.clone();
    sorted.sort_unstable();
    assert_eq!(names, sorted, "keep BUILTIN sorted by name");
}

/// Each metal's complex IOR n + ik at its red, green and blue wavelengths, exactly as its
/// description writes them.
const METALS: &[(&str, [(&str, &str); 3])] = &[
    // Rakic et al. 1998, Lorentz-Drude model, 650 / 546.1 / 450 nm.
    ("aluminium", [("1.420", "7.467"), ("0.949", "6.416"), ("0.590", "5.311")]),
    ("brushed-aluminium", [("1.420", "7.467"), ("0.949", "6.416"), ("0.590", "5.311")]),
    ("chrome", [("3.535", "4.348"), ("2.873", "4.222"), ("2.145", "3.862")]),
    ("platinum", [("2.370", "4.254"), ("2.081", "3.682"), ("1.851", "3.140")]),
    ("tungsten", [("3.717", "2.884"), ("3.448", "2.746"), ("3.370", "2.526")]),
    // Johnson & Christy 1972 at 659.5 and 450.9 nm; green from Ogaki and Ishiyama at 546 nm.
    ("gold", [("0.14", "3.697"), ("0.31", "2.34"), ("1.38", "1.914")]),
    ("silver", [("0.05", "4.483"), ("0.05", "3.54"), ("0.04", "2.657")]),
    ("copper", [("0.22", "3.747"), ("0.84", "2.41"), ("1.24", "2.397")]),
    // Johnson & Christy 1974 at 1.88 / 2.26 / 2.75 eV (659 / 549 / 451 nm).
    ("iron", [("2.92", "3.10"), ("2.95", "2.93"), ("2.59", "2.77")]),
    ("titanium", [("2.76", "3.84"), ("2.54", "3.43"), ("2.27", "3.04")]),
    ("nickel", [("1.99", "4.26"), ("1.92", "3.61"), ("1.73", "2.95")]),
    ("cobalt", [("2.25", "4.27"), ("2.05", "3.82"), ("1.74", "3.28")]),
    ("palladium", [("1.80", "4.42"), ("1.64", "3.84"), ("1.41", "3.26")]),
    // Querry 1985, 70 % Cu 30 % Zn, 650 / 550 / 450 nm.
    ("brass", [("0.444", "3.695"), ("0.527", "2.765"), ("1.094", "1.829")]),
    // Karlsson & Ribbing 1982, austenitic stainless steel, 640 / 540 / 460 nm.
    ("stainless-steel", [("2.3962", "4.1378"), ("2.0072", "3.6166"), ("1.7169", "3.1785")]),
    ("brushed-steel", [("2.3962", "4.1378"), ("2.0072", "3.6166"), ("1.7169", "3.1785")]),
];

#[test]
fn metal_base_colors_are_f0_of_the_cited_complex_ior() {
    for (name, nk) in METALS {
        let preset = get(name);
        assert_eq!(preset.params.metallic, 1.0, "{name}");
        for (channel, (n, k)) in nk.iter().enumerate() {
            let expected = f0(n.parse().unwrap(), k.parse().unwrap());
            let stored = preset.params.base_color[channel] as f64;
            assert!((stored - expected).abs() < 5e-4, "{name} channel {channel}: {stored} vs F0 {expected:.4}");
            let cited = format!("{n} + {k}i");
            assert!(preset.description.contains(&cited), "{name}: the description does not cite {cited}");
        }
    }
    // The cited values are also the preset's ior_n and ior_k, which the conductor Fresnel model
    // reads back through the material's edge parameter.
    for (name, nk) in METALS {
        let (n, k) = get(name).ior.unwrap_or_else(|| panic!("{name}: no ior_n and ior_k"));
        let p = get(name).params;
        for (c, (cn, ck)) in nk.iter().enumerate() {
            assert_eq!((n[c], k[c]), (cn.parse::<f32>().unwrap(), ck.parse::<f32>().unwrap()), "{name} channel {c}");
            let (n2, k2) = lookdev::shading::brdf::complex_ior(p.base_color[c], p.ior_edge[c]);
            assert!((n2 - n[c]).abs() < 0.02 * n[c].max(1.0) && (k2 - k[c]).abs() < 0.02 * k[c].max(1.0), "{name}");
        }
    }
    let tabled: BTreeSet<&str> = METALS.iter().map(|(name, _)| *name).collect();
    for preset in all().into_iter().filter(|p| p.params.metallic == 1.0) {
        assert!(tabled.contains(preset.name.as_str()), "{}: a metal without cited (n, k) in METALS", preset.name);
    }
}

/// The 546 nm values of Ogaki and Ishiyama's lecture, "An Introduction to Microfacet BRDFs for
/// Physically Based Materials". The presets may take green from another source or wavelength,
/// but not one that disagrees by more than 0.03.
#[test]
fn green_channels_agree_with_the_546nm_values() {
    for (name, n, k) in [("gold", 0.31, 2.34), ("silver", 0.05, 3.54), ("copper", 0.84, 2.41)] {
        let green = get(name).params.base_color[1] as f64;
        assert!((green - f0(n, k)).abs() <= 0.03, "{name}: green {green} vs F0 {:.4} at 546 nm", f0(n, k));
    }
}

#[test]
fn metallic_is_zero_or_one_and_dielectrics_are_plausible() {
    for preset in all() {
        let (name, p) = (&preset.name, &preset.params);
        assert!(p.metallic == 0.0 || p.metallic == 1.0, "{name}: metallic {}", p.metallic);
        if p.metallic == 0.0 {
            let y = luminance(p.base_color);
            assert!((0.02..=0.9).contains(&y), "{name}: base_color luminance {y:.4} is outside [0.02, 0.9]");
            assert!(p.specular <= 1.0 || has_tag(&preset, "high-ior"), "{name}: specular {} above 1", p.specular);
        }
    }
}

#[test]
fn reference_albedos() {
    let charcoal = luminance(get("charcoal").params.base_color);
    assert!((charcoal - 0.04).abs() <= 0.01, "charcoal luminance {charcoal}");
    let snow = luminance(get("fresh-snow").params.base_color);
    assert!((snow - 0.9).abs() <= 0.05, "fresh-snow luminance {snow}");
    for name in ["charcoal", "fresh-snow", "grey-card"] {
        assert!(has_tag(&get(name), "reference"), "{name}");
    }
}

#[test]
fn tags_use_the_vocabulary_and_match_the_parameters() {
    for preset in all() {
        let name = &preset.name;
        for tag in &preset.tags {
            assert!(VOCABULARY.contains(&tag.as_str()), "{name}: tag '{tag}' is not in the vocabulary");
        }
        let p = &preset.params;
        assert_eq!(has_tag(&preset, "metal"), p.metallic == 1.0, "{name}: tag 'metal' vs metallic");
        assert_eq!(has_tag(&preset, "dielectric"), p.metallic == 0.0, "{name}: tag 'dielectric' vs metallic");
        for (tag, value) in [
            ("clearcoat", p.clearcoat),
            ("sheen", p.sheen),
            ("subsurface", p.subsurface),
            ("anisotropic", p.anisotropic),
        ] {
            assert_eq!(has_tag(&preset, tag), value > 0.0, "{name}: tag '{tag}' vs {tag} = {value}");
        }
    }
}

#[test]
fn the_library_covers_the_material_families() {
    let presets = all();
    assert!(presets.len() >= 30, "only {} presets", presets.len());
    let metals = presets.iter().filter(|p| p.params.metallic == 1.0).count();
    assert!(metals >= 8, "only {metals} metals");

    let tagged = |tags: &[&str]| presets.iter().filter(|p| tags.iter().all(|t| has_tag(p, t))).count();
    for (tags, at_least) in [
        (&["dielectric", "plastic", "glossy"][..], 1),
        (&["dielectric", "plastic", "matte"][..], 1),
        (&["dielectric", "rubber"][..], 1),
        (&["dielectric", "ceramic"][..], 1),
        (&["dielectric", "paint", "matte"][..], 1),
        (&["dielectric", "paint", "glossy"][..], 1),
        (&["dielectric", "stone"][..], 3),
        (&["dielectric", "fabric"][..], 2),
        (&["dielectric", "reference"][..], 2),
    ] {
        assert!(tagged(tags) >= at_least, "fewer than {at_least} presets tagged {tags:?}");
    }

    // The default look's presets, and the plain-named aluminium beside the brushed one.
    for name in ["blue-rubber", "gold", "grime", "white-ceramic", "copper", "red-plastic"] {
        get(name);
    }
    for name in ["aluminium", "brushed-aluminium", "brushed-steel"] {
        assert_eq!(get(name).params.metallic, 1.0, "{name}");
    }
    for name in ["car-paint", "lacquered-wood"] {
        assert!(get(name).params.clearcoat > 0.0, "{name}: no clear coat");
    }
    for name in ["velvet", "cotton"] {
        assert!(get(name).params.sheen > 0.0, "{name}: no sheen");
    }
    for name in ["wax", "skin", "marble"] {
        assert!(get(name).params.subsurface > 0.0, "{name}: no subsurface");
    }
    for name in ["brushed-aluminium", "brushed-steel"] {
        assert!(get(name).params.anisotropic > 0.0, "{name}: not anisotropic");
    }
}
