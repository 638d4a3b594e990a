//! Visibility traced when a production render is read: from its world positions (Blender's
//! Position pass, Arnold's P) through the scene's triangles in a glTF file, which lookdev's
//! Blender script writes beside its g-buffer and `--occluders` names for any other
//! (docs/formats.md#occluders). The result is cached, keyed by everything it is made from.
//!
//! A renderer's position is filtered over the pixel, so it lies near the surface the pixel sees
//! rather than on it, and it says nothing of the triangle. Each one is therefore moved onto the
//! nearest triangle along its view line, within a short reach, which gives the geometric normal
//! that rays leave along. A position with no triangle in reach (an edge pixel whose filtered
//! position floats between two surfaces) is traced from where it is, its shading normal standing
//! in for the geometric one.

use super::{trace_reporting, Grid, Mesh, SurfacePoint, Visibility};
use crate::asset::{geometry, Asset, Texels};
use crate::cache::{self, Entry};
use crate::gbuffer::source::occluders::Occluders;
use crate::gbuffer::GBuffer;
use crate::input::{self, Kind};
use crate::{Error, Result};
use glam::Vec3;
use std::path::Path;

/// The code whose change makes a cached visibility stale.
const SOURCES: [&str; 4] =
    [include_str!("mod.rs"), include_str!("trace.rs"), include_str!("mesh.rs"), include_str!("occluders.rs")];
const CACHED: Entry = Entry { kind: "visible", version: 1, max_payload: Kind::Cache.cap() };
/// The cache folder keeps at most this many bytes: a 1080p visibility is 265 MB at 32².
const FOLDER_BUDGET: u64 = 2 << 30;
/// How far along its view line a position may be moved onto a triangle, as a share of the
/// occluders' bounding diameter.
const REACH: f32 = 1e-3;
/// How far rays leave from the surface, as a share of the bounding diameter (as in the bake).
const OFFSET: f32 = 1e-4;
/// More positions than this share off every triangle, and the occluders are not the scene's.
const MOST_OFF: f32 = 0.5;

/// A traced visibility, with what the read reports of it.
pub struct Traced {
    pub visibility: Visibility,
    /// How it was made, for the line that says where each channel comes from.
    pub how: String,
    pub warnings: Vec<String>,
}

