//! The shading frame: world ↔ tangent space, and world → environment space.

use glam::Vec3;

/// An orthonormal frame: tangent `x`, bitangent `y` = n × x, normal `n` (right-handed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub x: Vec3,
    pub y: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// The frame of a unit normal and a unit tangent orthogonal to it.
    pub fn new(n: Vec3, tangent: Vec3) -> Frame {
        Frame { x: tangent, y: n.cross(tangent), n }
    }

    pub fn to_local(&self, w: Vec3) -> Vec3 {
        Vec3::new(w.dot(self.x), w.dot(self.y), w.dot(self.n))
    }

    pub fn to_world(&self, l: Vec3) -> Vec3 {
        l.x * self.x + l.y * self.y + l.z * self.n
    }

    /// The same frame seen from environment space, where lookups use R_y(−rotation)·d.
    pub fn rotated_into_environment(&self, cos_rotation: f32, sin_rotation: f32) -> Frame {
        let r = |w: Vec3| environment_from_world(w, cos_rotation, sin_rotation);
        Frame { x: r(self.x), y: r(self.y), n: r(self.n) }
    }
}

/// R_y(−rotation)·d: a world direction expressed in the environment map's own space.
pub fn environment_from_world(d: Vec3, cos_rotation: f32, sin_rotation: f32) -> Vec3 {
    // R_y(a) maps (x, z) to (x·cos a + z·sin a, −x·sin a + z·cos a); here a = −rotation.
    Vec3::new(d.x * cos_rotation - d.z * sin_rotation, d.y, d.x * sin_rotation + d.z * cos_rotation)
}
