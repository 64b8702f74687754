//! Area lights sampled by solid angle: for every shape, from shading points near and far,
//! beside and inside, the density of the directions `Shape::sample_from` produces passes a
//! chi-square test against the density it claims, and `pdf_from` (what MIS uses when a
//! BSDF sample hits the light) agrees with the sample's own pdf.

use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_bsdf::validation::{chi2_test, corrected_significance, Chi2Config, SphereMap};
use facette_render::geometry::triangle::TriangleRay;
use facette_render::geometry::{
    Disk, Ray, Rectangle, Shape, Sphere, Transform, TriangleMesh, Vec2, Vec3,
};

/// The density of the directions `shape.sample_from(p, ·)` produces, summed over every
/// primitive the ray from `p` crosses (a mesh seen from outside can be sampled on a
/// triangle hidden behind another: those samples are occluded in a render, but they are
/// part of the sampler's density).
fn true_density(shape: &Shape, p: Vec3, d: Vec3) -> f64 {
    let ray = Ray::infinite(p, d);
    match shape {
        Shape::Mesh(m) => {
            let Some(tr) = TriangleRay::new(&ray) else {
                return 0.0;
            };
            (0..m.triangle_count())
                .filter_map(|i| {
                    let h = m.intersect_triangle(i, &tr, f64::INFINITY)?;
                    let hit = m.surface_hit(&ray, i, h, 0);
                    Some(shape.pdf_from(p, hit.p, hit.ng, i as u32))
                })
                .sum()
        }
        _ => shape
            .intersect(&ray)
            .map_or(0.0, |h| shape.pdf_from(p, h.p, h.ng, h.prim)),
    }
}

/// Chi-square of the sampler from `p`, on a map zoomed on the shape; returns the summary.
fn check(name: &str, shape: &Shape, p: Vec3, tests: usize) -> String {
    check_about(name, shape, p, None, tests)
}

/// [`check`] with the map's axis given (by default, towards the centre of the shape's
/// bounds): from a point almost on a plane, the plane's normal, so that the horizon, where
/// the density stops, runs along bin edges.
fn check_about(name: &str, shape: &Shape, p: Vec3, axis: Option<Vec3>, tests: usize) -> String {
    let b = shape.bounds();
    let centre = 0.5 * (b.min + b.max);
    let axis = axis.unwrap_or((centre - p).normalize());
    let half_diag = 0.5 * (b.max - b.min).length();
    let dist = (centre - p).length();
    // Angular radius of the bounding sphere seen from p (the whole sphere from inside it).
    let cone = if dist > half_diag {
        (half_diag / dist).asin()
    } else {
        std::f64::consts::PI
    };
    let map = SphereMap::new(axis, (cone / 3.0).min(1.0));
    let cfg = Chi2Config {
        bins: (24, 48),
        samples: 400_000,
        subdivisions: 8,
        seed: 17,
    };
    let out = chi2_test(
        &map,
        &cfg,
        |rng: &mut Pcg32| {
            shape
                .sample_from(p, rng.next_2d())
                .map(|s| (s.point - p).normalize())
        },
        |d| true_density(shape, p, d),
    );
    let summary = format!("{name} from {p}: {}", out.summary());
    println!("{summary}");
    assert!(out.passes(corrected_significance(0.01, tests)), "{summary}");
    // The claimed integral of the pdf over the sphere is 1 (every shape is hit).
    assert!(
        (out.pdf_integral - 1.0).abs() < 0.02,
        "{summary}: ∫pdf = {}",
        out.pdf_integral
    );
    summary
}

/// `pdf_from` at a sampled point equals the sample's pdf, and the point lies on the shape
/// (the ray from `p` towards it hits the shape there, or nearer for hidden mesh triangles).
fn check_consistency(shape: &Shape, p: Vec3) {
    let mut rng = Pcg32::new(5, 1);
    for _ in 0..2000 {
        let Some(s) = shape.sample_from(p, rng.next_2d()) else {
            continue;
        };
        assert!(s.pdf.is_finite() && s.pdf > 0.0, "pdf {}", s.pdf);
        let d = s.point - p;
        let ray = Ray::infinite(p, d.normalize());
        let hit = shape
            .intersect(&ray)
            .expect("the sampled point is on the shape");
        assert!(hit.t <= d.length() * (1.0 + 1e-6) + 1e-9);
        if !matches!(shape, Shape::Mesh(_)) {
            assert!((hit.p - s.point).length() <= 1e-6 * (1.0 + d.length()));
            let pdf = shape.pdf_from(p, s.point, s.normal, hit.prim);
            assert!(
                (pdf - s.pdf).abs() <= 1e-9 * s.pdf,
                "pdf_from {pdf} vs sample {}",
                s.pdf
            );
        }
    }
}

fn rotate_x(deg: f64) -> Transform {
    Transform::rotate(Vec3::X, deg).unwrap()
}

#[test]
fn sphere_lights_sample_their_cone() {
    let sphere: Shape = Sphere::new(Vec3::new(0.2, -0.1, 0.3), 0.5).unwrap().into();
    let points = [
        Vec3::new(0.0, 0.0, 3.0),   // near: a wide cone
        Vec3::new(40.0, 5.0, -7.0), // far: a narrow cone
        Vec3::new(0.2, -0.1, 0.82), // just outside the surface: almost a hemisphere
        Vec3::new(0.3, 0.0, 0.3),   // inside: area sampling
    ];
    for p in points {
        check("sphere", &sphere, p, points.len());
        check_consistency(&sphere, p);
    }
}

