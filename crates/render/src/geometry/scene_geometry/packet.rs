//! Ray queries for a packet of eight rays ([`Bvh::closest_hit_packet`],
//! [`Bvh::any_hit_packet`]): spheres and rectangles are tested eight lanes at a time by
//! their one-source tests ([`Sphere::intersect_lanes`],
//! [`Rectangle::intersect_lanes`](crate::geometry::Rectangle::intersect_lanes); with
//! `F64x8` the same bits as one ray at a time), triangles and disks lane by lane with
//! their one-ray tests. A lane's hit is
//! therefore the hit the one-ray query finds; only among primitives hit at exactly the
//! same distance may the two orders pick different ones.

use super::{HitDetail, SceneGeometry};
use crate::geometry::bvh::{lanes_of, Lanes, PacketBox, PACKET};
use crate::geometry::interaction::{PrimHit, SurfaceHit};
use crate::geometry::ray::Ray;
use crate::geometry::shape::Shape;
use crate::geometry::sphere::Sphere;
use crate::geometry::triangle::TriangleRay;
use crate::geometry::{Vec2, Vec3};
use facette_bsdf::lanes::{F64x8, LVec3, Mask, Real};

/// A packet lane's closest hit: the primitive's slot in the BVH order and the hit.
#[derive(Clone, Copy, Debug, Default)]
pub struct PacketHit {
    slot: u32,
    hit: PrimHit,
}

impl PacketHit {
    /// The ray distance of the hit.
    #[inline]
    pub fn t(&self) -> f64 {
        self.hit.t
    }
}

/// Eight rays in lanes of `R` (structure of arrays): origins and directions per axis, their
/// limits, and the lanes that hold a ray. The render kernel keeps its paths' rays in this
/// form (`F32x8` in renders, `F64x8` in the test that finds the scalar integrator's image);
/// lanes without a valid ray hold a harmless one.
#[derive(Clone, Copy, Debug)]
pub struct LaneRays<R: Real = F64x8> {
    pub o: LVec3<R>,
    pub d: LVec3<R>,
    pub t_max: R,
    /// The lanes with a valid ray (finite origin, finite non-zero direction).
    pub lanes: Lanes,
}

impl<R: Real> LaneRays<R> {
    /// The rays of `lanes` from `o` along `d` up to `t_max`; a lane whose ray is not a
    /// valid query (a non-finite origin, a zero or non-finite direction) is dropped and
    /// given a harmless ray.
    #[inline(always)]
    pub fn new(o: LVec3<R>, d: LVec3<R>, t_max: R, lanes: Lanes) -> LaneRays<R> {
        let valid = o.x.is_finite()
            & o.y.is_finite()
            & o.z.is_finite()
            & d.x.is_finite()
            & d.y.is_finite()
            & d.z.is_finite()
            & !(d.x.eq(R::zero()) & d.y.eq(R::zero()) & d.z.eq(R::zero()));
        let lanes = lanes & valid.lane_bits() as Lanes;
        let m = R::Mask::from_lane_bits(lanes as u32);
        let unit = LVec3::new(R::zero(), R::zero(), R::one());
        LaneRays {
            o: LVec3::select(m, o, LVec3::zero()),
            d: LVec3::select(m, d, unit),
            t_max: R::select(m, t_max, R::zero()),
            lanes,
        }
    }

    /// The packet of `rays` (`None` lanes hold no ray).
    #[inline(always)]
    pub fn from_rays(rays: &[Option<Ray>; PACKET]) -> LaneRays<R> {
        let lanes = (0..PACKET).fold(0, |set, i| set | ((rays[i].is_some() as Lanes) << i));
        let ray = |i: usize| {
            rays[i].unwrap_or(Ray {
                origin: Vec3::ZERO,
                dir: Vec3::Z,
                t_max: 0.0,
            })
        };
        let v = |f: &dyn Fn(&Ray) -> Vec3| LVec3::from_fn(|i| f(&ray(i)));
        LaneRays::new(
            v(&|r| r.origin),
            v(&|r| r.dir),
            R::from_fn(|i| ray(i).t_max),
            lanes,
        )
    }

