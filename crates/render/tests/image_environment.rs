//! Environment maps: Mitsuba 3's lat-long convention, the sampler against its pdf
//! (chi-square), normalization, and consistency of sample / eval / pdf.

use std::f64::consts::PI;

use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_bsdf::validation::chi2::expected_probabilities;
use facette_bsdf::validation::{chi2_test, Chi2Config, SphereMap};
use facette_bsdf::Spectrum;
use facette_render::image::environment::uv_to_direction;
use facette_render::image::{generate_sky, EnvironmentMap, RgbImage, SkyParams};
use glam::{DMat3, DVec2, DVec3};

fn rotation() -> DMat3 {
    DMat3::from_rotation_z(0.4) * DMat3::from_rotation_x(-1.1) * DMat3::from_rotation_y(2.0)
}

/// A small sky with a bright sun a few pixels wide.
fn sunny(width: usize, height: usize, radius: f64) -> RgbImage {
    generate_sky(&SkyParams {
        width,
        height,
        sun_direction: DVec3::new(0.5, 0.7, 0.3),
        sun_angular_radius: radius,
        sun_radiance: Spectrum::rgb(900.0, 800.0, 600.0),
        ..Default::default()
    })
    .unwrap()
}

#[test]
fn directions_map_to_mitsuba_uv() {
    // Each pixel a distinct value; the centre direction of a pixel reads it back.
    let (w, h) = (8, 4);
    let img = RgbImage::from_fn(w, h, |x, y| [x as f32, y as f32, 1.0]).unwrap();
    let env = EnvironmentMap::new(img, DMat3::IDENTITY, 1.0).unwrap();
    let uv = |d: DVec3| env.uv(d).unwrap();
    assert!((uv(-DVec3::Z) - DVec2::new(0.0, 0.5)).length() < 1e-12);
    assert!((uv(DVec3::X) - DVec2::new(0.25, 0.5)).length() < 1e-12);
    assert!((uv(DVec3::Z) - DVec2::new(0.5, 0.5)).length() < 1e-12);
    assert!((uv(-DVec3::X) - DVec2::new(0.75, 0.5)).length() < 1e-12);
    assert_eq!(uv(DVec3::Y).y, 0.0); // +y is the top row
    assert_eq!(uv(-DVec3::Y).y, 1.0);
    for y in 0..h {
        for x in 0..w {
            let centre = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            let v = env.eval(uv_to_direction(centre));
            assert!(
                (v - Spectrum::rgb(x as f64, y as f64, 1.0))
                    .max_component()
                    .abs()
                    < 1e-9
            );
        }
    }
    // Straight up reads the top row (clamped), the mean of the row's two nearest pixels
    // in φ at u = 0: pixels 7 and 0 of row 0 → x = 3.5.
    let up = env.eval(DVec3::Y);
    assert!(
        (up - Spectrum::rgb(3.5, 0.0, 1.0)).max_component().abs() < 1e-9,
        "{up:?}"
    );
}

#[test]
fn pdf_integrates_to_one() {
    // In the map's frame the pdf is constant on each pixel: Σ pdf(centre)·Ω(pixel) is the
    // integral exactly, and checks that `pdf` divides by the right solid angle.
    let (w, h) = (64, 32);
    let env = EnvironmentMap::new(sunny(w, h, 0.1), DMat3::IDENTITY, 1.0).unwrap();
    let mut s = 0.0;
    for y in 0..h {
        let omega = 2.0 * PI / w as f64
            * ((PI * y as f64 / h as f64).cos() - (PI * (y + 1) as f64 / h as f64).cos());
        for x in 0..w {
            let centre = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            s += env.pdf(uv_to_direction(centre)) * omega;
        }
    }
    assert!((s - 1.0).abs() < 1e-12, "Σ pdf Ω = {s}");
    // Rotated, by the validation harness's adaptive quadrature over the sphere (the pdf
    // jumps at every pixel edge, which a plain midpoint grid resolves only slowly).
    let env = EnvironmentMap::new(sunny(w, h, 0.1), rotation(), 1.0).unwrap();
    let p = expected_probabilities(&SphereMap::standard(), &Chi2Config::default(), &|d| {
        env.pdf(d)
    });
    let s: f64 = p.iter().sum();
    assert!((s - 1.0).abs() < 1e-3, "∫ pdf dω = {s}");
}

