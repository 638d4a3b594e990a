//! The environment's importance-sampling tables (docs/shading.md#sampling).
//!
//! Lighting treats the map as piecewise constant over its texels, and sampling draws directions
//! from a density that is piecewise constant *in solid angle* over cells of texels, with each
//! cell's probability the integral of luminance over it: Σ luminance·Ω over its texels, where a
//! texel of row y spans Ω = (2π/W)·(cos θ(y) − cos θ(y+1)). That is a luminance·sinθ weighting
//! integrated exactly over each texel, and it makes pdf_ω constant over each cell: the GPU stores it
//! beside each texel's radiance, so one fetch gives both and no sinθ is ever divided by.
//!
//! Cells are single texels up to [`MAX_CELLS`] texels a side; larger maps use blocks of texels
//! (the last block in a row or column may be smaller). Rows of cells are chosen by a marginal
//! CDF, cells within a row by a conditional CDF; both are inverted by a search bounded by a guide
//! table, which keeps the warp monotonic (so stratified points stay stratified) at the cost of
//! about two table fetches.

use super::Environment;
use crate::shading::common::luminance;
use glam::Vec3;
use std::f64::consts::PI;

/// The fraction of the mean luminance that compensated tables subtract (Karlík et al. 2019
/// subtract all of it). Measured with `lookdev bench --convergence` on the five built-in maps,
/// half the mean keeps the full subtraction's gain where it helps (studio, interior, courtyard)
/// and loses nothing against plain tables on maps dominated by a small sun (sunrise, city),
/// where the full subtraction lost up to 25% at 64 spp.
pub const COMPENSATION: f64 = 0.5;

/// At most this many cells a side. The tables then need images up to `MAX_CELLS + 1` texels a
/// side; on a device whose image limit is lower, [`Distribution::for_device`] uses fewer cells.
pub const MAX_CELLS: u32 = 4096;

/// Sampling tables, laid out as `glsl/include/environment.glsl` reads them.
#[derive(Clone, Debug)]
pub struct Distribution {
    /// The map's size in texels.
    pub width: u32,
    pub height: u32,
    /// Texels per cell, across and down.
    pub block_x: u32,
    pub block_y: u32,
    pub columns: u32,
    pub rows: u32,
    /// The marginal table over rows of cells (`rows` entries), then one conditional table over
    /// the cells of each row (`columns` entries each).
    pub marginal: Table,
    pub conditional: Vec<Table>,
    /// pdf over solid angle of each cell, row-major.
    pub cell_pdf: Vec<f32>,
}

/// The inverse-CDF table of one discrete distribution over n intervals.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// n + 1 entries, exactly 0 first and 1 last.
    pub cdf: Vec<f32>,
    /// n + 1 entries: `guide[k]` is the last interval r < n with `cdf[r] ≤ u` for the smallest
    /// f32 u that [`bucket`] puts in bucket k, so the answer for any u in bucket k lies in
    /// `guide[k] ..= guide[k + 1]`.
    pub guide: Vec<u32>,
}

/// The bucket of u among n, computed as the GPU does: ⌊u·n⌋ in f32 arithmetic.
pub fn bucket(u: f32, n: u32) -> u32 {
    ((u * n as f32) as u32).min(n - 1)
}

impl Table {
    pub(crate) fn new(weights: &[f64]) -> Table {
        Table::with_cdf(cdf(weights))
    }

    /// The table of a CDF: n + 1 entries, exactly 0 first and 1 last, never decreasing. None
    /// for anything else (a damaged cache file's): a search in it could go anywhere.
    pub(crate) fn from_cdf(cdf: Vec<f32>) -> Option<Table> {
        let valid = cdf.len() >= 2
            && cdf[0] == 0.0
            && cdf[cdf.len() - 1] == 1.0
            && cdf.windows(2).all(|pair| pair[0] <= pair[1]);
        valid.then(|| Table::with_cdf(cdf))
    }

    fn with_cdf(cdf: Vec<f32>) -> Table {
        let n = (cdf.len() - 1) as u32;
        let guide = (0..=n)
            .map(|k| {
                let u = if k == n { 1.0 } else { smallest_in_bucket(k, n) };
                // Last r < n with cdf[r] <= u (cdf[0] = 0 always qualifies).
                (cdf[..n as usize].partition_point(|&c| c <= u) - 1) as u32
            })
            .collect();
        Table { cdf, guide }
    }