    /// Lane `i`'s ray.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> Ray {
        Ray {
            origin: self.o.lane(i),
            dir: self.d.lane(i),
            t_max: self.t_max.lane(i),
        }
    }

    /// The coordinates as f64 arrays per axis (the traversal's set-up reads them so).
    #[inline(always)]
    fn axes(v: &LVec3<R>) -> [[f64; PACKET]; 3] {
        [v.x, v.y, v.z].map(|c| std::array::from_fn(|i| c.lane(i)))
    }

    /// The lanes of `lanes` whose ray hits `sphere` in `(0, t_max]`, with the distance.
    #[inline(always)]
    fn sphere(&self, sphere: &Sphere, lanes: Lanes, t_max: R) -> (Lanes, R) {
        let (m, t) = sphere.intersect_lanes(self.o, self.d, t_max);
        (m.lane_bits() as Lanes & lanes, t)
    }
}

/// The surface records of a packet's hits in lanes (structure of arrays): what
/// [`packet_hit_record`](SceneGeometry::packet_hit_record) gives each lane with
/// [`HitDetail::Shading`], sphere hits computed eight lanes at a time by their one-source
/// record ([`Sphere::shading_hit_lanes`]; their `dpdv` and `uv` are left at zero until
/// [`complete_hit`](SceneGeometry::complete_hit)), rectangle hits eight at a time too, the
/// other shapes lane by lane.
#[derive(Clone, Copy, Debug)]
pub struct HitLanes<R: Real = F64x8> {
    pub t: R,
    pub p: LVec3<R>,
    pub ng: LVec3<R>,
    pub ns: LVec3<R>,
    pub dpdu: LVec3<R>,
    pub dpdv: LVec3<R>,
    pub uv: [[f64; PACKET]; 2],
    pub shape: [u32; PACKET],
    pub prim: [u32; PACKET],
    /// The lanes with a hit.
    pub lanes: Lanes,
}

impl<R: Real> Default for HitLanes<R> {
    /// No lane, every field zero.
    fn default() -> Self {
        let zero = LVec3::zero();
        HitLanes {
            t: R::zero(),
            p: zero,
            ng: zero,
            ns: zero,
            dpdu: zero,
            dpdv: zero,
            uv: [[0.0; PACKET]; 2],
            shape: [0; PACKET],
            prim: [0; PACKET],
            lanes: 0,
        }
    }
}

impl<R: Real> HitLanes<R> {
    /// Lane `i`'s record.
    #[inline]
    pub fn surface_hit(&self, i: usize) -> SurfaceHit {
        SurfaceHit {
            t: self.t.lane(i),
            p: self.p.lane(i),
            ng: self.ng.lane(i),
            ns: self.ns.lane(i),
            uv: Vec2::new(self.uv[0][i], self.uv[1][i]),
            dpdu: self.dpdu.lane(i),
            dpdv: self.dpdv.lane(i),
            shape: self.shape[i],
            prim: self.prim[i],
        }
    }

    /// Stores `h` in lane `i`.
    #[inline]
    fn set(&mut self, i: usize, h: &SurfaceHit) {
        self.t.set_lane(i, h.t);
        self.p.set_lane(i, h.p);
        self.ng.set_lane(i, h.ng);
        self.ns.set_lane(i, h.ns);
        self.dpdu.set_lane(i, h.dpdu);
        self.dpdv.set_lane(i, h.dpdv);
        self.uv[0][i] = h.uv.x;
        self.uv[1][i] = h.uv.y;
        self.shape[i] = h.shape;
        self.prim[i] = h.prim;
    }
}

/// A closest-hit query in progress: the hit of each lane so far. Its primitive test is a
/// method forced inline so that it is compiled into the kernel's AVX2 instantiation.
struct Closest<'a, R: Real> {
    geometry: &'a SceneGeometry,
    rays: &'a LaneRays<R>,
    /// The caller's result, written in place for the lanes that hit (a by-value array
    /// here was copied out with `memcpy` at every query).
    best: &'a mut [PacketHit; PACKET],
    /// Each lane's distance limit: the ray's, then its closest hit's.
    t: R,
    /// The lanes with a hit so far.
    found: Lanes,
    tri: TriangleRays,
}

/// Each lane's triangle set-up, made at its first triangle test: none is made, and the
/// 640 bytes of eight empty slots are not even cleared, for a query that meets no triangle
/// (the clearing was a `memset` per query on sphere scenes).
#[derive(Default)]
struct TriangleRays(Option<[Option<TriangleRay>; PACKET]>);

