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
    if let Err(error) = lookdev::cli::catching_panics(|| lookdev::cli::run(std::env::args_os()), place) {
        eprintln!("lookdev: error: {error}");
        std::process::exit(error.exit_code());
    }
}
