//! The geometry of the built-in shader ball, and analytic ray casting against it.
//!
//! A unit ball centred at the origin sits on a pedestal: a narrow neck whose top is buried in
//! the ball, on a wider round foot. Everything is symmetric about the +Y axis, so one tangent
//! rule serves every surface: the direction around that axis.

use glam::Vec3;

/// Object 1: the unit ball, centred at the origin (and so at the image centre).
pub const BALL_ID: u32 = 1;
pub(crate) const BALL_NAME: &str = "ball";
/// Object 2: the pedestal under the ball.
pub const PEDESTAL_ID: u32 = 2;
pub(crate) const PEDESTAL_NAME: &str = "pedestal";

const BALL_RADIUS: f32 = 1.0;
/// The neck's top (y = -0.8) is inside the ball, so ball and pedestal meet without a gap.
const NECK: Cylinder = Cylinder { radius: 0.42, bottom: -1.06, top: -0.8, surfaces: [1, 2, 3] };
const FOOT: Cylinder = Cylinder { radius: 0.7, bottom: -1.2, top: -1.06, surfaces: [4, 5, 6] };
/// Surfaces of the scene, numbered 0 (the ball) to SURFACES - 1 (see [`Hit::surface`]).
pub(crate) const SURFACES: usize = 7;
/// A sphere (centre, radius) that encloses the neck and the foot: the foot's rim (0.7, -1.2) is
/// 0.728 from (0, -1, 0), the neck's top rim (0.42, -0.8) 0.465.
const PEDESTAL_BOUNDS: (Vec3, f32) = (Vec3::new(0.0, -1.0, 0.0), 0.75);

/// The lowest and highest visible points of an object, over which its `gradient` mask rises from 0
/// to 1: each object gets the whole ramp, so a layer through it shows on the pedestal as well
/// as on the ball.
pub(crate) fn height_span(object_id: u32) -> (f32, f32) {
    if object_id == BALL_ID {
        (-BALL_RADIUS, BALL_RADIUS)
    } else {
        // The pedestal's highest visible point: where the neck enters the ball.
        let neck_meets_ball = -(BALL_RADIUS * BALL_RADIUS - NECK.radius * NECK.radius).sqrt();
        (FOOT.bottom, neck_meets_ball)
    }
}

/// Vertical field of view of the camera.
pub(crate) const FIELD_OF_VIEW_DEGREES: f32 = 30.0;
/// The eye is at (0, 0, CAMERA_DISTANCE), looking toward −Z. At this distance the foot's front
/// edge clears the bottom of the frame by a small margin, which makes the ball as large as the
/// frame allows while it stays centred.
pub(crate) const CAMERA_DISTANCE: f32 = 5.5;

/// Rays closer than this to their origin are not hits (the eye is never that close to anything).
const MIN_DISTANCE: f32 = 1e-4;

/// A ray-surface intersection.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit {
    pub distance: f32,
    pub position: Vec3,
    /// Unit outward normal.
    pub normal: Vec3,
    pub object_id: u32,
    /// Which smooth piece of the scene was hit, below [`SURFACES`]: 0 the ball, then each
    /// cylinder's side, top and bottom cap. Normals vary smoothly within a surface and jump
    /// between two, where they meet in a crease or one is seen past the other's silhouette.
    pub surface: u32,
}

/// A closed cylinder around the +Y axis. `surfaces` numbers its side, top and bottom caps
/// (see [`Hit::surface`]).
#[derive(Clone, Copy)]
struct Cylinder {
    radius: f32,
    bottom: f32,
    top: f32,
    surfaces: [u32; 3],
}

/// The nearest hit of the ray `origin + t·direction` (unit direction) with the scene.
pub(crate) fn trace(origin: Vec3, direction: Vec3) -> Option<Hit> {
    let ball = hit_ball(origin, direction);
    // Most rays miss the pedestal; one test against its bounding sphere saves six.
    if !hits_sphere(PEDESTAL_BOUNDS, origin, direction) {
        return ball;
    }
    let neck = hit_cylinder(&NECK, origin, direction);
    let foot = hit_cylinder(&FOOT, origin, direction);
    nearest(nearest(ball, neck), foot)
}