impl TriangleRays {
    /// Lane `i`'s slot.
    #[inline(always)]
    fn lane(&mut self, i: usize) -> &mut Option<TriangleRay> {
        &mut self.0.get_or_insert([None; PACKET])[i]
    }
}

impl<R: Real> Closest<'_, R> {
    /// Tests the primitive in `slot` for `lanes` within `(0, t]`; lowers `t` where it
    /// hits and returns those lanes.
    #[inline(always)]
    fn test(&mut self, slot: usize, lanes: Lanes) -> Lanes {
        let g = self.geometry;
        match &g.shapes[g.prims[slot].shape as usize] {
            Shape::Sphere(s) => {
                let (hit, t) = self.rays.sphere(s, lanes, self.t);
                return self.keep(slot, hit, t, |_| Vec2::ZERO);
            }
            Shape::Rectangle(q) => {
                let (m, t, x, y) = q.intersect_lanes(self.rays.o, self.rays.d, self.t);
                let hit = m.lane_bits() as Lanes & lanes;
                return self.keep(slot, hit, t, |i| Vec2::new(x.lane(i), y.lane(i)));
            }
            _ => {}
        }
        let mut found = 0;
        for i in lanes_of(lanes) {
            let ray = self.rays.ray(i);
            let t_max = self.t.lane(i);
            if let Some(h) = g.test_prim(slot, &ray, self.tri.lane(i), t_max) {
                if h.t <= t_max {
                    self.t.set_lane(i, h.t);
                    self.best[i] = PacketHit {
                        slot: slot as u32,
                        hit: h,
                    };
                    found |= 1 << i;
                }
            }
        }
        self.found |= found;
        found
    }

    /// Records the lanes of `hit` (hits of the primitive in `slot` at distances `t`,
    /// object-space coordinates `local`) as the closest so far; returns them.
    #[inline(always)]
    fn keep(&mut self, slot: usize, hit: Lanes, t: R, local: impl Fn(usize) -> Vec2) -> Lanes {
        if hit != 0 {
            self.t = R::select(R::Mask::from_lane_bits(hit as u32), t, self.t);
            for i in lanes_of(hit) {
                self.best[i] = PacketHit {
                    slot: slot as u32,
                    hit: PrimHit {
                        t: t.lane(i),
                        local: local(i),
                    },
                };
            }
            self.found |= hit;
        }
        hit
    }
}

/// An occlusion query in progress (see [`Closest`]).
struct Occluded<'a, R: Real> {
    geometry: &'a SceneGeometry,
    rays: &'a LaneRays<R>,
    tri: TriangleRays,
}

impl<R: Real> Occluded<'_, R> {
    /// The lanes of `lanes` whose ray hits the primitive in `slot` within its limit.
    #[inline(always)]
    fn test(&mut self, slot: usize, lanes: Lanes) -> Lanes {
        let g = self.geometry;
        match &g.shapes[g.prims[slot].shape as usize] {
            Shape::Sphere(s) => return self.rays.sphere(s, lanes, self.rays.t_max).0,
            Shape::Rectangle(q) => {
                let (m, ..) = q.intersect_lanes(self.rays.o, self.rays.d, self.rays.t_max);
                return m.lane_bits() as Lanes & lanes;
            }
            _ => {}
        }
        lanes_of(lanes).fold(0, |hit, i| {
            let ray = self.rays.ray(i);
            let occluded = g
                .test_prim(slot, &ray, self.tri.lane(i), ray.t_max)
                .is_some();
            hit | ((occluded as Lanes) << i)
        })
    }
}

/// The largest hierarchy (in wide nodes) traversed by packets; larger ones are traversed
/// one lane at a time. On the 1M-triangle mesh scene (`scenes/mesh.toml`), whose
/// secondary rays scatter over the mesh, packet traversal rendered at 0.75–0.8× the speed
/// of one-ray traversal (the lanes are carried through each other's boxes, and triangles
/// are tested lane by lane anyway); on scenes of a few shapes it is the faster one
/// (docs/performance.md).
pub const PACKET_TRAVERSAL_MAX_NODES: usize = 64;

