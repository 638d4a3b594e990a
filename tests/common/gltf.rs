//! glTF files the tests write themselves: meshes with analytic normals, materials, textures,
//! cameras and node hierarchies, written as `.gltf` with a `.bin` beside it, or as `.glb`.

use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// One primitive's vertices and triangles, in its mesh's space.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    /// TEXCOORD_1, where the primitive has a second set.
    pub uvs1: Option<Vec<[f32; 2]>>,
    pub tangents: Option<Vec<[f32; 4]>>,
    pub colors: Option<Vec<[f32; 4]>>,
    pub indices: Vec<u32>,
}

impl Mesh {
    /// Adds a triangle, turned so that it winds counter-clockwise seen from `outward`, and left
    /// out when degenerate.
    fn triangle(&mut self, [a, b, c]: [u32; 3], outward: [f32; 3]) {
        let p = |i: u32| self.positions[i as usize];
        let (pa, pb, pc) = (p(a), p(b), p(c));
        let e1 = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
        let e2 = [pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]];
        let cross = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let facing = cross[0] * outward[0] + cross[1] * outward[1] + cross[2] * outward[2];
        let area = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
        if area < 1e-9 {
            return;
        }
        self.indices.extend(if facing > 0.0 { [a, b, c] } else { [a, c, b] });
    }
}

/// A sphere of `radius` about the origin, poles on ±Y, with smooth analytic normals and
/// longitude-latitude texcoords.
pub fn uv_sphere(radius: f32, segments: u32, rings: u32) -> Mesh {
    let mut mesh = Mesh::default();
    for ring in 0..=rings {
        let theta = std::f32::consts::PI * ring as f32 / rings as f32;
        for segment in 0..=segments {
            let phi = 2.0 * std::f32::consts::PI * segment as f32 / segments as f32;
            let n = [theta.sin() * phi.sin(), theta.cos(), theta.sin() * phi.cos()];
            mesh.positions.push(n.map(|c| c * radius));
            mesh.normals.push(n);
            mesh.uvs.push([segment as f32 / segments as f32, ring as f32 / rings as f32]);
        }
    }
    let row = segments + 1;
    for ring in 0..rings {
        for segment in 0..segments {
            let (a, b, c, d) = (
                ring * row + segment,
                (ring + 1) * row + segment,
                (ring + 1) * row + segment + 1,
                ring * row + segment + 1,
            );
            let centre = |i: &[u32]| {
                let sum = i.iter().fold([0.0; 3], |s, &k| {
                    let p = mesh.positions[k as usize];
                    [s[0] + p[0], s[1] + p[1], s[2] + p[2]]
                });
                sum
            };
            let out1 = centre(&[a, b, c]);
            let out2 = centre(&[a, c, d]);
            mesh.triangle([a, b, c], out1);
            mesh.triangle([a, c, d], out2);
        }
    }
    mesh
}

/// An axis-aligned cube of half-size `half` about the origin, flat-shaded, each face's texcoords
/// covering the unit square.
pub fn cube(half: f32) -> Mesh {
    let mut mesh = Mesh::default();
    let axes: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),
        ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
    ];
    for (normal, right, up) in axes {
        let first = mesh.positions.len() as u32;
        for (u, v) in [(0.0f32, 0.0f32), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            let (s, t) = (2.0 * u - 1.0, 1.0 - 2.0 * v);
            mesh.positions.push([0, 1, 2].map(|k| half * (normal[k] + s * right[k] + t * up[k])));
            mesh.normals.push(normal);
            mesh.uvs.push([u, v]);
        }
        mesh.triangle([first, first + 1, first + 2], normal);
        mesh.triangle([first, first + 2, first + 3], normal);
    }
    mesh
}

/// A square in the XY plane facing +Z, from −half to half, with the image upright on it: u
/// runs along +X and v down −Y.
pub fn plane(half: f32) -> Mesh {
    let mut mesh = Mesh::default();
    for (u, v) in [(0.0f32, 0.0f32), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
        mesh.positions.push([half * (2.0 * u - 1.0), half * (1.0 - 2.0 * v), 0.0]);
        mesh.normals.push([0.0, 0.0, 1.0]);
        mesh.uvs.push([u, v]);
    }
    mesh.triangle([0, 1, 2], [0.0, 0.0, 1.0]);
    mesh.triangle([0, 2, 3], [0.0, 0.0, 1.0]);
    mesh
}

