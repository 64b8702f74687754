//! A procedural sky, generated as a latitude-longitude image in the environment map's
//! convention (Mitsuba 3's `envmap`: +y is the zenith, the top row): a gradient from the
//! zenith colour down to the horizon colour, a ground colour below the horizon, and a sun
//! disk with a soft edge. Scenes reference it as an ordinary EXR (`scenes/assets/sky.exr`),
//! written on first use by [`ensure_sky`].
//!
//! | parameter            | meaning                                                   | default          |
//! |----------------------|-----------------------------------------------------------|------------------|
//! | `width`, `height`    | image size (2:1 for square texels)                        | 1024 × 512       |
//! | `zenith`             | sky radiance straight up                                  | (0.20, 0.38, 0.80) |
//! | `horizon`            | sky radiance at the horizon                               | (0.75, 0.82, 0.92) |
//! | `ground`             | radiance below the horizon                                | (0.18, 0.16, 0.14) |
//! | `gradient_exponent`  | L = horizon + (zenith − horizon)·(sin elevation)^exponent | 0.5              |
//! | `sun_direction`      | towards the sun, in the sky's frame (+y up); normalized   | (0.4, 0.6, −0.7) |
//! | `sun_angular_radius` | radians, in (0, 0.5]                                      | 0.0175 (1°)      |
//! | `sun_softness`       | fraction of the radius over which the edge fades, [0, 1]  | 0.2              |
//! | `sun_radiance`       | radiance of the disk's core, added to the sky             | 3000 (≈ 2.9 irradiance) |
//!
//! **Resolution independence.** Each pixel holds the *average* radiance over its solid
//! angle, not a point value: the gradient is averaged per row (it depends on elevation
//! only), and the sun's coverage of the pixels near it is supersampled and then scaled so
//! that the image's total sun power, Σ coverage·Ω, equals the disk's exact power
//! 2π ∫ w(γ) sin γ dγ. A 64×32 sky and a 4096×2048 sky thus light a scene equally, and a
//! sun smaller than the sampling grid is put whole into the pixel containing its centre.
//! Generation is deterministic (fixed sample positions, sums in a fixed order).

use std::f64::consts::PI;
use std::path::Path;

use facette_bsdf::math::fmt_num;
use facette_bsdf::{ParamError, ParamResult, Spectrum};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::environment::{direction_to_uv, uv_to_direction};
use super::error::ImageError;
use super::exr_file::write_exr_rgb;
use super::rgb_image::{from_spectrum, RgbImage};
use facette_bsdf::limits;
use facette_bsdf::storage::atomic_file::Existing;

/// Parameters of the procedural sky (see the module table).
#[derive(Clone, Debug, PartialEq)]
pub struct SkyParams {
    pub width: usize,
    pub height: usize,
    pub zenith: Spectrum,
    pub horizon: Spectrum,
    pub ground: Spectrum,
    pub gradient_exponent: f64,
    pub sun_direction: DVec3,
    pub sun_angular_radius: f64,
    pub sun_softness: f64,
    pub sun_radiance: Spectrum,
}

impl Default for SkyParams {
    fn default() -> Self {
        SkyParams {
            width: 1024,
            height: 512,
            zenith: Spectrum::rgb(0.20, 0.38, 0.80),
            horizon: Spectrum::rgb(0.75, 0.82, 0.92),
            ground: Spectrum::rgb(0.18, 0.16, 0.14),
            gradient_exponent: 0.5,
            sun_direction: DVec3::new(0.4, 0.6, -0.7),
            sun_angular_radius: 1f64.to_radians(),
            sun_softness: 0.2,
            sun_radiance: Spectrum::splat(3000.0),
        }
    }
}

/// A sky colour is a radiance: finite, ≥ 0 and within the radiance bound of every light
/// (`limits::MAX_RADIANCE`), so that film sums cannot overflow.
fn check_colour(name: &str, s: Spectrum) -> ParamResult<()> {
    for c in 0..3 {
        if limits::check_radiance(s[c]).is_err() {
            return Err(ParamError::OutOfRange {
                name: name.into(),
                value: s[c],
                expected: format!(
                    "a radiance in 0…{:e} (larger values overflow the film's sums; scale the exposure instead)",
                    limits::MAX_RADIANCE
                ),
            });
        }
    }
    Ok(())
}

