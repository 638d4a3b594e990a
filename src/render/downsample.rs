//! Filtering a render of a supersampled g-buffer down to its output size
//! (docs/formats.md#supersampled-g-buffers). A pixel that holds several surfaces at the output
//! size (an edge, a crease, a thin part) holds fewer at N times that size, each shaded with its
//! own normal; averaging each N × N block then filters the relit light, as a path tracer's pixel
//! filter does, instead of relighting one averaged normal.

use super::aov::{Aov, Layer};
use crate::shading::tonemap::{display_pixel, Tonemap};
use glam::Vec3;

/// Each `factor` × `factor` block of `values` (`width` wide, row-major, `output_size` checked)
/// reduced to one value by `reduce`, row-major.
fn blocks<T: Copy, U>(
    values: &[T],
    width: u32,
    factor: u32,
    reduce: impl Fn(&mut dyn Iterator<Item = T>) -> U,
) -> Vec<U> {
    let (w, f) = (width as usize, factor as usize);
    let height = values.len() / w.max(1);
    let (out_w, out_h) = (w / f, height / f);
    (0..out_w * out_h)
        .map(|o| {
            let (x, y) = (o % out_w * f, o / out_w * f);
            let mut block = (y..y + f).flat_map(|yy| (x..x + f).map(move |xx| yy * w + xx)).map(|i| values[i]);
            reduce(&mut block)
        })
        .collect()
}

/// The mean of each block, per channel: linear radiance and other linear quantities.
pub fn box_filter<const C: usize>(values: &[[f32; C]], width: u32, factor: u32) -> Vec<[f32; C]> {
    let n = (factor * factor) as f64;
    blocks(values, width, factor, |block| {
        let mut sum = [0.0f64; C];
        for v in block {
            sum.iter_mut().zip(v).for_each(|(s, x)| *s += x as f64);
        }
        sum.map(|s| (s / n) as f32)
    })
}

/// The most common value of each block, the lowest among ties: object ids, which do not average.
pub fn majority(values: &[f32], width: u32, factor: u32) -> Vec<f32> {
    blocks(values, width, factor, |block| {
        let mut seen: Vec<(f32, usize)> = Vec::new();
        for v in block {
            match seen.iter_mut().find(|(id, _)| *id == v) {
                Some((_, count)) => *count += 1,
                None => seen.push((v, 1)),
            }
        }
        seen.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.total_cmp(&b.0)));
        seen[0].0
    })
}

/// An AOV layer filtered down: object ids by [`majority`], the variance of each pixel's mean as
/// that of the block's mean (the mean variance over factor²), everything else by [`box_filter`].
pub fn layer(layer: Layer, width: u32, factor: u32) -> Layer {
    if factor == 1 {
        return layer;
    }
    let name = layer.name;
    let channels = layer
        .channels
        .into_iter()
        .map(|(channel, values)| {
            let filtered = if name == Aov::ObjectId.name() {
                majority(&values, width, factor)
            } else {
                let scale = if name == Aov::Variance.name() { 1.0 / (factor * factor) as f32 } else { 1.0 };
                let values: Vec<[f32; 1]> = values.iter().map(|&v| [v]).collect();
                box_filter(&values, width, factor).into_iter().map(|[v]| v * scale).collect()
            };
            (channel, filtered)
        })
        .collect();
    Layer { name, channels }
}

/// Display pixels (RGBA8 sRGB) of filtered radiance, as finalize.comp makes them: opaque with
/// the background; without it, the coverage-weighted colour (the premultiplied mean over alpha)
/// with alpha the mean coverage.
pub fn display(radiance: &[[f32; 4]], exposure: f32, tonemap: Tonemap, background: bool) -> Vec<u8> {
    radiance
        .iter()
        .flat_map(|&[r, g, b, a]| {
            let (colour, alpha) = match background {
                true => (Vec3::new(r, g, b), 1.0),
                false if a > 0.0 => (Vec3::new(r, g, b) / a, a),
                false => (Vec3::ZERO, 0.0),
            };
            let [r, g, b] = display_pixel(colour, exposure, tonemap);
            [r, g, b, (alpha.clamp(0.0, 1.0) * 255.0 + 0.5) as u8]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_are_averaged_and_ids_voted() {
        // 4 × 2, filtered by 2 into 2 × 1.
        let values: Vec<[f32; 1]> = [1.0, 3.0, 10.0, 10.0, 5.0, 7.0, 10.0, 30.0].map(|v| [v]).to_vec();
        assert_eq!(box_filter(&values, 4, 2), [[4.0], [15.0]]);
        let ids = [1.0, 2.0, 3.0, 3.0, 2.0, 1.0, 3.0, 4.0];
        assert_eq!(majority(&ids, 4, 2), [1.0, 3.0], "a tie goes to the lowest id");
        let variance = Layer { name: "variance".into(), channels: vec![("Y", vec![4.0; 8])] };
        assert_eq!(layer(variance, 4, 2).channels[0].1, [1.0, 1.0], "the variance of a mean of four");
    }

    #[test]
    fn display_pixels_un_premultiply_without_the_background() {
        let half = [[0.25, 0.25, 0.25, 0.5]];
        let shown = display(&half, 0.0, Tonemap::Linear, false);
        let [r, g, b] = display_pixel(Vec3::splat(0.5), 0.0, Tonemap::Linear);
        assert_eq!(shown, [r, g, b, 128]);
        assert_eq!(display(&half, 0.0, Tonemap::Linear, true)[3], 255);
    }
}
