//! The geometry of a scene as the integrator sees it: all shapes under one BVH.

use super::bounds::Bounds3;
use super::bvh::Bvh;
use super::error::{GeometryError, GeometryResult};
use super::interaction::{PrimHit, SurfaceHit};
use super::ray::Ray;
use super::shape::Shape;
use super::solid_angle_sampling::ShapeSample;
use super::triangle::TriangleRay;
use super::{Vec2, Vec3};
use rayon::prelude::*;

mod packet;

pub use packet::{HitLanes, LaneRays, PacketHit, PACKET_TRAVERSAL_MAX_NODES};

/// One BVH primitive: a triangle of a mesh or a whole analytic shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct PrimRef {
    shape: u32,
    prim: u32,
}

/// All shapes of a scene and one BVH over their primitives (each triangle is a
/// primitive, each analytic shape one). Shape ids are indices in the list given to
/// [`SceneGeometry::new`]; hits report them in [`SurfaceHit::shape`].
#[derive(Clone, Debug)]
pub struct SceneGeometry {
    shapes: Vec<Shape>,
    /// Primitives in BVH slot order.
    prims: Vec<PrimRef>,
    bvh: Bvh,
    bounds: Bounds3,
    /// Whether packet queries traverse the hierarchy as packets
    /// ([`packet::PACKET_TRAVERSAL_MAX_NODES`]).
    packet_traversal: bool,
}

impl SceneGeometry {
    /// Builds the BVH over every primitive of `shapes` (in parallel). An empty list is
    /// valid: nothing is ever hit.
    pub fn new(shapes: Vec<Shape>) -> GeometryResult<SceneGeometry> {
        let count: usize = shapes.iter().map(Shape::primitive_count).sum();
        if count > u32::MAX as usize || shapes.len() > u32::MAX as usize {
            return Err(GeometryError::TooManyPrimitives {
                count,
                max: u32::MAX as usize,
            });
        }
        let mut prims = Vec::with_capacity(count);
        let mut bounds = Vec::with_capacity(count);
        for (s, shape) in shapes.iter().enumerate() {
            let n = shape.primitive_count();
            prims.extend((0..n as u32).map(|prim| PrimRef {
                shape: s as u32,
                prim,
            }));
            bounds.par_extend((0..n).into_par_iter().map(|i| shape.primitive_bounds(i)));
        }
        let bvh = Bvh::build(&bounds);
        let prims = bvh.order().iter().map(|&i| prims[i as usize]).collect();
        let bounds = shapes
            .iter()
            .fold(Bounds3::EMPTY, |b, s| b.union(&s.bounds()));
        Ok(SceneGeometry {
            shapes,
            prims,
            packet_traversal: bvh.node_count() <= packet::PACKET_TRAVERSAL_MAX_NODES,
            bvh,
            bounds,
        })
    }

