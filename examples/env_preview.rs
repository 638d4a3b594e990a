fn main() {
    let env = lookdev::environment::Environment::studio();
    let mut img = image::RgbImage::new(env.width, env.height);
    for y in 0..env.height {
        for x in 0..env.width {
            let t = env.texel(x, y);
            let p = lookdev::render::tonemap::display_pixel(
                glam::Vec3::from(t),
                0.0,
                lookdev::render::tonemap::Tonemap::Neutral,
            );
            img.put_pixel(x, y, image::Rgb(p));
        }
    }
    img.save("/tmp/studio_preview.png").unwrap();
    let max = env.texels.iter().map(|t| t[1]).fold(0.0f32, f32::max);
    let mean: f32 = env.texels.iter().map(|t| t[1]).sum::<f32>() / env.texels.len() as f32;
    println!("max {max} mean {mean}");
}
