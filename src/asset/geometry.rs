//! A scene's meshes as one list of world-space triangles, ready to draw: every node of the scene
//! with its full transform, every primitive as its own object, tangents from the file or
//! generated with MikkTSpace.
//!
//! Triangles are unindexed (three vertices each): MikkTSpace gives each corner of a triangle its
//! own tangent, which shared vertices could not hold. Transforms are applied here, so the
//! vertex shader only projects. A transform with a negative determinant mirrors the mesh, so its
//! triangles' winding is reversed to keep their front faces in front, and the bitangent sign is
//! flipped with it.

use super::Asset;
use crate::{Error, Result};
use bevy_mikktspace::{Geometry as MikkGeometry, TangentSpace};
use glam::{Mat3, Mat4, Vec3, Vec4};

/// One vertex as the bake's vertex shader reads it (`glsl/bake.vert`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    /// xyz, and w = the bitangent's sign; zero where there is no tangent frame.
    pub tangent: [f32; 4],
    pub uv0: [f32; 2],
    pub uv1: [f32; 2],
    /// COLOR_0, or white.
    pub color: [f32; 4],
}

/// One primitive of one node: an object of the g-buffer.
#[derive(Clone, Debug, PartialEq)]
pub struct Draw {
    /// The g-buffer object id (from 1; 0 is the background).
    pub object_id: u32,
    /// "node/mesh", with "#primitive" when the mesh has more than one.
    pub name: String,
    /// The glTF material index; `None` for glTF's default material.
    pub material: Option<usize>,
    pub first_vertex: u32,
    pub vertex_count: u32,
    pub has_colors: bool,
}

/// Every triangle of a scene.
pub struct Geometry {
    pub vertices: Vec<Vertex>,
    pub draws: Vec<Draw>,
    /// A sphere around every vertex: centre and radius.
    pub bounds: (Vec3, f32),
    /// Skinned or morphed meshes, which are baked in their rest pose.
    pub posed_meshes: usize,
}

/// A node of the scene with the transform from its space to the world.
pub struct PlacedNode<'a> {
    pub node: gltf::Node<'a>,
    pub world: Mat4,
}

/// Nested deeper than this, a node hierarchy is taken to be a cycle.
const MAX_DEPTH: usize = 256;

/// The scene a bake shows: the file's default scene, else its first.
pub fn scene<'a>(asset: &'a Asset) -> Result<gltf::Scene<'a>> {
    asset
        .document
        .default_scene()
        .or_else(|| asset.document.scenes().next())
        .ok_or_else(|| Error::input_file(&asset.path, "the asset has no scene"))
}

/// Every node of the scene, parents before children, with its world transform.
pub fn placed_nodes<'a>(asset: &'a Asset) -> Result<Vec<PlacedNode<'a>>> {
    let mut placed = Vec::new();
    let mut stack: Vec<(gltf::Node<'a>, Mat4, usize)> =
        scene(asset)?.nodes().map(|node| (node, Mat4::IDENTITY, 0)).collect::<Vec<_>>();
    stack.reverse();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > MAX_DEPTH {
            return Err(Error::input_file(&asset.path, "the node hierarchy loops (or is nested too deeply)"));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(Error::input_file(
                &asset.path,
                format!("node {} has a transform that is not finite", node.index()),
            ));
        }
        let mut children: Vec<_> = node.children().map(|child| (child, world, depth + 1)).collect();
        children.reverse();
        stack.extend(children);
        placed.push(PlacedNode { node, world });
    }
    Ok(placed)
}

/// The scene's primitives in draw order, with their nodes and transforms.
pub fn primitives<'a>(asset: &'a Asset) -> Result<Vec<(PlacedNode<'a>, gltf::Primitive<'a>)>> {
    let mut out = Vec::new();
    for placed in placed_nodes(asset)? {
        if let Some(mesh) = placed.node.mesh() {
            for primitive in mesh.primitives() {
                out.push((PlacedNode { node: placed.node.clone(), world: placed.world }, primitive));
            }
        }
    }
    if out.is_empty() {
        return Err(Error::input_file(&asset.path, "the scene has no meshes to bake"));
    }
    Ok(out)
}

