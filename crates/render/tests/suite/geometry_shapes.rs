//! Shapes through the scene: uv derivatives of a camera's ray differentials against their
//! analytic values, area samples that rays find again, shadow rays between surfaces.

use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_render::geometry::generate::TorusKnot;
use facette_render::geometry::{
    Disk, Ray, RayDifferential, Rectangle, SceneGeometry, Shape, Sphere, Transform, Vec3,
};

/// A pinhole camera at the origin looking down +z (built with `look_at`), with ray
/// differentials one "pixel" of angle `delta` apart; returns the ray and differential
/// through the image centre.
fn camera_ray(delta: f64) -> (Ray, RayDifferential) {
    let cam = Transform::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y).unwrap();
    let o = cam.point(Vec3::ZERO);
    let d = cam.vector(Vec3::Z);
    let rd = RayDifferential {
        rx_origin: o,
        rx_dir: cam.vector(Vec3::new(delta, 0.0, 1.0)),
        ry_origin: o,
        ry_dir: cam.vector(Vec3::new(0.0, delta, 1.0)),
    };
    (Ray::infinite(o, d), rd)
}

#[test]
fn uv_derivatives_on_a_plane_at_known_distance() {
    let (d, delta, half) = (4.0, 1e-3, 5.0);
    for theta_deg in [0.0f64, 30.0, 60.0] {
        let theta = theta_deg.to_radians();
        let to_world = Transform::translate(Vec3::new(0.0, 0.0, d)).unwrap()
            * Transform::rotate(Vec3::Y, theta_deg).unwrap()
            * Transform::scale(Vec3::new(half, half, 1.0)).unwrap();
        let scene =
            SceneGeometry::new(vec![Rectangle::new(&to_world, false).unwrap().into()]).unwrap();
        let (ray, rd) = camera_ray(delta);
        let hit = scene.intersect(&ray).unwrap();
        assert!((hit.t - d).abs() < 1e-12);
        assert!((hit.uv.x - 0.5).abs() < 1e-12 && (hit.uv.y - 0.5).abs() < 1e-12);
        let [dudx, dvdx, dudy, dvdy] = hit.uv_derivatives(&rd);

        // The x-offset ray t·(δ, 0, 1) meets the plane n·p = d cos θ, n = (sin θ, 0,
        // cos θ), at t = d cos θ / (δ sin θ + cos θ); its local x is the distance along
        // the rotated x axis (cos θ, 0, −sin θ) over the half-size, and u = (x + 1)/2.
        let t = d * theta.cos() / (delta * theta.sin() + theta.cos());
        let p = t * Vec3::new(delta, 0.0, 1.0);
        let x_local =
            (p - Vec3::new(0.0, 0.0, d)).dot(Vec3::new(theta.cos(), 0.0, -theta.sin())) / half;
        let expected_dudx = x_local / 2.0;
        // The y-offset ray stays in the plane x = 0, where depth is d: v moves by d·δ/(2·half).
        let expected_dvdy = d * delta / (2.0 * half);
        assert!(
            (dudx - expected_dudx).abs() < 1e-12 * expected_dudx.abs().max(1e-3),
            "θ = {theta_deg}: du/dx {dudx} vs {expected_dudx}"
        );
        assert!(
            (dvdy - expected_dvdy).abs() < 1e-15,
            "θ = {theta_deg}: {dvdy}"
        );
        assert!(dvdx.abs() < 1e-15 && dudy.abs() < 1e-15);
    }
}

#[test]
fn uv_derivatives_match_on_a_sphere_and_stay_finite_on_a_mesh() {
    let shapes: Vec<Shape> = vec![
        // Local +z turned to world −y, so that the camera looks at the equator, away
        // from the parameterization's poles.
        Sphere::with_transform(
            Vec3::ZERO,
            1.0,
            &(Transform::translate(Vec3::new(0.0, 0.0, 10.0)).unwrap()
                * Transform::rotate(Vec3::X, 90.0).unwrap()),
            false,
        )
        .unwrap()
        .into(),
        TorusKnot::with_triangles(20_000)
            .mesh(&Transform::translate(Vec3::new(0.0, 0.0, 30.0)).unwrap())
            .unwrap()
            .into(),
    ];
    let scene = SceneGeometry::new(shapes).unwrap();
    let (ray, rd) = camera_ray(1e-3);
    let h = scene.intersect(&ray).unwrap();
    assert_eq!(h.shape, 0);
    let near = h.uv_derivatives(&rd);
    assert!(near.iter().all(|x| x.is_finite()));
    // At the sphere's nearest point (on its equator) the footprint is d·δ = 9e-3 long;
    // u = φ/2π changes by 9e-3 / (2π r) per pixel in x, v = θ/π by 9e-3 / (π r) in y.
    let pi = std::f64::consts::PI;
    assert!((near[0].abs() - 9e-3 / (2.0 * pi)).abs() < 1e-9, "{near:?}");
    assert!((near[3].abs() - 9e-3 / pi).abs() < 1e-9, "{near:?}");
    assert!(near[1].abs() < 1e-12 && near[2].abs() < 1e-12, "{near:?}");
    let mut rng = Pcg32::new(5, 5);
    let mut finite = 0;
    for _ in 0..2_000 {
        let target = Vec3::new(rng.next_f64() - 0.5, rng.next_f64() - 0.5, 0.0) * 2.5
            + Vec3::new(0.0, 0.0, 30.0);
        let dir = target.normalize();
        let ray = Ray::infinite(Vec3::ZERO, dir);
        let rd = RayDifferential {
            rx_origin: Vec3::ZERO,
            rx_dir: dir + Vec3::X * 1e-3,
            ry_origin: Vec3::ZERO,
            ry_dir: dir + Vec3::Y * 1e-3,
        };
        if let Some(h) = scene.intersect(&ray) {
            let d = h.uv_derivatives(&rd);
            assert!(d.iter().all(|x| x.is_finite() && x.abs() <= 1e8));
            finite += 1;
        }
    }
    assert!(finite > 100);
}

