//! Directional visibility: for each pixel, which world directions see the environment from its
//! surface point (docs/formats.md#visibility).
//!
//! The sphere of world directions is cut into the `side` × `side` cells of an octahedral map
//! ([`Grid`]), and a pixel stores one bit per cell: set where the cell's centre direction, traced
//! from the surface, escapes to the environment. The grid is fixed in world space, so the
//! environment turns under it with nothing to recompute, and any producer can write the bits
//! without knowing the pixel's frame. The relight kernel asks the same question of every
//! direction both of its strategies sample, so the estimate stays unbiased with respect to the
//! stored visibility. docs/decisions.md says why this representation, and gives its measured
//! error at each size.

mod mesh;
pub mod occluders;
mod trace;

pub use mesh::Mesh;
pub use trace::{trace, trace_reporting, Occluder, SurfacePoint};

use glam::{Vec2, Vec3};

/// The grid sides a g-buffer may use: 64 to 4096 directions, 8 to 512 bytes a pixel.
pub const SIDES: [u32; 4] = [8, 16, 32, 64];
/// The most bytes a default grid may take over a whole g-buffer (see [`default_side`]).
const DEFAULT_BUDGET: usize = 256 << 20;

/// The side used unless one is asked for: 64² (4096 directions, 512 bytes a pixel) where its
/// bits fit [`DEFAULT_BUDGET`], up to half a megapixel, else 32² (1024 directions, 128 bytes).
/// Against Cycles the finer grid is what brings a small sun's shadows and the soft shadows of
/// studio lights within 3% of the mean and 5% mean relative error (docs/decisions.md); above
/// half a megapixel its memory, and the 1080p trace's time, cost more than it brings.
pub fn default_side(pixels: usize) -> u32 {
    let fine = Grid::new(64).expect("64 is a side");
    if pixels.saturating_mul(fine.words() * 4) <= DEFAULT_BUDGET {
        64
    } else {
        32
    }
}
/// Bits per stored word.
pub const WORD_BITS: usize = 32;

/// A square octahedral grid over the sphere of world directions, +Y at its centre.
///
/// A unit direction d maps to (a, b) = (d.x, d.z) / (|d.x| + |d.y| + |d.z|) when d.y ≥ 0, and to
/// ((1 − |b'|)·sign a', (1 − |a'|)·sign b') of those (a', b') when d.y < 0 (sign 0 = +1). Then
/// (u, v) = ((a + 1)/2, (b + 1)/2), and the cell is column ⌊u·side⌋, row ⌊v·side⌋ (clamped to
/// side − 1), numbered `row * side + column`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Grid {
    side: u32,
}

impl Grid {
    /// The grid of `side` cells a side, one of [`SIDES`].
    pub fn new(side: u32) -> Result<Grid, String> {
        if SIDES.contains(&side) {
            Ok(Grid { side })
        } else {
            Err(format!("a visibility grid is {} cells a side, not {side}", side_list()))
        }
    }

    /// The grid whose bits fill `words` 32-bit words, if there is one.
    pub fn from_words(words: usize) -> Option<Grid> {
        SIDES.iter().map(|&side| Grid { side }).find(|grid| grid.words() == words)
    }

    pub fn side(self) -> u32 {
        self.side
    }

    /// Directions, one bit each.
    pub fn cells(self) -> usize {
        (self.side * self.side) as usize
    }

    /// 32-bit words a pixel's bits fill.
    pub fn words(self) -> usize {
        self.cells() / WORD_BITS
    }

    /// The cell a unit direction falls in.
    pub fn cell(self, direction: Vec3) -> usize {
        let uv = octahedral(direction);
        let side = self.side as f32;
        let column = ((uv.x * side) as u32).min(self.side - 1);
        let row = ((uv.y * side) as u32).min(self.side - 1);
        (row * self.side + column) as usize
    }

    /// The unit direction at a cell's centre: the one a producer traces for its bit.
    pub fn centre(self, cell: usize) -> Vec3 {
        let side = self.side as f32;
        let (column, row) = ((cell % self.side as usize) as f32, (cell / self.side as usize) as f32);
        from_octahedral(Vec2::new((column + 0.5) / side, (row + 0.5) / side))
    }

