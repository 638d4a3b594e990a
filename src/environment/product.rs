//! Product sampling (docs/shading.md#sampling): environment tables per cluster of shading
//! normals, each proportional to the environment's weight times a bound on the clamped cosine,
//! so that a pixel's environment samples go to its upper hemisphere, and more to its zenith.
//!
//! - **Clusters.** The normals are split by a cube map: the face of the largest axis, then
//!   [`GRID`] × [`GRID`] cells of that face. The lookup is O(1) ([`cluster_of`]), the same on the
//!   GPU (`env_cluster` in `glsl/include/environment.glsl`).
//! - **Coarse cells.** The global tables' cells ([`Distribution`]) are grouped into at most
//!   [`COARSE_COLUMNS`] × [`COARSE_ROWS`] coarse cells. Each coarse cell c has the probability G(c)
//!   the global tables give it.
//! - **A cluster's table** over coarse cells is ∝ G(c)·B(c), B(c) the largest clamped cosine between
//!   any normal of the cluster and any direction of the cell: cos(max(0, θmin − r)), θmin the least
//!   angle between the cluster's centre and the cell, r the cluster's angular radius. B is
//!   conservative, so every cell some normal of the cluster sees has B > 0.
//! - **Within a coarse cell** the sample follows the global tables restricted to it: a row of
//!   cells by the coarse cell's own table over its rows, then a cell of that row by the global
//!   conditional table searched within the coarse cell's span. So the density of the cluster's
//!   sampler is the global one times ratio(c) = P(c)/G(c), P(c) the cluster table's probability:
//!   one more fetch turns the stored pdf into the product pdf, for any direction.
//! - **Span guides.** The cell within the span is found as a global table's is, by a guide
//!   table: the rescaled u's bucket among the span's cells names the few cells its target can
//!   fall in ([`span_guides`]), so one fetch replaces a binary search of dependent fetches.

use super::distribution::{bucket, smallest_in_bucket, Distribution, Table, MAX_CELLS};
use super::sampling::texel_of;
use crate::shading::common::ONE_MINUS_EPSILON;
use glam::{UVec2, Vec2, Vec3};
use std::f64::consts::PI;

/// Clusters per side of each cube face: 6·GRID² clusters.
pub const GRID: u32 = 8;
/// Coarse cells across and down, at most (fewer when the global grid has fewer cells).
pub const COARSE_COLUMNS: u32 = 32;
pub const COARSE_ROWS: u32 = 16;
/// Added to each cluster's radius, in radians, so that a normal the GPU puts in a cluster by
/// float arithmetic on a cell boundary is still within the radius.
const RADIUS_MARGIN: f64 = 1e-3;

/// The product tables of one environment's global tables.
#[derive(Clone, Debug)]
pub struct Product {
    pub grid: u32,
    pub coarse_columns: u32,
    pub coarse_rows: u32,
    /// The global grid's size in cells (columns, rows), which the coarse cells group.
    pub columns: u32,
    pub rows: u32,
    /// One table per cluster over the coarse cells, row-major.
    pub clusters: Vec<Table>,
    /// One table per coarse cell (row-major) over its rows of global cells.
    pub cells: Vec<Table>,
    /// P(c)/G(c) per cluster and coarse cell: the product pdf over the global one.
    pub ratio: Vec<f32>,
    /// Lookups that spare each sample the integer divisions of [`coarse_of`] and
    /// [`coarse_start`] (which lavapipe runs lane by lane), as `env_product_index` holds them:
    /// each texel column's coarse column; each texel row's coarse row times `coarse_columns`;
    /// then three words per coarse cell, its columns of global cells `c0 | c1 << 16`, its rows
    /// `r0 | r1 << 16`, and where its table starts in the table images, `x | row << 16`.
    pub index: Vec<u32>,
    /// The rows of the table images the coarse cells' tables take, packed several to a row
    /// after the clusters' tables (most have a few entries; a row is as wide as a cluster's).
    pub cell_rows: u32,
    /// The span guides ([`span_guides`]): `columns` × `rows` entries, as `env_product_spans`
    /// holds them.
    pub spans: Vec<u32>,
}

/// For each row of global cells and each coarse column's span `c0 .. c1` of it, the guide of the
/// search within the span: entry `c0 + k` of the row is `first | last << 16`, the cells (absolute
/// columns) that hold the target `a + ux·(b − a)` (a, b the CDF at c0 and c1) of every ux in
/// bucket k of the span's n = c1 − c0 ([`bucket`]), whether or not the device fuses the multiply
/// and add. Usually one or two cells: no search, or one step.
fn span_guides(d: &Distribution, coarse_columns: u32) -> Vec<u32> {
    let columns = d.columns;
    let mut guides = vec![0u32; (columns * d.rows) as usize];
    // The least and the greatest ux of each bucket, per span width (there are at most two).
    let mut limits: Vec<(u32, Vec<(f32, f32)>)> = Vec::new();
    for cc in 0..coarse_columns {
        let n = coarse_start(cc + 1, coarse_columns, columns) - coarse_start(cc, coarse_columns, columns);
        if n > 0 && !limits.iter().any(|(w, _)| *w == n) {
            let least: Vec<f32> = (0..n).map(|k| smallest_in_bucket(k, n)).collect();
            let greatest =
                (0..n).map(|k| if k + 1 < n { least[k as usize + 1].next_down() } else { ONE_MINUS_EPSILON });
            limits.push((n, least.iter().copied().zip(greatest).collect()));
        }
    }
    for (row, table) in d.conditional.iter().enumerate() {
        let cdf = &table.cdf;
        let out = &mut guides[row * columns as usize..(row + 1) * columns as usize];
        for cc in 0..coarse_columns {
            let (c0, c1) = (coarse_start(cc, coarse_columns, columns), coarse_start(cc + 1, coarse_columns, columns));
            let Some((_, buckets)) = limits.iter().find(|(w, _)| *w == c1 - c0) else { continue };
            let (a, b) = (cdf[c0 as usize], cdf[c1 as usize]);
            let targets = |ux: f32| {
                let (plain, fused) = (a + ux * (b - a), ux.mul_add(b - a, a));
                (plain.min(fused), plain.max(fused))
            };
            // The last cell r of the span with cdf[r] <= t, walking up from `from` (t only grows).
            let last_at_most = |from: u32, t: f32| {
                let mut r = from;
                while r + 1 < c1 && cdf[r as usize + 1] <= t {
                    r += 1;
                }
                r
            };
            let mut first = c0;
            for (k, &(least, greatest)) in buckets.iter().enumerate() {
                first = last_at_most(first, targets(least).0);
                let last = last_at_most(first, targets(greatest).1);
                out[c0 as usize + k] = first | last << 16;
            }
        }
    }
    guides
}

