//! Golden-image comparison. A render must match the committed PNG within 5/255 per channel at
//! all but 0.1% of its pixels, as Filament's CI holds its renders on Mesa; the tolerance absorbs a
//! driver's different float rounding, not a change in what is rendered.
//!
//! After an intended change to the rendered images, regenerate them with
//! `LOOKDEV_BLESS=1 cargo test --release`, look at the new PNGs in `tests/golden/`, and commit.

use std::path::PathBuf;

const TOLERANCE: i32 = 5;
const MAX_FAILING: f64 = 0.001;

pub fn golden(name: &str, width: u32, height: u32, rgba: &[u8]) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden").join(name);
    if std::env::var("LOOKDEV_BLESS").is_ok_and(|v| v == "1") {
        image::RgbaImage::from_raw(width, height, rgba.to_vec()).unwrap().save(&path).unwrap();
        eprintln!("wrote {}", path.display());
        return;
    }
    let expected = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8();
    assert_eq!(expected.dimensions(), (width, height), "{name}: size");
    let failing = expected
        .as_raw()
        .chunks(4)
        .zip(rgba.chunks(4))
        .filter(|(e, g)| e.iter().zip(g.iter()).any(|(a, b)| (*a as i32 - *b as i32).abs() > TOLERANCE))
        .count();
    let fraction = failing as f64 / (width * height) as f64;
    assert!(
        fraction <= MAX_FAILING,
        "{name}: {failing} pixels ({:.3}%) differ by more than {TOLERANCE}/255",
        fraction * 100.0
    );
}
