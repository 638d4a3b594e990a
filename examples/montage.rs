fn main() {
    let paths: Vec<String> = std::env::args().skip(2).collect();
    let out = std::env::args().nth(1).unwrap();
    let images: Vec<image::RgbImage> = paths.iter().map(|p| image::open(p).unwrap().to_rgb8()).collect();
    let (w, h) = images[0].dimensions();
    let mut sheet = image::RgbImage::new(w * images.len() as u32, h);
    for (i, img) in images.iter().enumerate() {
        image::imageops::overlay(&mut sheet, img, (i as u32 * w) as i64, 0);
    }
    sheet.save(out).unwrap();
}
