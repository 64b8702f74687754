//! Interfaced Lambertian (issue: IL18/TSBRM): energy, limits, multiple scattering, tables.

use facette_bsdf::math::quadrature::GaussLegendre;
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::math::spherical_direction;
use facette_bsdf::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use facette_bsdf::microfacet::{Gaussian, Masking, Ndf};
use facette_bsdf::models::il::il_table::BodyTable;
use facette_bsdf::models::il::interfaced_lambertian::{BodyEvaluation, Scattering};
use facette_bsdf::models::InterfacedLambertian;
use facette_bsdf::recipe::{build_material, parse_inline_table};
use facette_bsdf::validation::measurements::hemispherical_reflectance;
use facette_bsdf::{Bsdf, BsdfContext, Spectrum, Vec3};
use std::sync::Arc;

fn material(s: &str) -> Arc<dyn Bsdf> {
    build_material(&parse_inline_table(s).unwrap()).unwrap_or_else(|e| panic!("{s}: {e}"))
}

fn eval(b: &dyn Bsdf, wo: Vec3, wi: Vec3) -> Spectrum {
    b.eval(wo, wi, &BsdfContext::RADIANCE, &mut Pcg32::new(1, 1))
}

/// ∫ f(wo, wi) cos θ_i dω_i of the non-delta part, by Gauss–Legendre in (cos θ, φ).
fn smooth_albedo(b: &dyn Bsdf, wo: Vec3) -> f64 {
    let gl = GaussLegendre::new(96);
    let mut s = 0.0;
    for (&x, &wx) in gl.nodes.iter().zip(&gl.weights) {
        let mu = 0.5 * (x + 1.0);
        for (&y, &wy) in gl.nodes.iter().zip(&gl.weights) {
            let phi = std::f64::consts::PI * (y + 1.0);
            let wi = Vec3::new(
                (1.0 - mu * mu).sqrt() * phi.cos(),
                (1.0 - mu * mu).sqrt() * phi.sin(),
                mu,
            );
            s += 0.5 * wx * std::f64::consts::PI * wy * eval(b, wo, wi)[1] * mu;
        }
    }
    s
}

#[test]
fn flat_il_with_white_substrate_reflects_exactly_one() {
    for ni in [1.2, 1.5, 2.0] {
        let b = material(&format!("{{type = \"il\", kd = 1, ni = {ni}, alpha = 0}}"));
        for deg in [0.0f64, 30.0, 60.0, 80.0, 89.0] {
            let wo = spherical_direction(deg.to_radians(), 0.0);
            let f = facette_bsdf::fresnel::fresnel_dielectric(wo.z, ni);
            let total = f + smooth_albedo(b.as_ref(), wo);
            assert!((total - 1.0).abs() < 1e-3, "ni {ni} at {deg}°: {total}");
        }
    }
}

#[test]
fn rough_il_loses_energy_in_single_scattering_and_multiple_scattering_restores_it() {
    // IL18 Fig. 7: K_d = 1, n_i = 1.5, Beckmann.
    let mut lines = Vec::new();
    for alpha in [0.1, 0.5, 1.0] {
        let single = material(&format!(
            "{{type = \"il\", kd = 1, ni = 1.5, distribution = \"beckmann\", alpha = {alpha}, masking = \"v-cavity\"}}"
        ));
        let multiple = material(&format!(
            "{{type = \"il\", kd = 1, ni = 1.5, distribution = \"beckmann\", alpha = {alpha}, scattering = \"multiple\"}}"
        ));
        let (r1, s1) = hemispherical_reflectance(single.as_ref(), 100_000, 3);
        let (rm, sm) = hemispherical_reflectance(multiple.as_ref(), 100_000, 4);
        lines.push(format!(
            "alpha {alpha}: single {r1:.4} ± {s1:.4}, multiple {rm:.4} ± {sm:.4}"
        ));
        assert!((rm - 1.0).abs() < 0.03, "IL_∞ at alpha {alpha}: {rm}");
        if alpha == 1.0 {
            assert!(
                r1 < 0.8,
                "single scattering at alpha 1 must lose more than 20 %: {r1}"
            );
        }
        assert!(r1 <= 1.0 + 3.0 * s1 && rm <= 1.0 + 3.0 * sm);
    }
    println!("{}", lines.join("\n"));
}