fn check_range(name: &str, v: f64, lo: f64, hi: f64, expected: &str) -> ParamResult<()> {
    if !(v >= lo && v <= hi) {
        return Err(ParamError::OutOfRange {
            name: name.into(),
            value: v,
            expected: expected.into(),
        });
    }
    Ok(())
}

impl SkyParams {
    pub fn validate(&self) -> ParamResult<()> {
        if self.width == 0 || self.height == 0 {
            return Err(ParamError::Invalid(format!(
                "sky resolution {}×{} must be at least 1×1",
                self.width, self.height
            )));
        }
        limits::IMAGE_PIXELS
            .check_product(&[self.width as u64, self.height as u64])
            .map_err(|e| ParamError::Invalid(format!("sky resolution: {e}")))?;
        check_colour("zenith", self.zenith)?;
        check_colour("horizon", self.horizon)?;
        check_colour("ground", self.ground)?;
        check_colour("sun_radiance", self.sun_radiance)?;
        check_range(
            "gradient_exponent",
            self.gradient_exponent,
            1e-3,
            1e3,
            "a number in [0.001, 1000]",
        )?;
        check_range(
            "sun_angular_radius",
            self.sun_angular_radius,
            1e-6,
            0.5,
            "radians in [1e-6, 0.5]",
        )?;
        check_range(
            "sun_softness",
            self.sun_softness,
            0.0,
            1.0,
            "a fraction in [0, 1]",
        )?;
        let len = self.sun_direction.length();
        if !(len > 1e-12) || !len.is_finite() {
            return Err(ParamError::Invalid(format!(
                "sun_direction must be a non-zero finite vector, got {}",
                self.sun_direction
            )));
        }
        Ok(())
    }

    /// The unit direction towards the sun.
    pub fn sun_unit(&self) -> DVec3 {
        self.sun_direction.normalize()
    }

    /// Weight of the sun disk (1 in the core, fading to 0 at the rim) at angular distance
    /// `gamma` from its centre: a smoothstep over the outer `sun_softness` of the radius.
    pub fn sun_profile(&self, gamma: f64) -> f64 {
        let r = self.sun_angular_radius;
        let r_in = r * (1.0 - self.sun_softness);
        if gamma <= r_in {
            1.0
        } else if gamma >= r {
            0.0
        } else {
            let t = (r - gamma) / (r - r_in);
            t * t * (3.0 - 2.0 * t)
        }
    }

    /// ∫ w(γ) dω over the sphere, the disk's effective solid angle (midpoint rule on
    /// 4096 rings; exact to ~1e-7 relative).
    pub fn sun_solid_angle(&self) -> f64 {
        let n = 4096;
        let r = self.sun_angular_radius;
        let h = r / n as f64;
        (0..n)
            .map(|k| {
                let g = (k as f64 + 0.5) * h;
                self.sun_profile(g) * g.sin()
            })
            .sum::<f64>()
            * h
            * 2.0
            * PI
    }

    /// Sky radiance (without the sun) along a unit direction of the sky's frame.
    pub fn sky_radiance(&self, d: DVec3) -> Spectrum {
        if d.y < 0.0 {
            self.ground
        } else {
            let t = d.y.min(1.0).powf(self.gradient_exponent);
            self.horizon * (1.0 - t) + self.zenith * t
        }
    }

    /// A one-line description stored in the EXR header (provenance of a cached sky).
    pub fn describe(&self) -> String {
        let s = |v: Spectrum| format!("({}, {}, {})", fmt_num(v[0]), fmt_num(v[1]), fmt_num(v[2]));
        let d = self.sun_direction;
        format!(
            "{}x{} zenith={} horizon={} ground={} gradient_exponent={} sun_direction=({}, {}, \
             {}) sun_angular_radius={} sun_softness={} sun_radiance={}",
            self.width,
            self.height,
            s(self.zenith),
            s(self.horizon),
            s(self.ground),
            fmt_num(self.gradient_exponent),
            fmt_num(d.x),
            fmt_num(d.y),
            fmt_num(d.z),
            fmt_num(self.sun_angular_radius),
            fmt_num(self.sun_softness),
            s(self.sun_radiance)
        )
    }
}