/// The width of the product tables' images: the longest table's CDF (its entries and 1).
fn table_width(clusters: &[Table], cells: &[Table]) -> u32 {
    clusters.iter().chain(cells).map(Table::len).max().unwrap_or(0) as u32 + 1
}

/// Places the coarse cells' tables (each its CDF's length) one after another in rows `width`
/// texels wide from row `first_row` on, starting a row where the next does not fit. Returns
/// each table's (x, row) and the rows taken.
fn pack_tables(cells: &[Table], width: u32, first_row: u32) -> (Vec<(u32, u32)>, u32) {
    let (mut x, mut row) = (0, first_row);
    let origins = cells
        .iter()
        .map(|table| {
            let len = table.len() as u32 + 1;
            if x + len > width {
                (x, row) = (0, row + 1);
            }
            x += len;
            (x - len, row)
        })
        .collect();
    (origins, if cells.is_empty() { 0 } else { row + 1 - first_row })
}

/// The first global cell of coarse cell `i` of `coarse` along an axis of `cells` cells.
pub fn coarse_start(i: u32, coarse: u32, cells: u32) -> u32 {
    i * cells / coarse
}

/// The coarse cell holding global cell `cell`: the inverse of [`coarse_start`].
pub fn coarse_of(cell: u32, coarse: u32, cells: u32) -> u32 {
    ((cell + 1) * coarse - 1) / cells
}

/// The cluster of unit normal `n` (in environment space) on a grid of `grid` cells per face.
pub fn cluster_of(n: Vec3, grid: u32) -> u32 {
    let a = n.abs();
    let (face, p) = if a.x >= a.y && a.x >= a.z {
        (if n.x > 0.0 { 0 } else { 1 }, Vec2::new(n.y, n.z) / a.x)
    } else if a.y >= a.z {
        (if n.y > 0.0 { 2 } else { 3 }, Vec2::new(n.x, n.z) / a.y)
    } else {
        (if n.z > 0.0 { 4 } else { 5 }, Vec2::new(n.x, n.y) / a.z)
    };
    let cell = ((p * 0.5 + 0.5) * grid as f32).as_uvec2().min(UVec2::splat(grid - 1));
    (face * grid + cell.y) * grid + cell.x
}