    pub fn len(&self) -> usize {
        self.cdf.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The last interval r with `cdf[r] ≤ u`, as `env_search` finds it.
    pub fn search(&self, u: f32) -> usize {
        let k = bucket(u, self.len() as u32) as usize;
        let (mut lo, mut hi) = (self.guide[k] as usize, self.guide[k + 1] as usize + 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if self.cdf[mid] <= u {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// Writes the GPU's bucket entries of this table at the start of `out`: entry k is
    /// (cdf[g], cdf[g + 1], g, guide[k + 1]) for g = guide[k]. When a bucket holds one interval
    /// (g = guide[k + 1]), as it usually does, that one fetch is the whole search.
    pub fn write_buckets(&self, out: &mut [[f32; 4]]) {
        for (k, texel) in out[..self.len()].iter_mut().enumerate() {
            let g = self.guide[k] as usize;
            *texel = [self.cdf[g], self.cdf[g + 1], g as f32, self.guide[k + 1] as f32];
        }
    }
}

/// The smallest f32 u in [0, 1) with `bucket(u, n) == k`.
pub(crate) fn smallest_in_bucket(k: u32, n: u32) -> f32 {
    let mut u = k as f32 / n as f32;
    while u > 0.0 && bucket(u.next_down(), n) >= k {
        u = u.next_down();
    }
    while bucket(u, n) < k {
        u = u.next_up();
    }
    u
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

/// cos θ at the top edge of texel row `y` of a map `height` texels high.
pub fn row_cos(y: u32, height: u32) -> f64 {
    (PI * y as f64 / height as f64).cos()
}

impl Distribution {
    pub fn build(env: &Environment) -> Distribution {
        Distribution::with_max_cells(env, MAX_CELLS)
    }

    /// The tables for a device whose images are at most `max_image_side` texels a side.
    pub fn for_device(env: &Environment, max_image_side: u32) -> Distribution {
        Distribution::with_max_cells(env, MAX_CELLS.min(max_image_side.saturating_sub(1)).max(1))
    }

    /// The tables with at most `max_cells` cells a side.
    pub fn with_max_cells(env: &Environment, max_cells: u32) -> Distribution {
        Distribution::weighted(env, max_cells, false)
    }

    /// The MIS-compensated tables (Karlík et al. 2019) for a device whose images are at most
    /// `max_image_side` texels a side: see [`Distribution::compensated_with_max_cells`].
    pub fn compensated_for_device(env: &Environment, max_image_side: u32) -> Distribution {
        Distribution::weighted(env, MAX_CELLS.min(max_image_side.saturating_sub(1)).max(1), true)
    }

    /// MIS-compensated tables: each texel weighs max(L − c·L̄, 0)·Ω instead of L·Ω, with L̄ the
    /// mean luminance over the sphere (Σ L·Ω / 4π) and c = [`COMPENSATION`]. Under MIS with a
    /// BRDF sample, whose pdf is positive wherever the BRDF is, the texels this leaves at pdf 0
    /// are still covered, so the estimate stays unbiased; the environment samples go where the
    /// map stands out, which the BRDF samples estimate poorly. A map that is constant up to
    /// rounding gets the plain tables.
    pub fn compensated_with_max_cells(env: &Environment, max_cells: u32) -> Distribution {
        Distribution::weighted(env, max_cells, true)
    }

    fn weighted(env: &Environment, max_cells: u32, compensated: bool) -> Distribution {
        let (block_x, block_y) = (env.width.div_ceil(max_cells), env.height.div_ceil(max_cells));
        let (columns, rows) = (env.width.div_ceil(block_x), env.height.div_ceil(block_y));
        let omegas: Vec<f64> = (0..env.height)
            .map(|y| 2.0 * PI / env.width as f64 * (row_cos(y, env.height) - row_cos(y + 1, env.height)))
            .collect();
        let texel_weight = |x: u32, y: u32| luminance(Vec3::from(env.texel(x, y))).max(0.0) as f64;
        let cell_weights = |offset: f64| {
            let mut weights = vec![0.0f64; (columns * rows) as usize];
            for y in 0..env.height {
                for x in 0..env.width {
                    let cell = ((y / block_y) * columns + x / block_x) as usize;
                    weights[cell] += (texel_weight(x, y) - offset).max(0.0) * omegas[y as usize];
                }
            }
            weights
        };
        let mut weights = cell_weights(0.0);
        if compensated {
            let mean = weights.iter().sum::<f64>() / (4.0 * PI);
            let above = cell_weights(COMPENSATION * mean);
            // A map constant up to rounding (where only rounding stands above the offset, at
            // full compensation) keeps its plain tables.
            if above.iter().sum::<f64>() > 1e-4 * mean * 4.0 * PI {
                weights = above;
            }
        }
        Distribution::from_weights(env.width, env.height, block_x, block_y, &weights)
    }

    /// The texel span [start, end) of cell `index` along an axis of `size` texels, `block` a cell.
    pub fn span(index: u32, block: u32, size: u32) -> (u32, u32) {
        (index * block, ((index + 1) * block).min(size))
    }

    /// The solid angle of cell (row, column).
    pub fn cell_solid_angle(&self, row: u32, column: u32) -> f64 {
        let (x0, x1) = Distribution::span(column, self.block_x, self.width);
        let (y0, y1) = Distribution::span(row, self.block_y, self.height);
        2.0 * PI * (x1 - x0) as f64 / self.width as f64 * (row_cos(y0, self.height) - row_cos(y1, self.height))
    }

    /// Tables for non-negative cell weights (row-major). All-zero weights (a black map) fall
    /// back to uniform over solid angle, so sampling stays defined.
    pub fn from_weights(width: u32, height: u32, block_x: u32, block_y: u32, weights: &[f64]) -> Distribution {
        let (columns, rows) = (width.div_ceil(block_x), height.div_ceil(block_y));
        let mut d = Distribution {
            width,
            height,
            block_x,
            block_y,
            columns,
            rows,
            marginal: Table { cdf: Vec::new(), guide: Vec::new() },
            conditional: Vec::new(),
            cell_pdf: Vec::new(),
        };
        let solid_angles: Vec<f64> =
            (0..rows).flat_map(|r| (0..columns).map(move |c| (r, c))).map(|(r, c)| d.cell_solid_angle(r, c)).collect();
        let weights = if weights.iter().sum::<f64>() > 0.0 { weights } else { &solid_angles[..] };
        let row_sums: Vec<f64> = weights.chunks(columns as usize).map(|row| row.iter().sum()).collect();
        d.conditional = weights.chunks(columns as usize).map(Table::new).collect();
        d.marginal = Table::new(&row_sums);
        // The pdf of exactly what the f32 tables sample: the product of the two CDF steps, not
        // the weights they were rounded from. A cell whose steps round to nothing is never
        // sampled and gets pdf 0, so MIS leaves it to the BRDF sample.
        d.cell_pdf = (0..rows as usize)
            .flat_map(|r| (0..columns as usize).map(move |c| (r, c)))
            .map(|(r, c)| {
                let row = d.marginal.cdf[r + 1] as f64 - d.marginal.cdf[r] as f64;
                let table = &d.conditional[r];
                let cell = table.cdf[c + 1] as f64 - table.cdf[c] as f64;
                (row * cell / solid_angles[r * columns as usize + c]) as f32
            })
            .collect();
        d
    }

    /// The header the GPU reads: sizes in texels, block sizes and the cell grid.
    pub fn header(&self) -> [u32; 8] {
        [self.width, self.height, self.block_x, self.block_y, self.columns, self.rows, 0, 0]
    }

    /// Writes the texels as the GPU stores them, row-major, for the rows from `first_row` on, as
    /// many as `out` holds: each one's radiance from `env`, and its cell's pdf_ω in a, so that
    /// one fetch gives both.
    pub fn write_texel_rows(&self, env: &Environment, first_row: u32, out: &mut [[f32; 4]]) {
        let width = self.width as usize;
        let texels = &env.texels[first_row as usize * width..];
        for (y, (texels, row)) in (first_row..).zip(texels.chunks(width).zip(out.chunks_mut(width))) {
            let pdfs = &self.cell_pdf[(y / self.block_y * self.columns) as usize..];
            for (x, (t, texel)) in texels.iter().zip(row).enumerate() {
                *texel = [t[0], t[1], t[2], pdfs[x / self.block_x as usize]];
            }
        }
    }

    /// The size of the table images: `max(rows, columns) + 1` by `rows + 1` texels. Row 0 holds
    /// the marginal table, row 1 + r the conditional table of row r.
    pub fn table_size(&self) -> (u32, u32) {
        (self.rows.max(self.columns) + 1, self.rows + 1)
    }

    /// The marginal and conditional tables, in [`Distribution::table_size`] order.
    fn tables(&self) -> impl Iterator<Item = &Table> {
        std::iter::once(&self.marginal).chain(&self.conditional)
    }

    /// Writes the bucket entries of the tables (an RGBA32F image of [`Distribution::table_size`]).
    pub fn write_buckets(&self, out: &mut [[f32; 4]]) {
        let (width, _) = self.table_size();
        for (row, table) in out.chunks_mut(width as usize).zip(self.tables()) {
            row.fill([0.0; 4]);
            table.write_buckets(row);
        }
    }

    /// Writes the plain CDFs of the tables (an R32F image of [`Distribution::table_size`]).
    pub fn write_cdfs(&self, out: &mut [f32]) {
        let (width, _) = self.table_size();
        for (row, table) in out.chunks_mut(width as usize).zip(self.tables()) {
            row.fill(0.0);
            row[..table.cdf.len()].copy_from_slice(&table.cdf);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plain_search(cdf: &[f32], u: f32) -> usize {
        cdf[..cdf.len() - 1].partition_point(|&c| c <= u) - 1
    }

    #[test]
    fn guided_search_agrees_with_a_plain_search() {
        // Plateaus (zero weights), tiny weights crowded into one bucket, and a dominant interval.
        let mut weights = vec![0.0; 50];
        weights.extend((0..300).map(|i| 1e-6 * (i % 7) as f64));
        weights.push(1000.0);
        weights.extend((0..40).map(|i| (i % 3) as f64));
        let table = Table::new(&weights);
        let n = table.len() as u32;
        let mut probes: Vec<f32> = (0..20000).map(|i| i as f32 / 20000.0).collect();
        for k in 0..n {
            let u = smallest_in_bucket(k, n);
            probes.extend([u, u.next_down().max(0.0), u.next_up()]);
        }
        probes.extend(table.cdf.iter().flat_map(|&c| [c, c.next_down().max(0.0), c.next_up()]).filter(|&u| u < 1.0));
        for u in probes {
            assert_eq!(table.search(u), plain_search(&table.cdf, u), "u = {u:e}");
        }
    }

    /// The stored pdf is the density the f32 tables actually sample, cell by cell, even for a
    /// map whose dim cells round to nothing beside a sun.
    #[test]
    fn stored_pdfs_are_the_sampled_probabilities() {
        let (w, h) = (512u32, 256u32);
        let texels = (0..w * h)
            .map(|i| if i % w > 200 && i % w < 203 && i / w == 60 { [1e6; 3] } else { [1e-4 * (i % 97) as f32; 3] })
            .collect();
        let d = Distribution::build(&Environment::new(w, h, texels, "sun"));
        let mut never = 0;
        for r in 0..d.rows as usize {
            let row = d.marginal.cdf[r + 1] as f64 - d.marginal.cdf[r] as f64;
            for c in 0..d.columns as usize {
                let cell = d.conditional[r].cdf[c + 1] as f64 - d.conditional[r].cdf[c] as f64;
                let sampled = row * cell;
                let stored = d.cell_pdf[r * d.columns as usize + c] as f64 * d.cell_solid_angle(r as u32, c as u32);
                assert!((sampled - stored).abs() <= 1e-6 * sampled.max(1e-30), "cell {r},{c}: {sampled} vs {stored}");
                never += (sampled == 0.0) as usize;
            }
        }
        assert!(never > 0, "the test map should have cells too dim to sample");
    }

    #[test]
    fn a_small_device_limit_shrinks_the_grid_to_fit() {
        let env = Environment::new(64, 32, vec![[1.0; 3]; 64 * 32], "x");
        let d = Distribution::for_device(&env, 33);
        let (width, height) = d.table_size();
        assert!(width <= 33 && height <= 33, "{width}x{height}");
    }

    #[test]
    fn cells_cover_the_sphere_and_probabilities_sum_to_one() {
        let env = Environment::new(301, 150, (0..301 * 150).map(|i| [(i % 17) as f32, 1.0, 0.5]).collect(), "test");
        for max_cells in [4096, 64] {
            let d = Distribution::with_max_cells(&env, max_cells);
            let mut sphere = 0.0;
            let mut probability = 0.0;
            for r in 0..d.rows {
                for c in 0..d.columns {
                    let omega = d.cell_solid_angle(r, c);
                    sphere += omega;
                    probability += d.cell_pdf[(r * d.columns + c) as usize] as f64 * omega;
                }
            }
            assert!((sphere - 4.0 * PI).abs() < 1e-9, "{sphere}");
            assert!((probability - 1.0).abs() < 1e-5, "{probability}");
        }
    }

    /// Compensation samples only what stands above the offset, in proportion to the excess, and
    /// leaves a map that is constant up to rounding with its plain tables.
    #[test]
    fn compensated_tables_weigh_the_excess_over_the_mean() {
        // Two texel rows of equal solid angle: 1 and 3 on top, 0 and 4 below; the mean is 2.
        let env = Environment::new(2, 2, vec![[1.0; 3], [3.0; 3], [0.0; 3], [4.0; 3]], "x");
        let d = Distribution::compensated_with_max_cells(&env, 4096);
        let omega = d.cell_solid_angle(0, 0);
        let p: Vec<f64> = d.cell_pdf.iter().map(|&pdf| pdf as f64 * omega).collect();
        let offset = COMPENSATION * 2.0;
        let excess = [1.0f64, 3.0, 0.0, 4.0].map(|l| (l - offset).max(0.0));
        let expected = excess.map(|e| e / excess.iter().sum::<f64>());
        assert_eq!(expected[2], 0.0);
        for (got, want) in p.iter().zip(expected) {
            assert!((got - want).abs() < 1e-6, "{p:?}");
        }
        let uniform = Environment::uniform([0.5; 3], 8, 4);
        let plain = Distribution::build(&uniform);
        assert_eq!(Distribution::compensated_with_max_cells(&uniform, 4096).cell_pdf, plain.cell_pdf);
    }
}
