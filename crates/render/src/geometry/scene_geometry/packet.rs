//! Ray queries for a packet of eight rays ([`Bvh::closest_hit_packet`],
//! [`Bvh::any_hit_packet`]): spheres are tested four lanes at a time by their one-source
//! test ([`Sphere::intersect_lanes`] with `F64x4`: the same bits as one ray at a time),
//! triangles, rectangles and disks lane by lane with their one-ray tests. A lane's hit is
//! therefore the hit the one-ray query finds; only among primitives hit at exactly the
//! same distance may the two orders pick different ones.

use super::{is_valid_query, HitDetail, SceneGeometry};
use crate::geometry::bvh::{lanes_of, Lanes, PacketBox, PACKET};
use crate::geometry::interaction::{PrimHit, SurfaceHit};
use crate::geometry::ray::Ray;
use crate::geometry::shape::Shape;
use crate::geometry::sphere::Sphere;
use crate::geometry::triangle::TriangleRay;
use crate::geometry::Vec2;
use facette_bsdf::lanes::{F64x4, LVec3};

/// A packet lane's closest hit: the primitive's slot in the BVH order and the hit.
#[derive(Clone, Copy, Debug)]
pub struct PacketHit {
    slot: u32,
    hit: PrimHit,
}

/// The packet's rays in lanes: f64 coordinates per axis (lanes without a valid ray hold
/// a harmless one), and as two groups of four f64 lanes for the sphere test.
struct LaneRays {
    o: [[f64; PACKET]; 3],
    d: [[f64; PACKET]; 3],
    t_max: [f64; PACKET],
    /// The lanes with a valid ray.
    lanes: Lanes,
}

impl LaneRays {
    #[inline(always)]
    fn new(rays: &[Option<Ray>; PACKET]) -> LaneRays {
        let mut r = LaneRays {
            o: [[0.0; PACKET]; 3],
            d: [[1.0; PACKET]; 3],
            t_max: [0.0; PACKET],
            lanes: 0,
        };
        for (i, ray) in rays.iter().enumerate() {
            let Some(ray) = ray.filter(is_valid_query) else {
                continue;
            };
            for a in 0..3 {
                r.o[a][i] = ray.origin[a];
                r.d[a][i] = ray.dir[a];
            }
            r.t_max[i] = ray.t_max;
            r.lanes |= 1 << i;
        }
        r
    }

    /// Group `h` (lanes 4h..4h + 4) of the coordinates `c`.
    #[inline(always)]
    fn group(c: &[[f64; PACKET]; 3], h: usize) -> LVec3<F64x4> {
        let g = |a: usize| F64x4(std::array::from_fn(|j| c[a][4 * h + j]));
        LVec3::new(g(0), g(1), g(2))
    }

    /// The lanes of `lanes` whose ray hits `sphere` in `(0, t_max[i]]`, with the distance.
    #[inline(always)]
    fn sphere(
        &self,
        sphere: &Sphere,
        lanes: Lanes,
        t_max: &[f64; PACKET],
    ) -> (Lanes, [f64; PACKET]) {
        let mut hit = 0;
        let mut t = [0.0; PACKET];
        for h in 0..2 {
            if (lanes >> (4 * h)) & 0xF == 0 {
                continue;
            }
            let limit = F64x4(std::array::from_fn(|j| t_max[4 * h + j]));
            let (o, d) = (Self::group(&self.o, h), Self::group(&self.d, h));
            let (m, th) = sphere.intersect_lanes(o, d, limit);
            hit |= (m.bits() as Lanes) << (4 * h);
            t[4 * h..4 * h + 4].copy_from_slice(&th.0);
        }
        (hit & lanes, t)
    }
}

/// A closest-hit query in progress: the hit of each lane so far. Its primitive test is a
/// method forced inline so that it is compiled into the kernel's AVX2 instantiation.
struct Closest<'a> {
    geometry: &'a SceneGeometry,
    rays: &'a [Option<Ray>; PACKET],
    lane_rays: &'a LaneRays,
    best: [Option<PacketHit>; PACKET],
    tri: [Option<TriangleRay>; PACKET],
}