/// The shader ball's own surfaces, as an occluder for its visibility.
pub(crate) struct Occluders;

impl crate::visibility::Occluder for Occluders {
    fn occluded(&self, origin: Vec3, direction: Vec3) -> bool {
        hit_ball(origin, direction).is_some()
            || (hits_sphere(PEDESTAL_BOUNDS, origin, direction)
                && (hit_cylinder(&NECK, origin, direction).is_some()
                    || hit_cylinder(&FOOT, origin, direction).is_some()))
    }

    /// A point on the ball sees the ball behind its own horizon (it is convex), so only the
    /// pedestal can stand in its way, and only where the pedestal rises above that horizon.
    fn may_block(&self, point: &crate::visibility::SurfacePoint) -> bool {
        let on_ball = (point.position.length() - BALL_RADIUS).abs() < 1e-3
            && point.geometric.dot(point.position.normalize()) > 0.999;
        let (centre, radius) = PEDESTAL_BOUNDS;
        !on_ball || (centre - point.position).dot(point.geometric) > -radius
    }
}

fn nearest(a: Option<Hit>, b: Option<Hit>) -> Option<Hit> {
    match (a, b) {
        (Some(a), Some(b)) => Some(if b.distance < a.distance { b } else { a }),
        (a, b) => a.or(b),
    }
}

/// Whether the ray's line passes through the sphere (a conservative test: hits behind the
/// origin count too, which only costs an exact test).
fn hits_sphere((centre, radius): (Vec3, f32), origin: Vec3, direction: Vec3) -> bool {
    let to_centre = centre - origin;
    let along = to_centre.dot(direction);
    to_centre.length_squared() - along * along <= radius * radius
}

/// The direction around the +Y axis at `position`: ∂p/∂φ for φ = atan2(x, z), with length equal
/// to the distance from the axis. It is the analytic tangent of every surface here (on the ball,
/// along the latitude circles, so anisotropic highlights run around it; +X at the image centre,
/// matching [`super::stable_tangent`]), and it is already orthogonal to their normals. On the axis
/// itself (the poles, the centres of the caps) it vanishes, and callers fall back on the stable
/// frame.
pub(crate) fn around_axis(position: Vec3) -> Vec3 {
    Vec3::new(position.z, 0.0, -position.x)
}

fn hit_ball(origin: Vec3, direction: Vec3) -> Option<Hit> {
    // |o + t·d|² = r² with |d| = 1: t = -b ± sqrt(r² - |o - b·d|²), b = o·d. The discriminant
    // is taken from the ray's closest approach to the centre rather than as b² - (|o|² - r²),
    // which cancels badly in f32 near the silhouette.
    let b = origin.dot(direction);
    let closest = origin - direction * b;
    let discriminant = BALL_RADIUS * BALL_RADIUS - closest.length_squared();
    if discriminant < 0.0 {
        return None;
    }
    let root = discriminant.sqrt();
    let distance = [-b - root, -b + root].into_iter().find(|&t| t > MIN_DISTANCE)?;
    let position = origin + direction * distance;
    Some(Hit { distance, position, normal: position.normalize(), object_id: BALL_ID, surface: 0 })
}

fn hit_cylinder(cylinder: &Cylinder, origin: Vec3, direction: Vec3) -> Option<Hit> {
    let side = hit_cylinder_side(cylinder, origin, direction);
    let [_, top_surface, bottom_surface] = cylinder.surfaces;
    let top = hit_cap(cylinder, (cylinder.top, Vec3::Y, top_surface), origin, direction);
    let bottom = hit_cap(cylinder, (cylinder.bottom, -Vec3::Y, bottom_surface), origin, direction);
    nearest(nearest(side, top), bottom)
}

