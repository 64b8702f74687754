//! The procedural sky: deterministic, sun where asked, resolution-independent lighting,
//! written once.

use std::f64::consts::PI;

use facette_bsdf::Spectrum;
use facette_render::image::environment::uv_to_direction;
use facette_render::image::{
    ensure_sky, generate_sky, read_exr_channels, read_image, ColorEncoding, EnvironmentMap,
    ImageError, RgbImage, SkyParams,
};
use glam::{DMat3, DVec2, DVec3};

fn params(w: usize, h: usize) -> SkyParams {
    SkyParams {
        width: w,
        height: h,
        sun_direction: DVec3::new(-0.6, 0.45, 0.3),
        sun_angular_radius: 0.02,
        ..Default::default()
    }
}

fn pixel_solid_angle(w: usize, h: usize, y: usize) -> f64 {
    2.0 * PI / w as f64
        * ((PI * y as f64 / h as f64).cos() - (PI * (y + 1) as f64 / h as f64).cos())
}

/// ∫ L(ω) max(0, ω·n) dω over the image, pixel by pixel.
fn irradiance(img: &RgbImage, n: DVec3) -> Spectrum {
    let (w, h) = (img.width(), img.height());
    let mut e = Spectrum::ZERO;
    for y in 0..h {
        let omega = pixel_solid_angle(w, h, y);
        for x in 0..w {
            let d = uv_to_direction(DVec2::new(
                (x as f64 + 0.5) / w as f64,
                (y as f64 + 0.5) / h as f64,
            ));
            e += img.spectrum(x, y) * (omega * d.dot(n).max(0.0));
        }
    }
    e
}

/// Σ (with − without)·Ω in channel `c`: the power the sun adds to the image.
fn sun_power(with: &RgbImage, without: &RgbImage, c: usize) -> f64 {
    let (w, h) = (with.width(), with.height());
    let mut power = 0.0;
    for y in 0..h {
        for x in 0..w {
            power +=
                (with.spectrum(x, y)[c] - without.spectrum(x, y)[c]) * pixel_solid_angle(w, h, y);
        }
    }
    power
}

#[test]
fn generation_is_deterministic_and_the_sun_is_where_asked() {
    let p = params(512, 256);
    let a = generate_sky(&p).unwrap();
    let b = generate_sky(&p).unwrap();
    assert_eq!(a, b);
    assert!(a.is_finite());
    // The brightest pixel looks at the sun.
    let (mut best, mut at) = (0.0, (0, 0));
    for y in 0..a.height() {
        for x in 0..a.width() {
            let l = a.spectrum(x, y).luminance();
            if l > best {
                best = l;
                at = (x, y);
            }
        }
    }
    let d = uv_to_direction(DVec2::new(
        (at.0 as f64 + 0.5) / 512.0,
        (at.1 as f64 + 0.5) / 256.0,
    ));
    let off = d.dot(p.sun_unit()).acos();
    assert!(
        off < PI / 256.0,
        "brightest pixel is {off} rad from the sun"
    );
    // As an environment map (identity frame), the sun direction is bright and the sky
    // elsewhere is the gradient: zenith at the top, ground below the horizon.
    let env = EnvironmentMap::new(a.clone(), DMat3::IDENTITY, 1.0).unwrap();
    assert!(env.eval(p.sun_unit()).luminance() > 1000.0);
    let top = a.spectrum(100, 0);
    assert!((top - p.zenith).max_component().abs() < 0.02, "{top:?}");
    let below = a.spectrum(100, 200);
    assert!((below - p.ground).max_component().abs() < 1e-6, "{below:?}");
    let horizon_row = a.spectrum(100, 127); // just above the horizon
    assert!(
        (horizon_row - p.horizon).max_component().abs() < 0.15,
        "{horizon_row:?}"
    );
}

#[test]
fn lighting_does_not_depend_on_resolution() {
    // Irradiance on planes facing up and facing the sun, at a coarse and a fine
    // resolution (the sun is smaller than a pixel of the coarse one).
    let coarse = generate_sky(&params(64, 32)).unwrap();
    let fine = generate_sky(&params(1024, 512)).unwrap();
    let sun = params(1, 1).sun_unit();
    for n in [DVec3::Y, sun] {
        let (ec, ef) = (irradiance(&coarse, n), irradiance(&fine, n));
        for c in 0..3 {
            assert!((ec[c] / ef[c] - 1.0).abs() < 0.03, "{n}: {ec:?} vs {ef:?}");
        }
    }
    // The sun's share matches its analytic power at both resolutions.
    let p = params(64, 32);
    let sky_only = generate_sky(&SkyParams {
        sun_radiance: Spectrum::ZERO,
        ..p.clone()
    })
    .unwrap();
    let power = sun_power(&coarse, &sky_only, 0);
    let exact = p.sun_radiance[0] * p.sun_solid_angle();
    assert!((power / exact - 1.0).abs() < 1e-4, "{power} vs {exact}");
}

#[test]
fn a_sun_smaller_than_the_sampling_grid_keeps_its_power() {
    let p = SkyParams {
        width: 16,
        height: 8,
        sun_angular_radius: 1e-5,
        sun_radiance: Spectrum::splat(1e9),
        ..Default::default()
    };
    let with = generate_sky(&p).unwrap();
    let without = generate_sky(&SkyParams {
        sun_radiance: Spectrum::ZERO,
        ..p.clone()
    })
    .unwrap();
    let power = sun_power(&with, &without, 1);
    let exact = 1e9 * p.sun_solid_angle();
    assert!((power / exact - 1.0).abs() < 1e-4, "{power} vs {exact}");
}

#[test]
fn ensure_sky_writes_once_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scenes/assets/sky.exr");
    let p = params(64, 32);
    assert!(ensure_sky(&path, &p).unwrap());
    let bytes = std::fs::read(&path).unwrap();
    let img = read_image(&path, ColorEncoding::Linear).unwrap();
    assert_eq!(img, generate_sky(&p).unwrap());
    let meta = read_exr_channels(&path).unwrap();
    let desc = meta.attribute("facette.sky").unwrap();
    assert!(
        desc.starts_with("64x32 ") && desc.contains("sun_angular_radius=0.02"),
        "{desc}"
    );
    // A second call, even with other parameters, leaves the file alone.
    assert!(!ensure_sky(&path, &params(128, 64)).unwrap());
    assert_eq!(std::fs::read(&path).unwrap(), bytes);
    let leftovers: Vec<_> = std::fs::read_dir(path.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");
    // Invalid parameters are reported with the path.
    let bad = SkyParams {
        sun_angular_radius: -1.0,
        ..p
    };
    let err = ensure_sky(dir.path().join("other.exr"), &bad).unwrap_err();
    assert!(matches!(err, ImageError::Param { .. }), "{err}");
    assert!(
        err.to_string().contains("other.exr") && err.to_string().contains("sun_angular_radius")
    );
    assert!(!dir.path().join("other.exr").exists());
}
