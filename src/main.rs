use std::sync::Mutex;

/// Where the last panic happened and what it said, kept by the hook for the one-line report.
static PANIC: Mutex<Option<String>> = Mutex::new(None);

fn main() {
    // Every input is validated before use, so a panic is a defect of lookdev. It is still
    // reported as one line rather than a trace; RUST_BACKTRACE=1 brings the trace back.
    if std::env::var_os("RUST_BACKTRACE").is_none() {
        std::panic::set_hook(Box::new(|info| {
            let message = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic".to_string());
            let place = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
            if let Ok(mut last) = PANIC.lock() {
                *last = Some(format!("{message}{place}"));
            }
        }));
    }
    let outcome = std::panic::catch_unwind(|| lookdev::cli::run(std::env::args_os()));
    match outcome {
        Ok(Ok(())) => {}
        Ok(Err(error)) => {
            eprintln!("lookdev: error: {error}");
            std::process::exit(error.exit_code());
        }
        Err(_) => {
            let what = PANIC.lock().ok().and_then(|mut last| last.take()).unwrap_or_else(|| "a panic".to_string());
            eprintln!(
                "lookdev: error: internal error ({}); this is a defect of lookdev, please report it",
                lookdev::printable(&what)
            );
            std::process::exit(1);
        }
    }
}
