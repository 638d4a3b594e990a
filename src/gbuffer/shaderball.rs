//! The built-in scene: a shader ball on a pedestal, ray cast analytically into a g-buffer.
//!
//! Each pixel is sampled on a regular 4×4 grid (regular, not jittered, so the output is
//! deterministic and identical on every machine). Coverage is the fraction of subsamples that hit;
//! view vectors are averaged over the hits and renormalised; the object ID is the one most hits
//! saw. The normal and tangent are averaged over the hits on one surface only, the one of that
//! object that most hits saw: where two surfaces meet in a pixel (a crease, or a silhouette
//! against another surface), an average of their normals faces a way neither does, and its
//! reflection shows light that neither surface sees. Masks are filtered over the pixel's
//! footprint on the surface (see `pixel_masks` and `procedural`).

use std::collections::BTreeMap;

use glam::Vec3;

use super::frame::tangent_or_stable;
use super::procedural::{masks_at, Footprint, MASK_NAMES};
use super::scene::Occluders;
use super::scene::{
    around_axis, height_span, trace, Hit, BALL_ID, BALL_NAME, CAMERA_DISTANCE, FIELD_OF_VIEW_DEGREES, PEDESTAL_ID,
    PEDESTAL_NAME, SURFACES,
};
use super::GBuffer;
use crate::visibility::{self, Grid, SurfacePoint};

/// Subsamples per pixel along each axis, and in all.
const GRID: usize = 4;
const SUBSAMPLES: usize = GRID * GRID;
/// A footprint more than this many head-on pixels wide counts as stretched (the surface is
/// turned more than about 75° away from the eye, 1/cos 75° ≈ 4): its masks are supersampled.
const STRETCHED: f32 = 4.0;
/// The built-in scene's visibility grid: 256 directions, within 1% of exact occlusion on the
/// analytic test scenes, at a quarter of the default's cost (the scene is made for every render).
const BUILTIN_VISIBILITY_SIDE: u32 = 16;
/// How far off its surface a visibility ray leaves: well above the float error of a hit on the
/// unit ball, well below any gap in the scene.
const SURFACE_OFFSET: f32 = 1e-4;
/// Object IDs that can appear, for per-pixel tallies (0 is background).
const OBJECT_IDS: [u32; 2] = [BALL_ID, PEDESTAL_ID];

impl GBuffer {
    /// The built-in look-dev scene at `width` × `height` (1024 × 1024 is the usual size).
    ///
    /// - Camera: eye at (0, 0, 5.5) looking exactly toward −Z, a 30° field of view across the
    ///   shorter side (vertical for a square or wide image), square pixels. The image centre is
    ///   the direction −Z.
    /// - Object 1 "ball": a unit sphere at the origin, centred in the frame.
    /// - Object 2 "pedestal": a neck (radius 0.42) on a round foot (radius 0.7, bottom at
    ///   y = −1.2) under the ball.
    /// - Tangents run around the +Y axis (the ball's latitude circles).
    /// - Visibility on a grid 16 cells a side, traced against the scene
    ///   itself from the hit of each pixel's main surface nearest its centre: the ball shades
    ///   the pedestal's foot, and the pedestal the ball's underside.
    /// - Masks, all functions of world position: `stripes` (latitude bands every 0.36 in Y),
    ///   `grunge` (thresholded fBm value noise), `gradient` (0 at each object's lowest point, 1
    ///   at its highest).
    /// - Background pixels: coverage 0, object 0, V = −(camera ray), so the renderer can show the
    ///   environment behind the objects.
    ///
    /// A zero width or height is raised to 1. The result is deterministic.
    pub fn shaderball(width: u32, height: u32) -> GBuffer {
        GBuffer::shaderball_with(width, height, true)
    }

    /// The built-in scene, with its visibility only when `visibility` is set (tracing it is most
    /// of the scene's cost).
    pub fn shaderball_with(width: u32, height: u32, visibility: bool) -> GBuffer {
        let camera = Camera::new(width.max(1), height.max(1));
        let pixels = render(&camera);

        let masks = MASK_NAMES
            .iter()
            .enumerate()
            .map(|(index, name)| (name.to_string(), pixels.iter().map(|p| p.masks[index]).collect()))
            .collect();
        GBuffer {
            width: camera.width,
            height: camera.height,
            normal: pixels.iter().map(|p| p.normal.to_array()).collect(),
            view: pixels.iter().map(|p| p.view.to_array()).collect(),
            tangent: pixels.iter().map(|p| p.tangent.to_array()).collect(),
            coverage: pixels.iter().map(|p| p.coverage).collect(),
            object_id: pixels.iter().map(|p| p.object_id).collect(),
            masks,
            maps: BTreeMap::new(),
            object_names: BTreeMap::from([(BALL_ID, BALL_NAME.to_string()), (PEDESTAL_ID, PEDESTAL_NAME.to_string())]),
            mask_names: BTreeMap::new(),
            visibility: visibility.then(|| {
                visibility::trace(
                    Grid::new(BUILTIN_VISIBILITY_SIDE).expect("a listed side"),
                    &pixels.iter().map(|p| p.surface).collect::<Vec<_>>(),
                    &Occluders,
                    SURFACE_OFFSET,
                )
            }),
            has_view: true,
            has_tangent: true,
            supersample: 1,
        }
    }
}

