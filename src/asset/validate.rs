//! The checks a glTF document must pass before the `gltf` crate's own validation and readers
//! see it. That crate indexes some arrays unchecked while validating (a primitive's `POSITION`
//! accessor), trusts each accessor's component type (an index accessor of floats reaches
//! `unreachable!`), and reads an accessor whose count runs past its buffer view as whatever
//! bytes are there. So everything an index, a type or a length in the JSON claims is checked
//! here, and every problem names the file and the JSON path:
//!
//! - `asset.version` (and `minVersion`) must be a 2.x version;
//! - every index a mesh, an accessor, a buffer view or a node holds names an existing element;
//! - every accessor's elements lie inside its buffer view, and every view inside its buffer as
//!   declared (the loader then checks each buffer holds its declared length);
//! - each vertex attribute and index accessor has a type and a component type glTF allows;
//! - the nodes form a forest: no node has two parents, none is its own ancestor, and a scene
//!   lists only root nodes.
//!
//! Material factors outside their range are not errors; they come back as warnings, since the
//! mapping clamps them.

use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;
use gltf::json::{Accessor, Root};

/// Checks `root`; the error is the problem, starting with the JSON path, for the caller to
/// prefix with the file. On success, the warnings (one line each, without the file).
pub fn check(root: &Root) -> Result<Vec<String>, String> {
    check_version(root)?;
    check_buffer_views(root)?;
    check_meshes(root)?;
    check_accessors(root)?;
    check_images(root)?;
    check_nodes(root)?;
    Ok(factor_warnings(root))
}

fn check_version(root: &Root) -> Result<(), String> {
    let major = |version: &str| version.split('.').next().and_then(|m| m.parse::<u32>().ok());
    if major(&root.asset.version) != Some(2) {
        return Err(format!(
            "asset.version: \"{}\" is not a glTF 2.x version; lookdev reads glTF 2.0",
            root.asset.version
        ));
    }
    if let Some(min) = &root.asset.min_version {
        let parts: Vec<Option<u32>> = min.split('.').map(|p| p.parse().ok()).collect();
        if !matches!(parts.as_slice(), [Some(2), Some(0)]) {
            return Err(format!("asset.minVersion: the asset needs glTF {min}; lookdev reads glTF 2.0"));
        }
    }
    Ok(())
}

/// `what` index `index` at `path`, which must be below `len`.
fn in_range(path: &str, what: &str, index: usize, len: usize) -> Result<(), String> {
    if index < len {
        Ok(())
    } else {
        Err(format!("{path}: {what} {index} does not exist (the file has {len})"))
    }
}

fn check_buffer_views(root: &Root) -> Result<(), String> {
    for (i, view) in root.buffer_views.iter().enumerate() {
        let path = format!("bufferViews[{i}]");
        in_range(&format!("{path}.buffer"), "buffer", view.buffer.value(), root.buffers.len())?;
        let buffer_length = root.buffers[view.buffer.value()].byte_length.0;
        let offset = view.byte_offset.map_or(0, |o| o.0);
        let end = offset.checked_add(view.byte_length.0);
        if end.is_none_or(|end| end > buffer_length) {
            return Err(format!(
                "{path}: bytes {offset}..{offset}+{} run past buffer {} of {buffer_length} bytes",
                view.byte_length.0,
                view.buffer.value()
            ));
        }
    }
    Ok(())
}

fn check_accessors(root: &Root) -> Result<(), String> {
    for (i, accessor) in root.accessors.iter().enumerate() {
        let path = format!("accessors[{i}]");
        let (Checked::Valid(component), Checked::Valid(kind)) = (&accessor.component_type, &accessor.type_) else {
            return Err(format!("{path}: its componentType or type is not one glTF defines"));
        };
        let element = component.0.size() as u64 * kind.multiplicity() as u64;
        if accessor.count.0 == 0 {
            return Err(format!("{path}: count is 0; an accessor holds at least one element"));
        }
        if let Some(view) = accessor.buffer_view {
            let byte_offset = accessor.byte_offset.map_or(0, |o| o.0);
            elements_fit(root, &path, view.value(), byte_offset, accessor.count.0, element)?;
        }
        if let Some(sparse) = &accessor.sparse {
            let path = format!("{path}.sparse");
            if sparse.count.0 == 0 || sparse.count.0 > accessor.count.0 {
                return Err(format!("{path}: count {} is not in 1..={}", sparse.count.0, accessor.count.0));
            }
            let Checked::Valid(index_type) = &sparse.indices.component_type else {
                return Err(format!("{path}.indices: its componentType is not one glTF allows"));
            };
            let (indices, values) = (&sparse.indices, &sparse.values);
            let index_size = index_type.0.size() as u64;
            elements_fit(
                root,
                &format!("{path}.indices"),
                indices.buffer_view.value(),
                indices.byte_offset.0,
                sparse.count.0,
                index_size,
            )?;
            elements_fit(
                root,
                &format!("{path}.values"),
                values.buffer_view.value(),
                values.byte_offset.0,
                sparse.count.0,
                element,
            )?;
        }
    }
    Ok(())
}

