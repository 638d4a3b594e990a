//! The committed SPIR-V in `spirv/` is what `glsl/` compiles to, and it validates.
//!
//! Both checks need the Khronos tools (Debian: glslang-tools, spirv-tools). They are skipped, with
//! a note, where the tools are missing, except in CI (`CI` set), where that fails. To regenerate the SPIR-V after editing a
//! kernel: `LOOKDEV_BLESS_SPIRV=1 cargo test --release --test spirv`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The GLSL files with the given extensions (`comp`: kernels; `vert`, `frag`: graphics stages).
fn shaders(extensions: &[&str]) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("glsl"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| extensions.iter().any(|x| e == *x)))
        .collect();
    files.sort();
    files
}

fn kernels() -> Vec<PathBuf> {
    shaders(&["comp"])
}

/// Every shader that is compiled: the kernels and the graphics stages.
fn all_shaders() -> Vec<PathBuf> {
    shaders(&["comp", "vert", "frag"])
}

/// Whether a tool is installed. In CI (`CI` set) a missing tool is a failure, not a skip: the
/// checks it makes are part of what CI vouches for.
fn tool(name: &str) -> bool {
    let found = Command::new(name).arg("--version").output().is_ok();
    assert!(found || std::env::var_os("CI").is_none(), "{name} is not installed, and CI needs it");
    found
}

fn spirv_path(kernel: &Path) -> PathBuf {
    root().join("spirv").join(format!("{}.spv", kernel.file_name().unwrap().to_string_lossy()))
}

#[test]
fn every_kernel_is_registered_and_committed() {
    let names: Vec<String> = kernels().iter().map(|k| k.file_stem().unwrap().to_string_lossy().into_owned()).collect();
    let registered: Vec<&str> = lookdev::gpu::shaders::ALL.iter().map(|k| k.name).collect();
    for name in &names {
        assert!(registered.contains(&name.as_str()), "glsl/{name}.comp is not in gpu::shaders::ALL");
    }
    for name in &registered {
        assert!(names.iter().any(|n| n == name), "gpu::shaders::ALL lists {name}, but glsl/{name}.comp is missing");
    }
    let files: Vec<String> =
        shaders(&["vert", "frag"]).iter().map(|s| s.file_name().unwrap().to_string_lossy().into_owned()).collect();
    let mut stages: Vec<&str> = lookdev::gpu::shaders::STAGES.iter().map(|s| s.file).collect();
    stages.sort_unstable();
    assert_eq!(files, stages, "gpu::shaders::STAGES must list every glsl/*.vert and *.frag");
    for shader in all_shaders() {
        assert!(spirv_path(&shader).is_file(), "{} has no committed SPIR-V", shader.display());
    }
}

#[test]
fn committed_spirv_matches_the_glsl() {
    if !tool("glslangValidator") {
        eprintln!("note: glslangValidator is not installed (Debian: glslang-tools); SPIR-V freshness not checked");
        return;
    }
    let bless = std::env::var("LOOKDEV_BLESS_SPIRV").is_ok_and(|v| v == "1");
    let out_dir = std::env::temp_dir().join(format!("lookdev-spirv-{}", std::process::id()));
    std::fs::create_dir_all(&out_dir).unwrap();
    let mut stale = Vec::new();
    for kernel in all_shaders() {
        let out = out_dir.join(spirv_path(&kernel).file_name().unwrap());
        // The exact command the committed files come from.
        let status = Command::new("glslangValidator")
            .current_dir(root())
            .args(["--quiet", "--target-env", "vulkan1.3", "-Os", "-Iglsl", "-Iglsl/include", "-o"])
            .arg(&out)
            .arg(kernel.strip_prefix(root()).unwrap())
            .status()
            .unwrap();
        assert!(status.success(), "{} does not compile", kernel.display());
        let fresh = std::fs::read(&out).unwrap();
        if std::fs::read(spirv_path(&kernel)).ok().as_deref() != Some(&fresh[..]) {
            if bless {
                std::fs::write(spirv_path(&kernel), &fresh).unwrap();
            } else {
                stale.push(kernel.display().to_string());
            }
        }
    }
    let _ = std::fs::remove_dir_all(&out_dir);
    assert!(
        stale.is_empty(),
        "stale SPIR-V for {stale:?}; run LOOKDEV_BLESS_SPIRV=1 cargo test --release --test spirv and commit spirv/"
    );
}

#[test]
fn committed_spirv_validates() {
    if !tool("spirv-val") {
        eprintln!("note: spirv-val is not installed (Debian: spirv-tools); SPIR-V not validated");
        return;
    }
    for kernel in all_shaders() {
        let output =
            Command::new("spirv-val").args(["--target-env", "vulkan1.3"]).arg(spirv_path(&kernel)).output().unwrap();
        assert!(output.status.success(), "{}: {}", kernel.display(), String::from_utf8_lossy(&output.stderr));
    }
}