/// Generates the sky image (see the module documentation).
pub fn generate_sky(params: &SkyParams) -> ParamResult<RgbImage> {
    params.validate()?;
    let (w, h) = (params.width, params.height);
    let cos_edge = |y: usize| (PI * y as f64 / h as f64).cos();
    let pixel_omega = |y: usize| 2.0 * PI / w as f64 * (cos_edge(y) - cos_edge(y + 1)).max(0.0);

    // Gradient: the row's mean over its solid angle (uniform in cos θ; the horizon, when
    // inside a row, splits it exactly).
    const ROW_SAMPLES: usize = 64;
    let rows: Vec<Spectrum> = (0..h)
        .map(|y| {
            let (c0, c1) = (cos_edge(y), cos_edge(y + 1));
            let mut s = Spectrum::ZERO;
            for k in 0..ROW_SAMPLES {
                let c = c0 + (c1 - c0) * (k as f64 + 0.5) / ROW_SAMPLES as f64;
                s += params.sky_radiance(DVec3::new((1.0 - c * c).max(0.0).sqrt(), c, 0.0));
            }
            s / ROW_SAMPLES as f64
        })
        .collect();

    // Sun coverage of the pixels that can touch the disk.
    let sun = params.sun_unit();
    let r = params.sun_angular_radius;
    let pixel_angle = (PI / h as f64).max(2.0 * PI / w as f64);
    let reach = r + pixel_angle; // ≥ centre-to-corner distance of any pixel
    let n = ((8.0 * pixel_angle / r).ceil() as usize).clamp(8, 64);
    let coverage: Vec<Vec<(usize, f64)>> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut out = Vec::new();
            let (c0, c1) = (cos_edge(y), cos_edge(y + 1));
            // Skip rows entirely out of reach (θ range vs the sun's θ).
            let theta_sun = sun.y.clamp(-1.0, 1.0).acos();
            let (t0, t1) = (PI * y as f64 / h as f64, PI * (y + 1) as f64 / h as f64);
            if t1 < theta_sun - reach || t0 > theta_sun + reach {
                return out;
            }
            for x in 0..w {
                let centre = uv_to_direction(DVec2::new(
                    (x as f64 + 0.5) / w as f64,
                    (y as f64 + 0.5) / h as f64,
                ));
                if centre.dot(sun).clamp(-1.0, 1.0).acos() > reach {
                    continue;
                }
                let mut s = 0.0;
                for j in 0..n {
                    let c = c0 + (c1 - c0) * (j as f64 + 0.5) / n as f64;
                    let st = (1.0 - c * c).max(0.0).sqrt();
                    for i in 0..n {
                        let phi = 2.0 * PI * (x as f64 + (i as f64 + 0.5) / n as f64) / w as f64;
                        let d = DVec3::new(phi.sin() * st, c, -phi.cos() * st);
                        s += params.sun_profile(d.dot(sun).clamp(-1.0, 1.0).acos());
                    }
                }
                if s > 0.0 {
                    out.push((x, s / (n * n) as f64));
                }
            }
            out
        })
        .collect();
    let mut estimated = 0.0;
    for (y, row) in coverage.iter().enumerate() {
        for &(_, c) in row {
            estimated += c * pixel_omega(y);
        }
    }
    let exact = params.sun_solid_angle();

    let mut data: Vec<[f32; 3]> = Vec::with_capacity(w * h);
    for row in &rows {
        data.extend(std::iter::repeat_n(from_spectrum(*row), w));
    }
    let mut add_sun = |x: usize, y: usize, c: f64| {
        let p = &mut data[y * w + x];
        let v = super::rgb_image::to_spectrum(*p) + params.sun_radiance * c;
        *p = from_spectrum(v);
    };
    if estimated > 0.0 {
        let norm = exact / estimated;
        for (y, row) in coverage.iter().enumerate() {
            for &(x, c) in row {
                add_sun(x, y, c * norm);
            }
        }
    } else {
        let uv = direction_to_uv(sun);
        let x = ((uv.x * w as f64) as usize).min(w - 1);
        let y = ((uv.y * h as f64) as usize).min(h - 1);
        let omega = pixel_omega(y);
        if omega > 0.0 {
            add_sun(x, y, exact / omega);
        }
    }
    Ok(RgbImage::new(w, h, data).expect("sizes match by construction"))
}

