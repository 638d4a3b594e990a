//! A virtual X server (Xvfb) for the tests that open windows.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};

/// A virtual X server for one test, stopped when dropped.
pub struct XServer {
    child: Child,
    pub display: String,
}

impl Drop for XServer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts Xvfb on a free display, or returns None (after saying why) where it is not installed.
pub fn xvfb() -> Option<XServer> {
    let spawned = Command::new("Xvfb")
        .args(["-displayfd", "1", "-screen", "0", "1280x800x24", "-nolisten", "tcp"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn();
    let mut child = match spawned {
        Ok(child) => child,
        Err(e) => {
            assert!(std::env::var_os("CI").is_none(), "Xvfb is needed for the viewer tests in CI ({e})");
            eprintln!("Xvfb is not installed (apt-get install xvfb): viewer test skipped");
            return None;
        }
    };
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
    let number = line.trim();
    assert!(!number.is_empty(), "Xvfb did not report its display");
    Some(XServer { child, display: format!(":{number}") })
}