impl SceneGeometry {
    /// Whether the packet queries traverse the hierarchy as packets
    /// ([`PACKET_TRAVERSAL_MAX_NODES`]); otherwise they query lane by lane, with the same
    /// results.
    #[inline]
    pub fn packet_traversal(&self) -> bool {
        self.packet_traversal
    }

    /// The closest hit of every ray of a packet (`None` lanes hit nothing), as the
    /// primitive's slot and its hit; [`packet_hit_record`](Self::packet_hit_record) makes
    /// the surface record of one.
    #[inline(always)]
    pub fn intersect_packet(&self, rays: &[Option<Ray>; PACKET]) -> [Option<PacketHit>; PACKET] {
        let mut hits = [PacketHit::default(); PACKET];
        let (found, _) = self.intersect_lanes(&LaneRays::<F64x8>::from_rays(rays), &mut hits);
        std::array::from_fn(|i| (found & (1 << i) != 0).then_some(hits[i]))
    }

    /// [`intersect_packet`](Self::intersect_packet) for rays already in lanes: the lanes
    /// with a hit and their distances in lanes, the hits written to `hits` (the other
    /// lanes of `hits` are left as they were: the caller keeps one buffer across queries,
    /// nothing is copied out).
    #[inline(always)]
    pub fn intersect_lanes<R: Real>(
        &self,
        rays: &LaneRays<R>,
        hits: &mut [PacketHit; PACKET],
    ) -> (Lanes, R) {
        let lanes = rays.lanes;
        if lanes == 0 {
            return (0, rays.t_max);
        }
        if !self.packet_traversal() {
            let mut found = 0;
            let mut t = rays.t_max;
            for i in lanes_of(lanes) {
                if let Some((slot, hit)) = self.closest_slot(&rays.ray(i)) {
                    hits[i] = PacketHit {
                        slot: slot as u32,
                        hit,
                    };
                    t.set_lane(i, hit.t);
                    found |= 1 << i;
                }
            }
            return (found, t);
        }
        let mut q = Closest {
            geometry: self,
            rays,
            best: hits,
            t: rays.t_max,
            found: 0,
            tri: TriangleRays::default(),
        };
        match self.bvh.single_leaf() {
            // A scene of a few primitives: no box to test.
            Some(slots) => {
                for slot in slots {
                    q.test(slot, lanes);
                }
            }
            None => {
                let pb = PacketBox::new(&LaneRays::axes(&rays.o), &LaneRays::axes(&rays.d));
                let mut t_max = std::array::from_fn(|i| rays.t_max.lane(i));
                self.bvh
                    .closest_hit_packet(&pb, lanes, &mut t_max, |slot, lanes, t_max| {
                        let hit = q.test(slot, lanes);
                        for i in lanes_of(hit) {
                            t_max[i] = q.t.lane(i);
                        }
                        hit
                    });
            }
        }
        (q.found, q.t)
    }

    /// The surface record of `ray`'s hit `hit` found by
    /// [`intersect_packet`](Self::intersect_packet), with the details asked for: what
    /// [`intersect_with`](Self::intersect_with) returns for that ray.
    #[inline]
    pub fn packet_hit_record(&self, ray: &Ray, hit: PacketHit, detail: HitDetail) -> SurfaceHit {
        self.hit_record(hit.slot as usize, ray, hit.hit, detail)
    }

