//! The modules' layering, read from the sources: lower modules never import higher ones, and
//! the shading mirror has no cycles. A `use` that breaks a rule fails here with its file and
//! line.

use std::path::{Path, PathBuf};

fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files.extend(rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
    files.sort();
    files
}

/// Each `(file, line, text)` of the module's code (comments left out) that names `pattern`.
fn uses(module: &str, pattern: &str) -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let dir = root.join(module);
    let files = if module.ends_with(".rs") { vec![dir] } else { rust_files(&dir) };
    let mut found = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap();
            if code.contains(pattern) {
                found.push(format!("{}:{}: {}", file.strip_prefix(&root).unwrap().display(), n + 1, line.trim()));
            }
        }
    }
    found
}

/// Fails with every line of `module` that names one of `forbidden`, except `allowed` ones.
fn assert_no_imports(module: &str, forbidden: &[&str], allowed: &[&str]) {
    let mut broken = Vec::new();
    for pattern in forbidden {
        broken.extend(uses(module, pattern).into_iter().filter(|line| !allowed.iter().any(|a| line.contains(a))));
    }
    assert!(broken.is_empty(), "{module} imports from above it:\n{}", broken.join("\n"));
}

const ABOVE_SHADING: [&str; 11] = [
    "crate::material",
    "crate::render",
    "crate::gpu",
    "crate::lab",
    "crate::viewer",
    "crate::cli",
    "crate::asset",
    "crate::gbuffer",
    "crate::environment",
    "crate::input",
    "crate::viewer_state",
];

#[test]
fn shading_imports_nothing_above_it() {
    assert_no_imports("shading", &ABOVE_SHADING, &[]);
}

#[test]
fn the_brdf_imports_neither_its_table_builder_nor_its_sampling() {
    let broken: Vec<String> = ["super::energy", "super::sampling", "shading::energy", "shading::sampling"]
        .iter()
        .flat_map(|pattern| uses("shading/brdf.rs", pattern))
        .collect();
    assert!(broken.is_empty(), "brdf.rs imports in a circle:\n{}", broken.join("\n"));
    assert!(uses("shading/sampling.rs", "super::energy").is_empty(), "sampling.rs imports the energy builder");
}

#[test]
fn materials_import_neither_the_renderer_nor_the_gpu() {
    // A look's `[render] aovs` names are checked as the look is read, so that an unknown name is
    // reported at its line: the AOV names are the one thing material takes from render. Its GPU
    // layouts are described (`crate::gpu::GlslStruct`), never built, here.
    assert_no_imports(
        "material",
        &["crate::render", "crate::gpu", "crate::viewer", "crate::cli", "crate::lab", "crate::asset"],
        &["crate::render::aov::Aov::parse", "crate::gpu::GlslStruct", "crate::gpu::GlslLayout"],
    );
}

#[test]
fn the_gpu_layer_knows_no_scene() {
    assert_no_imports(
        "gpu",
        &["crate::material", "crate::render", "crate::shading", "crate::viewer", "crate::cli", "crate::asset"],
        &[],
    );
}

/// The rules catch what they exist for.
#[test]
fn a_forbidden_import_is_found() {
    assert!(!uses("render", "crate::material").is_empty());
    assert!(!uses("shading/energy.rs", "super::brdf").is_empty());
}
