//! Triangles as an [`Occluder`], traced through a compressed wide BVH (the `obvhs` crate).

use super::Occluder;
use glam::{Vec3, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;

/// A triangle soup, ready to trace.
pub struct Mesh {
    bvh: CwBvh,
    triangles: Vec<Triangle>,
}

impl Mesh {
    /// Builds the BVH over `triangles` (world-space corners).
    pub fn new(triangles: impl IntoIterator<Item = [Vec3; 3]>) -> Mesh {
        let triangles: Vec<Triangle> =
            triangles.into_iter().map(|[a, b, c]| Triangle { v0: a.into(), v1: b.into(), v2: c.into() }).collect();
        let bvh = build_cwbvh_from_tris(&triangles, BvhBuildParams::medium_build(), &mut Default::default());
        Mesh { bvh, triangles }
    }

    /// The unit geometric normal of triangle `index` (counter-clockwise front), or zero for a
    /// degenerate one.
    pub fn normal(&self, index: usize) -> Vec3 {
        Vec3::from(self.triangles[index].compute_normal())
    }

    /// The nearest hit of the ray from `origin` along the unit `direction` within `reach`: its
    /// distance and the triangle's index.
    pub fn nearest_hit(&self, origin: Vec3, direction: Vec3, reach: f32) -> Option<(f32, usize)> {
        if self.triangles.is_empty() {
            return None;
        }
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(direction), 0.0, reach);
        let mut hit = RayHit::none();
        let triangle = |id: usize| self.bvh.primitive_indices[id] as usize;
        self.bvh
            .ray_traverse(ray, &mut hit, |ray, id| self.triangles[triangle(id)].intersect(ray))
            .then(|| (hit.t, triangle(hit.primitive_id as usize)))
    }
}

impl Occluder for Mesh {
    fn occluded(&self, origin: Vec3, direction: Vec3) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(direction), 0.0, f32::INFINITY);
        !self
            .bvh
            .ray_traverse_miss(ray, |ray, id| self.triangles[self.bvh.primitive_indices[id] as usize].intersect(ray))
    }
}
