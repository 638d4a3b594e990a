//! The environment's importance-sampling tables (LOOKDEV.md §5): a piecewise-constant density
//! over a grid of cells in (u, v), weighted by luminance·sinθ, as a marginal CDF over rows and
//! one conditional CDF per row. Built once per map; rotation only rotates directions.

use super::Environment;
use crate::shading::common::luminance;
use glam::Vec3;

/// The grid is at most this many cells wide. Wider maps are averaged in square blocks, which
/// keeps the tables inside every device's storage-buffer range (lavapipe's is 128 MiB) while the
/// radiance itself stays at full resolution; the density stays exact for the grid it describes,
/// so sampling is still unbiased.
pub const MAX_COLUMNS: u32 = 4096;

/// Sampling tables, laid out as `glsl/include/environment.glsl` reads them.
#[derive(Clone, Debug)]
pub struct Distribution {
    pub columns: u32,
    pub rows: u32,
    /// rows + 1 entries, from 0 to 1.
    pub marginal_cdf: Vec<f32>,
    /// rows × (columns + 1) entries, each row from 0 to 1.
    pub conditional_cdf: Vec<f32>,
    /// pdf over (u, v) of each cell, row-major; it integrates to 1 over [0, 1]².
    pub cell_pdf: Vec<f32>,
}

impl Distribution {
    pub fn build(env: &Environment) -> Distribution {
        let block = env.width.div_ceil(MAX_COLUMNS).max(1);
        let columns = env.width.div_ceil(block);
        let rows = env.height.div_ceil(block);
        let weights = cell_weights(env, block, columns, rows);
        Distribution::from_weights(columns, rows, &weights)
    }

    /// Tables for arbitrary non-negative cell weights (row-major). All-zero weights (a black
    /// environment) fall back to uniform, so sampling stays defined.
    pub fn from_weights(columns: u32, rows: u32, weights: &[f64]) -> Distribution {
        let (cols, rows_usize) = (columns as usize, rows as usize);
        let total: f64 = weights.iter().sum();
        let uniform = vec![1.0; weights.len()];
        let weights = if total > 0.0 { weights } else { &uniform[..] };
        let total: f64 = weights.iter().sum();

        let mut conditional_cdf = Vec::with_capacity(rows_usize * (cols + 1));
        let mut row_sums = Vec::with_capacity(rows_usize);
        for row in weights.chunks(cols) {
            let row_sum: f64 = row.iter().sum();
            row_sums.push(row_sum);
            conditional_cdf.extend(cdf(row));
        }
        let marginal_cdf = cdf(&row_sums);
        let scale = (cols * rows_usize) as f64 / total;
        let cell_pdf = weights.iter().map(|w| (w * scale) as f32).collect();
        Distribution { columns, rows, marginal_cdf, conditional_cdf, cell_pdf }
    }

    /// The marginal table as the GPU reads it: a 16-byte header (columns, rows) then the CDF.
    pub fn marginal_gpu_bytes(&self) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(16 + 4 * self.marginal_cdf.len());
        for word in [self.columns, self.rows, 0, 0] {
            bytes.extend_from_slice(&word.to_le_bytes());
        }
        bytes.extend_from_slice(bytemuck::cast_slice(&self.marginal_cdf));
        bytes
    }
}

/// CDF of `weights` with one more entry than weights; exactly 0 first and 1 last. A row of zeros
/// gets a uniform CDF (it is never chosen, but its search must still be well defined).
fn cdf(weights: &[f64]) -> Vec<f32> {
    let total: f64 = weights.iter().sum();
    let n = weights.len();
    let mut out = Vec::with_capacity(n + 1);
    out.push(0.0);
    let mut running = 0.0f64;
    for (i, w) in weights.iter().enumerate() {
        running += w;
        let value = if total > 0.0 { running / total } else { (i + 1) as f64 / n as f64 };
        out.push(value as f32);
    }
    out[n] = 1.0;
    out
}

/// Mean luminance over each block of texels, times sinθ at the cell's centre row.
fn cell_weights(env: &Environment, block: u32, columns: u32, rows: u32) -> Vec<f64> {
    let mut weights = vec![0.0f64; (columns * rows) as usize];
    let mut counts = vec![0u32; weights.len()];
    for y in 0..env.height {
        for x in 0..env.width {
            let cell = ((y / block) * columns + x / block) as usize;
            weights[cell] += luminance(Vec3::from(env.texel(x, y))).max(0.0) as f64;
            counts[cell] += 1;
        }
    }
    for row in 0..rows {
        let sin_theta = (std::f64::consts::PI * (row as f64 + 0.5) / rows as f64).sin();
        for column in 0..columns {
            let cell = (row * columns + column) as usize;
            weights[cell] = weights[cell] / counts[cell].max(1) as f64 * sin_theta;
        }
    }
    weights
}