#[test]
fn sphere_cone_pdf_is_uniform_and_falls_back_inside() {
    let s = Sphere::new(Vec3::ZERO, 1.0).unwrap();
    let p = Vec3::new(0.0, 0.0, 2.0);
    // sin θ_max = 1/2: the cone's solid angle is 2π (1 − cos 30°).
    let omega = std::f64::consts::TAU * (1.0 - 30f64.to_radians().cos());
    let mut rng = Pcg32::new(1, 2);
    for _ in 0..100 {
        let smp = s.sample_from(p, rng.next_2d()).unwrap();
        assert!((smp.pdf * omega - 1.0).abs() < 1e-12);
        // Every sample is on the visible cap (z ≥ 1/2).
        assert!(smp.point.z >= 0.5 - 1e-12, "{}", smp.point);
    }
    // Very far: the Taylor branch keeps the pdf finite and right.
    let far = Vec3::new(0.0, 0.0, 1e7);
    let smp = s.sample_from(far, Vec2::new(0.3, 0.7)).unwrap();
    let expect = 1.0 / (std::f64::consts::PI * 1e-14);
    assert!(
        (smp.pdf / expect - 1.0).abs() < 1e-6,
        "{} vs {expect}",
        smp.pdf
    );
    assert!((smp.point.length() - 1.0).abs() < 1e-9);
}

#[test]
fn rectangle_lights_sample_their_spherical_rectangle() {
    let t = rotate_x(-90.0) * Transform::scale(Vec3::new(1.5, 0.7, 1.0)).unwrap();
    let rect: Shape = Rectangle::new(&t, false).unwrap().into();
    let points = [
        Vec3::new(0.3, 1.0, 0.2),   // above: spherical-rectangle sampling
        Vec3::new(2.5, 0.3, -1.0),  // beside, at a grazing angle
        Vec3::new(30.0, 20.0, 9.0), // far: area sampling (tiny solid angle)
        Vec3::new(0.4, -0.8, 0.0),  // below (the back side)
    ];
    let tests = points.len() + 1;
    for p in points {
        check("rectangle", &rect, p, tests);
        check_consistency(&rect, p);
    }
    // Close to it: a solid angle near 2π, still sampled as a spherical rectangle.
    let near = Vec3::new(0.1, 0.04, 0.1);
    check_about("rectangle", &rect, near, Some(-Vec3::Y), tests);
    check_consistency(&rect, near);
    // Almost on it (solid angle above 6.22 sr): area sampling; its density is singular at
    // the horizon, where quadrature of the expected counts fails, so only consistency.
    check_consistency(&rect, Vec3::new(0.1, 1e-3, 0.1));
    // A sheared rectangle (a parallelogram) is area-sampled, still consistent.
    let shear = Transform::try_new(glam::DMat4::from_cols_array(&[
        1.0, 0.0, 0.0, 0.0, 0.6, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ]))
    .unwrap();
    let para: Shape = Rectangle::new(&shear, false).unwrap().into();
    check("parallelogram", &para, Vec3::new(0.2, 0.1, 1.2), 1);
    check_consistency(&para, Vec3::new(0.2, 0.1, 1.2));
}

#[test]
fn disk_lights_sample_by_area_in_solid_angle() {
    let disk: Shape = Disk::new(&rotate_x(30.0), false).unwrap().into();
    for p in [Vec3::new(0.2, 0.3, 1.5), Vec3::new(3.0, -2.0, -0.5)] {
        check("disk", &disk, p, 2);
        check_consistency(&disk, p);
    }
}

#[test]
fn triangle_and_mesh_lights_sample_spherical_triangles() {
    // One triangle: spherical-triangle sampling near, area sampling far.
    let tri = TriangleMesh::new(
        vec![
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.2, 0.0),
            Vec3::new(0.1, 1.3, 0.4),
        ],
        None,
        None,
        vec![0, 1, 2],
        &Transform::IDENTITY,
        false,
    )
    .unwrap();
    let tri: Shape = tri.into();
    let points = [
        Vec3::new(0.0, 0.4, 1.0),
        Vec3::new(-0.9, 0.05, 0.05), // close to a vertex
        Vec3::new(50.0, 40.0, 80.0),
    ];
    for p in points {
        check("triangle", &tri, p, points.len());
        check_consistency(&tri, p);
    }
    // A closed mesh seen from outside (a cube: 12 triangles of two sizes after a
    // non-uniform scale; hidden triangles are sampled too, occluded in a render): a
    // triangle is chosen by area, then sampled by its solid angle.
    let cube = facette_render::geometry::generate::cube_mesh_data();
    let t = Transform::scale(Vec3::new(0.5, 0.3, 0.2)).unwrap() * rotate_x(20.0);
    let mesh: Shape = cube.into_mesh(&t, false).unwrap().into();
    for p in [Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.3, 3.0, -0.5)] {
        check("mesh", &mesh, p, 2);
        check_consistency(&mesh, p);
    }
}