/// A pinhole camera at (0, 0, CAMERA_DISTANCE), looking toward −Z with +Y up.
struct Camera {
    width: u32,
    height: u32,
    eye: Vec3,
    /// tan(fov/2): the image-plane half height at distance 1.
    half_height: f32,
    aspect: f32,
}

impl Camera {
    fn new(width: u32, height: u32) -> Camera {
        // The field of view spans the shorter side, so a tall image frames the scene as a
        // square one does, with more above and below, rather than cropping the ball's sides.
        let aspect = width as f32 / height as f32;
        Camera {
            width,
            height,
            eye: Vec3::new(0.0, 0.0, CAMERA_DISTANCE),
            half_height: (FIELD_OF_VIEW_DEGREES.to_radians() * 0.5).tan() / aspect.min(1.0),
            aspect,
        }
    }

    /// The unit ray through image position (x, y) in pixels, (0,0) the top-left corner.
    fn ray(&self, x: f32, y: f32) -> Vec3 {
        let ndc_x = 2.0 * x / self.width as f32 - 1.0;
        let ndc_y = 1.0 - 2.0 * y / self.height as f32;
        Vec3::new(ndc_x * self.half_height * self.aspect, ndc_y * self.half_height, -1.0).normalize()
    }

    /// The angle one pixel subtends at the image centre, for mask filter widths.
    fn pixel_angle(&self) -> f32 {
        2.0 * self.half_height / self.height as f32
    }
}

/// One finished pixel.
#[derive(Clone, Copy)]
struct Pixel {
    normal: Vec3,
    view: Vec3,
    tangent: Vec3,
    coverage: f32,
    object_id: u32,
    masks: [f32; 3],
    /// Where the main surface's subsample nearest the pixel's centre hit it: what the pixel's
    /// visibility is traced from.
    surface: Option<SurfacePoint>,
}

/// A background pixel, before its view vector is known.
impl Default for Pixel {
    fn default() -> Pixel {
        Pixel {
            normal: Vec3::Z, // the file format's placeholder normal
            view: Vec3::Z,
            tangent: Vec3::X,
            coverage: 0.0,
            object_id: 0,
            masks: [0.0; 3],
            surface: None,
        }
    }
}

/// All pixels, row-major. Rows are split into one contiguous band per thread; every pixel is
/// computed independently, so the result does not depend on the thread count.
fn render(camera: &Camera) -> Vec<Pixel> {
    let width = camera.width as usize;
    let height = camera.height as usize;
    let mut pixels = vec![Pixel::default(); width * height];
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(height);
    let rows_per_band = height.div_ceil(threads);
    std::thread::scope(|scope| {
        for (band, band_pixels) in pixels.chunks_mut(rows_per_band * width).enumerate() {
            scope.spawn(move || {
                let first_row = band * rows_per_band;
                for (i, pixel) in band_pixels.iter_mut().enumerate() {
                    *pixel = shade_pixel(camera, i % width, first_row + i / width);
                }
            });
        }
    });
    pixels
}

/// Sums over the subsamples of one pixel that hit one object, and the box around their hits.
#[derive(Clone, Copy)]
struct ObjectTally {
    hits: usize,
    position: Vec3,
    view: Vec3,
    lowest: Vec3,
    highest: Vec3,
}

impl Default for ObjectTally {
    fn default() -> ObjectTally {
        ObjectTally {
            hits: 0,
            position: Vec3::ZERO,
            view: Vec3::ZERO,
            lowest: Vec3::INFINITY,
            highest: Vec3::NEG_INFINITY,
        }
    }
}

/// Sums over the subsamples of one pixel that hit one surface (see [`Hit::surface`]).
#[derive(Clone, Copy, Default)]
struct SurfaceTally {
    hits: usize,
    object_id: u32,
    surface: u32,
    normal: Vec3,
    /// Summed unnormalised: within a pixel the lengths barely differ, and the sum is made unit
    /// and orthogonal to the pixel's normal at the end.
    tangent: Vec3,
}

impl SurfaceTally {
    fn add(&mut self, hit: &Hit) {
        self.hits += 1;
        self.object_id = hit.object_id;
        self.surface = hit.surface;
        self.normal += hit.normal;
        self.tangent += around_axis(hit.position);
    }
}

impl ObjectTally {
    /// Adds one hit; `view` is the unit vector back along its ray, which is exactly the direction
    /// from the hit toward the eye.
    fn add(&mut self, hit: &Hit, view: Vec3) {
        self.hits += 1;
        self.position += hit.position;
        self.view += view;
        self.lowest = self.lowest.min(hit.position);
        self.highest = self.highest.max(hit.position);
    }

    /// The world-space extent of this object's part of the pixel, per axis. The subsamples
    /// span 3/4 of the pixel (from 1/8 to 7/8), hence the scale.
    fn extent(&self) -> Vec3 {
        (self.highest - self.lowest) * (GRID as f32 / (GRID - 1) as f32)
    }
}

