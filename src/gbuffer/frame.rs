//! Tangent frames: the stable frame for a bare normal, and Gram–Schmidt for a stored tangent.

use glam::Vec3;

/// The stable tangent for a unit normal `n`, from Duff et al. 2017, "Building an Orthonormal Basis,
/// Revisited" (JCGT 6(1)). The bitangent is `cross(n, t)`; for `n = (0,0,1)` the frame is the
/// identity: `t = (1,0,0)`, bitangent `(0,1,0)`.
///
/// The construction has no branch on a threshold, so the frame never flips between neighbouring
/// normals except across `n.z = 0`, where it is still continuous in every other component.
pub fn stable_tangent(n: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = n;
    // `copysign` rather than `signum`: n.z = -0.0 must pick the lower hemisphere's branch, or
    // the denominator below becomes zero.
    let sign = 1.0f32.copysign(z);
    let a = -1.0 / (sign + z);
    let b = x * y * a;
    [1.0 + sign * x * x * a, sign * b, -sign * x]
}

/// Below this, a vector is treated as zero.
const TINY_LENGTH: f32 = 1e-6;

/// A stored tangent whose component perpendicular to N is less than this fraction of its length
/// is treated as parallel to N. Half-precision tangents carry about 1e-3 of rounding noise, so
/// anything near that would give a direction made of noise.
const PARALLEL_SINE: f32 = 0.01;

/// Gram–Schmidt: the unit tangent closest to `t` that is perpendicular to the unit normal `n`,
/// or `None` where `t` is zero, not finite, or (nearly) parallel to `n`.
pub(crate) fn orthogonalize(n: Vec3, t: Vec3) -> Option<Vec3> {
    if !t.is_finite() {
        return None;
    }
    let length = t.length();
    if length < TINY_LENGTH {
        return None;
    }
    let perpendicular = t - n * n.dot(t);
    let perpendicular_length = perpendicular.length();
    if perpendicular_length < PARALLEL_SINE * length {
        return None;
    }
    Some(perpendicular / perpendicular_length)
}

/// The tangent to store for the unit normal `n`: `t` made perpendicular to `n`, falling back on
/// the stable frame where `t` is unusable. Always unit and orthogonal to `n`.
pub(crate) fn tangent_or_stable(n: Vec3, t: Vec3) -> Vec3 {
    orthogonalize(n, t).unwrap_or_else(|| Vec3::from(stable_tangent(n.to_array())))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn normals() -> Vec<Vec3> {
        let mut list = vec![Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
        list.push(Vec3::new(0.0, 0.0, -0.0));
        // A spread of directions, including ones near the z = 0 seam.
        for i in 0..200 {
            let u = (i as f32 + 0.5) / 200.0;
            let z = 1.0 - 2.0 * u;
            let phi = i as f32 * 2.399_963; // golden angle
            let r = (1.0 - z * z).sqrt();
            list.push(Vec3::new(r * phi.cos(), r * phi.sin(), z));
        }
        list.push(Vec3::new(0.6, 0.8, 1e-7));
        list.push(Vec3::new(0.6, 0.8, -1e-7));
        list
    }

    #[test]
    fn stable_tangent_is_identity_frame_for_plus_z() {
        assert_eq!(stable_tangent([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
        let bitangent = Vec3::Z.cross(Vec3::X);
        assert_eq!(bitangent, Vec3::Y);
    }

    #[test]
    fn stable_tangent_is_unit_and_orthogonal() {
        for n in normals() {
            let n = if n.length() > 0.5 { n.normalize() } else { Vec3::new(0.0, 0.0, -1.0) };
            let t = Vec3::from(stable_tangent(n.to_array()));
            assert!(t.is_finite(), "n = {n}");
            assert!((t.length() - 1.0).abs() < 1e-5, "n = {n}, t = {t}");
            assert!(t.dot(n).abs() < 1e-5, "n = {n}, t = {t}");
            // Right-handed: t × (n × t) = n.
            let b = n.cross(t);
            assert!((t.cross(b) - n).length() < 1e-5, "n = {n}");
        }
    }

    #[test]
    fn orthogonalize_rejects_degenerate_tangents() {
        let n = Vec3::Z;
        assert_eq!(orthogonalize(n, Vec3::ZERO), None);
        assert_eq!(orthogonalize(n, Vec3::new(f32::NAN, 1.0, 0.0)), None);
        assert_eq!(orthogonalize(n, Vec3::new(0.0, 0.0, -3.0)), None);
        assert_eq!(orthogonalize(n, Vec3::new(0.001, 0.0, 1.0)), None);
        let t = orthogonalize(n, Vec3::new(2.0, 0.0, 2.0)).unwrap();
        assert!((t - Vec3::X).length() < 1e-6);
        assert_eq!(tangent_or_stable(n, Vec3::ZERO), Vec3::X);
    }
}
