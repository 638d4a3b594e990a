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
