//! Ray queries for a packet of eight rays ([`Bvh::closest_hit_packet`],
//! [`Bvh::any_hit_packet`]): spheres are tested eight lanes at a time by their one-source
//! test ([`Sphere::intersect_lanes`] with `F64x8`: the same bits as one ray at a time),
//! triangles, rectangles and disks lane by lane with their one-ray tests. A lane's hit is
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
use facette_bsdf::lanes::{F64x8, LVec3, M64x8, Real};

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

/// Eight rays in lanes (structure of arrays): f64 origins and directions per axis, their
/// limits, and the lanes that hold a ray. The render kernel keeps its paths' rays in this
/// form; lanes without a valid ray hold a harmless one.
#[derive(Clone, Copy, Debug)]
pub struct LaneRays {
    pub o: LVec3<F64x8>,
    pub d: LVec3<F64x8>,
    pub t_max: F64x8,
    /// The lanes with a valid ray (finite origin, finite non-zero direction).
    pub lanes: Lanes,
}

impl LaneRays {
    /// The rays of `lanes` from `o` along `d` up to `t_max`; a lane whose ray is not a
    /// valid query (a non-finite origin, a zero or non-finite direction) is dropped and
    /// given a harmless ray.
    #[inline(always)]
    pub fn new(o: LVec3<F64x8>, d: LVec3<F64x8>, t_max: F64x8, lanes: Lanes) -> LaneRays {
        let valid = o.x.is_finite()
            & o.y.is_finite()
            & o.z.is_finite()
            & d.x.is_finite()
            & d.y.is_finite()
            & d.z.is_finite()
            & !(d.x.eq(F64x8::zero()) & d.y.eq(F64x8::zero()) & d.z.eq(F64x8::zero()));
        let lanes = lanes & valid.bits() as Lanes;
        let m = M64x8::from_bits(lanes as u32);
        let unit = LVec3::new(F64x8::zero(), F64x8::zero(), F64x8::one());
        LaneRays {
            o: LVec3::select(m, o, LVec3::zero()),
            d: LVec3::select(m, d, unit),
            t_max: F64x8::select(m, t_max, F64x8::zero()),
            lanes,
        }
    }

    /// The packet of `rays` (`None` lanes hold no ray).
    #[inline(always)]
    pub fn from_rays(rays: &[Option<Ray>; PACKET]) -> LaneRays {
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
            F64x8::from_fn(|i| ray(i).t_max),
            lanes,
        )
    }

    /// Lane `i`'s ray.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> Ray {
        Ray {
            origin: self.o.lane(i),
            dir: self.d.lane(i),
            t_max: self.t_max.0[i],
        }
    }

    /// The coordinates as arrays per axis (the traversal's set-up reads them so).
    #[inline(always)]
    fn axes(v: &LVec3<F64x8>) -> [[f64; PACKET]; 3] {
        [v.x.0, v.y.0, v.z.0]
    }

    /// The lanes of `lanes` whose ray hits `sphere` in `(0, t_max[i]]`, with the distance.
    #[inline(always)]
    fn sphere(
        &self,
        sphere: &Sphere,
        lanes: Lanes,
        t_max: &[f64; PACKET],
    ) -> (Lanes, [f64; PACKET]) {
        let (m, t) = sphere.intersect_lanes(self.o, self.d, F64x8(*t_max));
        (m.bits() as Lanes & lanes, t.0)
    }
}

/// The surface records of a packet's hits in lanes (structure of arrays): what
/// [`packet_hit_record`](SceneGeometry::packet_hit_record) gives each lane with
/// [`HitDetail::Shading`], sphere hits computed eight lanes at a time by their one-source
/// record ([`Sphere::shading_hit_lanes`]; their `dpdv` and `uv` are left at zero until
/// [`complete_hit`](SceneGeometry::complete_hit)), the other shapes lane by lane.
#[derive(Clone, Copy, Debug)]
pub struct HitLanes {
    pub t: F64x8,
    pub p: LVec3<F64x8>,
    pub ng: LVec3<F64x8>,
    pub ns: LVec3<F64x8>,
    pub dpdu: LVec3<F64x8>,
    pub dpdv: LVec3<F64x8>,
    pub uv: [[f64; PACKET]; 2],
    pub shape: [u32; PACKET],
    pub prim: [u32; PACKET],
    /// The lanes with a hit.
    pub lanes: Lanes,
}