    /// The surface records of the hits `hits` of `rays` in the lanes `found` at the
    /// distances `t` (as [`intersect_lanes`](Self::intersect_lanes) gives them), written
    /// into `out`: spheres and rectangles hit by several lanes eight lanes at a time, every
    /// other hit lane by lane. Only the
    /// lanes of `found` are written (and `out.lanes` set to them): the caller keeps one
    /// record across segments, neither cleared nor copied out (a `memset` and a `memcpy`
    /// of its 1.1 KB per segment before).
    #[inline(always)]
    pub fn hit_lanes<R: Real>(
        &self,
        rays: &LaneRays<R>,
        hits: &[PacketHit; PACKET],
        (found, t): (Lanes, R),
        out: &mut HitLanes<R>,
    ) {
        out.lanes = found;
        if found == 0 {
            return;
        }
        // Every lane's shape (the lanes without a hit read a stale or default slot, which
        // is a valid one: the scene has primitives since a lane hit one), then the lanes
        // of each shape by one comparison per lane — or, in a scene of one shape, every
        // hit lane at once.
        let one_shape = self.shapes.len() == 1;
        let shapes: [u32; PACKET] = if one_shape {
            [0; PACKET]
        } else {
            std::array::from_fn(|i| self.prims[hits[i].slot as usize].shape)
        };
        let mut todo = found;
        while todo != 0 {
            let first = todo.trailing_zeros() as usize;
            let shape = shapes[first];
            let group = if one_shape {
                todo
            } else {
                (0..PACKET).fold(0, |m: Lanes, i| m | (((shapes[i] == shape) as Lanes) << i)) & todo
            };
            todo &= !group;
            match &self.shapes[shape as usize] {
                Shape::Sphere(sphere) if group.count_ones() > 1 => {
                    let (p, n, dpdu, _) = sphere.shading_hit_lanes(rays.o, rays.d, t);
                    let m = R::Mask::from_lane_bits(group as u32);
                    let zero = LVec3::zero();
                    out.t = R::select(m, t, out.t);
                    out.p = LVec3::select(m, p, out.p);
                    out.ng = LVec3::select(m, n, out.ng);
                    out.ns = LVec3::select(m, n, out.ns);
                    out.dpdu = LVec3::select(m, dpdu, out.dpdu);
                    // What the one-lane record leaves for `complete_hit`: zero.
                    out.dpdv = LVec3::select(m, zero, out.dpdv);
                    for i in lanes_of(group) {
                        out.shape[i] = shape;
                        out.prim[i] = 0;
                        out.uv[0][i] = 0.0;
                        out.uv[1][i] = 0.0;
                    }
                }
                Shape::Rectangle(q) if group.count_ones() > 1 => {
                    // `Rectangle::surface_hit` in lanes.
                    let m = R::Mask::from_lane_bits(group as u32);
                    let n = LVec3::splat(q.normal());
                    let (dpdu, dpdv) = q.tangents();
                    out.t = R::select(m, t, out.t);
                    out.p = LVec3::select(m, q.hit_points_lanes(rays.o, rays.d, t), out.p);
                    out.ng = LVec3::select(m, n, out.ng);
                    out.ns = LVec3::select(m, n, out.ns);
                    out.dpdu = LVec3::select(m, LVec3::splat(dpdu), out.dpdu);
                    out.dpdv = LVec3::select(m, LVec3::splat(dpdv), out.dpdv);
                    for i in lanes_of(group) {
                        let uv = hits[i].hit.local * 0.5 + Vec2::splat(0.5);
                        out.shape[i] = shape;
                        out.prim[i] = 0;
                        out.uv[0][i] = uv.x;
                        out.uv[1][i] = uv.y;
                    }
                }
                _ => {
                    for i in lanes_of(group) {
                        let h = hits[i];
                        let rec = self.hit_record(
                            h.slot as usize,
                            &rays.ray(i),
                            h.hit,
                            HitDetail::Shading,
                        );
                        out.set(i, &rec);
                    }
                }
            }
        }
    }

    /// [`occluded_ray`](Self::occluded_ray) for every ray of a packet: the occluded lanes
    /// (`None` lanes are not).
    #[inline(always)]
    pub fn occluded_packet(&self, rays: &[Option<Ray>; PACKET]) -> Lanes {
        self.occluded_lanes(&LaneRays::<F64x8>::from_rays(rays))
    }

