//! Model-specific properties the papers state, and the measurements docs/ reports.

use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::math::spherical_direction;
use facette_bsdf::models::Kelemen;
use facette_bsdf::recipe::{build_material, parse_inline_table};
use facette_bsdf::validation::measurements::{
    dielectric_max_weight, mean_weight, oren_nayar_error,
};
use facette_bsdf::{Bsdf, BsdfContext, Spectrum, Vec3};

fn material(s: &str) -> std::sync::Arc<dyn Bsdf> {
    build_material(&parse_inline_table(s).unwrap()).unwrap()
}

#[test]
fn lambert_is_kd_over_pi() {
    let b = material(r#"{type = "lambert", reflectance = [0.2, 0.4, 0.6]}"#);
    let f = b.eval(
        spherical_direction(0.3, 0.0),
        spherical_direction(1.2, 2.0),
        &BsdfContext::RADIANCE,
        &mut Pcg32::new(1, 1),
    );
    for (c, kd) in [0.2, 0.4, 0.6].iter().enumerate() {
        assert!((f[c] - kd / std::f64::consts::PI).abs() < 1e-15);
    }
}

#[test]
fn smooth_dielectric_albedo_is_fresnel() {
    let b = material(r#"{type = "dielectric", alpha = 0, ior = 1.5}"#);
    for deg in [0.0f64, 45.0, 80.0] {
        let wo = spherical_direction(deg.to_radians(), 0.0);
        let f = facette_bsdf::fresnel::fresnel_dielectric(wo.z, 1.5);
        // Reflected fraction: count reflection samples.
        let mut rng = Pcg32::new(3, 3);
        let n = 400_000;
        let mut refl = 0usize;
        for _ in 0..n {
            let s = b.sample(wo, &BsdfContext::IMPORTANCE, &mut rng).unwrap();
            assert_eq!(s.weight, Spectrum::ONE);
            if s.wi.z > 0.0 {
                refl += 1;
                assert!((s.pdf - f).abs() < 1e-15);
            }
        }
        let r = refl as f64 / n as f64;
        let se = (f * (1.0 - f) / n as f64).sqrt();
        assert!((r - f).abs() < 4.0 * se + 1e-12, "{deg}°: {r} vs F = {f}");
    }
}

#[test]
fn kelemen_with_white_matte_sums_to_one_at_every_angle() {
    // KSK01 Fig. 5: a_spec(θ) + a_matte(θ) = 1 when k = 1.
    for s in [
        r#"{type = "kelemen", distribution = "ward", alpha = 0.8, kd = 1.0}"#,
        r#"{type = "kelemen", distribution = "ward", alpha = 0.1, kd = 1.0}"#,
        r#"{type = "kelemen", distribution = "phong", exponent = 20, kd = 1.0}"#,
        r#"{type = "kelemen", distribution = "beckmann", alpha = 0.4, kd = 1.0}"#,
    ] {
        let b = material(s);
        let mut worst: f64 = 0.0;
        for deg in (0..=85).step_by(5) {
            let wo = spherical_direction((deg as f64).to_radians(), 0.0);
            let (m, se) = mean_weight(b.as_ref(), wo, 200_000, deg as u64);
            worst = worst.max((m[1] - 1.0).abs());
            assert!(
                (m[1] - 1.0).abs() < 0.01,
                "{s} at {deg}°: total albedo {} ± {}",
                m[1],
                se[1]
            );
        }
        println!("{s}: max |a_spec + a_matte − 1| = {worst:.4}");
    }
}

#[test]
fn kelemen_exposes_russian_roulette_probabilities() {
    let b = Kelemen::new(
        facette_bsdf::microfacet::half_vector_density::HalfVectorDensity::new("ward", 0.3).unwrap(),
        facette_bsdf::fresnel::Fresnel::Dielectric { eta: 1.5 },
        Spectrum::splat(0.6),
        4096,
    )
    .unwrap();
    for deg in [0.0f64, 60.0, 85.0] {
        let (s, m, t) = b.lobe_probabilities(spherical_direction(deg.to_radians(), 0.0));
        assert!((s + m + t - 1.0).abs() < 1e-12);
        assert!((m - 0.6 * (1.0 - s)).abs() < 1e-12);
    }
    // Specular albedo grows toward grazing (KSK01 Fig. 3) and its table is accurate.
    let a0 = b.albedo_at(0.0)[0];
    let a85 = b.albedo_at(85f64.to_radians())[0];
    assert!(a85 > a0, "{a0} {a85}");
    assert!(b.albedo_table_stderr() < 2e-3);
}

#[test]
fn oren_nayar_qualitative_vs_exact_is_measured() {
    for sigma in [0.1, 0.3, 0.5, 1.0] {
        let q = oren_nayar_error(sigma, 16384, false);
        let l = oren_nayar_error(sigma, 16384, true);
        for (name, e) in [("qualitative", &q), ("L1", &l)] {
            println!(
                "sigma {sigma}, {name}: mean relative error {:.3}, max {:.3} at θi={}°, θo={}°, Δφ={}°",
                e.mean_rel, e.max_rel, e.worst.0, e.worst.1, e.worst.2
            );
        }
        // Approximations of the same integral: in the right ballpark, L1 the closer one.
        assert!(q.mean_rel < 0.25 && l.mean_rel < 0.1, "{q:?} {l:?}");
        assert!(l.mean_rel < q.mean_rel, "{q:?} {l:?}");
    }
}

#[test]
fn widened_sampling_bounds_the_weights() {
    // WMLT07 §5.3: widening the Beckmann sampler reduces the maximum weight to about four.
    for alpha in [0.1, 0.3, 0.5] {
        let (plain, at_p) = dielectric_max_weight(alpha, 1.5, false, 20_000);
        let (wide, at_w) = dielectric_max_weight(alpha, 1.5, true, 20_000);
        println!("alpha {alpha}: max weight {plain:.2} (at {at_p}°) with D|m·n| sampling, {wide:.2} (at {at_w}°) widened");
        assert!(wide < plain, "widening must lower the maximum weight");
        assert!(wide < 10.0, "widened maximum weight {wide}");
    }
}

#[test]
fn dielectric_modes_are_adjoint_and_bsdf_conserves_energy_from_both_sides() {
    let b = material(r#"{type = "dielectric", distribution = "ggx", alpha = 0.3, ior = 1.5}"#);
    for wo in [
        spherical_direction(0.5, 0.2),
        -spherical_direction(0.3, 1.0),
        Vec3::new(0.0, 0.0, -1.0),
    ] {
        let (m, se) = mean_weight(b.as_ref(), wo, 200_000, 5);
        assert!(m[0] <= 1.0 + 3.0 * se[0], "{m:?}");
    }
}
