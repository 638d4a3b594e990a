//! The camera a bake looks through: one of the asset's own cameras, or one placed to frame the
//! scene's bounding sphere.
//!
//! Projections map to Vulkan's clip space (depth 0 to 1, y down), so that row 0 of the image is
//! the top of the view. A glTF camera looks down its node's −Z with +Y up; the node's
//! scale is ignored, as glTF asks.

use super::geometry::placed_nodes;
use super::Asset;
use crate::{Error, Result};
use glam::camera::rh::proj::vulkan;
use glam::camera::rh::view::{look_at_mat4, look_to_mat4};
use glam::{Mat4, Vec3};

/// How the camera is chosen (docs/commands.md#lookdev-bake-modelgltfglb---out-gbufferexr).
#[derive(Clone, Debug, PartialEq)]
pub enum CameraChoice {
    /// The scene's first camera, else framing.
    Default,
    /// The camera of the node, or the camera, with this name.
    Named(String),
    /// Framing the bounding sphere from a direction: yaw about +Y from +Z toward +X, pitch up
    /// from the horizon (the camera looks down at positive pitch), vertical field of view.
    Frame { yaw_degrees: f32, pitch_degrees: f32, fov_degrees: f32 },
}

/// Framing's defaults: from +Z, level, 30° vertical field of view, like the built-in scene.
pub const DEFAULT_YAW: f32 = 0.0;
pub const DEFAULT_PITCH: f32 = 0.0;
pub const DEFAULT_FOV: f32 = 30.0;

/// A camera ready to draw with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    /// Unit direction the camera looks along.
    pub forward: Vec3,
    /// World to Vulkan clip space (y down, depth 0 to 1).
    pub view_projection: Mat4,
    pub orthographic: bool,
}

impl Camera {
    /// The unit direction from a world point toward the eye.
    pub fn toward_eye(&self, point: Vec3) -> Vec3 {
        if self.orthographic {
            -self.forward
        } else {
            (self.eye - point).normalize_or_zero()
        }
    }

    /// The world-space direction of the ray through image position (x, y) in pixels (0,0 the
    /// top-left corner), for a `width`×`height` image.
    pub fn ray(&self, x: f32, y: f32, width: u32, height: u32) -> Vec3 {
        let inverse = self.view_projection.inverse();
        let ndc_x = 2.0 * x / width as f32 - 1.0;
        let ndc_y = 2.0 * y / height as f32 - 1.0;
        let near = inverse.project_point3(Vec3::new(ndc_x, ndc_y, 0.0));
        let far = inverse.project_point3(Vec3::new(ndc_x, ndc_y, 0.5));
        (far - near).normalize_or_zero()
    }
}

/// Builds the camera for a `width`×`height` bake of a scene bounded by `bounds`.
pub fn choose(asset: &Asset, choice: &CameraChoice, bounds: (Vec3, f32), width: u32, height: u32) -> Result<Camera> {
    let aspect = width as f32 / height as f32;
    match choice {
        CameraChoice::Frame { yaw_degrees, pitch_degrees, fov_degrees } => {
            frame(bounds, *yaw_degrees, *pitch_degrees, *fov_degrees, aspect)
        }
        CameraChoice::Named(name) => {
            let cameras = scene_cameras(asset)?;
            let found = cameras.iter().find(|(node, _)| {
                node.name() == Some(name.as_str()) || node.camera().and_then(|c| c.name()) == Some(name.as_str())
            });
            match found {
                Some((node, world)) => from_gltf(asset, node, *world, aspect),
                None => {
                    let names: Vec<String> = cameras
                        .iter()
                        .map(|(node, _)| {
                            node.name()
                                .or_else(|| node.camera().and_then(|c| c.name()))
                                .unwrap_or("(unnamed)")
                                .to_string()
                        })
                        .collect();
                    let has = if names.is_empty() {
                        "the scene has no cameras".into()
                    } else {
                        format!("it has {}", names.join(", "))
                    };
                    Err(Error::input_file(&asset.path, format!("no camera named '{name}' ({has})")))
                }
            }
        }
        CameraChoice::Default => match scene_cameras(asset)?.first() {
            Some((node, world)) => from_gltf(asset, node, *world, aspect),
            None => frame(bounds, DEFAULT_YAW, DEFAULT_PITCH, DEFAULT_FOV, aspect),
        },
    }
}

fn scene_cameras(asset: &Asset) -> Result<Vec<(gltf::Node<'_>, Mat4)>> {
    Ok(placed_nodes(asset)?.into_iter().filter(|p| p.node.camera().is_some()).map(|p| (p.node, p.world)).collect())
}