impl Default for HitLanes {
    /// No lane, every field zero.
    fn default() -> Self {
        let zero = LVec3::zero();
        HitLanes {
            t: F64x8::zero(),
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

impl HitLanes {
    /// Lane `i`'s record.
    #[inline]
    pub fn surface_hit(&self, i: usize) -> SurfaceHit {
        SurfaceHit {
            t: self.t.0[i],
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
        let put = |v: &mut LVec3<F64x8>, w: Vec3| {
            v.x.0[i] = w.x;
            v.y.0[i] = w.y;
            v.z.0[i] = w.z;
        };
        self.t.0[i] = h.t;
        put(&mut self.p, h.p);
        put(&mut self.ng, h.ng);
        put(&mut self.ns, h.ns);
        put(&mut self.dpdu, h.dpdu);
        put(&mut self.dpdv, h.dpdv);
        self.uv[0][i] = h.uv.x;
        self.uv[1][i] = h.uv.y;
        self.shape[i] = h.shape;
        self.prim[i] = h.prim;
    }
}

/// A closest-hit query in progress: the hit of each lane so far. Its primitive test is a
/// method forced inline so that it is compiled into the kernel's AVX2 instantiation.
struct Closest<'a> {
    geometry: &'a SceneGeometry,
    rays: &'a LaneRays,
    /// The caller's result, written in place for the lanes that hit (a by-value array
    /// here was copied out with `memcpy` at every query).
    best: &'a mut [PacketHit; PACKET],
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

impl Closest<'_> {
    /// Tests the primitive in `slot` for `lanes` within `(0, t_max[i]]`; lowers `t_max`
    /// where it hits and returns those lanes.
    #[inline(always)]
    fn test(&mut self, slot: usize, lanes: Lanes, t_max: &mut [f64; PACKET]) -> Lanes {
        let g = self.geometry;
        if let Shape::Sphere(s) = &g.shapes[g.prims[slot].shape as usize] {
            let (hit, t) = self.rays.sphere(s, lanes, t_max);
            for i in lanes_of(hit) {
                t_max[i] = t[i];
                self.best[i] = PacketHit {
                    slot: slot as u32,
                    hit: PrimHit {
                        t: t[i],
                        local: Vec2::ZERO,
                    },
                };
            }
            self.found |= hit;
            return hit;
        }
        let mut found = 0;
        for i in lanes_of(lanes) {
            let ray = self.rays.ray(i);
            if let Some(h) = g.test_prim(slot, &ray, self.tri.lane(i), t_max[i]) {
                if h.t <= t_max[i] {
                    t_max[i] = h.t;
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
}

/// An occlusion query in progress (see [`Closest`]).
struct Occluded<'a> {
    geometry: &'a SceneGeometry,
    rays: &'a LaneRays,
    tri: TriangleRays,
}

impl Occluded<'_> {
    /// The lanes of `lanes` whose ray hits the primitive in `slot` within `t_max`.
    #[inline(always)]
    fn test(&mut self, slot: usize, lanes: Lanes, t_max: &[f64; PACKET]) -> Lanes {
        let g = self.geometry;
        if let Shape::Sphere(s) = &g.shapes[g.prims[slot].shape as usize] {
            return self.rays.sphere(s, lanes, t_max).0;
        }
        lanes_of(lanes).fold(0, |hit, i| {
            let ray = self.rays.ray(i);
            let occluded = g
                .test_prim(slot, &ray, self.tri.lane(i), t_max[i])
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
        let found = self.intersect_lanes(&LaneRays::from_rays(rays), &mut hits);
        std::array::from_fn(|i| (found & (1 << i) != 0).then_some(hits[i]))
    }

    /// [`intersect_packet`](Self::intersect_packet) for rays already in lanes: the lanes
    /// with a hit, whose hits are written to `hits` (the other lanes of `hits` are left as
    /// they were: the caller keeps one buffer across queries, nothing is copied out).
    #[inline(always)]
    pub fn intersect_lanes(&self, rays: &LaneRays, hits: &mut [PacketHit; PACKET]) -> Lanes {
        let lanes = rays.lanes;
        if lanes == 0 {
            return 0;
        }
        if !self.packet_traversal() {
            let mut found = 0;
            for i in lanes_of(lanes) {
                if let Some((slot, hit)) = self.closest_slot(&rays.ray(i)) {
                    hits[i] = PacketHit {
                        slot: slot as u32,
                        hit,
                    };
                    found |= 1 << i;
                }
            }
            return found;
        }
        let mut t_max = rays.t_max.0;
        let mut q = Closest {
            geometry: self,
            rays,
            best: hits,
            found: 0,
            tri: TriangleRays::default(),
        };
        match self.bvh.single_leaf() {
            // A scene of a few primitives: no box to test.
            Some(slots) => {
                for slot in slots {
                    q.test(slot, lanes, &mut t_max);
                }
            }
            None => {
                let pb = PacketBox::new(&LaneRays::axes(&rays.o), &LaneRays::axes(&rays.d));
                self.bvh
                    .closest_hit_packet(&pb, lanes, &mut t_max, |slot, lanes, t_max| {
                        q.test(slot, lanes, t_max)
                    });
            }
        }
        q.found
    }

    /// The surface record of `ray`'s hit `hit` found by
    /// [`intersect_packet`](Self::intersect_packet), with the details asked for: what
    /// [`intersect_with`](Self::intersect_with) returns for that ray.
    #[inline]
    pub fn packet_hit_record(&self, ray: &Ray, hit: PacketHit, detail: HitDetail) -> SurfaceHit {
        self.hit_record(hit.slot as usize, ray, hit.hit, detail)
    }

    /// The surface records of the hits `hits` of `rays` in the lanes `found` (as
    /// [`intersect_lanes`](Self::intersect_lanes) gives them), written into `out`: spheres
    /// hit by several lanes eight lanes at a time, every other hit lane by lane. Only the
    /// lanes of `found` are written (and `out.lanes` set to them): the caller keeps one
    /// record across segments, neither cleared nor copied out (a `memset` and a `memcpy`
    /// of its 1.1 KB per segment before).
    #[inline(always)]
    pub fn hit_lanes(
        &self,
        rays: &LaneRays,
        hits: &[PacketHit; PACKET],
        found: Lanes,
        out: &mut HitLanes,
    ) {
        out.lanes = found;
        if found == 0 {
            return;
        }
        // Every lane's shape (the lanes without a hit read a stale or default slot, which
        // is a valid one: the scene has primitives since a lane hit one), then the lanes
        // of each shape by one comparison per lane.
        let shapes: [u32; PACKET] =
            std::array::from_fn(|i| self.prims[hits[i].slot as usize].shape);
        let mut todo = found;
        while todo != 0 {
            let first = todo.trailing_zeros() as usize;
            let shape = shapes[first];
            let group = (0..PACKET)
                .fold(0, |m: Lanes, i| m | (((shapes[i] == shape) as Lanes) << i))
                & todo;
            todo &= !group;
            match &self.shapes[shape as usize] {
                Shape::Sphere(sphere) if group.count_ones() > 1 => {
                    let t = F64x8::from_fn(|i| hits[i].hit.t);
                    let (p, n, dpdu, _) = sphere.shading_hit_lanes(rays.o, rays.d, t);
                    let m = M64x8::from_bits(group as u32);
                    let zero = LVec3::zero();
                    out.t = F64x8::select(m, t, out.t);
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
        self.occluded_lanes(&LaneRays::from_rays(rays))
    }

    /// [`occluded_packet`](Self::occluded_packet) for rays already in lanes.
    #[inline(always)]
    pub fn occluded_lanes(&self, rays: &LaneRays) -> Lanes {
        let lanes = rays.lanes;
        if lanes == 0 {
            return 0;
        }
        if !self.packet_traversal() {
            return lanes_of(lanes).fold(0, |set, i| {
                set | ((self.occluded_ray(&rays.ray(i)) as Lanes) << i)
            });
        }
        let t_max = rays.t_max.0;
        let mut q = Occluded {
            geometry: self,
            rays,
            tri: TriangleRays::default(),
        };
        let mut test = |slot, lanes| q.test(slot, lanes, &t_max);
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
