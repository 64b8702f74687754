//! The BVH against brute force: closest hits and occlusion on random rays over random
//! triangle soups and over scenes mixing every shape kind; spawned rays never re-hit the
//! surface they leave.

use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_render::geometry::generate::TorusKnot;
use facette_render::geometry::{
    Disk, Ray, Rectangle, SceneGeometry, Shape, Sphere, SurfaceHit, Transform, TriangleMesh, Vec3,
};

fn rand_vec(rng: &mut Pcg32, lo: f64, hi: f64) -> Vec3 {
    Vec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * (hi - lo) + Vec3::splat(lo)
}

fn rand_dir(rng: &mut Pcg32) -> Vec3 {
    facette_bsdf::math::warp::square_to_uniform_sphere(rng.next_2d())
}

/// `n` random triangles of random size (some long and thin) in [-5, 5]³.
fn triangle_soup(rng: &mut Pcg32, n: usize) -> TriangleMesh {
    let mut positions = Vec::with_capacity(3 * n);
    for _ in 0..n {
        let c = rand_vec(rng, -5.0, 5.0);
        let size = 0.05 + 1.5 * rng.next_f64().powi(3);
        for _ in 0..3 {
            positions.push(c + rand_vec(rng, -size, size));
        }
    }
    let indices = (0..3 * n as u32).collect();
    TriangleMesh::new(positions, None, None, indices, &Transform::IDENTITY, false).unwrap()
}

fn mixed_shapes(rng: &mut Pcg32) -> Vec<Shape> {
    let mut shapes: Vec<Shape> = vec![triangle_soup(rng, 2_000).into()];
    for _ in 0..20 {
        shapes.push(
            Sphere::new(rand_vec(rng, -5.0, 5.0), 0.1 + rng.next_f64())
                .unwrap()
                .into(),
        );
    }
    for k in 0..10 {
        let t = Transform::translate(rand_vec(rng, -5.0, 5.0)).unwrap()
            * Transform::rotate(rand_dir(rng), 360.0 * rng.next_f64()).unwrap()
            * Transform::scale(Vec3::new(0.2 + rng.next_f64(), 0.2 + rng.next_f64(), 1.0)).unwrap();
        if k % 2 == 0 {
            shapes.push(Rectangle::new(&t, k % 4 == 0).unwrap().into());
        } else {
            shapes.push(Disk::new(&t, k % 3 == 0).unwrap().into());
        }
    }
    let knot = TorusKnot::with_triangles(5_000)
        .mesh(
            &(Transform::translate(Vec3::new(1.0, -1.0, 0.5)).unwrap()
                * Transform::scale(Vec3::splat(2.0)).unwrap()),
        )
        .unwrap();
    shapes.push(knot.into());
    shapes
}

/// Closest hit over all shapes without the BVH.
fn brute_force(shapes: &[Shape], ray: &Ray) -> Option<SurfaceHit> {
    let mut best: Option<SurfaceHit> = None;
    for (id, shape) in shapes.iter().enumerate() {
        let r = Ray {
            t_max: best.map_or(ray.t_max, |b| b.t),
            ..*ray
        };
        if let Some(mut h) = shape.intersect(&r) {
            h.shape = id as u32;
            best = Some(h);
        }
    }
    best
}

fn random_ray(rng: &mut Pcg32) -> Ray {
    let origin = rand_vec(rng, -8.0, 8.0);
    // Half the rays aim into the scene, half go anywhere; a third have a finite t_max.
    let dir = if rng.next_f64() < 0.5 {
        rand_vec(rng, -4.0, 4.0) - origin
    } else {
        rand_dir(rng)
    };
    let t_max = if rng.next_f64() < 0.33 {
        rng.next_f64() * 12.0
    } else {
        f64::INFINITY
    };
    Ray::new(origin, dir, t_max)
}

