//! benches/compare_mitsuba.py, as far as it runs without Mitsuba: its unit tests (relative MSE,
//! the EXR reader, the looks it writes), and its lookdev half end to end. Skipped where there
//! is no python3.

use lookdev::gbuffer::GBuffer;
use std::path::Path;
use std::process::Command;

fn python3() -> Option<Command> {
    let found = Command::new("python3").arg("--version").output().is_ok_and(|o| o.status.success());
    if !found {
        eprintln!("skipped: no python3");
    }
    found.then(|| {
        let mut command = Command::new("python3");
        command.current_dir(env!("CARGO_MANIFEST_DIR")).env("PYTHONDONTWRITEBYTECODE", "1");
        command
    })
}

#[test]
fn the_scripts_unit_tests_pass() {
    let Some(mut python) = python3() else { return };
    let out = python.args(["-m", "unittest", "discover", "-s", "benches", "-p", "test_*.py"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("OK"), "{stderr}");
}

#[test]
fn the_lookdev_half_measures_every_material() {
    let Some(mut python) = python3() else { return };
    let size = 64;
    let out = python
        .args(["benches/compare_mitsuba.py", "--lookdev-only", "--spp", "4", "--reference-spp", "16", "--repeats", "1"])
        .args(["--size", &size.to_string(), "--lookdev", env!("CARGO_BIN_EXE_lookdev")])
        .env("LOOKDEV_VALIDATION", "1")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    // The wholly covered pixels it read from the g-buffer are the sphere's.
    let sphere = GBuffer::sphere(size, size);
    let whole = sphere.coverage.iter().filter(|&&c| c == 1.0).count();
    assert!(stdout.contains(&format!("{whole} wholly covered pixels")), "{stdout}");
    for material in ["metallic", "rough-dielectric", "clearcoat"] {
        let row = stdout
            .lines()
            .find(|l| l.starts_with(&format!("{material} ")) && l.contains("lookdev (process)"))
            .unwrap_or_else(|| panic!("no row for {material}: {stdout}"));
        let numbers: Vec<f64> = row.split_whitespace().filter_map(|w| w.parse().ok()).collect();
        let [seconds, rel_mse, efficiency] = numbers[..] else { panic!("{row}") };
        assert!(seconds > 0.0 && seconds < 30.0, "{row}");
        // 4 spp against 16: noisy, but far from 0 and from an unrelated image.
        assert!((1e-3..1.0).contains(&rel_mse), "{row}");
        assert!((efficiency - 1.0 / (seconds * rel_mse)).abs() < 0.02 * efficiency, "{row}");
    }
    assert!(Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/README.md").is_file());
}
