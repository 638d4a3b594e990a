//! cargo fuzz target: the bytes read as lookdev reads this kind of input (see lookdev::input::readers).
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let _ = lookdev::input::readers::Reader::Preset.read(bytes, std::path::Path::new("/dev/null/case"));
});
