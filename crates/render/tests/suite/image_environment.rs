//! Environment maps: Mitsuba 3's lat-long convention, the sampler against its pdf
//! (chi-square), normalization, and consistency of sample / eval / pdf.

use std::f64::consts::PI;

use facette_bsdf::lanes::{F32x8, M32x8, Mask, Real};
use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_bsdf::validation::chi2::expected_probabilities;
use facette_bsdf::validation::{chi2_test, Chi2Config, SphereMap};
use facette_bsdf::Spectrum;
use facette_render::image::environment::uv_to_direction;
use facette_render::image::{generate_sky, Distribution2D, EnvironmentMap, RgbImage, SkyParams};
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

/// Gauss–Legendre nodes and weights on [0, 1].
fn gauss_legendre_01(n: usize) -> Vec<(f64, f64)> {
    let (x, w): (&[f64], &[f64]) = match n {
        3 => (
            &[-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4],
            &[5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0],
        ),
        6 => (
            &[
                -0.932_469_514_203_152,
                -0.661_209_386_466_264_5,
                -0.238_619_186_083_196_9,
                0.238_619_186_083_196_9,
                0.661_209_386_466_264_5,
                0.932_469_514_203_152,
            ],
            &[
                0.171_324_492_379_170_3,
                0.360_761_573_048_138_6,
                0.467_913_934_572_691,
                0.467_913_934_572_691,
                0.360_761_573_048_138_6,
                0.171_324_492_379_170_3,
            ],
        ),
        _ => unreachable!(),
    };
    x.iter()
        .zip(w)
        .map(|(&x, &w)| (0.5 * (x + 1.0), 0.5 * w))
        .collect()
}

/// ∫ f dω over the sphere of a W×H map (in the map's frame), by Gauss–Legendre on each cell
/// between pixel centres (and the half-cells at u = 0 / 1 and at the poles): there both
/// `eval` and `pdf` are bilinear in uv, so with dω = 2π² sin(πv) du dv this is exact up to
/// the (tiny) error of the 6-point rule on sin over a row.
fn integrate_sphere(w: usize, h: usize, f: impl Fn(DVec3) -> f64) -> f64 {
    let breaks = |n: usize| {
        let mut b = vec![0.0];
        b.extend((0..n).map(|k| (k as f64 + 0.5) / n as f64));
        b.push(1.0);
        b
    };
    let (bu, bv) = (breaks(w), breaks(h));
    let (gu, gv) = (gauss_legendre_01(3), gauss_legendre_01(6));
    let mut total = 0.0;
    for v in bv.windows(2) {
        let dv = v[1] - v[0];
        for &(tv, wv) in &gv {
            let vv = v[0] + dv * tv;
            let jac = 2.0 * PI * PI * (PI * vv).sin() * dv * wv;
            for u in bu.windows(2) {
                let du = u[1] - u[0];
                for &(tu, wu) in &gu {
                    let d = uv_to_direction(DVec2::new(u[0] + du * tu, vv));
                    total += f(d) * du * wu * jac;
                }
            }
        }
    }
    total
}