#[test]
fn area_samples_are_found_again_by_rays() {
    let place = Transform::translate(Vec3::new(1.0, 2.0, -1.0)).unwrap()
        * Transform::rotate(Vec3::new(1.0, 2.0, 3.0), 25.0).unwrap()
        * Transform::scale(Vec3::new(1.5, 0.7, 1.0)).unwrap();
    let similarity = Transform::translate(Vec3::new(1.0, 2.0, -1.0)).unwrap()
        * Transform::rotate(Vec3::new(1.0, 2.0, 3.0), 25.0).unwrap()
        * Transform::scale(Vec3::splat(1.3)).unwrap();
    let shapes: Vec<Shape> = vec![
        Sphere::with_transform(Vec3::new(0.5, 0.0, 0.0), 0.8, &similarity, true)
            .unwrap()
            .into(),
        Rectangle::new(&place, false).unwrap().into(),
        Disk::new(&place, true).unwrap().into(),
        TorusKnot::with_triangles(2_000)
            .mesh(&place)
            .unwrap()
            .into(),
    ];
    let mut rng = Pcg32::new(77, 0);
    for (id, shape) in shapes.iter().enumerate() {
        // Each shape alone, so that nothing else is in the way.
        let scene = SceneGeometry::new(vec![shape.clone()]).unwrap();
        let area = scene.shape_area(0);
        assert_eq!(area, shape.area());
        assert!(area > 0.0);
        for _ in 0..2_000 {
            let (p, n, pdf) = scene.sample_shape(0, rng.next_2d());
            assert!((pdf * area - 1.0).abs() < 1e-12, "shape {id}");
            assert!((n.length() - 1.0).abs() < 1e-12, "shape {id}");
            // A ray from just above the point, straight down the normal, finds it with
            // the same geometric normal.
            let ray = Ray::infinite(p + n * 1e-3, -n);
            let h = scene
                .intersect(&ray)
                .unwrap_or_else(|| panic!("shape {id}: sample {p} not found"));
            assert!((h.p - p).length() < 1e-9, "shape {id}: {} vs {p}", h.p);
            assert!(
                (h.ng - n).length() < 1e-9,
                "shape {id}: normal {} vs {n}",
                h.ng
            );
        }
    }
}

#[test]
fn shadow_rays_between_surfaces() {
    let floor = Rectangle::new(
        &Transform::scale(Vec3::new(10.0, 10.0, 1.0)).unwrap(),
        false,
    )
    .unwrap();
    let light = Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0).unwrap();
    let blocker = Disk::new(
        &Transform::translate(Vec3::new(2.5, 0.0, 1.0)).unwrap(),
        false,
    )
    .unwrap();
    let scene = SceneGeometry::new(vec![floor.into(), light.into(), blocker.into()]).unwrap();
    let p = Vec3::new(0.0, 0.0, 0.0);
    // The light's bottom pole faces p: visible. Its top pole is behind the sphere itself.
    let bottom = Vec3::new(0.0, 0.0, 4.0);
    assert!(!scene.occluded_ray(&Ray::spawn_between(p, Vec3::Z, bottom, -Vec3::Z)));
    let top = Vec3::new(0.0, 0.0, 6.0);
    assert!(scene.occluded_ray(&Ray::spawn_between(p, Vec3::Z, top, Vec3::Z)));
    // Under the disk, the light is blocked.
    let q = Vec3::new(3.0, 0.0, 0.0);
    assert!(scene.occluded_ray(&Ray::spawn_between(q, Vec3::Z, bottom, -Vec3::Z)));
    // The public form with a direction to the target and t_max just short of it.
    assert!(!scene.occluded(p + Vec3::Z * 1e-6, bottom - p, 1.0 - 1e-6));
}
