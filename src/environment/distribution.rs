//! The environment's importance-sampling tables (LOOKDEV.md §5): a piecewise-constant density
//! over cells of texels, weighted by luminance·sinθ, as a marginal CDF over rows of cells and one
//! conditional CDF per row, each with a guide table. Built once per map; rotation only rotates
//! directions.
//!
//! Cells are single texels up to [`MAX_COLUMNS`] texels wide; wider maps use square blocks of
//! texels (the last block in a row or column may be smaller). Keeping every cell a whole number
//! of texels means each texel lies in exactly one cell, so the GPU stores each cell's pdf beside
//! the texel's radiance and one fetch gives both.

use super::Environment;
use crate::shading::common::luminance;
use glam::Vec3;

/// The cell grid is at most this many cells wide, which keeps the tables inside every device's
/// storage-buffer range (lavapipe's is 128 MiB). Sampling stays exact for the grid it describes.
pub const MAX_COLUMNS: u32 = 4096;

/// Sampling tables, laid out as `glsl/include/environment.glsl` reads them.
#[derive(Clone, Debug)]
pub struct Distribution {
    /// The map's size in texels.
    pub width: u32,
    pub height: u32,
    /// Texels per cell side.
    pub block: u32,
    pub columns: u32,
    pub rows: u32,
    /// rows + 1 entries, from 0 to 1.
    pub marginal_cdf: Vec<f32>,
    /// rows + 1 entries: `guide[k]` is the last row r with `cdf[r] ≤ k/rows`.
    pub marginal_guide: Vec<u32>,
    /// rows × (columns + 1) entries, each row from 0 to 1.
    pub conditional_cdf: Vec<f32>,
    /// rows × (columns + 1) entries, a guide per row as for the marginal.
    pub conditional_guide: Vec<u32>,
    /// pdf over (u, v) of each cell, row-major; it integrates to 1 over [0, 1]².
    pub cell_pdf: Vec<f32>,
}

impl Distribution {
    pub fn build(env: &Environment) -> Distribution {
        Distribution::with_max_columns(env, MAX_COLUMNS)
    }

    /// The tables with cells of square blocks of texels, so that there are at most
    /// `max_columns` cells across.
    pub fn with_max_columns(env: &Environment, max_columns: u32) -> Distribution {
        let block = env.width.div_ceil(max_columns).max(1);
        let columns = env.width.div_ceil(block);
        let rows = env.height.div_ceil(block);
        // Σ luminance·sinθ over each cell's texels: proportional to the cell's share of the
        // integral of luminance over solid angle.
        let mut weights = vec![0.0f64; (columns * rows) as usize];
        for y in 0..env.height {
            let sin_theta = (std::f64::consts::PI * (y as f64 + 0.5) / env.height as f64).sin();
            for x in 0..env.width {
                let cell = ((y / block) * columns + x / block) as usize;
                weights[cell] += luminance(Vec3::from(env.texel(x, y))).max(0.0) as f64 * sin_theta;
            }
        }
        Distribution::from_weights(env.width, env.height, block, &weights)
    }

    /// The texel range [start, end) of cell `index` along an axis of `size` texels.
    pub fn cell_span(&self, index: u32, size: u32) -> (u32, u32) {
        let start = index * self.block;
        (start, (start + self.block).min(size))
    }

    /// Tables for non-negative cell weights (row-major) over a `width`×`height` map with cells of
    /// `block` texels. All-zero weights (a black map) fall back to uniform, so sampling stays
    /// defined.
    pub fn from_weights(width: u32, height: u32, block: u32, weights: &[f64]) -> Distribution {
        let columns = width.div_ceil(block);
        let rows = height.div_ceil(block);
        let mut d = Distribution {
            width,
            height,
            block,
            columns,
            rows,
            marginal_cdf: Vec::new(),
            marginal_guide: Vec::new(),
            conditional_cdf: Vec::new(),
            conditional_guide: Vec::new(),
            cell_pdf: Vec::new(),
        };
        let total: f64 = weights.iter().sum();
        let uniform: Vec<f64>;
        let weights = if total > 0.0 {
            weights
        } else {
            // Uniform over solid angle would need sinθ; uniform over texels is enough to keep
            // a black map's sampling defined (it contributes nothing).
            uniform = (0..rows).flat_map(|r| (0..columns).map(move |c| d_area(width, height, block, r, c))).collect();
            &uniform[..]
        };
        let total: f64 = weights.iter().sum();
        let mut row_sums = Vec::with_capacity(rows as usize);
        for row in weights.chunks(columns as usize) {
            row_sums.push(row.iter().sum::<f64>());
            let cdf = cdf(row);
            d.conditional_guide.extend(guide(&cdf));
            d.conditional_cdf.extend(cdf);
        }
        d.marginal_cdf = cdf(&row_sums);
        d.marginal_guide = guide(&d.marginal_cdf);
        d.cell_pdf = (0..rows)
            .flat_map(|r| (0..columns).map(move |c| (r, c)))
            .map(|(r, c)| (weights[(r * columns + c) as usize] / total / d_area(width, height, block, r, c)) as f32)
            .collect();
        d
    }

    /// The per-table header the GPU reads before the marginal CDF.
    pub fn header(&self) -> [u32; 8] {
        [self.width, self.height, self.block, self.columns, self.rows, 0, 0, 0]
    }

    /// The cell pdf of every texel, row-major: what the GPU stores in the radiance texels' alpha.
    pub fn texel_pdf(&self) -> Vec<f32> {
        let mut out = Vec::with_capacity((self.width * self.height) as usize);
        for y in 0..self.height {
            for x in 0..self.width {
                out.push(self.cell_pdf[((y / self.block) * self.columns + x / self.block) as usize]);
            }
        }
        out
    }
}

/// The area in (u, v) of cell (row, column).
fn d_area(width: u32, height: u32, block: u32, row: u32, column: u32) -> f64 {
    let w = ((column + 1) * block).min(width) - column * block;
    let h = ((row + 1) * block).min(height) - row * block;
    (w as f64 / width as f64) * (h as f64 / height as f64)
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

/// `guide[k]` (k = 0..=n) is the last interval r < n with `cdf[r] ≤ k/n`: a search for u only
/// needs the intervals between the guides of the buckets around u, usually one or two.
fn guide(cdf: &[f32]) -> Vec<u32> {
    let n = cdf.len() - 1;
    let mut out = Vec::with_capacity(n + 1);
    let mut r = 0usize;
    for k in 0..=n {
        let threshold = k as f64 / n as f64;
        while r + 1 < n && cdf[r + 1] as f64 <= threshold {
            r += 1;
        }
        out.push(r as u32);
    }
    out
}