/// Whether `count` elements of `element` bytes, from `byte_offset` in buffer view `view`, at its
/// stride, lie inside the view.
fn elements_fit(
    root: &Root,
    path: &str,
    view: usize,
    byte_offset: u64,
    count: u64,
    element: u64,
) -> Result<(), String> {
    in_range(&format!("{path}.bufferView"), "buffer view", view, root.buffer_views.len())?;
    let view_json = &root.buffer_views[view];
    let stride = view_json.byte_stride.map_or(element, |s| s.0 as u64);
    if stride < element {
        return Err(format!(
            "{path}: buffer view {view}'s byteStride {stride} is shorter than its {element}-byte elements"
        ));
    }
    let end = (count - 1).checked_mul(stride).and_then(|last| last.checked_add(byte_offset)?.checked_add(element));
    if end.is_none_or(|end| end > view_json.byte_length.0) {
        return Err(format!(
            "{path}: {count} elements of {element} bytes from byte {byte_offset} run past buffer view {view} of {} bytes",
            view_json.byte_length.0
        ));
    }
    Ok(())
}

/// The types glTF allows for a vertex attribute: (element types, float, normalized u8/u16,
/// plain u8/u16).
fn allowed(semantic: &str) -> Option<(&'static [Type], bool, bool, bool)> {
    let name = semantic.split('_').next().unwrap_or(semantic);
    Some(match name {
        "POSITION" | "NORMAL" => (&[Type::Vec3], true, false, false),
        "TANGENT" => (&[Type::Vec4], true, false, false),
        "TEXCOORD" => (&[Type::Vec2], true, true, false),
        "COLOR" => (&[Type::Vec3, Type::Vec4], true, true, false),
        "JOINTS" => (&[Type::Vec4], false, false, true),
        "WEIGHTS" => (&[Type::Vec4], true, true, false),
        _ => return None,
    })
}

fn type_name(kind: Type) -> &'static str {
    match kind {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

fn component_name(component: ComponentType) -> &'static str {
    match component {
        ComponentType::I8 => "BYTE",
        ComponentType::U8 => "UNSIGNED_BYTE",
        ComponentType::I16 => "SHORT",
        ComponentType::U16 => "UNSIGNED_SHORT",
        ComponentType::U32 => "UNSIGNED_INT",
        ComponentType::F32 => "FLOAT",
    }
}

/// The accessor's element type and component type.
fn types(accessor: &Accessor, index: usize) -> Result<(Type, ComponentType), String> {
    match (&accessor.type_, &accessor.component_type) {
        (Checked::Valid(kind), Checked::Valid(component)) => Ok((*kind, component.0)),
        _ => Err(format!("accessors[{index}]: its componentType or type is not one glTF defines")),
    }
}