/// The visibility of `gbuffer` (read from `gbuffer_path`), traced over `grid` from its
/// `positions` through `occluders`, or loaded from the cache. A trace calls `progress(done,
/// total)` as it goes.
pub fn trace_positions(
    gbuffer: &GBuffer,
    gbuffer_path: &Path,
    positions: &[Vec3],
    occluders: &Occluders,
    grid: Grid,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Traced> {
    let file = &occluders.file;
    if !file.is_file() {
        return Err(Error::input_file(
            gbuffer_path,
            format!(
                "its occluders {} (from {}) are not there; render with --no-visibility to go without shadows",
                file.display(),
                occluders.from
            ),
        ));
    }
    let bytes = input::read(file, Kind::Gltf)?;
    let key = cache_key(gbuffer, positions, &bytes, grid);
    let path = cache::folder("visibility").map(|f| f.join(format!("{}.bits", cache::hex(&cache::hash128(&key)))));
    let expected = gbuffer.pixel_count() * grid.words();
    let cached = path.as_deref().and_then(|path| CACHED.load(path, &key)).filter(|p| p.len() == expected * 4);
    let name = file.file_name().map_or_else(|| file.display().to_string(), |n| n.to_string_lossy().into_owned());
    if let Some(payload) = cached {
        cache::touch(path.as_deref());
        let words = payload.chunks_exact(4).map(|w| u32::from_le_bytes(w.try_into().expect("4 bytes"))).collect();
        let how = format!("{name}, traced over {}² directions (cached)", grid.side());
        return Ok(Traced { visibility: Visibility { grid, words }, how, warnings: Vec::new() });
    }

    let asset = Asset::from_bytes(&bytes, file, Texels::Check)?;
    let scene = geometry::flatten(&asset, |_, _| {})?;
    let corners = |t: usize| [0, 1, 2].map(|k| Vec3::from(scene.vertices[3 * t + k].position));
    let mesh = Mesh::new((0..scene.vertices.len() / 3).map(corners));
    let diameter = 2.0 * scene.bounds.1.max(f32::MIN_POSITIVE);
    let (points, off) = surface_points(gbuffer, positions, &mesh, REACH * diameter);
    let covered = (0..gbuffer.pixel_count()).filter(|&p| gbuffer.coverage[p] >= 1.0 && points[p].is_some()).count();
    let mut warnings = Vec::new();
    if covered > 0 && off as f32 > MOST_OFF * covered as f32 {
        return Err(Error::input_file(
            gbuffer_path,
            format!(
                "{off} of its {covered} wholly covered pixels lie on none of the triangles of {}: are they the same scene, Y up, in the g-buffer's units?",
                file.display()
            ),
        ));
    }
    if off * 20 > covered {
        warnings.push(format!(
            "{}: {off} of {covered} wholly covered pixels lie on none of the triangles of {}; they are traced from their filtered positions",
            gbuffer_path.display(),
            file.display()
        ));
    }
    let visibility = trace_reporting(grid, &points, &mesh, OFFSET * diameter, progress);
    if let Some(path) = &path {
        let payload: Vec<u8> = visibility.words.iter().flat_map(|w| w.to_le_bytes()).collect();
        if payload.len() as u64 <= CACHED.max_payload {
            CACHED.store(path, &key, &payload);
            cache::prune(path, FOLDER_BUDGET);
        }
    }
    let how = format!("{name}, traced over {}² directions", grid.side());
    Ok(Traced { visibility, how, warnings })
}

/// Each covered pixel's surface point: its position moved onto the nearest triangle along its
/// view line within `reach`, with that triangle's normal facing the eye. Also gives how many
/// wholly covered pixels found no triangle (at edges, filtered positions may float).
fn surface_points(
    gbuffer: &GBuffer,
    positions: &[Vec3],
    mesh: &Mesh,
    reach: f32,
) -> (Vec<Option<SurfacePoint>>, usize) {
    let mut off = 0;
    let points = (0..gbuffer.pixel_count())
        .map(|p| {
            let position = positions[p];
            if gbuffer.coverage[p] == 0.0 || !position.is_finite() {
                return None;
            }
            let shading = Vec3::from(gbuffer.normal[p]);
            let view = Vec3::from(gbuffer.view[p]);
            let start = position + view * reach;
            let Some((t, triangle)) = mesh.nearest_hit(start, -view, 2.0 * reach) else {
                off += usize::from(gbuffer.coverage[p] >= 1.0);
                return Some(SurfacePoint { position, geometric: shading, shading });
            };
            let facing = mesh.normal(triangle);
            let geometric = match facing.dot(view) {
                d if d < 0.0 => -facing,
                d if d > 0.0 => facing,
                _ => shading,
            };
            Some(SurfacePoint { position: start - view * t, geometric, shading })
        })
        .collect();
    (points, off)
}

/// Everything a traced visibility is made from: the code, the grid, the occluder file, and the
/// pixels' positions, normals, view vectors and coverage.
fn cache_key(gbuffer: &GBuffer, positions: &[Vec3], occluders: &[u8], grid: Grid) -> Vec<u8> {
    let mut key = Vec::new();
    for source in SOURCES {
        key.extend_from_slice(&cache::hash128(source.as_bytes()));
    }
    key.extend_from_slice(&grid.side().to_le_bytes());
    key.extend_from_slice(&cache::hash128(occluders));
    let floats = |values: &mut dyn Iterator<Item = f32>| -> [u8; 16] {
        let bytes: Vec<u8> = values.flat_map(f32::to_le_bytes).collect();
        cache::hash128(&bytes)
    };
    key.extend_from_slice(&floats(&mut positions.iter().flat_map(|p| p.to_array())));
    key.extend_from_slice(&floats(&mut gbuffer.normal.iter().flatten().copied()));
    key.extend_from_slice(&floats(&mut gbuffer.view.iter().flatten().copied()));
    key.extend_from_slice(&floats(&mut gbuffer.coverage.iter().copied()));
    key
}
