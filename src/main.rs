fn main() {
    if let Err(error) = lookdev::cli::run(std::env::args_os()) {
        eprintln!("lookdev: error: {error}");
        std::process::exit(error.exit_code());
    }
}