/// Reads and flattens every primitive of the scene. `progress(done, total)` follows the
/// primitives.
pub fn flatten(asset: &Asset, mut progress: impl FnMut(usize, usize)) -> Result<Geometry> {
    let primitives = primitives(asset)?;
    let mut vertices = Vec::new();
    let mut draws = Vec::new();
    let mut posed_meshes = 0;
    for (index, (placed, primitive)) in primitives.iter().enumerate() {
        let mesh = placed.node.mesh().expect("primitives come from meshes");
        if placed.node.skin().is_some() || primitive.morph_targets().len() > 0 {
            posed_meshes += 1;
        }
        let first_vertex = vertices.len() as u32;
        let triangles = read_primitive(asset, &mesh, primitive)?;
        let has_colors = triangles.has_colors;
        place(triangles.vertices, placed.world, &mut vertices);
        let node_name = placed.node.name().map_or_else(|| format!("node{}", placed.node.index()), str::to_string);
        let mesh_name = mesh.name().map_or_else(|| format!("mesh{}", mesh.index()), str::to_string);
        let name = if mesh.primitives().len() > 1 {
            format!("{node_name}/{mesh_name}#{}", primitive.index())
        } else {
            format!("{node_name}/{mesh_name}")
        };
        draws.push(Draw {
            object_id: index as u32 + 1,
            name,
            material: primitive.material().index(),
            first_vertex,
            vertex_count: vertices.len() as u32 - first_vertex,
            has_colors,
        });
        progress(index + 1, primitives.len());
    }
    if vertices.is_empty() {
        return Err(Error::input_file(&asset.path, "the scene's meshes have no triangles"));
    }
    let bounds = bounding_sphere(&vertices);
    Ok(Geometry { vertices, draws, bounds, posed_meshes })
}

/// A primitive's triangles in its mesh's space, three vertices each.
struct Triangles {
    vertices: Vec<Vertex>,
    has_colors: bool,
}