/// Writes the sky to `path` as an EXR if no file exists there yet (creating missing parent
/// directories); returns whether it wrote. The write is atomic and never replaces an
/// existing file, even when another process creates it concurrently. The parameters are
/// recorded in the header attribute `facette.sky`.
pub fn ensure_sky(path: impl AsRef<Path>, params: &SkyParams) -> Result<bool, ImageError> {
    let path = path.as_ref();
    params.validate().map_err(|source| ImageError::Param {
        path: path.to_path_buf(),
        source,
    })?;
    if path.exists() {
        return Ok(false);
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| ImageError::Write {
            path: path.to_path_buf(),
            reason: format!("cannot create directory `{}`: {e}", dir.display()),
        })?;
    }
    let image = generate_sky(params).map_err(|source| ImageError::Param {
        path: path.to_path_buf(),
        source,
    })?;
    write_exr_rgb(
        path,
        &image,
        1.0,
        &[("facette.sky", params.describe())],
        Existing::Keep,
    )
}

/// The sky for `params`, cached as an EXR at `path`: read from the file when it holds this
/// very sky (its `facette.sky` header attribute equals the parameters), generated and
/// written (atomically) when the file is missing or holds a facette sky of other
/// parameters. A file at `path` that facette did not generate is never replaced: that is
/// an error.
pub fn load_or_generate_sky(
    path: impl AsRef<Path>,
    params: &SkyParams,
) -> Result<RgbImage, ImageError> {
    let path = path.as_ref();
    params.validate().map_err(|source| ImageError::Param {
        path: path.to_path_buf(),
        source,
    })?;
    let wanted = params.describe();
    if path.exists() {
        let file = super::exr_file::read_exr_channels(path)?;
        match file.attribute("facette.sky") {
            Some(a) if a == wanted => {
                return super::io::read_image(path, super::io::ColorEncoding::Linear)
            }
            Some(_) => {
                let image = generate_sky(params).map_err(|source| ImageError::Param {
                    path: path.to_path_buf(),
                    source,
                })?;
                write_exr_rgb(
                    path,
                    &image,
                    1.0,
                    &[("facette.sky", wanted)],
                    Existing::Replace,
                )?;
                return Ok(image);
            }
            None => return Err(ImageError::InvalidData {
                path: path.to_path_buf(),
                reason:
                    "this file is not a sky generated by facette; it is not replaced. Remove it, \
                             or give the sky another `file` name"
                        .into(),
            }),
        }
    }
    ensure_sky(path, params)?;
    generate_sky(params).map_err(|source| ImageError::Param {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> SkyParams {
        SkyParams {
            width: 128,
            height: 64,
            sun_direction: DVec3::new(0.3, 0.5, 0.8),
            sun_angular_radius: 0.05,
            ..Default::default()
        }
    }

    #[test]
    fn validation_names_the_parameter() {
        let bad = SkyParams {
            sun_softness: 2.0,
            ..small()
        };
        assert!(generate_sky(&bad)
            .unwrap_err()
            .to_string()
            .contains("sun_softness"));
        let bad = SkyParams {
            sun_direction: DVec3::ZERO,
            ..small()
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .contains("sun_direction"));
        let bad = SkyParams {
            width: 0,
            ..small()
        };
        assert!(bad.validate().is_err());
        let bad = SkyParams {
            zenith: Spectrum::splat(f64::NAN),
            ..small()
        };
        assert!(bad.validate().unwrap_err().to_string().contains("zenith"));
    }

    #[test]
    fn profile_and_solid_angle() {
        let p = small();
        assert_eq!(p.sun_profile(0.0), 1.0);
        assert_eq!(p.sun_profile(0.05), 0.0);
        assert!((p.sun_profile(0.045) - 0.5).abs() < 1e-12);
        // A hard disk has solid angle 2π(1 − cos r).
        let hard = SkyParams {
            sun_softness: 0.0,
            ..p
        };
        let exact = 2.0 * PI * (1.0 - 0.05f64.cos());
        assert!((hard.sun_solid_angle() - exact).abs() < 1e-6 * exact);
    }

    #[test]
    fn gradient_runs_from_horizon_to_zenith_and_ground_below() {
        let p = small();
        assert_eq!(p.sky_radiance(DVec3::Y), p.zenith);
        assert_eq!(p.sky_radiance(DVec3::X), p.horizon);
        assert_eq!(
            p.sky_radiance(DVec3::new(0.0, -0.2, 1.0).normalize()),
            p.ground
        );
    }
}