    /// [`occluded_packet`](Self::occluded_packet) for rays already in lanes.
    #[inline(always)]
    pub fn occluded_lanes<R: Real>(&self, rays: &LaneRays<R>) -> Lanes {
        let lanes = rays.lanes;
        if lanes == 0 {
            return 0;
        }
        if !self.packet_traversal() {
            return lanes_of(lanes).fold(0, |set, i| {
                set | ((self.occluded_ray(&rays.ray(i)) as Lanes) << i)
            });
        }
        let mut q = Occluded {
            geometry: self,
            rays,
            tri: TriangleRays::default(),
        };
        let mut test = |slot, lanes| q.test(slot, lanes);
        match self.bvh.single_leaf() {
            Some(slots) => {
                let mut left = lanes;
                for slot in slots {
                    if left == 0 {
                        break;
                    }
                    left &= !test(slot, left);
                }
                lanes & !left
            }
            None => {
                let pb = PacketBox::new(&LaneRays::axes(&rays.o), &LaneRays::axes(&rays.d));
                let t_max = std::array::from_fn(|i| rays.t_max.lane(i));
                self.bvh.any_hit_packet(&pb, lanes, &t_max, test)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::generate::TorusKnot;
    use crate::geometry::{Disk, Rectangle, Transform, Vec3};
    use facette_bsdf::math::rng::{Pcg32, RandomSource};
    use facette_bsdf::math::warp::square_to_uniform_sphere;

    /// Every kind of primitive: a floor, two spheres (one inside the other's box), a disk
    /// lamp, and a 2,000-triangle torus knot (a BVH of many nodes).
    fn scene() -> SceneGeometry {
        let mut shapes = small_scene_shapes();
        let knot = TorusKnot::with_triangles(2000)
            .mesh(&Transform::translate(Vec3::new(3.0, 0.0, 1.5)).unwrap())
            .unwrap();
        shapes.push(knot.into());
        SceneGeometry::new(shapes).unwrap()
    }

    /// Four primitives: one leaf.
    fn small_scene_shapes() -> Vec<Shape> {
        let floor = Rectangle::new(
            &Transform::scale(Vec3::new(10.0, 10.0, 1.0)).unwrap(),
            false,
        )
        .unwrap();
        let ball = Sphere::new(Vec3::new(0.0, 0.0, 1.0), 1.0).unwrap();
        let far_ball = Sphere::new(Vec3::new(1e4, -2e4, 3.0), 2.5).unwrap();
        let lamp = Disk::new(
            &(Transform::translate(Vec3::new(0.0, 0.0, 5.0)).unwrap()
                * Transform::rotate(Vec3::X, 180.0).unwrap()),
            false,
        )
        .unwrap();
        vec![floor.into(), ball.into(), far_ball.into(), lamp.into()]
    }

    /// Rays of three kinds: from a camera (coherent), from random points in random
    /// directions, and spawned from hits on the surfaces (the path tracer's secondary and
    /// shadow rays, starting on a surface), with some lanes empty.
    fn packets(geometry: &SceneGeometry, count: usize) -> Vec<[Option<Ray>; PACKET]> {
        let mut rng = Pcg32::new(7, 1);
        let mut out = Vec::new();
        for n in 0..count {
            let packet = std::array::from_fn(|i| {
                let u = [
                    rng.next_f64(),
                    rng.next_f64(),
                    rng.next_f64(),
                    rng.next_f64(),
                ];
                let dir = square_to_uniform_sphere(Vec2::new(u[0], u[1]));
                let ray = match n % 3 {
                    0 => {
                        let o = Vec3::new(0.5, -8.0, 3.0);
                        let target = Vec3::new(8.0 * u[2] - 3.0, 0.0, 4.0 * u[3]);
                        Ray::new(o, target - o, f64::INFINITY)
                    }
                    1 => {
                        let o = Vec3::new(8.0 * u[2] - 4.0, 6.0 * u[3] - 3.0, 3.0 * u[2]);
                        Ray::new(o, dir, if u[3] < 0.3 { 2.0 } else { f64::INFINITY })
                    }
                    _ => {
                        let o = Vec3::new(8.0 * u[2] - 4.0, 6.0 * u[3] - 3.0, 6.0);
                        let first = Ray::new(o, Vec3::new(u[0] - 0.5, u[1] - 0.5, -1.0), 1e9);
                        match geometry.intersect_with(&first, HitDetail::Shading) {
                            Some(h) if u[3] < 0.5 => h.spawn_ray(dir),
                            Some(h) => h.spawn_ray_to(Vec3::new(0.0, 0.0, 4.9)),
                            None => first,
                        }
                    }
                };
                (i != 3 || n % 4 != 0).then_some(ray)
            });
            out.push(packet);
        }
        out
    }

    /// Each lane finds the one-ray query's hit: the same primitive at the same distance
    /// to the bit, and the same occlusion.
    #[test]
    fn packets_find_what_one_ray_queries_find() {
        let mut geometry = scene();
        // The knot's hierarchy is beyond the packet traversal's limit: both ways, packet
        // traversal first.
        assert!(!geometry.packet_traversal());
        for packet_traversal in [true, false] {
            geometry.packet_traversal = packet_traversal;
            let (hits, occluded) = compare_with_one_ray_queries(&geometry);
            // Enough of each outcome for the comparison to mean something.
            assert!(
                hits > 6000 && occluded > 6000,
                "{hits} hits, {occluded} occluded"
            );
        }
        // A hierarchy of one leaf is not traversed at all: two nested spheres.
        let inner = Sphere::new(Vec3::new(0.2, 0.0, 1.0), 0.4).unwrap();
        let mut shapes = small_scene_shapes();
        shapes.truncate(2);
        shapes[0] = inner.into();
        let small = SceneGeometry::new(shapes).unwrap();
        assert_eq!(small.bvh.single_leaf(), Some(0..2));
        let (hits, occluded) = compare_with_one_ray_queries(&small);
        assert!(
            hits > 1000 && occluded > 1000,
            "{hits} hits, {occluded} occluded"
        );
    }

    /// Rays spawned in f32 lanes (the render kernel's) off spheres and meshes far from the
    /// origin, and off a tiny sphere near it, in random directions, never hit the
    /// primitive they leave (outwards) and never leak out of a sphere (inwards: they hit
    /// its far side, at the chord's length). The same in f64 lanes.
    #[test]
    fn rays_spawned_in_lanes_do_not_hit_their_own_surface() {
        use crate::geometry::ray::offset_origin_lanes;
        use facette_bsdf::lanes::F32x8;
        let spheres = [
            (Vec3::new(1e3, -2e3, 5e2), 1.0),
            (Vec3::new(3e4, 1e4, -2e4), 50.0),
            (Vec3::new(-0.3, 0.2, 0.1), 1e-3),
        ];
        let mut shapes: Vec<Shape> = spheres
            .iter()
            .map(|&(c, r)| Sphere::new(c, r).unwrap().into())
            .collect();
        let knot_at = Vec3::new(-5e3, 2e3, 1e3);
        let knot = TorusKnot::with_triangles(100_000)
            .mesh(
                &(Transform::translate(knot_at).unwrap()
                    * Transform::scale(Vec3::splat(40.0)).unwrap()),
            )
            .unwrap();
        shapes.push(knot.into());
        let floor_at = Vec3::new(2e3, 3e3, -1e3);
        let floor = Rectangle::new(
            &(Transform::translate(floor_at).unwrap()
                * Transform::rotate(Vec3::new(1.0, 2.0, 0.5), 33.0).unwrap()
                * Transform::scale(Vec3::new(400.0, 300.0, 1.0)).unwrap()),
            false,
        )
        .unwrap();
        shapes.push(floor.into());
        let mut geometry = SceneGeometry::new(shapes).unwrap();
        // Aim points and sizes: the spheres, the knot (about 3 × 40 across), the floor.
        let mut targets: Vec<(Vec3, f64)> = spheres.to_vec();
        targets.push((knot_at, 60.0));
        targets.push((floor_at, 250.0));
        for packet_traversal in [false, true] {
            geometry.packet_traversal = packet_traversal;
            let f32_counts = spawn_off_surfaces::<F32x8>(&geometry, &targets, spheres.len());
            let f64_counts = spawn_off_surfaces::<F64x8>(&geometry, &targets, spheres.len());
            for (out, inward, mesh) in [f32_counts, f64_counts] {
                // Enough of each kind for the check to mean something.
                assert!(
                    out > 3000 && inward > 1000 && mesh > 1000,
                    "{out} outward, {inward} inward, {mesh} off the knot and floor"
                );
            }
        }

        /// Spawns rays off first hits; panics at a self-hit or a leak; returns the counts
        /// of outward and inward sphere rays and of mesh and floor rays checked.
        fn spawn_off_surfaces<R: Real>(
            geometry: &SceneGeometry,
            targets: &[(Vec3, f64)],
            sphere_count: usize,
        ) -> (usize, usize, usize) {
            let mut rng = Pcg32::new(11, 3);
            let (mut out, mut inward, mut mesh) = (0, 0, 0);
            let mut hits = [PacketHit::default(); PACKET];
            let mut record = HitLanes::<R>::default();
            for n in 0..2000 {
                let (center, size) = targets[n % targets.len()];
                let mut u = || Vec2::new(rng.next_f64(), rng.next_f64());
                let from: [Vec3; PACKET] =
                    std::array::from_fn(|_| center + square_to_uniform_sphere(u()) * (4.0 * size));
                let to: [Vec3; PACKET] = std::array::from_fn(|_| {
                    center + square_to_uniform_sphere(u()) * (0.7 * size * u().x)
                });
                let o = LVec3::from_fn(|i| from[i]);
                let d = LVec3::from_fn(|i| (to[i] - from[i]).normalize());
                let rays = LaneRays::new(o, d, R::splat(f64::INFINITY), 0xff);
                let found = geometry.intersect_lanes(&rays, &mut hits);
                geometry.hit_lanes(&rays, &hits, found, &mut record);
                let dirs: [Vec3; PACKET] = std::array::from_fn(|_| square_to_uniform_sphere(u()));
                let dir = LVec3::from_fn(|i| dirs[i]);
                let spawned = LaneRays::new(
                    offset_origin_lanes(record.p, record.ng, dir),
                    dir,
                    R::splat(f64::INFINITY),
                    found.0,
                );
                let mut again = [PacketHit::default(); PACKET];
                let (hit, t) = geometry.intersect_lanes(&spawned, &mut again);
                let blocked = geometry.occluded_lanes(&spawned);
                assert_eq!(blocked, hit, "the occlusion query disagrees");
                for i in lanes_of(spawned.lanes) {
                    let (shape, prim) = (record.shape[i], record.prim[i]);
                    let outward = dirs[i].dot(record.ng.lane(i)) > 0.0;
                    let again = (hit & (1 << i) != 0).then(|| {
                        let h = geometry.packet_hit_record(
                            &spawned.ray(i),
                            again[i],
                            HitDetail::Shading,
                        );
                        (h.shape, h.prim, t.lane(i))
                    });
                    let same = again.filter(|&(s, p, _)| (s, p) == (shape, prim));
                    if (shape as usize) < sphere_count {
                        let (c, r) = targets[shape as usize];
                        if outward {
                            assert!(same.is_none(), "self-hit off sphere {shape}: {same:?}");
                            out += 1;
                        } else {
                            // It leaves the sphere: its hit is on the surface (to a few
                            // ulps of the coordinates), on the far side (moving outwards).
                            let Some((_, _, t)) = same else {
                                panic!("leak out of sphere {shape}: {again:?}")
                            };
                            let ray = spawned.ray(i);
                            let q = ray.origin + ray.dir * t;
                            let scale = 1.0 + ray.origin.abs().max_element();
                            let off = ((q - c).length() - r).abs();
                            assert!(
                                off <= 1e-5 * scale && (q - c).dot(ray.dir) > 0.0,
                                "sphere {shape} ({} bits): exit {q:?} off the surface by {off}",
                                R::DIGITS
                            );
                            inward += 1;
                        }
                    } else {
                        assert!(same.is_none(), "self-hit off shape {shape} prim {prim}");
                        mesh += 1;
                    }
                }
            }
            (out, inward, mesh)
        }
    }

    /// The lanes that hit something and the occluded lanes.
    fn compare_with_one_ray_queries(geometry: &SceneGeometry) -> (usize, usize) {
        let (mut hits, mut occluded) = (0, 0);
        for rays in packets(geometry, 3000) {
            let packet = geometry.intersect_packet(&rays);
            let blocked = geometry.occluded_packet(&rays);
            for i in 0..PACKET {
                let one = rays[i].and_then(|r| geometry.intersect_with(&r, HitDetail::Shading));
                let packet = packet[i].map(|h| {
                    geometry.packet_hit_record(rays[i].as_ref().unwrap(), h, HitDetail::Shading)
                });
                match (&one, &packet) {
                    (None, None) => {}
                    (Some(a), Some(b)) => {
                        assert_eq!((a.shape, a.prim), (b.shape, b.prim), "lane {i}: {rays:?}");
                        assert_eq!(a.t.to_bits(), b.t.to_bits());
                        assert_eq!(a.p, b.p);
                        hits += 1;
                    }
                    _ => panic!("lane {i}: one ray {one:?}, packet {packet:?}"),
                }
                let one = rays[i].is_some_and(|r| geometry.occluded_ray(&r));
                assert_eq!(one, blocked & (1 << i) != 0, "lane {i}: {:?}", rays[i]);
                occluded += one as usize;
            }
        }
        (hits, occluded)
    }
}