/// The point of face `face` at face coordinates `p` ∈ [−1, 1]², as [`cluster_of`] reads them.
fn face_point(face: u32, p: [f64; 2]) -> [f64; 3] {
    let s = if face % 2 == 0 { 1.0 } else { -1.0 };
    match face / 2 {
        0 => [s, p[0], p[1]],
        1 => [p[0], s, p[1]],
        _ => [p[0], p[1], s],
    }
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Each cluster's centre and angular radius: the largest angle to a corner of its face cell
/// (the farthest point, as angle from the centre is quasi-convex in face coordinates).
pub fn cluster_cones(grid: u32) -> Vec<([f64; 3], f64)> {
    let mut cones = Vec::with_capacity((6 * grid * grid) as usize);
    let at = |i: u32| -1.0 + 2.0 * i as f64 / grid as f64;
    for face in 0..6 {
        for y in 0..grid {
            for x in 0..grid {
                let (x0, x1, y0, y1) = (at(x), at(x + 1), at(y), at(y + 1));
                let centre = normalize(face_point(face, [0.5 * (x0 + x1), 0.5 * (y0 + y1)]));
                let radius = [[x0, y0], [x1, y0], [x0, y1], [x1, y1]]
                    .into_iter()
                    .map(|p| dot(centre, normalize(face_point(face, p))).clamp(-1.0, 1.0).acos())
                    .fold(0.0, f64::max);
                cones.push((centre, radius + RADIUS_MARGIN));
            }
        }
    }
    cones
}

/// max cos(x − c) over x ∈ [a, b] (b − a ≤ 2π): at c + 2πm when inside, else at an end.
fn max_cos_over(a: f64, b: f64, c: f64) -> f64 {
    if (-2..=2).any(|m| (a..=b).contains(&(c + 2.0 * PI * m as f64))) {
        return 1.0;
    }
    (a - c).cos().max((b - c).cos())
}

/// For the azimuths φ ∈ [φa, φb]: R and θ* with max over φ of n·ω = R cos(θ − θ*) at polar
/// angle θ, since n·ω = n_y cos θ + sin θ·ρ cos(φ − ψ), ρ = |n_xz|, ψ = atan2(n_x, −n_z).
fn azimuth_reduction(n: [f64; 3], phi: [f64; 2]) -> (f64, f64) {
    let rho = (n[0] * n[0] + n[2] * n[2]).sqrt();
    let g = if rho > 0.0 { rho * max_cos_over(phi[0], phi[1], n[0].atan2(-n[2])) } else { 0.0 };
    ((n[1] * n[1] + g * g).sqrt(), g.atan2(n[1]))
}

/// The largest n·ω over directions ω of the lat-long rectangle of azimuths φ ∈ [φa, φb] (as in
/// [`direction`]: φ = 2π(u − ½)) and polar angles θ ∈ [θa, θb].
pub fn max_dot_over_rectangle(n: [f64; 3], phi: [f64; 2], theta: [f64; 2]) -> f64 {
    let (r, theta_star) = azimuth_reduction(n, phi);
    r * max_cos_over(theta[0], theta[1], theta_star)
}

impl Product {
    /// The product tables of the global tables `d`.
    pub fn build(d: &Distribution) -> Product {
        Product::with_grid(d, GRID)
    }

    pub fn with_grid(d: &Distribution, grid: u32) -> Product {
        let (columns, rows) = (d.columns, d.rows);
        let (coarse_columns, coarse_rows) = (COARSE_COLUMNS.min(columns), COARSE_ROWS.min(rows));
        let step = |t: &Table, a: usize, b: usize| t.cdf[b] as f64 - t.cdf[a] as f64;
        // Each coarse cell's probability under the global tables, from their f32 CDFs, and its
        // table over its rows of cells.
        let mut global = Vec::with_capacity((coarse_columns * coarse_rows) as usize);
        let mut cells = Vec::with_capacity(global.capacity());
        let mut bounds = Vec::with_capacity(global.capacity());
        for cr in 0..coarse_rows {
            let (r0, r1) = (coarse_start(cr, coarse_rows, rows), coarse_start(cr + 1, coarse_rows, rows));
            for cc in 0..coarse_columns {
                let (c0, c1) =
                    (coarse_start(cc, coarse_columns, columns), coarse_start(cc + 1, coarse_columns, columns));
                let weights: Vec<f64> = (r0..r1)
                    .map(|r| {
                        step(&d.marginal, r as usize, r as usize + 1)
                            * step(&d.conditional[r as usize], c0 as usize, c1 as usize)
                    })
                    .collect();
                global.push(weights.iter().sum::<f64>());
                cells.push(Table::new(&weights));
                let (x0, _) = Distribution::span(c0, d.block_x, d.width);
                let (x1, _) = Distribution::span(c1, d.block_x, d.width);
                let (y0, _) = Distribution::span(r0, d.block_y, d.height);
                let (y1, _) = Distribution::span(r1, d.block_y, d.height);
                let phi =
                    [2.0 * PI * (x0 as f64 / d.width as f64 - 0.5), 2.0 * PI * (x1 as f64 / d.width as f64 - 0.5)];
                let theta = [PI * y0 as f64 / d.height as f64, PI * y1 as f64 / d.height as f64];
                bounds.push((phi, theta));
            }
        }
        let cones = cluster_cones(grid);
        let mut clusters = Vec::with_capacity(cones.len());
        let mut ratio = Vec::with_capacity(cones.len() * global.len());
        let (phis, thetas): (Vec<[f64; 2]>, Vec<[f64; 2]>) = (
            (0..coarse_columns).map(|cc| bounds[cc as usize].0).collect(),
            (0..coarse_rows).map(|cr| bounds[(cr * coarse_columns) as usize].1).collect(),
        );
        let theta_edges: Vec<[(f64, f64); 2]> =
            thetas.iter().map(|t| [(t[0].cos(), t[0].sin()), (t[1].cos(), t[1].sin())]).collect();
        for (centre, radius) in cones {
            let (cos_r, sin_r) = (radius.cos(), radius.sin());
            let mut weights = vec![0.0f64; global.len()];
            for (cc, phi) in phis.iter().enumerate() {
                let (r, theta_star) = azimuth_reduction(centre, *phi);
                let (cos_star, sin_star) = (theta_star.cos(), theta_star.sin());
                for (cr, theta) in thetas.iter().enumerate() {
                    // max n·ω over the cell (see max_dot_over_rectangle), without trigonometry.
                    let m = if (theta[0]..=theta[1]).contains(&theta_star) {
                        r
                    } else {
                        let [(ca, sa), (cb, sb)] = theta_edges[cr];
                        r * (ca * cos_star + sa * sin_star).max(cb * cos_star + sb * sin_star)
                    }
                    .clamp(-1.0, 1.0);
                    // cos(max(0, acos(m) − radius)), and 0 from π/2 on.
                    let bound = if m >= cos_r { 1.0 } else { (m * cos_r + (1.0 - m * m).sqrt() * sin_r).max(0.0) };
                    let c = cr * coarse_columns as usize + cc;
                    weights[c] = global[c] * bound;
                }
            }
            // A cluster that sees nothing the global tables sample samples as they do.
            if weights.iter().sum::<f64>() <= 0.0 {
                weights.clone_from(&global);
            }
            let table = Table::new(&weights);
            ratio.extend(global.iter().enumerate().map(|(c, &g)| {
                if g > 0.0 {
                    (step(&table, c, c + 1) / g) as f32
                } else {
                    0.0
                }
            }));
            clusters.push(table);
        }
        let width = table_width(&clusters, &cells);
        let (origins, cell_rows) = pack_tables(&cells, width, clusters.len() as u32);
        let index = Product::build_index(d, coarse_columns, coarse_rows, &origins);
        let spans = span_guides(d, coarse_columns);
        Product { grid, coarse_columns, coarse_rows, columns, rows, clusters, cells, ratio, index, cell_rows, spans }
    }

    /// [`Product::index`] for the global tables `d` grouped into coarse cells whose tables
    /// start at `origins` (x, row).
    fn build_index(d: &Distribution, coarse_columns: u32, coarse_rows: u32, origins: &[(u32, u32)]) -> Vec<u32> {
        let (columns, rows) = (d.columns, d.rows);
        // The spans are packed in 16 bits: a side has at most MAX_CELLS cells.
        debug_assert!(columns <= MAX_CELLS && rows <= MAX_CELLS && MAX_CELLS < 1 << 16);
        let span = |i, coarse, cells| coarse_start(i, coarse, cells) | coarse_start(i + 1, coarse, cells) << 16;
        let mut index = Vec::with_capacity((d.width + d.height + 3 * coarse_columns * coarse_rows) as usize);
        index.extend((0..d.width).map(|x| coarse_of(x / d.block_x, coarse_columns, columns)));
        index.extend((0..d.height).map(|y| coarse_of(y / d.block_y, coarse_rows, rows) * coarse_columns));
        for cr in 0..coarse_rows {
            for cc in 0..coarse_columns {
                let (x, row) = origins[(cr * coarse_columns + cc) as usize];
                index.extend([span(cc, coarse_columns, columns), span(cr, coarse_rows, rows), x | row << 16]);
            }
        }
        index
    }

    /// Coarse cell `c`'s global cells: columns `c0 .. c1` and rows `r0 .. r1`, as (c0, c1, r0, r1).
    fn coarse_span(&self, d: &Distribution, c: u32) -> (u32, u32, u32, u32) {
        let [columns, rows, _] = self.cell_words(d, c);
        (columns & 0xffff, columns >> 16, rows & 0xffff, rows >> 16)
    }

    /// Where coarse cell `c`'s table starts in the table images: (x, row).
    pub fn cell_table_origin(&self, d: &Distribution, c: u32) -> (u32, u32) {
        let [_, _, origin] = self.cell_words(d, c);
        (origin & 0xffff, origin >> 16)
    }

    /// Coarse cell `c`'s three words of [`Product::index`].
    fn cell_words(&self, d: &Distribution, c: u32) -> [u32; 3] {
        let at = (d.width + d.height + 3 * c) as usize;
        [self.index[at], self.index[at + 1], self.index[at + 2]]
    }

    /// The row of the CDF image that holds cluster 0's ratios; cluster k's is k rows below.
    pub fn ratio_row(&self) -> u32 {
        self.clusters.len() as u32 + self.cell_rows
    }

    /// The size of the table images as `glsl/include/environment.glsl` reads them:
    /// `max(coarse cells, rows per coarse cell) + 1` texels across, [`Product::ratio_row`] rows
    /// of bucket entries (RGBA32F) and `clusters` more of CDFs (R32F). Row k holds cluster k's
    /// table, the next [`Product::cell_rows`] rows the coarse cells' tables where
    /// [`Product::cell_table_origin`] says, and the CDF image's last rows each cluster's ratios.
    /// Returns (width, bucket rows, CDF rows).
    pub fn table_size(&self) -> (u32, u32, u32) {
        let bucket_rows = self.ratio_row();
        (table_width(&self.clusters, &self.cells), bucket_rows, bucket_rows + self.clusters.len() as u32)
    }

    /// Every table with where it starts in the table images, (x, row): the clusters', then the
    /// coarse cells'.
    fn placed_tables<'a>(&'a self, d: &'a Distribution) -> impl Iterator<Item = ((u32, u32), &'a Table)> {
        let origins = (0..self.clusters.len() as u32).map(|k| (0, k));
        let cell_origins = (0..self.coarse_cells()).map(|c| self.cell_table_origin(d, c));
        origins.chain(cell_origins).zip(self.clusters.iter().chain(&self.cells))
    }

    /// Writes the bucket image (of [`Product::table_size`]).
    pub fn write_buckets(&self, d: &Distribution, out: &mut [[f32; 4]]) {
        let (width, _, _) = self.table_size();
        out.fill([0.0; 4]);
        for ((x, row), table) in self.placed_tables(d) {
            table.write_buckets(&mut out[(row * width + x) as usize..]);
        }
    }

    /// Writes the CDF image (of [`Product::table_size`]): the tables' CDFs, then the ratios.
    pub fn write_cdfs(&self, d: &Distribution, out: &mut [f32]) {
        let (width, bucket_rows, _) = self.table_size();
        out.fill(0.0);
        for ((x, row), table) in self.placed_tables(d) {
            let start = (row * width + x) as usize;
            out[start..start + table.cdf.len()].copy_from_slice(&table.cdf);
        }
        let cells = self.coarse_cells() as usize;
        for (k, ratios) in self.ratio.chunks(cells).enumerate() {
            let start = (bucket_rows as usize + k) * width as usize;
            out[start..start + cells].copy_from_slice(ratios);
        }
    }

    /// The two table images' texels, for tests: (width, bucket rows, CDF rows, buckets, CDFs).
    #[cfg(test)]
    fn table_texels(&self, d: &Distribution) -> (u32, u32, u32, Vec<[f32; 4]>, Vec<f32>) {
        let (width, bucket_rows, cdf_rows) = self.table_size();
        let mut buckets = vec![[1.0f32; 4]; (width * bucket_rows) as usize];
        let mut cdfs = vec![1.0f32; (width * cdf_rows) as usize];
        self.write_buckets(d, &mut buckets);
        self.write_cdfs(d, &mut cdfs);
        (width, bucket_rows, cdf_rows, buckets, cdfs)
    }

    /// The environment sample of `env_sample_mixture`: from `cluster`'s table with probability
    /// `q`, from the global tables otherwise. Returns the direction and its texel.
    pub fn sample_mixture(&self, d: &Distribution, cluster: u32, q: f32, u: Vec2) -> (Vec3, UVec2) {
        if u.x < q {
            self.sample(d, cluster, Vec2::new((u.x / q).min(ONE_MINUS_EPSILON), u.y))
        } else {
            d.sample(Vec2::new(((u.x - q) / (1.0 - q)).min(ONE_MINUS_EPSILON), u.y))
        }
    }

    /// The pdf_ω of [`Product::sample_mixture`] at texel `t`.
    pub fn mixture_pdf(&self, d: &Distribution, cluster: u32, q: f32, t: UVec2) -> f32 {
        d.texel_cell_pdf(t) * ((1.0 - q) + q * self.texel_ratio(d, cluster, t))
    }

    pub fn coarse_cells(&self) -> u32 {
        self.coarse_columns * self.coarse_rows
    }

    /// The coarse cell holding texel `t` of the global tables `d`.
    pub fn coarse_cell(&self, d: &Distribution, t: UVec2) -> u32 {
        self.index[t.x as usize] + self.index[(d.width + t.y) as usize]
    }

    /// The product pdf over its global pdf of a direction in texel `t`, for `cluster`.
    pub fn texel_ratio(&self, d: &Distribution, cluster: u32, t: UVec2) -> f32 {
        self.ratio[(cluster * self.coarse_cells() + self.coarse_cell(d, t)) as usize]
    }

    /// pdf over solid angle of [`Product::sample`] for `cluster` producing a direction at `uv`.
    pub fn pdf(&self, d: &Distribution, cluster: u32, uv: Vec2) -> f32 {
        let t = texel_of(d.width, d.height, uv);
        d.texel_cell_pdf(t) * self.texel_ratio(d, cluster, t)
    }

    /// Samples a direction for `cluster`, as `env_sample_product` does: a coarse cell by the
    /// cluster's table (u.x), a row of cells within it by its own table (u.y), a cell of that row
    /// by the global conditional table within the coarse cell's span (u.x rescaled, its search
    /// started from the span's guide), then a point uniform in solid angle within the cell.
    /// Returns the direction and its texel.
    pub fn sample(&self, d: &Distribution, cluster: u32, u: Vec2) -> (Vec3, UVec2) {
        let table = &self.clusters[cluster as usize];
        let c = table.search(u.x);
        let ux = rescale(u.x, table.cdf[c], table.cdf[c + 1]);
        let (c0, c1, r0, _) = self.coarse_span(d, c as u32);
        let cell = &self.cells[c];
        let k = cell.search(u.y);
        let dv = rescale(u.y, cell.cdf[k], cell.cdf[k + 1]);
        let row = r0 + k as u32;
        let conditional = &d.conditional[row as usize];
        let (a, b) = (conditional.cdf[c0 as usize], conditional.cdf[c1 as usize]);
        let target = a + ux * (b - a);
        // The last cell of the span whose CDF value is ≤ target, among those its guide names.
        let guide = self.spans[(row * self.columns + c0 + bucket(ux, c1 - c0)) as usize];
        let (mut lo, mut hi) = ((guide & 0xffff) as usize, (guide >> 16) as usize + 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if conditional.cdf[mid] <= target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let column = lo as u32;
        let du = rescale(target, conditional.cdf[lo], conditional.cdf[lo + 1]);
        d.point_in_cell(row, column, du, dv)
    }
}

/// Where `u` lies in [a, b), in [0, 1); ½ for an empty interval.
pub fn rescale(u: f32, a: f32, b: f32) -> f32 {
    let t = if b > a { (u - a) / (b - a) } else { 0.5 };
    t.clamp(0.0, ONE_MINUS_EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::environment::Environment;

    #[test]
    fn coarse_cells_partition_the_grid() {
        for (coarse, cells) in [(32, 32), (32, 300), (16, 4096), (7, 9), (1, 1)] {
            let mut previous = 0;
            for cell in 0..cells {
                let c = coarse_of(cell, coarse, cells);
                assert!(coarse_start(c, coarse, cells) <= cell && cell < coarse_start(c + 1, coarse, cells));
                assert!(c == previous || c == previous + 1);
                previous = c;
            }
            assert_eq!(previous, coarse - 1);
        }
    }

    /// Maps for the layout's tests: a sun, a map of blocked cells and a single texel, each with
    /// its tables and product tables.
    fn layout_cases() -> Vec<(Environment, Distribution, Product)> {
        let blocked = Environment::new(45, 23, (0..45 * 23).map(|i| [(i % 11) as f32 + 0.5; 3]).collect(), "blocked");
        [(sun_map(), 4096), (blocked, 7), (Environment::new(1, 1, vec![[0.5; 3]], "1x1"), 4096)]
            .into_iter()
            .map(|(env, max_cells)| {
                let d = Distribution::compensated_with_max_cells(&env, max_cells);
                let p = Product::build(&d);
                (env, d, p)
            })
            .collect()
    }

    /// Each span guide names cells that hold the answer of a plain binary search within the
    /// span, for every ux of its bucket, with the target rounded after the multiply or fused:
    /// checked at each bucket's least and greatest ux and at random ones, over every row and
    /// span of each layout case; and the search steps left after the guides are at most half
    /// of a plain search's.
    #[test]
    fn span_guides_hold_the_search_within_the_span() {
        let mut rng = 0x2545_f491u32;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            (rng >> 8) as f32 / 16_777_216.0
        };
        for (env, d, p) in layout_cases() {
            let (mut steps, mut plain) = (0, 0);
            for (row, table) in d.conditional.iter().enumerate() {
                for cc in 0..p.coarse_columns {
                    let (c0, c1) = (
                        coarse_start(cc, p.coarse_columns, d.columns),
                        coarse_start(cc + 1, p.coarse_columns, d.columns),
                    );
                    let n = c1 - c0;
                    let (a, b) = (table.cdf[c0 as usize], table.cdf[c1 as usize]);
                    let searched = |target: f32| (c0..c1).rfind(|&r| table.cdf[r as usize] <= target).unwrap();
                    for k in 0..n {
                        let guide = p.spans[(row as u32 * d.columns + c0 + k) as usize];
                        let (first, last) = (guide & 0xffff, guide >> 16);
                        steps += (last - first + 1).next_power_of_two().trailing_zeros() as usize;
                        plain += n.next_power_of_two().trailing_zeros() as usize;
                        let least = smallest_in_bucket(k, n);
                        let greatest =
                            if k + 1 < n { smallest_in_bucket(k + 1, n).next_down() } else { ONE_MINUS_EPSILON };
                        let random = (0..4).map(|_| least + next() * (greatest - least));
                        for ux in [least, greatest].into_iter().chain(random).filter(|&ux| bucket(ux, n) == k) {
                            for target in [a + ux * (b - a), ux.mul_add(b - a, a)] {
                                let r = searched(target);
                                assert!(
                                    (first..=last).contains(&r),
                                    "{}: row {row}, span {c0}..{c1}, ux {ux}: cell {r} outside {first}..={last}",
                                    env.source
                                );
                            }
                        }
                    }
                }
            }
            assert!(steps * 2 <= plain, "{}: {steps} search steps after the guides, {plain} without", env.source);
        }
    }

    /// The table images hold every table whole, each where the index says, none overlapping
    /// another, and the coarse cells' short tables share rows.
    #[test]
    fn the_tables_are_packed_without_overlap() {
        for (env, d, p) in layout_cases() {
            let (width, bucket_rows, cdf_rows, buckets, cdfs) = p.table_texels(&d);
            assert_eq!((bucket_rows, cdf_rows), (p.ratio_row(), p.ratio_row() + p.clusters.len() as u32));
            assert_eq!((buckets.len(), cdfs.len()), ((width * bucket_rows) as usize, (width * cdf_rows) as usize));
            let mut used = vec![false; (width * bucket_rows) as usize];
            let cluster_origins = (0..p.clusters.len() as u32).map(|k| (0, k));
            let cell_origins = (0..p.coarse_cells()).map(|c| p.cell_table_origin(&d, c));
            for ((x, row), table) in cluster_origins.chain(cell_origins).zip(p.clusters.iter().chain(&p.cells)) {
                let len = table.len() as u32 + 1;
                assert!(x + len <= width && row < bucket_rows, "{}: a table runs off its image", env.source);
                let start = (row * width + x) as usize;
                assert_eq!(&cdfs[start..start + table.cdf.len()], &table.cdf[..], "{}", env.source);
                for cell in &mut used[start..start + len as usize] {
                    assert!(!*cell, "{}: two tables overlap at row {row}", env.source);
                    *cell = true;
                }
            }
            let longest = p.cells.iter().map(|t| t.len() as u32 + 1).max().unwrap_or(1);
            assert!(p.cell_rows <= p.coarse_cells().div_ceil(width / longest), "{}: {} rows", env.source, p.cell_rows);
            let ratios = &cdfs[(p.ratio_row() * width) as usize..];
            for (k, row) in p.ratio.chunks(p.coarse_cells() as usize).enumerate() {
                assert_eq!(&ratios[k * width as usize..][..row.len()], row, "{}: cluster {k}'s ratios", env.source);
            }
        }
    }

    /// The lookups that replace the divisions agree with them: each texel's coarse cell spans
    /// the texel's cell, and the spans tile the grid.
    #[test]
    fn the_index_puts_each_texel_in_the_coarse_cell_that_spans_it() {
        for (env, d, p) in layout_cases() {
            let mut covered = vec![0u32; (d.columns * d.rows) as usize];
            for c in 0..p.coarse_cells() {
                let (c0, c1, r0, r1) = p.coarse_span(&d, c);
                assert_eq!(
                    (c0, r0),
                    (
                        coarse_start(c % p.coarse_columns, p.coarse_columns, d.columns),
                        coarse_start(c / p.coarse_columns, p.coarse_rows, d.rows)
                    )
                );
                for r in r0..r1 {
                    for column in c0..c1 {
                        covered[(r * d.columns + column) as usize] += 1;
                    }
                }
            }
            assert!(covered.iter().all(|&n| n == 1), "{}: the spans do not tile the grid", env.source);
            for y in 0..d.height {
                for x in 0..d.width {
                    let (c0, c1, r0, r1) = p.coarse_span(&d, p.coarse_cell(&d, UVec2::new(x, y)));
                    let (column, row) = (x / d.block_x, y / d.block_y);
                    assert!((c0..c1).contains(&column) && (r0..r1).contains(&row), "{}: texel ({x}, {y})", env.source);
                }
            }
        }
    }

    #[test]
    fn every_normal_lies_within_its_clusters_cone() {
        let cones = cluster_cones(GRID);
        assert_eq!(cones.len(), 6 * (GRID * GRID) as usize);
        let mut seen = vec![false; cones.len()];
        for i in 0..20000u32 {
            // A spiral over the sphere, plus the axes and the cube's edges.
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / 20000.0;
            let phi = i as f64 * 2.399963;
            let r = (1.0 - z * z).sqrt();
            let n = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32).normalize();
            for n in [n, Vec3::X, -Vec3::Y, Vec3::new(1.0, 1.0, 0.0).normalize(), Vec3::ONE.normalize()] {
                let k = cluster_of(n, GRID) as usize;
                seen[k] = true;
                let (centre, radius) = cones[k];
                let angle = dot(centre, [n.x as f64, n.y as f64, n.z as f64]).clamp(-1.0, 1.0).acos();
                assert!(angle <= radius, "{n:?} in cluster {k}: {angle} > {radius}");
            }
        }
        assert!(seen.iter().all(|&s| s), "some clusters never chosen");
    }

    #[test]
    fn the_bound_is_the_largest_dot_product_over_the_rectangle() {
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f64 / (1u64 << 24) as f64
        };
        for _ in 0..300 {
            let n = normalize([next() - 0.5, next() - 0.5, next() - 0.5]);
            let (pa, pb) = (2.0 * PI * (next() - 0.5), 2.0 * PI * (next() - 0.5));
            let phi = [pa.min(pb), pa.max(pb)];
            let (ta, tb) = (PI * next(), PI * next());
            let theta = [ta.min(tb), ta.max(tb)];
            let bound = max_dot_over_rectangle(n, phi, theta);
            let mut best = f64::MIN;
            for i in 0..=60 {
                for j in 0..=60 {
                    let p = phi[0] + (phi[1] - phi[0]) * i as f64 / 60.0;
                    let t = theta[0] + (theta[1] - theta[0]) * j as f64 / 60.0;
                    let w = [t.sin() * p.sin(), t.cos(), -t.sin() * p.cos()];
                    best = best.max(dot(n, w));
                }
            }
            assert!(bound >= best - 1e-12 && bound <= best + 2e-3, "{bound} vs {best}");
        }
    }

    /// Each cluster's probabilities are G(c)·cos(max(0, θmin − r)), normalised, with θmin from
    /// the direct maximum of n·ω over the cell.
    #[test]
    fn cluster_tables_weigh_the_global_probability_by_the_cosine_bound() {
        let env = sun_map();
        let d = Distribution::compensated_with_max_cells(&env, 4096);
        let p = Product::build(&d);
        let cones = cluster_cones(GRID);
        let mut fallbacks = 0;
        for (k, (centre, radius)) in cones.iter().enumerate() {
            let mut expected = Vec::new();
            let mut global = Vec::new();
            for cr in 0..p.coarse_rows {
                for cc in 0..p.coarse_columns {
                    let span = |i, coarse, cells, block, size| {
                        let a = Distribution::span(coarse_start(i, coarse, cells), block, size).0;
                        let b = Distribution::span(coarse_start(i + 1, coarse, cells), block, size).0;
                        [a as f64 / size as f64, b as f64 / size as f64]
                    };
                    let x = span(cc, p.coarse_columns, p.columns, d.block_x, d.width);
                    let y = span(cr, p.coarse_rows, p.rows, d.block_y, d.height);
                    let phi = [2.0 * PI * (x[0] - 0.5), 2.0 * PI * (x[1] - 0.5)];
                    let least = max_dot_over_rectangle(*centre, phi, [PI * y[0], PI * y[1]]).clamp(-1.0, 1.0).acos();
                    let angle = (least - radius).max(0.0);
                    expected.push(if angle < 0.5 * PI { angle.cos() } else { 0.0 });
                    let r0 = coarse_start(cr, p.coarse_rows, p.rows) as usize;
                    let r1 = coarse_start(cr + 1, p.coarse_rows, p.rows) as usize;
                    let (c0, c1) = (
                        coarse_start(cc, p.coarse_columns, p.columns) as usize,
                        coarse_start(cc + 1, p.coarse_columns, p.columns) as usize,
                    );
                    global.push(
                        (r0..r1)
                            .map(|r| {
                                (d.marginal.cdf[r + 1] as f64 - d.marginal.cdf[r] as f64)
                                    * (d.conditional[r].cdf[c1] as f64 - d.conditional[r].cdf[c0] as f64)
                            })
                            .sum::<f64>(),
                    );
                }
            }
            let total: f64 = expected.iter().zip(&global).map(|(b, g)| b * g).sum();
            fallbacks += (total == 0.0) as usize;
            for (c, (b, g)) in expected.iter().zip(&global).enumerate() {
                if *g > 1e-6 {
                    let got = p.ratio[k * p.coarse_cells() as usize + c] as f64;
                    // A cluster that sees nothing sampled samples as the global tables do.
                    let b = if total > 0.0 { *b } else { 1.0 };
                    let total = if total > 0.0 { total } else { 1.0 };
                    assert!(
                        (got - b / total).abs() <= 1e-3 * (b / total) + 1e-4,
                        "cluster {k}, cell {c}: {got} vs {}",
                        b / total
                    );
                }
            }
        }
        assert!(fallbacks > 0 && fallbacks < cones.len() / 2, "{fallbacks} clusters see nothing");
    }

    /// Maps smaller than the coarse grid, and blocked cells of a map wider than the cell
    /// limit, still give tables whose every pdf integrates to 1.
    #[test]
    fn tiny_and_blocked_maps_give_whole_tables() {
        let maps = [
            (Environment::new(2, 1, vec![[1.0; 3], [3.0; 3]], "2x1"), 4096),
            (Environment::new(1, 1, vec![[0.5; 3]], "1x1"), 4096),
            (Environment::new(40, 20, (0..800).map(|i| [(i % 11) as f32; 3]).collect(), "blocked"), 7),
        ];
        for (env, max_cells) in maps {
            let d = Distribution::compensated_with_max_cells(&env, max_cells);
            let p = Product::build(&d);
            let (w, bucket_rows, cdf_rows, buckets, cdfs) = p.table_texels(&d);
            assert_eq!((buckets.len(), cdfs.len()), ((w * bucket_rows) as usize, (w * cdf_rows) as usize));
            for cluster in 0..p.clusters.len() as u32 {
                let mut total = 0.0;
                for r in 0..d.rows {
                    for c in 0..d.columns {
                        let t = UVec2::new(c * d.block_x, r * d.block_y);
                        total += d.texel_cell_pdf(t) as f64
                            * p.texel_ratio(&d, cluster, t) as f64
                            * d.cell_solid_angle(r, c);
                    }
                }
                assert!((total - 1.0).abs() < 1e-4, "{}: cluster {cluster}: {total}", env.source);
                let (dir, t) = p.sample(&d, cluster, Vec2::new(0.3, 0.7));
                assert!(dir.is_finite() && t.x < env.width && t.y < env.height, "{}", env.source);
            }
        }
    }

    fn sun_map() -> Environment {
        let (w, h) = (128u32, 64u32);
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if (x as i32 - 40).abs() < 2 && (y as i32 - 20).abs() < 2 {
                    [3000.0; 3]
                } else {
                    [0.2 + 0.01 * (x % 9) as f32 + (h - y) as f32 / h as f32; 3]
                }
            })
            .collect();
        Environment::new(w, h, texels, "sun")
    }

    /// Each cluster's pdf integrates to 1 over the sphere, and is positive wherever the global
    /// pdf is and some normal of the cluster has a positive cosine.
    #[test]
    fn the_product_pdf_integrates_to_one_and_covers_each_clusters_hemispheres() {
        for compensated in [false, true] {
            let env = sun_map();
            let d = if compensated {
                Distribution::compensated_with_max_cells(&env, 4096)
            } else {
                Distribution::build(&env)
            };
            let p = Product::build(&d);
            let cones = cluster_cones(GRID);
            for cluster in 0..cones.len() as u32 {
                let mut total = 0.0;
                for r in 0..d.rows {
                    for c in 0..d.columns {
                        let t = UVec2::new(c * d.block_x, r * d.block_y);
                        let pdf = d.texel_cell_pdf(t) as f64 * p.texel_ratio(&d, cluster, t) as f64;
                        total += pdf * d.cell_solid_angle(r, c);
                    }
                }
                assert!((total - 1.0).abs() < 1e-4, "cluster {cluster}: {total}");
            }
            // Normals near cluster edges, directions just above their horizons.
            let mut uncovered = 0;
            for i in 0..4000u32 {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / 4000.0;
                let phi = i as f32 * 2.399963;
                let r = (1.0 - z * z).sqrt();
                let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                let k = cluster_of(n, GRID);
                for j in 0..64 {
                    let a = j as f32 * std::f32::consts::TAU / 64.0;
                    let (t, b) = n.any_orthonormal_pair();
                    let w = (0.02 * n + a.cos() * t + a.sin() * b).normalize();
                    let uv = crate::environment::sampling::direction_to_uv(w);
                    if d.pdf(uv) > 0.0 && p.pdf(&d, k, uv) <= 0.0 {
                        uncovered += 1;
                    }
                }
            }
            assert_eq!(uncovered, 0, "directions some normal sees with product pdf 0");
        }
    }

    /// Samples land where the pdf says, cell by cell, and report texels whose pdf is positive.
    #[test]
    fn cpu_samples_follow_the_pdf() {
        let env = sun_map();
        let d = Distribution::compensated_with_max_cells(&env, 4096);
        let p = Product::build(&d);
        for cluster in [0u32, 37, 95] {
            let count = 200_000;
            let mut observed = vec![0.0f64; (d.columns * d.rows) as usize];
            let mut state = 99u32 + cluster;
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                (state >> 8) as f32 / (1u32 << 24) as f32
            };
            for _ in 0..count {
                let (dir, t) = p.sample(&d, cluster, Vec2::new(next(), next()));
                let uv = crate::environment::sampling::direction_to_uv(dir);
                assert!(p.pdf(&d, cluster, uv) > 0.0 || p.texel_ratio(&d, cluster, t) > 0.0);
                observed[((t.y / d.block_y) * d.columns + t.x / d.block_x) as usize] += 1.0;
            }
            // Group into coarse cells, where counts are large enough to compare.
            let mut grouped = vec![(0.0f64, 0.0f64); p.coarse_cells() as usize];
            for r in 0..d.rows {
                for c in 0..d.columns {
                    let t = UVec2::new(c * d.block_x, r * d.block_y);
                    let expected = d.texel_cell_pdf(t) as f64
                        * p.texel_ratio(&d, cluster, t) as f64
                        * d.cell_solid_angle(r, c)
                        * count as f64;
                    let g = &mut grouped[p.coarse_cell(&d, t) as usize];
                    g.0 += observed[(r * d.columns + c) as usize];
                    g.1 += expected;
                }
            }
            for (i, (o, e)) in grouped.iter().enumerate() {
                assert!((o - e).abs() <= 5.0 * e.sqrt() + 1.0, "cluster {cluster}, coarse cell {i}: {o} vs {e}");
            }
        }
    }
}