#[test]
fn pdf_integrates_to_one() {
    // In the map's frame the pdf is bilinear in uv between pixel centres: Gauss–Legendre on
    // those cells integrates it exactly, and checks that `pdf` is normalized with the right
    // Jacobian. (Before the pdf was bilinear this test summed pdf(centre)·Ω over pixels.)
    let (w, h) = (64, 32);
    let env = EnvironmentMap::new(sunny(w, h, 0.1), DMat3::IDENTITY, 1.0).unwrap();
    let s = integrate_sphere(w, h, |d| env.pdf(d));
    assert!((s - 1.0).abs() < 1e-12, "∫ pdf dω = {s}");
    // Rotated, by the validation harness's adaptive quadrature over the sphere.
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

/// The default procedural sky (1024×512) with its 1° sun, about 6 pixels across.
fn one_degree_sun() -> (RgbImage, DVec3) {
    let p = SkyParams {
        sun_direction: DVec3::new(0.5, 0.7, 0.3),
        ..Default::default()
    };
    (generate_sky(&p).unwrap(), p.sun_direction.normalize())
}

#[test]
fn sampler_matches_pdf_chi_square_on_a_one_degree_sun() {
    let (img, sun) = one_degree_sun();
    let env = EnvironmentMap::new(img, rotation(), 1.0).unwrap();
    let sun = rotation() * sun;
    // Zoomed on the sun (its radius), where the bilinear density varies inside every
    // pixel, and the whole sphere.
    assert!(chi2_env(
        &env,
        &SphereMap::new(sun, 1f64.to_radians()),
        1_000_000,
        21
    ));
    assert!(chi2_env(&env, &SphereMap::standard(), 1_000_000, 22));
}

/// A lane sampler's draw for `u`, put in a lane chosen by `rng` among eight lanes drawing
/// other numbers (so that every lane position is exercised): its direction and the
/// radiance and density it reports.
fn f32_lane_draw(env: &EnvironmentMap, rng: &mut Pcg32) -> Option<(DVec3, Spectrum, f64)> {
    let lane = (rng.next_f64() * 8.0) as usize;
    let (mut u0, mut u1) = ([0.0f64; 8], [0.0f64; 8]);
    for i in 0..8 {
        (u0[i], u1[i]) = (rng.next_f64(), rng.next_f64());
    }
    let set = M32x8::from_fn(|i| i != (lane + 3) % 8);
    let s = env.sample_lanes(F32x8::from_fn(|i| u0[i]), F32x8::from_fn(|i| u1[i]), set);
    assert!(
        !s.drawn.lane((lane + 3) % 8),
        "a lane outside the set was drawn"
    );
    s.drawn.lane(lane).then(|| {
        let r = s.radiance;
        (
            s.direction.lane(lane),
            Spectrum::rgb(r[0].lane(lane), r[1].lane(lane), r[2].lane(lane)),
            s.pdf.lane(lane),
        )
    })
}

/// The f32 lane sampler of the render kernel (the same source as `sample`, in f32 lanes)
/// against the f64 density: chi-square on the whole sphere and zoomed on a 1° sun, and each
/// draw's radiance and density those of `eval` and `pdf` at its direction within f32
/// rounding.
#[test]
fn f32_lane_sampler_matches_pdf_chi_square() {
    let (img, sun) = one_degree_sun();
    let env = EnvironmentMap::new(img, rotation(), 1.0).unwrap();
    assert!(env.serves_lanes::<F32x8>());
    let sun = rotation() * sun;
    for (map, seed) in [
        (SphereMap::standard(), 31),
        (SphereMap::new(sun, 1f64.to_radians()), 32),
    ] {
        let cfg = Chi2Config {
            samples: 1_000_000,
            seed,
            ..Default::default()
        };
        let out = chi2_test(
            &map,
            &cfg,
            |rng| f32_lane_draw(&env, rng).map(|d| d.0),
            |d| env.pdf(d),
        );
        println!("{}", out.summary());
        assert!(out.passes(0.01), "{}", out.summary());
    }
    let mut rng = Pcg32::new(33, 0);
    let mut worst: [f64; 2] = [0.0; 2];
    for _ in 0..100_000 {
        let (d, radiance, pdf) = f32_lane_draw(&env, &mut rng).expect("a sky draws every lane");
        assert!((d.length() - 1.0).abs() < 1e-6);
        let (want_radiance, want_pdf) = env.eval_pdf(d);
        assert!(pdf > 0.0 && radiance.is_finite());
        worst[0] = worst[0].max((pdf / want_pdf - 1.0).abs());
        for c in 0..3 {
            worst[1] = worst[1].max((radiance[c] / want_radiance[c] - 1.0).abs());
        }
    }
    println!(
        "largest relative differences: pdf {:e}, radiance {:e}",
        worst[0], worst[1]
    );
    assert!(worst[0] < 1e-3 && worst[1] < 1e-3, "{worst:?}");
}

/// The sampler this map had before the bilinear one, rebuilt as the baseline: per pixel,
/// luminance filtered by the tent (⅛, ¾, ⅛) × the pixel's solid angle, uniform in solid
/// angle inside the pixel (identity frame only).
struct PiecewiseConstant {
    w: usize,
    dist: Distribution2D,
    cos_edges: Vec<f64>,
}

impl PiecewiseConstant {
    fn new(img: &RgbImage) -> Self {
        let (w, h) = (img.width(), img.height());
        let cos_edges: Vec<f64> = (0..=h).map(|y| (PI * y as f64 / h as f64).cos()).collect();
        let lum = |x: usize, y: usize| img.spectrum(x, y).luminance();
        const TENT: [f64; 3] = [0.125, 0.75, 0.125];
        let mut weights = vec![0.0; w * h];
        for y in 0..h {
            let omega = 2.0 * PI / w as f64 * (cos_edges[y] - cos_edges[y + 1]);
            for x in 0..w {
                let mut s = 0.0;
                for (dy, ky) in TENT.iter().enumerate() {
                    let yy = (y + dy).saturating_sub(1).min(h - 1);
                    for (dx, kx) in TENT.iter().enumerate() {
                        s += ky * kx * lum((x + w + dx - 1) % w, yy);
                    }
                }
                weights[y * w + x] = s * omega;
            }
        }
        PiecewiseConstant {
            w,
            dist: Distribution2D::new(w, h, &weights),
            cos_edges,
        }
    }

    fn sample(&self, u: DVec2) -> (DVec3, f64) {
        let (x, y, p, f) = self.dist.sample(u).unwrap();
        let z = self.cos_edges[y] + (self.cos_edges[y + 1] - self.cos_edges[y]) * f.y;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (sp, cp) = (2.0 * PI * (x as f64 + f.x) / self.w as f64).sin_cos();
        let omega = 2.0 * PI / self.w as f64 * (self.cos_edges[y] - self.cos_edges[y + 1]);
        (DVec3::new(sp * r, z, -cp * r), p / omega)
    }
}

/// Estimates of ∫ Y(ω) cos⁺(ω·n) dω (Y the luminance of `eval`) from a sampler returning
/// (direction, pdf): `seeds` runs of `n` samples. Returns the mean, the relative standard
/// deviation of the runs' estimates, and the relative variance of one sample (pooled over
/// all runs: a much steadier figure than the spread of 64 estimates).
fn sun_estimates(
    env: &EnvironmentMap,
    normal: DVec3,
    n: usize,
    seeds: u64,
    sample: impl Fn(DVec2) -> Option<(DVec3, f64)>,
) -> (f64, f64, f64) {
    let (mut s1, mut s2) = (0.0, 0.0);
    let estimates: Vec<f64> = (0..seeds)
        .map(|seed| {
            let mut rng = Pcg32::new(1000 + seed, 3);
            let mut sum = 0.0;
            for _ in 0..n {
                if let Some((d, pdf)) = sample(rng.next_2d()) {
                    let f = env.eval(d).luminance() * d.dot(normal).max(0.0) / pdf;
                    sum += f;
                    s2 += f * f;
                }
            }
            s1 += sum;
            sum / n as f64
        })
        .collect();
    let mean = estimates.iter().sum::<f64>() / seeds as f64;
    let var = estimates.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (seeds - 1) as f64;
    let m = (n as u64 * seeds) as f64;
    let per_sample = (s2 / m - (s1 / m).powi(2)) / (s1 / m).powi(2);
    (mean, var.sqrt() / mean, per_sample)
}

#[test]
fn bilinear_sampling_removes_the_sun_pixels_noise() {
    // Direct lighting of a surface facing a 1° sun, 4096 samples × 64 seeds: the bilinear
    // sampler against the per-pixel constant density it replaced, with the sky and with
    // the sun alone (where nothing but the sampler's own swings is left).
    for sky in [true, false] {
        let (img, sun) = one_degree_sun();
        let img = if sky {
            img
        } else {
            let p = SkyParams {
                sun_direction: sun,
                zenith: Spectrum::ZERO,
                horizon: Spectrum::ZERO,
                ground: Spectrum::ZERO,
                ..Default::default()
            };
            generate_sky(&p).unwrap()
        };
        let env = EnvironmentMap::new(img.clone(), DMat3::IDENTITY, 1.0).unwrap();
        let exact = integrate_sphere(img.width(), img.height(), |d| {
            env.eval(d).luminance() * d.dot(sun).max(0.0)
        });
        let (m_new, rs_new, v_new) = sun_estimates(&env, sun, 4096, 64, |u| {
            env.sample(u).map(|s| (s.direction, s.pdf))
        });
        let pc = PiecewiseConstant::new(&img);
        let (m_old, rs_old, v_old) = sun_estimates(&env, sun, 4096, 64, |u| Some(pc.sample(u)));
        println!(
            "sky {sky}: ∫Y cos⁺ dω = {exact:.6}; bilinear: mean {m_new:.6}, rel. std \
             {rs_new:.3e}, per-sample rel. var. {v_new:.4e}; piecewise constant: mean \
             {m_old:.6}, rel. std {rs_old:.3e}, per-sample rel. var. {v_old:.4e}; \
             variance ratio old/new {:.3}",
            v_old / v_new
        );
        for m in [m_new, m_old] {
            assert!((m / exact - 1.0).abs() < 0.01, "{m} vs {exact}");
        }
        if sky {
            // The sky's own cos⁺ spread is common to both; the sun pixels' swings add 24 %.
            assert!(v_new < 0.85 * v_old, "{v_new} vs {v_old}");
        } else {
            // Only the cosine's variation across the 1° disk is left: ~1e-9.
            assert!(
                v_new < 1e-7 && rs_new < 1e-5 && v_old > 1e-2,
                "{v_new} vs {v_old}"
            );
        }
    }
}

#[test]
fn weight_is_the_luminance_integral_times_chroma() {
    // A grey map: eval/pdf is the same number, ∫Y dω, for every sample — the poles' half
    // rows included.
    let (img, _) = one_degree_sun();
    let (w, h) = (img.width(), img.height());
    let grey = RgbImage::from_fn(w, h, |x, y| [img.spectrum(x, y).luminance() as f32; 3]).unwrap();
    let env = EnvironmentMap::new(grey, rotation(), 1.0).unwrap();
    let env_id = EnvironmentMap::new(env.image().clone(), DMat3::IDENTITY, 1.0).unwrap();
    let integral = integrate_sphere(w, h, |d| env_id.eval(d).luminance());
    let mut rng = Pcg32::new(3, 0);
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for _ in 0..200_000 {
        let s = env.sample(rng.next_2d()).unwrap();
        assert_eq!(s.pdf, env.pdf(s.direction));
        let r = s.radiance.luminance() / s.pdf;
        (lo, hi) = (lo.min(r), hi.max(r));
    }
    println!("grey map: eval/pdf ∈ [{lo:.12}, {hi:.12}], ∫Y dω = {integral:.12}");
    assert!((hi - lo) / lo < 1e-6, "{lo} … {hi}");
    assert!((hi / integral - 1.0).abs() < 1e-9, "{hi} vs {integral}");

    // A coloured map: each channel of eval/pdf is bounded by ∫Y dω × the largest
    // channel-to-luminance ratio of the pixels.
    let env = EnvironmentMap::new(img.clone(), rotation(), 3.0).unwrap();
    let env_id = EnvironmentMap::new(img.clone(), DMat3::IDENTITY, 3.0).unwrap();
    let integral = integrate_sphere(w, h, |d| env_id.eval(d).luminance());
    let mut chroma = [0.0f64; 3];
    for y in 0..h {
        for x in 0..w {
            let p = img.spectrum(x, y);
            for (c, m) in chroma.iter_mut().enumerate() {
                if p.luminance() > 0.0 {
                    *m = m.max(p[c] / p.luminance());
                }
            }
        }
    }
    let mut rng = Pcg32::new(4, 0);
    for _ in 0..100_000 {
        let s = env.sample(rng.next_2d()).unwrap();
        for (c, m) in chroma.iter().enumerate() {
            assert!(s.radiance[c] / s.pdf <= integral * m * (1.0 + 1e-9));
        }
    }
}

#[test]
fn degenerate_maps_poles_and_the_seam() {
    // One pixel, one column, one row, and a map black but for one pole row.
    let cases = [
        RgbImage::filled(1, 1, [2.0, 1.0, 0.5]).unwrap(),
        RgbImage::from_fn(1, 5, |_, y| [y as f32, 1.0, 0.0]).unwrap(),
        RgbImage::from_fn(7, 1, |x, _| [0.0, x as f32, 1.0]).unwrap(),
        RgbImage::from_fn(8, 4, |x, y| [if y == 3 { x as f32 } else { 0.0 }; 3]).unwrap(),
    ];
    for img in cases {
        let (w, h) = (img.width(), img.height());
        let env = EnvironmentMap::new(img.clone(), DMat3::IDENTITY, 1.0).unwrap();
        let s = integrate_sphere(w, h, |d| env.pdf(d));
        assert!((s - 1.0).abs() < 1e-12, "{w}×{h}: ∫ pdf dω = {s}");
        for d in [DVec3::Y, -DVec3::Y] {
            assert!(env.pdf(d).is_finite() && env.eval(d).is_finite());
        }
        // Continuous across the seam u = 0 ≡ 1.
        for k in 1..10 {
            let v = k as f64 / 10.0;
            let a = env.pdf(uv_to_direction(DVec2::new(0.0, v)));
            let b = env.pdf(uv_to_direction(DVec2::new(1.0 - 1e-12, v)));
            assert!((a - b).abs() <= 1e-9 * a.max(1e-300), "{a} {b}");
        }
        for u in [
            DVec2::ZERO,
            DVec2::ONE,
            DVec2::new(0.0, 1.0),
            DVec2::splat(f64::NAN),
        ] {
            let s = env.sample(u).unwrap();
            assert!(s.pdf > 0.0 && s.direction.is_finite(), "{w}×{h} {u}");
        }
        let rot = EnvironmentMap::new(img, rotation(), 1.0).unwrap();
        assert!(
            chi2_env(&rot, &SphereMap::standard(), 200_000, 9),
            "{w}×{h}"
        );
    }
}