fn check_meshes(root: &Root) -> Result<(), String> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let path = format!("meshes[{m}].primitives[{p}]");
            for (semantic, index) in &primitive.attributes {
                let Checked::Valid(semantic) = semantic else {
                    return Err(format!("{path}.attributes: an attribute's name is not one glTF defines"));
                };
                let name = semantic.to_string();
                let attribute = format!("{path}.attributes[\"{name}\"]");
                in_range(&attribute, "accessor", index.value(), root.accessors.len())?;
                let accessor = &root.accessors[index.value()];
                let (kind, component) = types(accessor, index.value())?;
                let Some((kinds, float, normalized, plain)) = allowed(&name) else { continue };
                let component_ok = match component {
                    ComponentType::F32 => float,
                    ComponentType::U8 | ComponentType::U16 => {
                        (normalized && accessor.normalized) || (plain && !accessor.normalized)
                    }
                    _ => false,
                };
                if !kinds.contains(&kind) || !component_ok {
                    return Err(format!(
                        "{attribute}: accessor {} is {}{} {}, which glTF does not allow for {name}",
                        index.value(),
                        if accessor.normalized { "normalized " } else { "" },
                        component_name(component),
                        type_name(kind)
                    ));
                }
            }
            if !primitive.attributes.keys().any(|s| matches!(s, Checked::Valid(s) if s.to_string() == "POSITION")) {
                return Err(format!("{path}.attributes: there is no POSITION"));
            }
            if let Some(index) = primitive.indices {
                let indices = format!("{path}.indices");
                in_range(&indices, "accessor", index.value(), root.accessors.len())?;
                let accessor = &root.accessors[index.value()];
                let (kind, component) = types(accessor, index.value())?;
                let unsigned = matches!(component, ComponentType::U8 | ComponentType::U16 | ComponentType::U32);
                if kind != Type::Scalar || !unsigned || accessor.normalized {
                    return Err(format!(
                        "{indices}: accessor {} is {} {}; indices must be SCALAR UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
                        index.value(),
                        component_name(component),
                        type_name(kind)
                    ));
                }
            }
            if let Some(material) = primitive.material {
                in_range(&format!("{path}.material"), "material", material.value(), root.materials.len())?;
            }
            for (t, target) in primitive.targets.iter().flatten().enumerate() {
                for (name, index) in
                    [("POSITION", target.positions), ("NORMAL", target.normals), ("TANGENT", target.tangents)]
                {
                    if let Some(index) = index {
                        let path = format!("{path}.targets[{t}].{name}");
                        in_range(&path, "accessor", index.value(), root.accessors.len())?;
                    }
                }
            }
        }
    }
    Ok(())
}

/// Each image has its data in a buffer view (with its MIME type) or behind a URI.
fn check_images(root: &Root) -> Result<(), String> {
    for (i, image) in root.images.iter().enumerate() {
        let path = format!("images[{i}]");
        match (&image.buffer_view, &image.uri, &image.mime_type) {
            (Some(view), None, Some(_)) => {
                in_range(&format!("{path}.bufferView"), "buffer view", view.value(), root.buffer_views.len())?
            }
            (Some(_), None, None) => return Err(format!("{path}: an image in a buffer view needs its mimeType")),
            (None, Some(_), _) => {}
            (Some(_), Some(_), _) => return Err(format!("{path}: it has both a uri and a bufferView")),
            (None, None, _) => return Err(format!("{path}: it has neither a uri nor a bufferView")),
        }
    }
    Ok(())
}

fn check_nodes(root: &Root) -> Result<(), String> {
    let count = root.nodes.len();
    let mut parent: Vec<Option<usize>> = vec![None; count];
    for (i, node) in root.nodes.iter().enumerate() {
        let path = format!("nodes[{i}]");
        if let Some(mesh) = node.mesh {
            in_range(&format!("{path}.mesh"), "mesh", mesh.value(), root.meshes.len())?;
        }
        if let Some(camera) = node.camera {
            in_range(&format!("{path}.camera"), "camera", camera.value(), root.cameras.len())?;
        }
        for (c, child) in node.children.iter().flatten().enumerate() {
            let child = child.value();
            in_range(&format!("{path}.children[{c}]"), "node", child, count)?;
            if let Some(first) = parent[child] {
                return Err(format!(
                    "{path}.children[{c}]: node {child} is already a child of node {first}; glTF nodes form a tree"
                ));
            }
            parent[child] = Some(i);
        }
    }
    // With one parent each, a node is in a loop exactly when walking up never ends.
    for start in 0..count {
        let mut node = start;
        for _ in 0..=count {
            match parent[node] {
                Some(up) if up == start => {
                    return Err(format!("nodes[{start}]: the node is its own ancestor; glTF nodes form a tree"))
                }
                Some(up) => node = up,
                None => break,
            }
        }
    }
    for (s, scene) in root.scenes.iter().enumerate() {
        for (n, node) in scene.nodes.iter().enumerate() {
            let path = format!("scenes[{s}].nodes[{n}]");
            in_range(&path, "node", node.value(), count)?;
            if let Some(up) = parent[node.value()] {
                return Err(format!("{path}: node {} is a child of node {up}, not a root node", node.value()));
            }
        }
    }
    Ok(())
}

