//! Blurred masks (a layer's `mask_blur`, [`crate::material::mask`]): a separable Gaussian over
//! the g-buffer's pixels, edges clamped. The whole channel, for upload and the AOVs, and one
//! pixel of it, for the inspector, come from the same two sums in the same order, so they agree
//! bit for bit.

/// A normalised Gaussian kernel of σ, reaching 3σ each side.
struct Kernel {
    weights: Vec<f32>,
    radius: i64,
}

impl Kernel {
    fn new(sigma: f32) -> Kernel {
        let radius = (3.0 * sigma).ceil().max(1.0) as i64;
        let raw: Vec<f64> =
            (-radius..=radius).map(|k| (-(k * k) as f64 / (2.0 * sigma as f64 * sigma as f64)).exp()).collect();
        let sum: f64 = raw.iter().sum();
        Kernel { weights: raw.iter().map(|w| (w / sum) as f32).collect(), radius }
    }

    /// Σ w_k · value(i + k), with i + k clamped to [0, len).
    fn sum(&self, i: i64, len: i64, value: impl Fn(usize) -> f32) -> f32 {
        let mut total = 0.0f32;
        for (k, w) in (-self.radius..=self.radius).zip(&self.weights) {
            total += w * value((i + k).clamp(0, len - 1) as usize);
        }
        total
    }
}

/// `values` (`width × height`, row-major) blurred with σ = `sigma` pixels: rows first, then
/// columns. Split over the machine's cores by rows.
pub fn blur(values: &[f32], width: u32, height: u32, sigma: f32) -> Vec<f32> {
    let kernel = Kernel::new(sigma);
    let (w, h) = (width as usize, height as usize);
    let mut across = vec![0.0f32; w * h];
    by_rows(&mut across, w, |y, row| {
        for (x, out) in row.iter_mut().enumerate() {
            *out = kernel.sum(x as i64, w as i64, |i| values[y * w + i]);
        }
    });
    let mut out = vec![0.0f32; w * h];
    by_rows(&mut out, w, |y, row| {
        for (x, out) in row.iter_mut().enumerate() {
            *out = kernel.sum(y as i64, h as i64, |j| across[j * w + x]);
        }
    });
    out
}

/// Pixel `index` of [`blur`]'s result, computed alone.
pub fn blur_at(values: &[f32], width: u32, height: u32, sigma: f32, index: usize) -> f32 {
    let kernel = Kernel::new(sigma);
    let (w, h) = (width as usize, height as usize);
    let (x, y) = (index % w, index / w);
    kernel.sum(y as i64, h as i64, |j| kernel.sum(x as i64, w as i64, |i| values[j * w + i]))
}

/// Runs `fill(y, row)` for every row of `out`, on as many threads as there are cores.
fn by_rows(out: &mut [f32], width: usize, fill: impl Fn(usize, &mut [f32]) + Sync) {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let rows_per_thread = (out.len() / width.max(1)).div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        for (chunk_index, chunk) in out.chunks_mut(rows_per_thread * width).enumerate() {
            let fill = &fill;
            scope.spawn(move || {
                for (k, row) in chunk.chunks_mut(width).enumerate() {
                    fill(chunk_index * rows_per_thread + k, row);
                }
            });
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_blur_keeps_the_mean_of_a_flat_image_and_softens_an_edge() {
        let (w, h) = (32u32, 8u32);
        let flat = vec![0.25f32; (w * h) as usize];
        assert!(blur(&flat, w, h, 2.0).iter().all(|&v| (v - 0.25).abs() < 1e-6));
        // A vertical edge at x = 16: the blurred values ramp, 0.5 about the edge.
        let edge: Vec<f32> = (0..w * h).map(|i| if i % w >= 16 { 1.0 } else { 0.0 }).collect();
        let blurred = blur(&edge, w, h, 2.0);
        let row: Vec<f32> = blurred[(3 * w) as usize..(4 * w) as usize].to_vec();
        assert!(row[0] < 1e-4 && row[31] > 1.0 - 1e-4);
        assert!(row[14] > 0.1 && row[14] < 0.5 && row[17] > 0.5 && row[17] < 0.9, "{row:?}");
        assert!(row.windows(2).all(|p| p[1] >= p[0]), "monotone across the edge");
    }

    #[test]
    fn one_pixel_alone_is_the_same_bits_as_the_whole_image() {
        let (w, h) = (23u32, 17u32);
        let values: Vec<f32> = (0..w * h).map(|i| ((i * 7919) % 101) as f32 / 100.0).collect();
        let whole = blur(&values, w, h, 3.5);
        for index in [0, 5, 100, 390] {
            assert_eq!(blur_at(&values, w, h, 3.5, index).to_bits(), whole[index].to_bits());
        }
    }
}