    /// The largest angle between a cell's centre and any direction in it, in radians: at a
    /// corner, as a cell's edges map to great-circle arcs.
    pub fn cell_radius(self) -> f32 {
        let side = self.side as f32;
        let mut widest = 0.0f32;
        for cell in 0..self.cells() {
            let centre = self.centre(cell);
            let (column, row) = ((cell % self.side as usize) as f32, (cell / self.side as usize) as f32);
            for (i, j) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                let corner = from_octahedral(Vec2::new((column + i) / side, (row + j) / side));
                widest = widest.max(corner.dot(centre).clamp(-1.0, 1.0).acos());
            }
        }
        widest
    }
}

/// The sides of [`SIDES`], listed for a message.
pub fn side_list() -> String {
    let sides: Vec<String> = SIDES.iter().map(u32::to_string).collect();
    format!("{} or {}", sides[..sides.len() - 1].join(", "), sides[sides.len() - 1])
}

fn sign(x: f32) -> f32 {
    if x >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// A unit direction's place on the octahedral map, in [0, 1]² ([`Grid`] gives the formula).
pub fn octahedral(d: Vec3) -> Vec2 {
    let p = d / (d.x.abs() + d.y.abs() + d.z.abs());
    let (a, b) = if p.y >= 0.0 { (p.x, p.z) } else { ((1.0 - p.z.abs()) * sign(p.x), (1.0 - p.x.abs()) * sign(p.z)) };
    Vec2::new(a * 0.5 + 0.5, b * 0.5 + 0.5)
}

/// The unit direction at a place on the octahedral map: the inverse of [`octahedral`].
pub fn from_octahedral(uv: Vec2) -> Vec3 {
    let (a, b) = (uv.x * 2.0 - 1.0, uv.y * 2.0 - 1.0);
    let y = 1.0 - a.abs() - b.abs();
    let fold = (-y).max(0.0);
    Vec3::new(a - sign(a) * fold, y, b - sign(b) * fold).normalize()
}

/// A g-buffer's visibility: each pixel's bits over one [`Grid`], pixel-major (`words()` words a
/// pixel, the cell `c` in bit `c % 32` of word `c / 32`). A set bit is a direction that sees the
/// environment.
#[derive(Clone, Debug, PartialEq)]
pub struct Visibility {
    pub grid: Grid,
    pub words: Vec<u32>,
}

impl Visibility {
    /// A pixel's words.
    pub fn pixel(&self, pixel: usize) -> &[u32] {
        let words = self.grid.words();
        &self.words[pixel * words..(pixel + 1) * words]
    }

    /// Whether the environment is seen from `pixel` along the unit world direction `direction`.
    pub fn seen(&self, pixel: usize, direction: Vec3) -> bool {
        let cell = self.grid.cell(direction);
        self.pixel(pixel)[cell / WORD_BITS] >> (cell % WORD_BITS) & 1 == 1
    }
}

/// Cosine-weighted integration over a grid's cells: each cell's directions and solid angles at
/// `SUB` × `SUB` points, so that the occlusion of a stored mask is its exact integral up to that
/// quadrature.
pub struct Quadrature {
    pub(crate) grid: Grid,
    /// Per cell: its sub-directions and their solid angles.
    pub(crate) points: Vec<[(Vec3, f32); SUB * SUB]>,
    /// Per cell: its centre.
    pub(crate) centres: Vec<Vec3>,
    /// The sine of the widest cell's radius: a cell whose centre is further below a horizon
    /// lies wholly under it.
    pub(crate) sin_radius: f32,
    /// The cosine of a quarter of that radius.
    pub(crate) cos_quarter_radius: f32,
}

const SUB: usize = 4;

impl Quadrature {
    /// On the octahedral map the un-normalised point q has |det(q, ∂q/∂u, ∂q/∂v)| = 4
    /// everywhere, so a patch of area du·dv spans 4·du·dv / |q|³ steradians.
    pub fn new(grid: Grid) -> Quadrature {
        let side = grid.side as usize;
        let step = 1.0 / (side * SUB) as f32;
        let radius = grid.cell_radius();
        let mut points = Vec::with_capacity(grid.cells());
        let mut centres = Vec::with_capacity(grid.cells());
        for cell in 0..grid.cells() {
            let (column, row) = (cell % side, cell / side);
            let mut cell_points = [(Vec3::ZERO, 0.0); SUB * SUB];
            for (k, point) in cell_points.iter_mut().enumerate() {
                let u = ((column * SUB + k % SUB) as f32 + 0.5) * step;
                let v = ((row * SUB + k / SUB) as f32 + 0.5) * step;
                let (a, b) = (u * 2.0 - 1.0, v * 2.0 - 1.0);
                let y = 1.0 - a.abs() - b.abs();
                let fold = (-y).max(0.0);
                let q = Vec3::new(a - sign(a) * fold, y, b - sign(b) * fold);
                let length = q.length();
                *point = (q / length, 4.0 * step * step / (length * length * length));
            }
            points.push(cell_points);
            centres.push(grid.centre(cell));
        }
        Quadrature { grid, points, centres, sin_radius: radius.sin(), cos_quarter_radius: (radius / 4.0).cos() }
    }

    /// The cosine-weighted share of the hemisphere about the unit normal `normal` that `words`
    /// (one pixel's bits) see: 1 where nothing occludes, 0 where everything does.
    pub fn occlusion(&self, words: &[u32], normal: Vec3) -> f32 {
        let mut seen = 0.0;
        for (cell, (points, &centre)) in self.points.iter().zip(&self.centres).enumerate() {
            if words[cell / WORD_BITS] >> (cell % WORD_BITS) & 1 == 0 {
                continue;
            }
            // A cell wholly below the horizon adds nothing: its centre is more than its radius below.
            if centre.dot(normal) < -self.sin_radius {
                continue;
            }
            seen += points.iter().map(|&(d, area)| d.dot(normal).max(0.0) * area).sum::<f32>();
        }
        seen / std::f32::consts::PI
    }
}

/// Each pixel's occlusion ([`Quadrature::occlusion`] about its normal): 1 on covered pixels of a
/// g-buffer without visibility, 0 on the background. The pixels are split between the cores.
pub fn occlusion(gbuffer: &crate::gbuffer::GBuffer) -> Vec<f32> {
    let covered = |p: usize| gbuffer.coverage[p] > 0.0;
    let Some(visibility) = &gbuffer.visibility else {
        return (0..gbuffer.pixel_count()).map(|p| if covered(p) { 1.0 } else { 0.0 }).collect();
    };
    let quadrature = Quadrature::new(visibility.grid);
    let mut out = vec![0.0; gbuffer.pixel_count()];
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let per_thread = out.len().div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        for (chunk, values) in out.chunks_mut(per_thread).enumerate() {
            let quadrature = &quadrature;
            scope.spawn(move || {
                for (k, value) in values.iter_mut().enumerate() {
                    let p = chunk * per_thread + k;
                    if covered(p) {
                        *value = quadrature.occlusion(visibility.pixel(p), Vec3::from(gbuffer.normal[p]));
                    }
                }
            });
        }
    });
    out
}