fn compare(shapes: Vec<Shape>, rays: usize, seed: u64) {
    let scene = SceneGeometry::new(shapes.clone()).unwrap();
    let mut rng = Pcg32::new(seed, 7);
    let (mut hits, mut occluded) = (0, 0);
    for k in 0..rays {
        let ray = random_ray(&mut rng);
        let expected = brute_force(&shapes, &ray);
        let got = scene.intersect(&ray);
        match (expected, got) {
            (None, None) => {}
            (Some(e), Some(g)) => {
                hits += 1;
                assert_eq!(e.t, g.t, "ray {k}: distance differs");
                // Equal distances on different primitives are ties; otherwise the very
                // same surface point must come back.
                if (e.shape, e.prim) == (g.shape, g.prim) {
                    assert_eq!(e, g, "ray {k}");
                }
            }
            (e, g) => panic!("ray {k}: brute force {e:?}, BVH {g:?}"),
        }
        let blocked = scene.occluded_ray(&ray);
        assert_eq!(blocked, expected.is_some(), "ray {k}: occlusion differs");
        occluded += usize::from(blocked);
        // The public (origin, dir, t_max) form agrees.
        assert_eq!(
            scene.occluded(ray.origin, ray.dir * 2.0, ray.t_max / 2.0),
            blocked,
            "ray {k}"
        );
    }
    // The test is only meaningful if both outcomes are common.
    assert!(hits > rays / 20 && hits < rays * 19 / 20, "{hits} hits");
    assert_eq!(occluded, hits);
}

#[test]
fn closest_hit_and_occlusion_match_brute_force_on_triangle_soups() {
    let mut rng = Pcg32::new(100, 0);
    for soup in 0..3 {
        let n = [200, 1_000, 5_000][soup];
        compare(vec![triangle_soup(&mut rng, n).into()], 4_000, soup as u64);
    }
}

#[test]
fn closest_hit_and_occlusion_match_brute_force_on_mixed_shapes() {
    let mut rng = Pcg32::new(200, 0);
    let shapes = mixed_shapes(&mut rng);
    compare(shapes, 12_000, 42);
}

#[test]
fn spawned_rays_do_not_hit_their_own_surface() {
    let mut rng = Pcg32::new(300, 0);
    let shapes = mixed_shapes(&mut rng);
    let scene = SceneGeometry::new(shapes).unwrap();
    let mut tested = 0;
    for _ in 0..20_000 {
        let Some(h) = scene.intersect(&random_ray(&mut rng)) else {
            continue;
        };
        tested += 1;
        // Leave the surface on both sides, including at grazing angles.
        let mut d = rand_dir(&mut rng);
        if rng.next_f64() < 0.3 {
            d = (d - h.ng * h.ng.dot(d)).normalize() + h.ng * 1e-4 * d.dot(h.ng).signum();
        }
        let ray = h.spawn_ray(d);
        if let Some(again) = scene.intersect(&ray) {
            let same = again.shape == h.shape && again.prim == h.prim;
            assert!(
                !(same && again.t < 1e-6),
                "self-intersection at t = {} on shape {} prim {}",
                again.t,
                h.shape,
                h.prim
            );
        }
    }
    assert!(tested > 5_000);
}

#[test]
fn generated_mesh_bvh_is_shallow_and_agrees() {
    let knot = TorusKnot::with_triangles(100_000)
        .mesh(&Transform::IDENTITY)
        .unwrap();
    let shapes: Vec<Shape> = vec![knot.into()];
    let scene = SceneGeometry::new(shapes.clone()).unwrap();
    assert_eq!(scene.primitive_count(), 102_400);
    assert!(scene.bvh().depth() < 40, "depth {}", scene.bvh().depth());
    let mut rng = Pcg32::new(400, 0);
    let mut hits = 0;
    for _ in 0..1_000 {
        let o = rand_vec(&mut rng, -3.0, 3.0);
        let ray = Ray::infinite(o, rand_vec(&mut rng, -1.0, 1.0) - o);
        let e = brute_force(&shapes, &ray);
        let g = scene.intersect(&ray);
        assert_eq!(e.map(|h| h.t), g.map(|h| h.t));
        hits += usize::from(g.is_some());
    }
    assert!(hits > 100);
}