impl Closest<'_> {
    /// Tests the primitive in `slot` for `lanes` within `(0, t_max[i]]`; lowers `t_max`
    /// where it hits and returns those lanes.
    #[inline(always)]
    fn test(&mut self, slot: usize, lanes: Lanes, t_max: &mut [f64; PACKET]) -> Lanes {
        let g = self.geometry;
        if let Shape::Sphere(s) = &g.shapes[g.prims[slot].shape as usize] {
            let (hit, t) = self.lane_rays.sphere(s, lanes, t_max);
            for i in lanes_of(hit) {
                t_max[i] = t[i];
                self.best[i] = Some(PacketHit {
                    slot: slot as u32,
                    hit: PrimHit {
                        t: t[i],
                        local: Vec2::ZERO,
                    },
                });
            }
            return hit;
        }
        let mut found = 0;
        for i in lanes_of(lanes) {
            let Some(ray) = &self.rays[i] else { continue };
            if let Some(h) = g.test_prim(slot, ray, &mut self.tri[i], t_max[i]) {
                if h.t <= t_max[i] {
                    t_max[i] = h.t;
                    self.best[i] = Some(PacketHit {
                        slot: slot as u32,
                        hit: h,
                    });
                    found |= 1 << i;
                }
            }
        }
        found
    }
}

/// An occlusion query in progress (see [`Closest`]).
struct Occluded<'a> {
    geometry: &'a SceneGeometry,
    rays: &'a [Option<Ray>; PACKET],
    lane_rays: &'a LaneRays,
    tri: [Option<TriangleRay>; PACKET],
}

impl Occluded<'_> {
    /// The lanes of `lanes` whose ray hits the primitive in `slot` within `t_max`.
    #[inline(always)]
    fn test(&mut self, slot: usize, lanes: Lanes, t_max: &[f64; PACKET]) -> Lanes {
        let g = self.geometry;
        if let Shape::Sphere(s) = &g.shapes[g.prims[slot].shape as usize] {
            return self.lane_rays.sphere(s, lanes, t_max).0;
        }
        lanes_of(lanes).fold(0, |hit, i| {
            let occluded = self.rays[i]
                .as_ref()
                .is_some_and(|ray| g.test_prim(slot, ray, &mut self.tri[i], t_max[i]).is_some());
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
    /// the surface record of one, so the kernel moves 24 bytes per lane, not a record.
    #[inline(always)]
    pub fn intersect_packet(&self, rays: &[Option<Ray>; PACKET]) -> [Option<PacketHit>; PACKET] {
        let mut best: [Option<PacketHit>; PACKET] = [None; PACKET];
        if !self.packet_traversal() {
            for (b, ray) in best.iter_mut().zip(rays) {
                *b = ray
                    .as_ref()
                    .and_then(|r| self.closest_slot(r))
                    .map(|(slot, hit)| PacketHit {
                        slot: slot as u32,
                        hit,
                    });
            }
            return best;
        }
        let lane_rays = LaneRays::new(rays);
        let lanes = lane_rays.lanes;
        if lanes == 0 {
            return best;
        }
        let mut t_max = lane_rays.t_max;
        let mut q = Closest {
            geometry: self,
            rays,
            lane_rays: &lane_rays,
            best,
            tri: [None; PACKET],
        };
        match self.bvh.single_leaf() {
            // A scene of a few primitives: no box to test.
            Some(slots) => {
                for slot in slots {
                    q.test(slot, lanes, &mut t_max);
                }
            }
            None => {
                let pb = PacketBox::new(&lane_rays.o, &lane_rays.d);
                self.bvh
                    .closest_hit_packet(&pb, lanes, &mut t_max, |slot, lanes, t_max| {
                        q.test(slot, lanes, t_max)
                    });
            }
        }
        q.best
    }

    /// The surface record of `ray`'s hit `hit` found by
    /// [`intersect_packet`](Self::intersect_packet), with the details asked for: what
    /// [`intersect_with`](Self::intersect_with) returns for that ray.
    #[inline]
    pub fn packet_hit_record(&self, ray: &Ray, hit: PacketHit, detail: HitDetail) -> SurfaceHit {
        self.hit_record(hit.slot as usize, ray, hit.hit, detail)
    }

    /// [`occluded_ray`](Self::occluded_ray) for every ray of a packet: the occluded lanes
    /// (`None` lanes are not).
    #[inline(always)]
    pub fn occluded_packet(&self, rays: &[Option<Ray>; PACKET]) -> Lanes {
        if !self.packet_traversal() {
            return (0..PACKET).fold(0, |set, i| {
                let occluded = rays[i].as_ref().is_some_and(|r| self.occluded_ray(r));
                set | ((occluded as Lanes) << i)
            });
        }
        let lane_rays = LaneRays::new(rays);
        let lanes = lane_rays.lanes;
        if lanes == 0 {
            return 0;
        }
        let t_max = lane_rays.t_max;
        let mut q = Occluded {
            geometry: self,
            rays,
            lane_rays: &lane_rays,
            tri: [None; PACKET],
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
                let pb = PacketBox::new(&lane_rays.o, &lane_rays.d);
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