fn read_primitive(asset: &Asset, mesh: &gltf::Mesh, primitive: &gltf::Primitive) -> Result<Triangles> {
    let label = || match mesh.name() {
        Some(name) => format!("mesh {} '{name}' primitive {}", mesh.index(), primitive.index()),
        None => format!("mesh {} primitive {}", mesh.index(), primitive.index()),
    };
    let error = |problem: String| Error::input_file(&asset.path, format!("{}: {problem}", label()));
    let reader = primitive.reader(|buffer| Some(&asset.buffers[buffer.index()]));
    let positions: Vec<[f32; 3]> =
        reader.read_positions().ok_or_else(|| error("has no POSITION attribute".into()))?.collect();
    let count = positions.len();
    let indices: Vec<u32> = match reader.read_indices() {
        Some(indices) => indices.into_u32().collect(),
        None => (0..count as u32).collect(),
    };
    if let Some(bad) = indices.iter().find(|&&i| i as usize >= count) {
        return Err(error(format!("index {bad} is past its {count} vertices")));
    }
    let corners = triangle_list(primitive.mode(), &indices).map_err(error)?;
    let attribute = |len: usize, what: &str| {
        if len == count {
            Ok(())
        } else {
            Err(error(format!("{what} has {len} values for {count} vertices")))
        }
    };
    let normals: Option<Vec<[f32; 3]>> = reader.read_normals().map(Iterator::collect);
    let tangents: Option<Vec<[f32; 4]>> = reader.read_tangents().map(Iterator::collect);
    let uv0: Option<Vec<[f32; 2]>> = reader.read_tex_coords(0).map(|t| t.into_f32().collect());
    let uv1: Option<Vec<[f32; 2]>> = reader.read_tex_coords(1).map(|t| t.into_f32().collect());
    let mut colors: Option<Vec<[f32; 4]>> = reader.read_colors(0).map(|c| c.into_rgba_f32().collect());
    let accessor = |semantic: gltf::Semantic| {
        let name = semantic.to_string();
        primitive.get(&semantic).map_or(name.clone(), |a| format!("{name} (accessor {})", a.index()))
    };
    use gltf::Semantic;
    let finite = |values: Option<&[f32]>, semantic: Semantic| match values {
        Some(values) if !values.iter().all(|v| v.is_finite()) => {
            Err(error(format!("{} has values that are not finite (NaN or infinite)", accessor(semantic))))
        }
        _ => Ok(()),
    };
    finite(normals.as_deref().map(|v| v.as_flattened()), Semantic::Normals)?;
    finite(tangents.as_deref().map(|v| v.as_flattened()), Semantic::Tangents)?;
    finite(uv0.as_deref().map(|v| v.as_flattened()), Semantic::TexCoords(0))?;
    finite(uv1.as_deref().map(|v| v.as_flattened()), Semantic::TexCoords(1))?;
    finite(colors.as_deref().map(|v| v.as_flattened()), Semantic::Colors(0))?;
    // A vertex colour is a multiplier in [0, 1] (glTF 2.0, 3.7.2.1), and lookdev bakes it into
    // masks, which hold [0, 1]: more is clamped, and said.
    if let Some(colors) = colors.as_mut().filter(|c| c.iter().flatten().any(|v| !(0.0..=1.0).contains(v))) {
        let (low, high) = colors.iter().flatten().fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
        crate::warn(format!(
            "{}: {}: {} holds values from {} to {}, outside [0, 1]; clamped",
            asset.path.display(),
            label(),
            accessor(Semantic::Colors(0)),
            crate::error::number_text(low),
            crate::error::number_text(high)
        ));
        colors.iter_mut().flatten().for_each(|v| *v = v.clamp(0.0, 1.0));
    }
    for (len, what) in [
        (normals.as_ref().map(Vec::len), "NORMAL"),
        (tangents.as_ref().map(Vec::len), "TANGENT"),
        (uv0.as_ref().map(Vec::len), "TEXCOORD_0"),
        (uv1.as_ref().map(Vec::len), "TEXCOORD_1"),
        (colors.as_ref().map(Vec::len), "COLOR_0"),
    ] {
        if let Some(len) = len {
            attribute(len, what)?;
        }
    }
    let mut vertices: Vec<Vertex> = corners
        .iter()
        .map(|&i| {
            let i = i as usize;
            Vertex {
                position: positions[i],
                normal: normals.as_ref().map_or([0.0; 3], |n| n[i]),
                tangent: tangents.as_ref().map_or([0.0; 4], |t| t[i]),
                uv0: uv0.as_ref().map_or([0.0; 2], |t| t[i]),
                uv1: uv1.as_ref().map_or([0.0; 2], |t| t[i]),
                color: colors.as_ref().map_or([1.0; 4], |c| c[i]),
            }
        })
        .collect();
    if vertices.iter().any(|v| !v.position.iter().all(|c| c.is_finite())) {
        return Err(error("has positions that are not finite".into()));
    }
    if normals.is_none() {
        flat_normals(&mut vertices);
    }
    if tangents.is_none() {
        // MikkTSpace follows the normal map's texcoords, as the bake samples it: its set (set 0
        // unless told) under its KHR_texture_transform, so the frame turns with the texture.
        let material = primitive.material();
        let normal_map = super::textures::material_textures(&material)[super::textures::Slot::Normal as usize];
        let (set, transform) = normal_map.map_or((0, None), |r| (r.tex_coord, Some(r.transform)));
        let has_set = if set == 1 { uv1.is_some() } else { uv0.is_some() };
        if has_set {
            generate_tangents(&mut vertices, set == 1, transform);
        }
    }
    Ok(Triangles { vertices, has_colors: colors.is_some() })
}