    #[inline]
    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }

    #[inline]
    pub fn shape(&self, id: u32) -> Option<&Shape> {
        self.shapes.get(id as usize)
    }

    #[inline]
    pub fn shape_count(&self) -> usize {
        self.shapes.len()
    }

    /// Number of BVH primitives.
    #[inline]
    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    /// The BVH (for statistics).
    #[inline]
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// Box of the whole scene.
    #[inline]
    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    /// Surface area of shape `id`; 0 for an unknown id.
    pub fn shape_area(&self, id: u32) -> f64 {
        self.shape(id).map_or(0.0, Shape::area)
    }

    /// Uniform area sample of shape `id`: `(point, geometric normal, pdf per unit area)`.
    /// An unknown id gives pdf 0.
    pub fn sample_shape(&self, id: u32, u: Vec2) -> (Vec3, Vec3, f64) {
        match self.shape(id) {
            Some(s) => s.sample(u),
            None => (Vec3::ZERO, Vec3::Z, 0.0),
        }
    }

    /// Shape `id` sampled from the reference point `p` by solid angle
    /// ([`Shape::sample_from`]); `None` for an unknown id or no sample.
    pub fn sample_shape_from(&self, id: u32, p: Vec3, u: Vec2) -> Option<ShapeSample> {
        self.shape(id)?.sample_from(p, u)
    }

    /// Solid-angle density of [`sample_shape_from`](Self::sample_shape_from) at `p` for
    /// the point `q` (normal `nq`) of primitive `prim` of shape `id`; 0 for an unknown id.
    pub fn shape_pdf_from(&self, id: u32, prim: u32, p: Vec3, q: Vec3, nq: Vec3) -> f64 {
        self.shape(id).map_or(0.0, |s| s.pdf_from(p, q, nq, prim))
    }

    /// Tests the primitive in `slot` against the ray restricted to `(0, t_max]`. The
    /// triangle set-up of the ray (a shear transform) is made at the first triangle the
    /// ray meets, so scenes of analytic shapes never pay for it.
    #[inline]
    fn test_prim(
        &self,
        slot: usize,
        ray: &Ray,
        tri: &mut Option<TriangleRay>,
        t_max: f64,
    ) -> Option<PrimHit> {
        let r = self.prims[slot];
        match &self.shapes[r.shape as usize] {
            Shape::Mesh(m) => {
                // Only valid rays get here (`is_valid_query`), for which `new` succeeds.
                let tri = match tri {
                    Some(t) => t,
                    None => tri.insert(TriangleRay::new(ray)?),
                };
                m.intersect_triangle(r.prim as usize, tri, t_max)
            }
            Shape::Sphere(s) => s.intersect_prim(&Ray { t_max, ..*ray }),
            Shape::Rectangle(q) => q.intersect_prim(&Ray { t_max, ..*ray }),
            Shape::Disk(d) => d.intersect_prim(&Ray { t_max, ..*ray }),
        }
    }

    /// The closest hit in `(0, ray.t_max]`, if any, with every surface detail (uv and its
    /// derivatives). Rays with a zero or non-finite direction or origin hit nothing.
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit> {
        self.intersect_with(ray, HitDetail::Full)
    }

    /// The closest hit with the details asked for: [`HitDetail::Shading`] leaves `uv`
    /// zero and `dpdu`, `dpdv` at their directions only where a shape would need
    /// transcendental functions for them (the sphere's `acos`/`atan2`), which is all a
    /// material without textures or glints reads (the shading frame normalizes `dpdu`).
    /// Complete such a hit later with [`complete_hit`](Self::complete_hit).
    pub fn intersect_with(&self, ray: &Ray, detail: HitDetail) -> Option<SurfaceHit> {
        let (slot, hit) = self.closest_slot(ray)?;
        Some(self.hit_record(slot, ray, hit, detail))
    }

    /// The slot of the primitive `ray` hits first, and the hit.
    #[inline]
    fn closest_slot(&self, ray: &Ray) -> Option<(usize, PrimHit)> {
        if !is_valid_query(ray) {
            return None;
        }
        let mut tri = None;
        let (_, found) = self.bvh.closest_hit(ray, |slot, t_max| {
            self.test_prim(slot, ray, &mut tri, t_max)
                .map(|h| (h.t, (slot, h)))
        })?;
        Some(found)
    }

    /// The surface details of `ray`'s hit `hit` on the primitive in `slot`.
    #[inline]
    fn hit_record(&self, slot: usize, ray: &Ray, hit: PrimHit, detail: HitDetail) -> SurfaceHit {
        let r = self.prims[slot];
        match &self.shapes[r.shape as usize] {
            Shape::Mesh(m) => m.surface_hit(ray, r.prim as usize, hit, r.shape),
            Shape::Sphere(s) => match detail {
                HitDetail::Full => s.surface_hit(ray, hit, r.shape),
                HitDetail::Shading => s.shading_hit(ray, hit, r.shape),
            },
            Shape::Rectangle(q) => q.surface_hit(ray, hit, r.shape),
            Shape::Disk(d) => d.surface_hit(ray, hit, r.shape),
        }
    }

    /// Fills in the details [`HitDetail::Shading`] left out, as [`HitDetail::Full`]
    /// would have computed them.
    pub fn complete_hit(&self, hit: &mut SurfaceHit) {
        if let Some(Shape::Sphere(s)) = self.shape(hit.shape) {
            s.complete_hit(hit);
        }
    }

    /// Whether anything lies on the segment `origin + t·dir`, `0 < t ≤ t_max` (`dir`
    /// need not be unit; `t_max` is then in units of `|dir|`). For shadow rays, build the
    /// segment with [`Ray::spawn_to`] / [`Ray::spawn_between`] so that the end surfaces
    /// are excluded.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f64) -> bool {
        let len = dir.length();
        let ray = Ray::new(origin, dir, t_max * len);
        self.occluded_ray(&ray)
    }

    /// [`occluded`](Self::occluded) for a prepared ray.
    pub fn occluded_ray(&self, ray: &Ray) -> bool {
        if !is_valid_query(ray) {
            return false;
        }
        let mut tri = None;
        self.bvh.any_hit(ray, |slot, t_max| {
            self.test_prim(slot, ray, &mut tri, t_max).is_some()
        })
    }
}