/// Factors glTF bounds to [0, 1] that lie outside it; the mapping clamps them.
fn factor_warnings(root: &Root) -> Vec<String> {
    let mut warnings = Vec::new();
    for (i, material) in root.materials.iter().enumerate() {
        let pbr = &material.pbr_metallic_roughness;
        let path = format!("materials[{i}].pbrMetallicRoughness");
        let mut outside = |key: &str, values: &[f32]| {
            if values.iter().any(|v| !(0.0..=1.0).contains(v)) {
                let shown: Vec<String> = values.iter().map(f32::to_string).collect();
                warnings.push(format!("{path}.{key} = {} lies outside [0, 1]; it is clamped", shown.join(", ")));
            }
        };
        outside("metallicFactor", &[pbr.metallic_factor.0]);
        outside("roughnessFactor", &[pbr.roughness_factor.0]);
        outside("baseColorFactor", &pbr.base_color_factor.0);
    }
    warnings
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A triangle with positions and 16-bit indices, in the JSON form the tests edit.
    fn triangle() -> serde_json::Value {
        serde_json::json!({
            "asset": {"version": "2.0"},
            "scene": 0, "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
            "materials": [{"pbrMetallicRoughness": {}}],
            "buffers": [{"byteLength": 44}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
                {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
            ]
        })
    }

    fn problem(edit: impl FnOnce(&mut serde_json::Value)) -> String {
        let mut json = triangle();
        edit(&mut json);
        let root: Root = serde_json::from_value(json).expect("the test's JSON deserialises");
        check(&root).expect_err("the edit makes the document invalid")
    }

    #[test]
    fn a_valid_document_passes() {
        let root: Root = serde_json::from_value(triangle()).unwrap();
        assert_eq!(check(&root), Ok(vec![]));
    }

    #[test]
    fn each_claim_of_the_json_is_checked_and_named_by_its_path() {
        type Edit = fn(&mut serde_json::Value);
        let cases: [(&str, Edit); 10] = [
            ("images[0]: it has neither a uri nor a bufferView", |j| {
                j["images"] = serde_json::json!([{"name": "lost"}])
            }),
            ("meshes[0].primitives[0].attributes[\"POSITION\"]: accessor 99 does not exist (the file has 2)", |j| {
                j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 99.into()
            }),
            ("meshes[0].primitives[0].indices: accessor 1 is FLOAT SCALAR; indices must be", |j| {
                j["accessors"][1]["componentType"] = 5126.into();
                j["bufferViews"][1]["byteLength"] = 12.into();
                j["buffers"][0]["byteLength"] = 48.into();
            }),
            ("accessors[1]: 1000 elements of 2 bytes from byte 0 run past buffer view 1 of 6 bytes", |j| {
                j["accessors"][1]["count"] = 1000.into()
            }),
            ("accessor 0 is FLOAT VEC2, which glTF does not allow for POSITION", |j| {
                j["accessors"][0]["type"] = "VEC2".into()
            }),
            ("asset.version: \"3.0\" is not a glTF 2.x version", |j| j["asset"]["version"] = "3.0".into()),
            ("nodes[1].children[0]: node 2 is already a child of node 0", |j| {
                j["nodes"] = serde_json::json!([{"children": [2]}, {"children": [2]}, {"mesh": 0}]);
                j["scenes"][0]["nodes"] = serde_json::json!([0, 1]);
            }),
            ("the node is its own ancestor", |j| {
                j["nodes"] = serde_json::json!([{"children": [1]}, {"children": [0], "mesh": 0}]);
                j["scenes"][0]["nodes"] = serde_json::json!([]);
            }),
            ("scenes[0].nodes[0]: node 1 is a child of node 0, not a root node", |j| {
                j["nodes"] = serde_json::json!([{"children": [1]}, {"mesh": 0}]);
                j["scenes"][0]["nodes"] = serde_json::json!([1]);
            }),
            ("bufferViews[1]: bytes 36..36+6 run past buffer 0 of 40 bytes", |j| {
                j["buffers"][0]["byteLength"] = 40.into()
            }),
        ];
        for (expected, edit) in cases {
            let message = problem(edit);
            assert!(message.contains(expected), "expected '{expected}' in '{message}'");
        }
    }

    #[test]
    fn factors_out_of_range_are_warned_of() {
        let mut json = triangle();
        json["materials"][0]["pbrMetallicRoughness"] = serde_json::json!({"metallicFactor": -5, "roughnessFactor": 7});
        let root: Root = serde_json::from_value(json).unwrap();
        let warnings = check(&root).unwrap();
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert!(warnings[0].contains("materials[0].pbrMetallicRoughness.metallicFactor = -5 lies outside [0, 1]"));
        assert!(warnings[1].contains("roughnessFactor = 7"));
    }
}