/// The corners of a primitive's triangles, three per triangle, from its indices.
fn triangle_list(mode: gltf::mesh::Mode, indices: &[u32]) -> std::result::Result<Vec<u32>, String> {
    use gltf::mesh::Mode;
    match mode {
        Mode::Triangles => Ok(indices[..indices.len() / 3 * 3].to_vec()),
        // Every other strip triangle is reversed to keep one winding.
        Mode::TriangleStrip => Ok((2..indices.len())
            .flat_map(|i| {
                let (a, b, c) = (indices[i - 2], indices[i - 1], indices[i]);
                if i % 2 == 0 {
                    [a, b, c]
                } else {
                    [b, a, c]
                }
            })
            .collect()),
        Mode::TriangleFan => Ok((2..indices.len()).flat_map(|i| [indices[i - 1], indices[i], indices[0]]).collect()),
        other => Err(format!(
            "draws {}, and lookdev bakes only triangles (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN)",
            mode_name(other)
        )),
    }
}

fn mode_name(mode: gltf::mesh::Mode) -> &'static str {
    use gltf::mesh::Mode;
    match mode {
        Mode::Points => "POINTS",
        Mode::Lines => "LINES",
        Mode::LineLoop => "LINE_LOOP",
        Mode::LineStrip => "LINE_STRIP",
        Mode::Triangles => "TRIANGLES",
        Mode::TriangleStrip => "TRIANGLE_STRIP",
        Mode::TriangleFan => "TRIANGLE_FAN",
    }
}

/// glTF: a primitive without normals is shaded flat.
fn flat_normals(vertices: &mut [Vertex]) {
    for triangle in vertices.chunks_exact_mut(3) {
        let [a, b, c] = [0, 1, 2].map(|i| Vec3::from(triangle[i].position));
        let normal = (b - a).cross(c - a).normalize_or_zero();
        for vertex in triangle {
            vertex.normal = normal.to_array();
        }
    }
}

/// MikkTSpace tangents for unindexed triangles, from texcoord set 0 (or 1) under `transform`
/// (the rows of a 2×3 texture transform), with the bitangent pointing up the image.
fn generate_tangents(vertices: &mut [Vertex], second_set: bool, transform: Option<[[f32; 3]; 2]>) {
    struct Mesh<'a> {
        vertices: &'a mut [Vertex],
        second_set: bool,
        transform: [[f32; 3]; 2],
    }
    impl MikkGeometry for Mesh<'_> {
        fn num_faces(&self) -> usize {
            self.vertices.len() / 3
        }
        fn num_vertices_of_face(&self, _face: usize) -> usize {
            3
        }
        fn position(&self, face: usize, vert: usize) -> [f32; 3] {
            self.vertices[face * 3 + vert].position
        }
        fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
            self.vertices[face * 3 + vert].normal
        }
        fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
            let v = &self.vertices[face * 3 + vert];
            let [u, v] = if self.second_set { v.uv1 } else { v.uv0 };
            let [row0, row1] = self.transform;
            let (s, t) = (row0[0] * u + row0[1] * v + row0[2], row1[0] * u + row1[1] * v + row1[2]);
            // glTF's v runs down the image and its normal maps' +Y points up it: MikkTSpace
            // works with v up, as the tangents exporters write do.
            [s, 1.0 - t]
        }
        fn set_tangent(&mut self, tangent: Option<TangentSpace>, face: usize, vert: usize) {
            // A corner MikkTSpace could not give a frame keeps none; the bake then builds one from N.
            if let Some(space) = tangent {
                let [x, y, z] = space.tangent();
                let sign = if space.is_orientation_preserving() { 1.0 } else { -1.0 };
                self.vertices[face * 3 + vert].tangent = [x, y, z, sign];
            }
        }
    }
    // A mesh MikkTSpace rejects (nothing but degenerate triangles) keeps no tangents.
    let transform = transform.unwrap_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let _ = bevy_mikktspace::generate_tangents(&mut Mesh { vertices, second_set, transform });
}