/// A glTF document under construction, with its binary buffer.
pub struct Gltf {
    pub json: Value,
    bin: Vec<u8>,
    /// PNG images: (bytes, whether to write them as files rather than embed them).
    images: Vec<Vec<u8>>,
}

impl Default for Gltf {
    fn default() -> Self {
        Gltf::new()
    }
}

impl Gltf {
    pub fn new() -> Gltf {
        Gltf { json: json!({ "asset": { "version": "2.0" } }), bin: Vec::new(), images: Vec::new() }
    }

    fn push(&mut self, key: &str, value: Value) -> usize {
        let array = self.json.as_object_mut().unwrap().entry(key).or_insert_with(|| json!([]));
        let array = array.as_array_mut().unwrap();
        array.push(value);
        array.len() - 1
    }

    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let mut view = json!({ "buffer": 0, "byteOffset": offset, "byteLength": bytes.len() });
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.push("bufferViews", view)
    }

    fn floats<const N: usize>(&mut self, data: &[[f32; N]], kind: &str, bounds: bool) -> usize {
        let bytes: Vec<u8> = data.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(34962));
        let mut accessor = json!({ "bufferView": view, "componentType": 5126, "count": data.len(), "type": kind });
        if bounds {
            let min: Vec<f32> = (0..N).map(|k| data.iter().map(|v| v[k]).fold(f32::MAX, f32::min)).collect();
            let max: Vec<f32> = (0..N).map(|k| data.iter().map(|v| v[k]).fold(f32::MIN, f32::max)).collect();
            accessor["min"] = json!(min);
            accessor["max"] = json!(max);
        }
        self.push("accessors", accessor)
    }

    /// A mesh of one primitive per (mesh, material) pair; returns the mesh index.
    pub fn mesh(&mut self, name: &str, primitives: &[(&Mesh, Option<usize>)]) -> usize {
        let primitives: Vec<Value> =
            primitives.iter().map(|(mesh, material)| self.primitive(mesh, *material, 4)).collect();
        self.push("meshes", json!({ "name": name, "primitives": primitives }))
    }

    /// A primitive with the given glTF mode (4 = triangles).
    pub fn primitive(&mut self, mesh: &Mesh, material: Option<usize>, mode: u32) -> Value {
        let mut attributes = json!({
            "POSITION": self.floats(&mesh.positions, "VEC3", true),
            "NORMAL": self.floats(&mesh.normals, "VEC3", false),
            "TEXCOORD_0": self.floats(&mesh.uvs, "VEC2", false),
        });
        if let Some(tangents) = &mesh.tangents {
            attributes["TANGENT"] = json!(self.floats(tangents, "VEC4", false));
        }
        if let Some(uvs) = &mesh.uvs1 {
            attributes["TEXCOORD_1"] = json!(self.floats(uvs, "VEC2", false));
        }
        if let Some(colors) = &mesh.colors {
            attributes["COLOR_0"] = json!(self.floats(colors, "VEC4", false));
        }
        let bytes: Vec<u8> = mesh.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(34963));
        let indices = self.push(
            "accessors",
            json!({ "bufferView": view, "componentType": 5125, "count": mesh.indices.len(), "type": "SCALAR" }),
        );
        let mut primitive = json!({ "attributes": attributes, "indices": indices, "mode": mode });
        if let Some(material) = material {
            primitive["material"] = json!(material);
        }
        primitive
    }

    pub fn material(&mut self, material: Value) -> usize {
        self.push("materials", material)
    }

    pub fn node(&mut self, node: Value) -> usize {
        self.push("nodes", node)
    }

    pub fn camera(&mut self, camera: Value) -> usize {
        self.push("cameras", camera)
    }

    /// A PNG texture (embedded as a data URI in .gltf, a buffer view in .glb); returns the
    /// texture index.
    pub fn texture(&mut self, image: &image::RgbaImage) -> usize {
        let mut png = Vec::new();
        image::DynamicImage::ImageRgba8(image.clone())
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        self.images.push(png);
        let image = self.images.len() - 1;
        self.push("textures", json!({ "source": image }))
    }

    pub fn uses_extension(&mut self, name: &str) {
        self.push("extensionsUsed", json!(name));
    }

    /// The scene's roots: every node no other node lists as a child.
    fn finish_json(&mut self, embed_images: bool) -> Value {
        let mut json = self.json.clone();
        let nodes = json["nodes"].as_array().cloned().unwrap_or_default();
        let children: Vec<u64> = nodes
            .iter()
            .flat_map(|n| n["children"].as_array().cloned().unwrap_or_default())
            .filter_map(|c| c.as_u64())
            .collect();
        let roots: Vec<usize> = (0..nodes.len()).filter(|i| !children.contains(&(*i as u64))).collect();
        json["scenes"] = json!([{ "nodes": roots }]);
        json["scene"] = json!(0);
        let mut images = Vec::new();
        for png in self.images.clone() {
            if embed_images {
                use base64::Engine;
                let data = base64::engine::general_purpose::STANDARD.encode(&png);
                images.push(json!({ "uri": format!("data:image/png;base64,{data}") }));
            } else {
                let view = self.view(&png, None);
                images.push(json!({ "bufferView": view, "mimeType": "image/png" }));
            }
        }
        if !images.is_empty() {
            json["images"] = json!(images);
        }
        json
    }

    /// Writes `<dir>/<name>.gltf` and `<dir>/<name>.bin`; returns the .gltf's path.
    pub fn write_gltf(&mut self, dir: &Path, name: &str) -> PathBuf {
        let mut json = self.finish_json(true);
        json["buffers"] = json!([{ "uri": format!("{name}.bin"), "byteLength": self.bin.len() }]);
        std::fs::write(dir.join(format!("{name}.bin")), &self.bin).unwrap();
        let path = dir.join(format!("{name}.gltf"));
        std::fs::write(&path, serde_json::to_string_pretty(&json).unwrap()).unwrap();
        path
    }

    /// Writes `<dir>/<name>.glb`, images and all in its binary chunk; returns its path.
    pub fn write_glb(&mut self, dir: &Path, name: &str) -> PathBuf {
        let mut json = self.finish_json(false);
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        json["buffers"] = json!([{ "byteLength": self.bin.len() }]);
        let mut text = serde_json::to_vec(&json).unwrap();
        while text.len() % 4 != 0 {
            text.push(b' ');
        }
        let mut glb = Vec::new();
        glb.extend_from_slice(b"glTF");
        glb.extend_from_slice(&2u32.to_le_bytes());
        glb.extend_from_slice(&((12 + 8 + text.len() + 8 + self.bin.len()) as u32).to_le_bytes());
        glb.extend_from_slice(&(text.len() as u32).to_le_bytes());
        glb.extend_from_slice(b"JSON");
        glb.extend_from_slice(&text);
        glb.extend_from_slice(&(self.bin.len() as u32).to_le_bytes());
        glb.extend_from_slice(b"BIN\0");
        glb.extend_from_slice(&self.bin);
        let path = dir.join(format!("{name}.glb"));
        std::fs::write(&path, glb).unwrap();
        path
    }
}

/// A perspective camera node at `eye` looking toward −Z with the given vertical field of view.
pub fn camera_looking_down_z(gltf: &mut Gltf, name: &str, eye: [f32; 3], yfov_degrees: f32, aspect: f32) -> usize {
    let camera = gltf.camera(json!({
        "type": "perspective",
        "perspective": { "yfov": yfov_degrees.to_radians(), "znear": 0.1, "zfar": 100.0, "aspectRatio": aspect }
    }));
    gltf.node(json!({ "name": name, "camera": camera, "translation": eye }))
}

/// An sRGB-encoded 8-bit value decoded to linear, by the sRGB definition.
pub fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}