fn shade_pixel(camera: &Camera, x: usize, y: usize) -> Pixel {
    let mut hits = [None; SUBSAMPLES];
    let mut tallies = [ObjectTally::default(); OBJECT_IDS.len()];
    let mut surfaces = [SurfaceTally::default(); SURFACES];
    let mut background_view = Vec3::ZERO;
    for (s, hit) in hits.iter_mut().enumerate() {
        let offset = |s: usize| (s as f32 + 0.5) / GRID as f32;
        let direction = camera.ray(x as f32 + offset(s % GRID), y as f32 + offset(s / GRID));
        *hit = trace(camera.eye, direction);
        match hit {
            Some(hit) => {
                tallies[slot(hit.object_id)].add(hit, -direction);
                surfaces[hit.surface as usize].add(hit);
            }
            None => background_view -= direction,
        }
    }

    let hit_count: usize = tallies.iter().map(|t| t.hits).sum();
    if hit_count == 0 {
        let view = background_view.normalize();
        return Pixel { view, ..Pixel::default() };
    }
    let object_id = majority_object(&tallies);
    let surface = main_surface(&surfaces, object_id);
    let normal = surface.normal.normalize_or(Vec3::Z);
    // The subsamples nearest the centre come first in this order (the middle four, then the rest).
    let nearest_first = [5, 6, 9, 10, 1, 2, 4, 7, 8, 11, 13, 14, 0, 3, 12, 15];
    let surface_point = nearest_first
        .iter()
        .filter_map(|&s| hits[s])
        .find(|hit| hit.surface == surface.surface)
        .map(|hit| SurfacePoint { position: hit.position, geometric: hit.normal, shading: normal });
    Pixel {
        normal,
        view: tallies.iter().map(|t| t.view).sum::<Vec3>().normalize_or(Vec3::Z),
        tangent: tangent_or_stable(normal, surface.tangent),
        coverage: hit_count as f32 / SUBSAMPLES as f32,
        object_id,
        masks: pixel_masks(camera, &tallies, &hits, hit_count),
        surface: surface_point,
    }
}

/// The tally slot of an object ID ([`trace`] only returns IDs from [`OBJECT_IDS`]).
fn slot(object_id: u32) -> usize {
    OBJECT_IDS.iter().position(|&id| id == object_id).unwrap_or(0)
}

/// The object with the most hits; on a tie, the lower ID (a fixed rule keeps output stable).
fn majority_object(tallies: &[ObjectTally; OBJECT_IDS.len()]) -> u32 {
    let mut best = (0, 0);
    for (&id, tally) in OBJECT_IDS.iter().zip(tallies) {
        if tally.hits > best.1 {
            best = (id, tally.hits);
        }
    }
    best.0
}

/// The surface of `object_id` with the most hits; on a tie, the lower-numbered one.
fn main_surface(surfaces: &[SurfaceTally; SURFACES], object_id: u32) -> SurfaceTally {
    let mut best = SurfaceTally::default();
    for surface in surfaces.iter().filter(|s| s.object_id == object_id) {
        if surface.hits > best.hits {
            best = *surface;
        }
    }
    best
}

/// Masks averaged over the objects in the pixel, weighted by hits.
///
/// Where an object's part of the pixel is roughly as wide as the pixel seen head on, its masks
/// are taken once, at the centroid of its hits, filtered over the box its hits span. That suits
/// the stripes and the gradient, which are box-filtered in closed form, and is close for the
/// noise. Near silhouettes a pixel spans a long strip of surface, and the thresholded noise
/// would filter to its threshold of the mean rather than the mean coverage of grime; there each
/// hit is evaluated with its own, smaller footprint, and the results averaged.
fn pixel_masks(
    camera: &Camera,
    tallies: &[ObjectTally; OBJECT_IDS.len()],
    hits: &[Option<Hit>; SUBSAMPLES],
    hit_count: usize,
) -> [f32; 3] {
    let mut masks = [0.0; 3];
    for (&object_id, tally) in OBJECT_IDS.iter().zip(tallies).filter(|(_, t)| t.hits > 0) {
        let centroid = tally.position / tally.hits as f32;
        // A pixel with a single hit has no spread to measure, so never go below head-on size.
        let head_on = camera.eye.distance(centroid) * camera.pixel_angle();
        let extent = tally.extent().max(Vec3::splat(head_on));
        let span = height_span(object_id);
        let object_masks = if extent.max_element() <= STRETCHED * head_on {
            masks_at(centroid, Footprint { extent }, span)
        } else {
            let per_hit = Footprint { extent: (extent / GRID as f32).max(Vec3::splat(head_on / GRID as f32)) };
            let own_hits = hits.iter().flatten().filter(|hit| hit.object_id == object_id);
            let total = own_hits.fold([0.0; 3], |sum, hit| add(sum, masks_at(hit.position, per_hit, span)));
            total.map(|m| m / tally.hits as f32)
        };
        let weight = tally.hits as f32 / hit_count as f32;
        masks = add(masks, object_masks.map(|m| m * weight));
    }
    masks
}

fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
