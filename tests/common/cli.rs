//! Running the `lookdev` binary as a pipeline does, with validation on, and checking its exit.

use std::process::{Command, Output};

/// Runs `lookdev` with the arguments and Vulkan validation on.
pub fn lookdev(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lookdev")).args(args).env("LOOKDEV_VALIDATION", "1").output().unwrap()
}

pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Exit code 0 and no validation error.
pub fn assert_success(output: &Output) {
    assert!(output.status.success(), "failed: {}", stderr(output));
    assert!(!stderr(output).contains("validation error"), "{}", stderr(output));
}

/// Exit code 2 and one line on stderr that contains every fragment (file name, problem).
pub fn assert_bad_input(output: &Output, fragments: &[&str]) {
    let text = stderr(output);
    assert_eq!(output.status.code(), Some(2), "expected exit code 2, got {:?}: {text}", output.status.code());
    assert!(!text.contains("panicked"), "{text}");
    let errors: Vec<&str> = text.lines().filter(|l| l.starts_with("lookdev: error:")).collect();
    assert_eq!(errors.len(), 1, "expected one error line: {text}");
    for fragment in fragments {
        assert!(errors[0].contains(fragment), "error line lacks '{fragment}': {}", errors[0]);
    }
}

/// A run of `lookdev` with what it cost.
pub struct Measured {
    pub output: Output,
    /// Peak resident memory in MiB (VmHWM), as last read while it ran.
    pub peak_mib: f64,
    pub seconds: f64,
}

/// Runs `lookdev` (validation on) from `dir`, killing it after `limit` seconds. With
/// `max_mib`, its data (heap, private mappings) is limited to that many MiB, so an allocation
/// beyond aborts it rather than passing unseen; the peak resident memory is read from
/// /proc while it runs. (The kernel's rusage cannot be used: a child's maxrss starts from the
/// test process's at the fork.)
#[cfg(target_os = "linux")]
pub fn lookdev_measured(dir: &std::path::Path, args: &[&str], limit: f64, max_mib: Option<u64>) -> Measured {
    use std::io::Read;
    use std::os::unix::process::CommandExt;
    use std::process::Stdio;
    let start = std::time::Instant::now();
    let mut command = Command::new(env!("CARGO_BIN_EXE_lookdev"));
    command
        .args(args)
        .current_dir(dir)
        .env("LOOKDEV_VALIDATION", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if let Some(mib) = max_mib {
        let bytes = mib << 20;
        unsafe {
            command.pre_exec(move || {
                let limit = libc::rlimit { rlim_cur: bytes, rlim_max: bytes };
                if libc::setrlimit(libc::RLIMIT_DATA, &limit) == 0 {
                    Ok(())
                } else {
                    Err(std::io::Error::last_os_error())
                }
            });
        }
    }
    let mut child = command.spawn().unwrap();
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            bytes
        })
    };
    let stdout = drain(Box::new(child.stdout.take().unwrap()));
    let stderr = drain(Box::new(child.stderr.take().unwrap()));
    let status_file = format!("/proc/{}/status", child.id());
    let mut peak_kib = 0u64;
    let status = loop {
        if let Ok(text) = std::fs::read_to_string(&status_file) {
            let hwm = text
                .lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches(" kB").parse().ok());
            peak_kib = peak_kib.max(hwm.unwrap_or(0));
        }
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed().as_secs_f64() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("lookdev {} did not finish in {limit} s", args.join(" "));
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    };
    let output = Output { status, stdout: stdout.join().unwrap(), stderr: stderr.join().unwrap() };
    Measured { output, peak_mib: peak_kib as f64 / 1024.0, seconds: start.elapsed().as_secs_f64() }
}

/// The linear radiance of an EXR lookdev wrote, as bits, row by row: for comparing images
/// whose files differ in their metadata.
pub fn exr_bits(path: &std::path::Path) -> Vec<[u32; 4]> {
    use exr::prelude::{read_first_rgba_layer_from_file, RgbaChannels};
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _: &RgbaChannels| (resolution.width(), vec![[0u32; 4]; resolution.width() * resolution.height()]),
        |(width, pixels), position, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[position.y() * *width + position.x()] = [r, g, b, a].map(f32::to_bits);
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels.1
}
