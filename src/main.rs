use std::sync::Mutex;

/// Where the last panic happened, kept by the hook for the one-line report.
static PANIC_PLACE: Mutex<Option<String>> = Mutex::new(None);

fn main() {
    // Before any thread starts and before the Vulkan loader opens (see driver_cache).
    lookdev::gpu::driver_cache::prepare();
    // A panic is reported as one line (see catching_panics), not a trace; RUST_BACKTRACE=1
    // brings the trace back.
    if std::env::var_os("RUST_BACKTRACE").is_none() {
        std::panic::set_hook(Box::new(|info| {
            if let (Some(location), Ok(mut place)) = (info.location(), PANIC_PLACE.lock()) {
                *place = Some(format!("{}:{}", location.file(), location.line()));
            }
        }));
    }
    let place = || PANIC_PLACE.lock().ok().and_then(|mut place| place.take());
    let result = lookdev::cli::catching_panics(|| lookdev::cli::run(std::env::args_os()), place);
    lookdev::timings::note(|| match lookdev::timings::host_peak_bytes() {
        Some(bytes) => format!("host memory: peak {:.1} MiB (VmHWM)", bytes as f64 / (1 << 20) as f64),
        None => "host memory: peak unknown".into(),
    });
    if let Err(error) = result {
        eprintln!("lookdev: error: {error}");
        std::process::exit(error.exit_code());
    }
}