#[test]
fn zero_substrate_is_the_rough_specular_lobe() {
    let il = material(r#"{type = "il", kd = 0, ni = 1.5, distribution = "ggx", alpha = 0.3}"#);
    let metal =
        material(r#"{type = "conductor", distribution = "ggx", alpha = 0.3, eta = 1.5, k = 0}"#);
    for (a, b) in [(0.3, 0.9), (1.2, 0.1), (0.7, 0.7)] {
        let wo = spherical_direction(a, 0.2);
        let wi = spherical_direction(b, 3.0);
        let (x, y) = (eval(il.as_ref(), wo, wi), eval(metal.as_ref(), wo, wi));
        assert!(
            (x[0] - y[0]).abs() <= 1e-12 * y[0].max(1.0),
            "{x:?} vs {y:?}"
        );
    }
}

#[test]
fn unit_index_is_the_exact_oren_nayar_model() {
    let il = material(
        r#"{type = "il", kd = 0.7, ni = 1.0, distribution = "gaussian", sigma = 0.4, evaluation = "quadrature", samples = 65536}"#,
    );
    let on = material(r#"{type = "oren-nayar", reflectance = 0.7, sigma = 0.4, samples = 65536}"#);
    for (a, b, p) in [
        (0.3, 0.9, 0.5),
        (1.2, 0.4, 3.0),
        (0.7, 1.3, 0.1),
        (1.4, 1.4, 0.0),
    ] {
        let wo = spherical_direction(a, p);
        let wi = spherical_direction(b, 0.0);
        let ctx = BsdfContext::RADIANCE;
        let (x, sx) = il.eval_estimate(wo, wi, &ctx, 0, &mut Pcg32::new(1, 1));
        let (y, sy) = on.eval_estimate(wo, wi, &ctx, 0, &mut Pcg32::new(1, 1));
        let se = (sx[0] * sx[0] + sy[0] * sy[0]).sqrt();
        assert!(
            (x[0] - y[0]).abs() <= 4.0 * se + 1e-9,
            "{x:?} ± {sx:?} vs {y:?} ± {sy:?}"
        );
    }
}

#[test]
fn vanishing_roughness_tends_to_flat_il() {
    let flat = material(r#"{type = "il", kd = 0.8, ni = 1.5, alpha = 0}"#);
    let rough = material(
        r#"{type = "il", kd = 0.8, ni = 1.5, distribution = "beckmann", alpha = 0.005, evaluation = "quadrature", samples = 4096}"#,
    );
    // Away from the specular peak the rough model is its body term.
    for (a, b) in [(0.3, 0.9), (1.0, 0.2), (0.5, 1.2)] {
        let wo = spherical_direction(a, 0.0);
        let wi = spherical_direction(b, 2.0);
        let (x, y) = (
            eval(rough.as_ref(), wo, wi)[1],
            eval(flat.as_ref(), wo, wi)[1],
        );
        assert!((x - y).abs() < 2e-3 * y, "{x} vs {y}");
    }
}

#[test]
fn multiple_scattering_orders_are_ordered() {
    // f₁ ≤ f₂ ≤ f_∞ (IL18 Fig. 9), estimated with many walks.
    let base =
        "kd = 0.9, ni = 1.5, distribution = \"beckmann\", alpha = 0.8, masking = \"v-cavity\"";
    let one = material(&format!(
        "{{type = \"il\", {base}, evaluation = \"quadrature\", samples = 8192}}"
    ));
    let two = material(&format!(
        "{{type = \"il\", {base}, scattering = \"double\"}}"
    ));
    let inf = material(&format!(
        "{{type = \"il\", {base}, scattering = \"multiple\"}}"
    ));
    let wo = spherical_direction(1.0, 0.0);
    let wi = spherical_direction(0.6, 0.4);
    let ctx = BsdfContext::RADIANCE;
    let (f1, _) = one.eval_estimate(wo, wi, &ctx, 0, &mut Pcg32::new(2, 2));
    let (f2, s2) = two.eval_estimate(wo, wi, &ctx, 400_000, &mut Pcg32::new(3, 3));
    let (fi, si) = inf.eval_estimate(wo, wi, &ctx, 400_000, &mut Pcg32::new(4, 4));
    assert!(f2[1] > f1[1] + 3.0 * s2[1], "{f1:?} {f2:?}");
    assert!(fi[1] > f2[1], "{f2:?} ± {s2:?} vs {fi:?} ± {si:?}");
}

fn gaussian_il_lobe(sigma: f64) -> SpecularLobe {
    SpecularLobe::new(
        Ndf::Gaussian(Gaussian::new(sigma).unwrap()),
        Masking::VCavity,
        NormalSampling::Distribution,
    )
    .unwrap()
}

#[test]
fn tables_interpolate_the_quadrature_and_round_trip_through_files() {
    // TSBRM Fig. 10's material: K_d = 0.9, n_i = 1.2, σ = 0.3.
    let lobe = gaussian_il_lobe(0.3);
    let quad = InterfacedLambertian::new(
        Spectrum::splat(0.9),
        1.2,
        Some(lobe.clone()),
        BodyEvaluation::Quadrature { samples: 16384 },
        Scattering::Single,
    )
    .unwrap();
    let mut errors = Vec::new();
    for step in [10.0, 5.0] {
        let t = BodyTable::build(&lobe, 1.2, step, 4096, &|_, _| {}).unwrap();
        let il = InterfacedLambertian::new(
            Spectrum::splat(0.9),
            1.2,
            Some(lobe.clone()),
            BodyEvaluation::Table(Arc::new(t)),
            Scattering::Single,
        )
        .unwrap();
        let mut rng = Pcg32::new(11, 0);
        let (mut sum, mut max, mut n) = (0.0, 0.0f64, 0);
        use facette_bsdf::math::rng::RandomSource;
        for _ in 0..300 {
            let wo =
                spherical_direction(rng.next_f64() * 1.4, rng.next_f64() * std::f64::consts::TAU);
            let wi =
                spherical_direction(rng.next_f64() * 1.4, rng.next_f64() * std::f64::consts::TAU);
            let (a, _) = il.body_integral(wi, wo, 0, &mut rng);
            let (b, _) = quad.body_integral(wi, wo, 0, &mut rng);
            let e = ((a - b) / b).abs();
            sum += e;
            max = max.max(e);
            n += 1;
        }
        errors.push((step, sum / n as f64, max));
    }
    println!("table vs quadrature (θ ≤ 80°): {errors:?}");
    assert!(errors[0].1 < 0.02 && errors[1].1 < 0.01, "{errors:?}");
    assert!(
        errors[1].1 < errors[0].1,
        "a 5° table must beat a 10° table"
    );

    // File round trip, and corrupted files are clear errors.
    let t = BodyTable::build(&lobe, 1.2, 10.0, 256, &|_, _| {}).unwrap();
    let dir = std::env::temp_dir().join(format!("facette-il-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("body.fctab");
    t.save(&p).unwrap();
    let back = BodyTable::load(&p).unwrap();
    assert_eq!(back.values(), t.values());
    let mut bytes = std::fs::read(&p).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x55;
    let e = BodyTable::from_bytes(&bytes, "x.fctab")
        .unwrap_err()
        .to_string();
    assert!(e.contains("checksum"), "{e}");
    let e = BodyTable::from_bytes(&bytes[..40], "x.fctab")
        .unwrap_err()
        .to_string();
    assert!(e.contains("truncated"), "{e}");
    let e = BodyTable::from_bytes(b"not a table at all, just text", "x.fctab")
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad magic"), "{e}");
    // A table for other parameters is refused by the material.
    let e = material_err(&format!("{{type = \"il\", kd = 0.5, ni = 1.5, distribution = \"gaussian\", sigma = 0.3, table = \"{}\"}}", p.display()));
    assert!(e.contains("was built for ni = 1.2"), "{e}");
    // Anisotropic distributions are refused clearly.
    let aniso = SpecularLobe::new(
        Ndf::Beckmann(facette_bsdf::microfacet::Beckmann::new(0.1, 0.5).unwrap()),
        Masking::VCavity,
        NormalSampling::Distribution,
    )
    .unwrap();
    let e = BodyTable::build(&aniso, 1.5, 10.0, 64, &|_, _| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("isotropic"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

fn material_err(s: &str) -> String {
    match build_material(&parse_inline_table(s).unwrap()) {
        Ok(_) => panic!("{s} should fail"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_parameters_are_clear_errors() {
    for (s, needle) in [
        (r#"{type = "il", kd = 1.2, alpha = 0.1}"#, "kd"),
        (r#"{type = "il", ni = 0.9, alpha = 0.1}"#, "ni"),
        (r#"{type = "il", ni = nan, alpha = 0.1}"#, "finite"),
        (
            r#"{type = "il", alpha = 0.1, distribution = "cauchy"}"#,
            "beckmann, ggx, gaussian, phong",
        ),
        (
            r#"{type = "il", alpha = 0.1, masking = "smith", scattering = "multiple"}"#,
            "v-cavity",
        ),
        (
            r#"{type = "il", alpha = 0.1, scattering = "infinite"}"#,
            "single, double, multiple",
        ),
        (
            r#"{type = "il", alpha = 0.1, evaluation = "table"}"#,
            "missing required key `table",
        ),
        (
            r#"{type = "il", alpha = 0.1, table = "/nonexistent.fctab"}"#,
            "/nonexistent.fctab",
        ),
    ] {
        let e = material_err(s);
        assert!(e.contains(needle), "{s}: {e}");
    }
}

#[test]
fn approximation_has_the_exact_limits_and_bounded_error() {
    use facette_bsdf::models::il::il_approx::{ApproxFamily, IlApprox};
    use facette_bsdf::models::oren_nayar::oren_nayar_l1_factor;
    // σ → 0: flat IL, for every family and index.
    let mut rng = Pcg32::new(5, 5);
    for fam in ApproxFamily::ALL {
        for ni in [1.0, 1.4, 2.7] {
            let a = IlApprox::for_family(fam, 0.0, ni).unwrap();
            let re = facette_bsdf::fresnel::external_diffuse_reflectance(ni);
            for (x, y) in [(0.2, 0.7), (1.1, 0.4)] {
                let (i, o) = (spherical_direction(x, 0.0), spherical_direction(y, 1.0));
                let t = |u: Vec3| 1.0 - facette_bsdf::fresnel::fresnel_dielectric(u.z, ni);
                assert!((a.body_integral(i, o, ni, re) - t(i) * t(o)).abs() < 1e-12);
            }
        }
    }
    // n_i = 1 with the Gaussian: Oren & Nayar's L1 model.
    let il = material(
        r#"{type = "il", kd = 0.7, ni = 1.0, distribution = "gaussian", sigma = 0.45, evaluation = "approx"}"#,
    );
    for (x, y, p) in [(0.2, 0.7, 0.3), (1.1, 0.4, 2.5), (1.3, 1.2, 0.0)] {
        let (wi, wo) = (spherical_direction(x, 0.0), spherical_direction(y, p));
        let f = il.eval(wo, wi, &BsdfContext::RADIANCE, &mut rng)[0];
        let on = 0.7 / std::f64::consts::PI * oren_nayar_l1_factor(0.45, [1.0; 3], wi, wo);
        assert!((f - on).abs() < 1e-12, "{f} vs {on}");
    }
    // Accuracy against the quadrature at one interior point of each V-cavity family.
    for (fam, bound) in [
        (ApproxFamily::GaussianVCavity, 0.12),
        (ApproxFamily::BeckmannVCavity, 0.12),
    ] {
        let e = facette_lab_free_accuracy(fam, 0.35, 1.5);
        println!(
            "{}: σ = 0.35, n_i = 1.5: mean relative error {e:.4}",
            fam.name()
        );
        assert!(e < bound, "{e}");
    }
}

/// Mean relative error of the approximation against the quadrature over θ ≤ 75°.
fn facette_lab_free_accuracy(
    fam: facette_bsdf::models::il::il_approx::ApproxFamily,
    sigma: f64,
    ni: f64,
) -> f64 {
    use facette_bsdf::models::il::il_approx::{ApproxFamily, IlApprox};
    let lobe = match fam {
        ApproxFamily::GaussianVCavity => gaussian_il_lobe(sigma),
        _ => SpecularLobe::new(
            Ndf::Beckmann(
                facette_bsdf::microfacet::Beckmann::isotropic(std::f64::consts::SQRT_2 * sigma)
                    .unwrap(),
            ),
            Masking::VCavity,
            NormalSampling::Distribution,
        )
        .unwrap(),
    };
    let quad = InterfacedLambertian::new(
        Spectrum::ONE,
        ni,
        Some(lobe),
        BodyEvaluation::Quadrature { samples: 16384 },
        Scattering::Single,
    )
    .unwrap();
    let approx = IlApprox::for_family(fam, sigma, ni).unwrap();
    let re = facette_bsdf::fresnel::external_diffuse_reflectance(ni);
    let mut rng = Pcg32::new(1, 1);
    let (mut sum, mut n) = (0.0, 0);
    for ti in (5..=75).step_by(10) {
        for to in (5..=75).step_by(10) {
            for p in [0.0f64, 60.0, 120.0, 180.0] {
                let i = spherical_direction((ti as f64).to_radians(), 0.0);
                let o = spherical_direction((to as f64).to_radians(), p.to_radians());
                let e = quad.body_integral(i, o, 0, &mut rng).0;
                sum += ((approx.body_integral(i, o, ni, re) - e) / e).abs();
                n += 1;
            }
        }
    }
    sum / n as f64
}