/// A camera that fits the bounding sphere in the frame, from the given direction.
pub fn frame(
    bounds: (Vec3, f32),
    yaw_degrees: f32,
    pitch_degrees: f32,
    fov_degrees: f32,
    aspect: f32,
) -> Result<Camera> {
    if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
        return Err(Error::input(format!("--fov {fov_degrees}: the field of view must be between 0° and 180°")));
    }
    if !(-89.0..=89.0).contains(&pitch_degrees) {
        return Err(Error::input(format!("--pitch {pitch_degrees}: the pitch must be within ±89°")));
    }
    if !yaw_degrees.is_finite() {
        return Err(Error::input(format!("--yaw {yaw_degrees}: must be a finite number")));
    }
    let (centre, radius) = bounds;
    let vertical = fov_degrees.to_radians();
    let horizontal = 2.0 * ((vertical / 2.0).tan() * aspect).atan();
    // The sphere touches the narrower side of the frame.
    let distance = radius / (vertical.min(horizontal) / 2.0).sin();
    let (yaw, pitch) = (yaw_degrees.to_radians(), pitch_degrees.to_radians());
    let from_centre = Vec3::new(yaw.sin() * pitch.cos(), pitch.sin(), yaw.cos() * pitch.cos());
    let eye = centre + from_centre * distance;
    let near = (distance - radius) * 0.5;
    let far = distance + radius * 1.5;
    let view = look_at_mat4(eye, centre, Vec3::Y);
    let projection = vulkan::perspective(vertical, aspect, near.max(radius * 1e-4), far);
    Ok(Camera { eye, forward: -from_centre, view_projection: projection * view, orthographic: false })
}

fn from_gltf(asset: &Asset, node: &gltf::Node, world: Mat4, aspect: f32) -> Result<Camera> {
    let camera = node.camera().expect("a camera node");
    let name =
        node.name().or(camera.name()).map_or_else(|| format!("camera {}", camera.index()), |n| format!("camera '{n}'"));
    let bad = |problem: String| Error::input_file(&asset.path, format!("{name}: {problem}"));
    // The node's rotation and translation; glTF cameras ignore scale.
    let (_, rotation, eye) = world.to_scale_rotation_translation();
    let forward = (rotation * -Vec3::Z).normalize();
    let up = (rotation * Vec3::Y).normalize();
    if !eye.is_finite() || !forward.is_finite() {
        return Err(bad("its node's transform is not usable".into()));
    }
    let view = look_to_mat4(eye, forward, up);
    match camera.projection() {
        gltf::camera::Projection::Perspective(p) => {
            let yfov = p.yfov();
            if !(yfov > 0.0 && yfov < std::f32::consts::PI) {
                return Err(bad(format!("yfov {yfov} is out of range (0 to π radians)")));
            }
            let near = p.znear();
            if !(near > 0.0 && near.is_finite()) {
                return Err(bad(format!("znear {near} is out of range (it must be above 0)")));
            }
            if let Some(ratio) = p.aspect_ratio() {
                if (ratio - aspect).abs() > 0.01 * aspect {
                    crate::warn(format!(
                        "{}: {name} has aspect ratio {ratio}, the bake {aspect:.4}; the vertical field of view is kept",
                        asset.path.display()
                    ));
                }
            }
            let projection = match p.zfar() {
                None => vulkan::perspective_infinite(yfov, aspect, near),
                Some(far) if far > near && far.is_finite() => vulkan::perspective(yfov, aspect, near, far),
                Some(far) => return Err(bad(format!("zfar {far} is out of range (it must be beyond znear {near})"))),
            };
            Ok(Camera { eye, forward, view_projection: projection * view, orthographic: false })
        }
        gltf::camera::Projection::Orthographic(o) => {
            let (xmag, ymag, near, far) = (o.xmag(), o.ymag(), o.znear(), o.zfar());
            if !(ymag.abs() > 0.0 && xmag.abs() > 0.0 && ymag.is_finite() && xmag.is_finite()) {
                return Err(bad(format!("xmag {xmag} and ymag {ymag} must be non-zero")));
            }
            if !(near >= 0.0 && far > near && far.is_finite()) {
                return Err(bad(format!("znear {near} and zfar {far} are out of range (0 ≤ znear < zfar)")));
            }
            let half_height = ymag.abs();
            let half_width = half_height * aspect;
            let projection = vulkan::orthographic(-half_width, half_width, -half_height, half_height, near, far);
            Ok(Camera { eye, forward, view_projection: projection * view, orthographic: true })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn framing_fits_the_sphere_and_looks_at_it() {
        let camera = frame((Vec3::new(1.0, 2.0, 3.0), 2.0), 0.0, 0.0, 30.0, 2.0).unwrap();
        assert!((camera.eye - Vec3::new(1.0, 2.0, 3.0 + 2.0 / 15f32.to_radians().sin())).length() < 1e-4);
        assert!((camera.forward - -Vec3::Z).length() < 1e-6);
        // The sphere's top touches the top of the frame: the ray through row 0's centre grazes it.
        let top = camera.ray(512.0, 0.0, 1024, 512);
        let to_centre = Vec3::new(1.0, 2.0, 3.0) - camera.eye;
        let miss = (to_centre - top * to_centre.dot(top)).length();
        assert!((miss - 2.0).abs() < 1e-3, "the top ray passes {miss} from the centre");
        assert!(top.y > 0.0, "row 0 is the top of the image");
    }

    #[test]
    fn framing_rejects_impossible_angles() {
        for (yaw, pitch, fov, flag) in
            [(0.0, 0.0, 0.0, "--fov"), (0.0, 90.0, 30.0, "--pitch"), (f32::NAN, 0.0, 30.0, "--yaw")]
        {
            let message = frame((Vec3::ZERO, 1.0), yaw, pitch, fov, 1.0).unwrap_err().to_string();
            assert!(message.starts_with(flag), "{message}");
        }
    }
}