/// Per object, the share of its covered pixels whose visibility sees the environment along no
/// direction at all, so that they render black under any light: most often a visibility traced
/// from inside the surfaces. Empty without visibility.
pub fn blind_shares(gbuffer: &crate::gbuffer::GBuffer) -> std::collections::BTreeMap<u32, f32> {
    let mut counts: std::collections::BTreeMap<u32, (usize, usize)> = Default::default();
    let Some(visibility) = &gbuffer.visibility else { return Default::default() };
    for p in (0..gbuffer.pixel_count()).filter(|&p| gbuffer.coverage[p] > 0.0) {
        let (blind, all) = counts.entry(gbuffer.object_id[p]).or_default();
        *blind += usize::from(visibility.pixel(p).iter().all(|&w| w == 0));
        *all += 1;
    }
    counts.into_iter().map(|(id, (blind, all))| (id, blind as f32 / all as f32)).collect()
}

/// The share of environment samples, among those above a covered pixel's horizon, that its
/// visibility blocks: what a sampler that skipped blocked directions could save at most.
/// `sample` maps a point of the unit square to a world direction as the environment sampler
/// draws it; each covered pixel takes `per_side`² stratified points.
pub fn blocked_share(gbuffer: &crate::gbuffer::GBuffer, sample: impl Fn(Vec2) -> Vec3, per_side: u32) -> Option<f64> {
    let visibility = gbuffer.visibility.as_ref()?;
    let (mut blocked, mut above) = (0u64, 0u64);
    for p in (0..gbuffer.pixel_count()).filter(|&p| gbuffer.coverage[p] > 0.0) {
        let normal = Vec3::from(gbuffer.normal[p]);
        for k in 0..per_side * per_side {
            let u = Vec2::new((k % per_side) as f32 + 0.5, (k / per_side) as f32 + 0.5) / per_side as f32;
            let d = sample(u);
            if d.dot(normal) > 0.0 {
                above += 1;
                blocked += u64::from(!visibility.seen(p, d));
            }
        }
    }
    (above > 0).then(|| blocked as f64 / above as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn directions(n: usize) -> impl Iterator<Item = Vec3> {
        // A Fibonacci sphere: evenly spread, deterministic.
        let golden = std::f32::consts::PI * (3.0 - 5.0f32.sqrt());
        (0..n).map(move |i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).sqrt();
            let phi = golden * i as f32;
            Vec3::new(r * phi.cos(), y, r * phi.sin())
        })
    }

    #[test]
    fn the_map_round_trips_and_each_centre_is_in_its_own_cell() {
        for d in directions(5000) {
            let back = from_octahedral(octahedral(d));
            assert!((back - d).length() < 1e-5, "{d} came back as {back}");
        }
        for side in SIDES {
            let grid = Grid::new(side).unwrap();
            for cell in 0..grid.cells() {
                assert_eq!(grid.cell(grid.centre(cell)), cell, "side {side}");
            }
        }
    }

    #[test]
    fn the_pole_and_the_axes_fall_where_the_format_says() {
        let grid = Grid::new(16).unwrap();
        // +Y is the map's centre: the cell right of and below the middle.
        assert_eq!(grid.cell(Vec3::Y), 8 * 16 + 8);
        // −Y is the corners; (1, 1) after clamping.
        assert_eq!(grid.cell(Vec3::NEG_Y), 15 * 16 + 15);
        assert_eq!(grid.cell(Vec3::X), 8 * 16 + 15);
        assert_eq!(grid.cell(Vec3::Z), 15 * 16 + 8);
        assert_eq!(grid.cell(Vec3::NEG_Z), 8);
    }

    #[test]
    fn sides_and_words_name_each_other() {
        for side in SIDES {
            let grid = Grid::new(side).unwrap();
            assert_eq!(Grid::from_words(grid.words()), Some(grid));
        }
        assert_eq!(Grid::from_words(3), None);
        assert!(Grid::new(12).unwrap_err().contains("8, 16, 32 or 64"));
    }

    #[test]
    fn the_cells_cover_the_sphere_and_an_open_mask_is_unoccluded() {
        for side in SIDES {
            let quadrature = Quadrature::new(Grid::new(side).unwrap());
            let total: f32 = quadrature.points.iter().flatten().map(|&(_, area)| area).sum();
            assert!((total - 4.0 * std::f32::consts::PI).abs() < 1e-3, "side {side}: {total}");
            let open = vec![u32::MAX; quadrature.grid.words()];
            for n in directions(50) {
                let seen = quadrature.occlusion(&open, n);
                assert!((seen - 1.0).abs() < 2e-3, "side {side}, normal {n}: {seen}");
            }
        }
    }

    #[test]
    fn the_cell_radius_bounds_every_direction_in_a_cell() {
        let grid = Grid::new(16).unwrap();
        let radius = grid.cell_radius();
        for d in directions(20000) {
            let angle = d.dot(grid.centre(grid.cell(d))).clamp(-1.0, 1.0).acos();
            assert!(angle <= radius + 1e-5, "{d}: {angle} > {radius}");
        }
    }
}