#[test]
fn samples_carry_eval_and_pdf_of_their_direction() {
    let env = EnvironmentMap::new(sunny(64, 32, 0.1), rotation(), 2.5).unwrap();
    let mut rng = Pcg32::new(11, 0);
    // The importance-sampled estimate of the mean radiance, E[L/pdf]/4π.
    let n = 400_000;
    let mut est = Spectrum::ZERO;
    for _ in 0..n {
        let s = env.sample(rng.next_2d()).unwrap();
        assert!((s.direction.length() - 1.0).abs() < 1e-12);
        assert_eq!(s.radiance, env.eval(s.direction));
        assert_eq!(s.pdf, env.pdf(s.direction));
        assert!(s.pdf > 0.0 && s.radiance.is_finite());
        est += s.radiance / s.pdf;
    }
    let est = est / (n as f64 * 4.0 * PI);
    let mean = env.mean_radiance();
    // `mean_radiance` sums pixels; `eval` interpolates them — equal up to the smoothing
    // of the sun's edge, well under 1 %.
    for c in 0..3 {
        assert!((est[c] / mean[c] - 1.0).abs() < 0.01, "{est:?} vs {mean:?}");
    }
    // Degenerate sample inputs still give valid samples.
    for u in [DVec2::ZERO, DVec2::ONE, DVec2::splat(f64::NAN)] {
        let s = env.sample(u).unwrap();
        assert!(s.pdf > 0.0 && s.direction.is_finite());
    }
}

fn chi2_env(env: &EnvironmentMap, map: &SphereMap, samples: usize, seed: u64) -> bool {
    let cfg = Chi2Config {
        samples,
        seed,
        ..Default::default()
    };
    let out = chi2_test(
        map,
        &cfg,
        |rng| env.sample(rng.next_2d()).map(|s| s.direction),
        |d| env.pdf(d),
    );
    assert!((out.pdf_integral - 1.0).abs() < 1e-3, "{}", out.summary());
    println!("{}", out.summary());
    out.passes(0.01)
}

#[test]
fn sampler_matches_pdf_chi_square_on_a_sunny_sky() {
    // The whole sphere, with a sun covering a few pixels of a coarse map.
    let env = EnvironmentMap::new(sunny(64, 32, 0.1), rotation(), 1.0).unwrap();
    assert!(chi2_env(&env, &SphereMap::standard(), 1_000_000, 7));

    // Zoomed on the sun of a finer map: the structure inside the disk is tested too.
    let env = EnvironmentMap::new(sunny(256, 128, 0.03), rotation(), 1.0).unwrap();
    let sun = rotation() * DVec3::new(0.5, 0.7, 0.3).normalize();
    assert!(chi2_env(&env, &SphereMap::new(sun, 0.03), 1_000_000, 8));
}

#[test]
fn chi_square_rejects_a_wrong_pdf() {
    let env = EnvironmentMap::new(sunny(64, 32, 0.1), rotation(), 1.0).unwrap();
    let cfg = Chi2Config {
        samples: 200_000,
        ..Default::default()
    };
    // Claiming uniform sampling while sampling the sun.
    let out = chi2_test(
        &SphereMap::standard(),
        &cfg,
        |rng| env.sample(rng.next_2d()).map(|s| s.direction),
        |_| 0.25 / PI,
    );
    assert!(!out.passes(0.01), "{}", out.summary());
}

#[test]
fn the_sun_draws_most_samples() {
    let env = EnvironmentMap::new(sunny(128, 64, 0.05), DMat3::IDENTITY, 1.0).unwrap();
    let sun = DVec3::new(0.5, 0.7, 0.3).normalize();
    let mut rng = Pcg32::new(5, 0);
    let n = 100_000;
    let near = (0..n)
        .filter(|_| {
            let s = env.sample(rng.next_2d()).unwrap();
            s.direction.dot(sun).acos() < 0.05 + 2.0 * PI / 128.0
        })
        .count();
    // Sun luminance × solid angle ≈ 800 · π 0.05² ≈ 6.3 vs sky ≈ 0.75 · 4π ≈ 9 · ½ → the
    // sun holds well over half the power.
    assert!(near as f64 / n as f64 > 0.5, "{near}");
}