/// Appends a primitive's vertices in world space.
fn place(vertices: Vec<Vertex>, world: Mat4, out: &mut Vec<Vertex>) {
    let linear = Mat3::from_mat4(world);
    let determinant = linear.determinant();
    let normal_matrix = if determinant.abs() > f32::MIN_POSITIVE { linear.inverse().transpose() } else { linear };
    let mirrored = determinant < 0.0;
    let transform = |v: &Vertex| {
        let tangent = Vec4::from(v.tangent);
        let t = (linear * tangent.truncate()).normalize_or_zero();
        let sign = if mirrored { -tangent.w } else { tangent.w };
        Vertex {
            position: world.transform_point3(Vec3::from(v.position)).to_array(),
            normal: (normal_matrix * Vec3::from(v.normal)).normalize_or_zero().to_array(),
            tangent: [t.x, t.y, t.z, sign],
            ..*v
        }
    };
    for triangle in vertices.chunks_exact(3) {
        let corners = if mirrored { [0, 2, 1] } else { [0, 1, 2] };
        out.extend(corners.map(|i| transform(&triangle[i])));
    }
}

/// A sphere around every vertex: the box's centre and the farthest vertex from it.
fn bounding_sphere(vertices: &[Vertex]) -> (Vec3, f32) {
    let (min, max) = vertices.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), v| {
        let p = Vec3::from(v.position);
        (lo.min(p), hi.max(p))
    });
    let centre = (min + max) * 0.5;
    let radius = vertices.iter().map(|v| Vec3::from(v.position).distance(centre)).fold(0.0f32, f32::max);
    (centre, radius.max(1e-6))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_become_triangles_with_one_winding() {
        use gltf::mesh::Mode;
        assert_eq!(triangle_list(Mode::TriangleStrip, &[0, 1, 2, 3]).unwrap(), [0, 1, 2, 2, 1, 3]);
        assert_eq!(triangle_list(Mode::TriangleFan, &[0, 1, 2, 3]).unwrap(), [1, 2, 0, 2, 3, 0]);
        assert_eq!(triangle_list(Mode::Triangles, &[0, 1, 2, 3]).unwrap(), [0, 1, 2]);
        let lines = triangle_list(Mode::Lines, &[0, 1]).unwrap_err();
        assert!(lines.contains("draws LINES"), "{lines}");
    }

    #[test]
    fn a_mirroring_transform_keeps_front_faces_and_outward_normals() {
        let triangle = vec![
            Vertex {
                position: [0.0, 0.0, 0.0],
                normal: [0.0, 0.0, 1.0],
                tangent: [1.0, 0.0, 0.0, 1.0],
                ..Default::default()
            },
            Vertex {
                position: [1.0, 0.0, 0.0],
                normal: [0.0, 0.0, 1.0],
                tangent: [1.0, 0.0, 0.0, 1.0],
                ..Default::default()
            },
            Vertex {
                position: [0.0, 1.0, 0.0],
                normal: [0.0, 0.0, 1.0],
                tangent: [1.0, 0.0, 0.0, 1.0],
                ..Default::default()
            },
        ];
        let mut out = Vec::new();
        place(triangle, Mat4::from_scale(Vec3::new(-2.0, 1.0, 1.0)), &mut out);
        let [a, b, c] = [0, 1, 2].map(|i| Vec3::from(out[i].position));
        let geometric = (b - a).cross(c - a).normalize();
        assert_eq!(geometric, Vec3::Z, "the winding still faces +Z");
        assert_eq!(out[0].normal, [0.0, 0.0, 1.0]);
        assert_eq!(out[0].tangent, [-1.0, 0.0, 0.0, -1.0], "the tangent is mirrored and its bitangent sign flips");
    }
}