/// The curved side: (o.x + t·d.x)² + (o.z + t·d.z)² = r², between bottom and top.
fn hit_cylinder_side(cylinder: &Cylinder, origin: Vec3, direction: Vec3) -> Option<Hit> {
    let a = direction.x * direction.x + direction.z * direction.z;
    if a < 1e-12 {
        return None; // parallel to the axis: only the caps can be hit
    }
    let b = origin.x * direction.x + origin.z * direction.z;
    let c = origin.x * origin.x + origin.z * origin.z - cylinder.radius * cylinder.radius;
    let discriminant = b * b - a * c;
    if discriminant < 0.0 {
        return None;
    }
    let root = discriminant.sqrt();
    [(-b - root) / a, (-b + root) / a].into_iter().find_map(|distance| {
        let position = origin + direction * distance;
        let within = (cylinder.bottom..=cylinder.top).contains(&position.y);
        (distance > MIN_DISTANCE && within).then(|| {
            let normal = Vec3::new(position.x, 0.0, position.z).normalize();
            Hit { distance, position, normal, object_id: PEDESTAL_ID, surface: cylinder.surfaces[0] }
        })
    })
}

/// A flat cap at height `y`, facing `normal` (±Y), numbered `surface`.
fn hit_cap(cylinder: &Cylinder, (y, normal, surface): (f32, Vec3, u32), origin: Vec3, direction: Vec3) -> Option<Hit> {
    if direction.y.abs() < 1e-12 {
        return None;
    }
    let distance = (y - origin.y) / direction.y;
    let position = origin + direction * distance;
    let inside = position.x * position.x + position.z * position.z <= cylinder.radius * cylinder.radius;
    (distance > MIN_DISTANCE && inside).then_some(Hit { distance, position, normal, object_id: PEDESTAL_ID, surface })
}

#[cfg(test)]
mod tests {
    use super::super::frame::tangent_or_stable;
    use super::*;

    fn tangent_at(position: Vec3, normal: Vec3) -> Vec3 {
        tangent_or_stable(normal, around_axis(position))
    }

    const EYE: Vec3 = Vec3::new(0.0, 0.0, CAMERA_DISTANCE);

    #[test]
    fn central_ray_hits_the_ball_head_on() {
        let hit = trace(EYE, -Vec3::Z).unwrap();
        assert_eq!(hit.object_id, BALL_ID);
        assert!((hit.distance - (CAMERA_DISTANCE - 1.0)).abs() < 1e-5);
        assert!((hit.normal - Vec3::Z).length() < 1e-5);
        assert!((tangent_at(hit.position, hit.normal) - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn rays_below_the_ball_hit_the_pedestal_from_the_front() {
        let neck_front = Vec3::new(0.0, -1.0, NECK.radius);
        let hit = trace(EYE, (neck_front - EYE).normalize()).unwrap();
        assert_eq!(hit.object_id, PEDESTAL_ID);
        assert!((hit.normal - Vec3::Z).length() < 1e-4, "{:?}", hit);

        // Aim at the foot's top cap from above: it faces +Y.
        let cap = Vec3::new(0.0, FOOT.top, 0.6);
        let hit = trace(EYE, (cap - EYE).normalize()).unwrap();
        assert_eq!(hit.object_id, PEDESTAL_ID);
        assert_eq!(hit.normal, Vec3::Y);
        let t = tangent_at(hit.position, hit.normal);
        assert!((t - Vec3::X).length() < 1e-5, "{t}");
    }

    #[test]
    fn the_eye_does_not_see_the_bottom_cap_and_misses_are_misses() {
        assert!(trace(EYE, Vec3::Y).is_none());
        assert!(trace(EYE, Vec3::new(0.5, 0.0, -1.0).normalize()).is_none());
        // From below, the foot's bottom cap faces down.
        let hit = trace(Vec3::new(0.1, -5.0, 0.0), Vec3::Y).unwrap();
        assert_eq!(hit.normal, -Vec3::Y);
        assert!((hit.position.y - FOOT.bottom).abs() < 1e-5);
    }

    #[test]
    fn tangents_are_unit_and_orthogonal_everywhere() {
        for (i, j) in (0..40).flat_map(|i| (0..40).map(move |j| (i, j))) {
            let target = Vec3::new(-1.2 + i as f32 * 0.06, -1.3 + j as f32 * 0.06, 0.0);
            if let Some(hit) = trace(EYE, (target - EYE).normalize()) {
                let t = tangent_at(hit.position, hit.normal);
                assert!((t.length() - 1.0).abs() < 1e-5);
                assert!(t.dot(hit.normal).abs() < 1e-5);
                assert!((hit.normal.length() - 1.0).abs() < 1e-5);
            }
        }
    }
}