/// Which surface details a closest-hit query computes (Mitsuba 3's ray flags): the
/// integrator asks only for what the material at the hit reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HitDetail {
    /// Position, normals and tangent directions: enough to shade an untextured material.
    Shading,
    /// Everything, including uv and the magnitudes of dp/du, dp/dv (textures, glints,
    /// ray-differential footprints).
    Full,
}

/// A ray that can hit something: finite origin, finite non-zero direction.
#[inline]
fn is_valid_query(ray: &Ray) -> bool {
    ray.dir.is_finite() && ray.dir != Vec3::ZERO && ray.origin.is_finite()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Disk, Rectangle, Sphere, Transform, TriangleMesh};

    fn scene() -> SceneGeometry {
        let floor = Rectangle::new(
            &Transform::scale(Vec3::new(10.0, 10.0, 1.0)).unwrap(),
            false,
        )
        .unwrap();
        let ball = Sphere::new(Vec3::new(0.0, 0.0, 1.0), 1.0).unwrap();
        let lamp = Disk::new(
            &(Transform::translate(Vec3::new(0.0, 0.0, 5.0)).unwrap()
                * Transform::rotate(Vec3::X, 180.0).unwrap()),
            false,
        )
        .unwrap();
        let tri = TriangleMesh::new(
            vec![
                Vec3::new(3.0, 0.0, 0.5),
                Vec3::new(4.0, 0.0, 0.5),
                Vec3::new(3.0, 1.0, 0.5),
            ],
            None,
            None,
            vec![0, 1, 2],
            &Transform::IDENTITY,
            false,
        )
        .unwrap();
        SceneGeometry::new(vec![floor.into(), ball.into(), lamp.into(), tri.into()]).unwrap()
    }

    #[test]
    fn closest_hits_report_shape_ids() {
        let s = scene();
        assert_eq!(s.primitive_count(), 4);
        let down = |x: f64, y: f64| Ray::infinite(Vec3::new(x, y, 3.0), -Vec3::Z);
        let h = s.intersect(&down(0.0, 0.0)).unwrap();
        assert_eq!(h.shape, 1);
        assert!((h.t - 1.0).abs() < 1e-14);
        assert_eq!(s.intersect(&down(5.0, 5.0)).unwrap().shape, 0);
        let h = s.intersect(&down(3.2, 0.2)).unwrap();
        assert_eq!((h.shape, h.prim), (3, 0));
        let up = Ray::infinite(Vec3::new(0.1, 0.1, 2.5), Vec3::Z);
        let h = s.intersect(&up).unwrap();
        assert_eq!(h.shape, 2);
        assert!(h.ng.z < 0.0);
        assert!(s
            .intersect(&Ray::infinite(Vec3::new(0.0, 0.0, 6.0), Vec3::Z))
            .is_none());
        assert!(s
            .intersect(&Ray::infinite(Vec3::ZERO, Vec3::ZERO))
            .is_none());
        assert!(s
            .intersect(&Ray::infinite(Vec3::splat(f64::NAN), Vec3::Z))
            .is_none());
    }

    #[test]
    fn shading_hits_complete_to_full_hits() {
        let s = scene();
        let tilted = Sphere::new(Vec3::new(0.3, -0.2, 0.9), 1.3).unwrap();
        let far = Sphere::new(Vec3::new(1e4, 2e4, -3e4), 2.0).unwrap();
        let geometry = SceneGeometry::new(vec![tilted.into(), far.into()]).unwrap();
        let mut checked = 0;
        for (g, origin) in [
            (&s, Vec3::new(0.2, 0.1, 5.0)),
            (&geometry, Vec3::new(0.2, 0.1, 5.0)),
            (&geometry, Vec3::new(1e4, 2e4, -3e4 + 10.0)),
        ] {
            for k in 0..64 {
                let (a, b) = ((k % 8) as f64 / 8.0 - 0.45, (k / 8) as f64 / 8.0 - 0.45);
                let target = origin + Vec3::new(a, b, -1.0) * 4.0;
                let ray = Ray::infinite(origin, target - origin);
                let full = g.intersect(&ray);
                let lean = g.intersect_with(&ray, HitDetail::Shading);
                assert_eq!(full.is_some(), lean.is_some());
                let (Some(full), Some(mut lean)) = (full, lean) else {
                    continue;
                };
                assert_eq!(
                    (full.t, full.p, full.ng, full.ns),
                    (lean.t, lean.p, lean.ng, lean.ns)
                );
                // The shading frame only reads the direction of dp/du.
                let (ff, fl) = (full.shading_frame(), lean.shading_frame());
                assert!((ff.s - fl.s).length() < 1e-12, "{:?} {:?}", ff.s, fl.s);
                g.complete_hit(&mut lean);
                assert_eq!(full, lean);
                checked += 1;
            }
        }
        assert!(checked > 80, "{checked}");
    }

    #[test]
    fn occlusion_respects_t_max() {
        let s = scene();
        let o = Vec3::new(0.0, 0.0, 4.0);
        assert!(s.occluded(o, -Vec3::Z, 10.0));
        assert!(!s.occluded(o, -Vec3::Z, 1.9));
        // Non-unit direction: t_max in units of |dir|.
        assert!(!s.occluded(o, -Vec3::Z * 2.0, 0.95));
        assert!(s.occluded(o, -Vec3::Z * 2.0, 1.05));
        assert!(!s.occluded(o, Vec3::ZERO, 10.0));
    }

    #[test]
    fn areas_and_samples() {
        let s = scene();
        assert!((s.shape_area(0) - 400.0).abs() < 1e-10);
        assert!((s.shape_area(1) - 4.0 * std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(s.shape_area(99), 0.0);
        let (p, n, pdf) = s.sample_shape(2, Vec2::new(0.3, 0.7));
        assert!((p.z - 5.0).abs() < 1e-14 && n.z < 0.0);
        assert!((pdf - 1.0 / std::f64::consts::PI).abs() < 1e-14);
        assert_eq!(s.sample_shape(42, Vec2::ZERO).2, 0.0);
        let b = s.bounds();
        assert!(b.contains(Vec3::new(0.0, 0.0, 5.0)) && b.contains(Vec3::new(-10.0, 10.0, 0.0)));
    }

    #[test]
    fn is_shareable_across_threads() {
        fn assert_send_sync<T: Send + Sync>() {}
        assert_send_sync::<SceneGeometry>();
    }

    #[test]
    fn empty_scene() {
        let s = SceneGeometry::new(vec![]).unwrap();
        assert!(s.intersect(&Ray::infinite(Vec3::ZERO, Vec3::Z)).is_none());
        assert!(!s.occluded(Vec3::ZERO, Vec3::Z, 1.0));
        assert!(s.bounds().is_empty());
    }
}
