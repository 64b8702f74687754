//! An environment map: radiance arriving from infinitely far away, stored as a latitude-
//! longitude image, with importance sampling proportional to its luminance.
//!
//! **Mapping** — Mitsuba 3's `envmap` emitter (`src/emitters/envmap.cpp`,
//! `direction_to_uv` / `uv_to_direction`). A world direction d (pointing from the scene
//! towards the sky) is taken to the map's frame, v = to_world⁻¹ d, and
//!
//! u = atan2(v.x, −v.z) / 2π  (wrapped into [0, 1)),   v_tex = acos(v.y) / π,
//!
//! inversely v = (sin φ sin θ, cos θ, −cos φ sin θ) with φ = 2π u, θ = π v_tex. So +y is up
//! (the top row), −z is the centre of the left edge (u = 0), +x is a quarter across
//! (u = ¼), +z the middle (u = ½) and −x three quarters (u = ¾).
//!
//! **Texels** — pixel (x, y) of a W×H image covers u ∈ [x/W, (x+1)/W], θ ∈ [πy/H, π(y+1)/H],
//! centre at ((x+½)/W, (y+½)/H), and radiance is interpolated bilinearly between pixel
//! centres (wrapping in u, clamping at the poles). Mitsuba agrees horizontally (its
//! half-texel shift) but places its first and last rows *on* the poles (θ = πy/(H−1)); we
//! keep the pixel-centre convention of ordinary equirectangular images (pbrt's and most HDRI
//! tools'), so a map is not stretched by half a row.
//!
//! **Sampling** — a piecewise-constant distribution over pixels ([`Distribution2D`]) with
//! weight = L̄ · Ω: L̄ is the pixel's luminance convolved with the tent (⅛, ¾, ⅛) in each
//! axis — exactly the mean of the bilinear reconstruction over the pixel, in uv — and Ω the
//! pixel's solid angle (2π/W)(cos θ₀ − cos θ₁), the exact integral of the "sin θ" factor of
//! the Mitsuba/pbrt weighting. The filtered luminance is positive wherever the bilinear
//! radiance can be, so the sampler covers everything `eval` can return. Within the chosen
//! pixel the direction is uniform in solid angle (uniform in φ and in cos θ), which makes
//! the density piecewise constant on the sphere, pdf = P(pixel)/Ω(pixel) — bounded at the
//! poles, unlike sampling uniformly in uv. `sample` returns `eval` and `pdf` of the very
//! direction it produces.
//!
//! Negative and non-finite pixel values are stored as 0 (radiance is non-negative).

use std::f64::consts::{FRAC_1_PI, PI};

use facette_bsdf::{ParamError, ParamResult, Spectrum};
use glam::{DMat3, DVec2, DVec3};

use super::distribution_2d::Distribution2D;
use super::rgb_image::{to_spectrum, RgbImage};

const TWO_PI: f64 = 2.0 * PI;
const INV_TWO_PI: f64 = 0.5 * FRAC_1_PI;

/// A direction drawn from an environment, its radiance and its density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvSample {
    /// Unit world direction from the scene towards the environment.
    pub direction: DVec3,
    /// `eval(direction)`.
    pub radiance: Spectrum,
    /// `pdf(direction)`, per unit solid angle.
    pub pdf: f64,
}

/// Checks that `to_world` is a rotation (or a rotation with a mirror): the map's frame
/// must stay orthonormal for directions and solid angles to carry over.
pub(crate) fn check_rotation(to_world: DMat3) -> ParamResult<()> {
    let gram = to_world.transpose() * to_world;
    let err = (gram - DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if !(err < 1e-6) {
        return Err(ParamError::Invalid(format!(
            "`to_world` of an environment must be a rotation (orthonormal); its columns \
             deviate from orthonormal by {err:.3e}"
        )));
    }
    Ok(())
}

pub(crate) fn check_scale(scale: f64) -> ParamResult<()> {
    if !(scale >= 0.0) || !scale.is_finite() {
        return Err(ParamError::OutOfRange {
            name: "scale".into(),
            value: scale,
            expected: "a finite number ≥ 0".into(),
        });
    }
    Ok(())
}

/// Mitsuba 3's `direction_to_uv` for a local unit direction, u wrapped into [0, 1).
#[inline]
pub fn direction_to_uv(v: DVec3) -> DVec2 {
    let mut u = v.x.atan2(-v.z) * INV_TWO_PI;
    if u < 0.0 {
        u += 1.0;
    }
    if u >= 1.0 {
        u -= 1.0;
    }
    DVec2::new(u, v.y.clamp(-1.0, 1.0).acos() * FRAC_1_PI)
}

/// Mitsuba 3's `uv_to_direction`: the local unit direction of texture coordinates `uv`.
#[inline]
pub fn uv_to_direction(uv: DVec2) -> DVec3 {
    let (sin_theta, cos_theta) = (PI * uv.y).sin_cos();
    let (sin_phi, cos_phi) = (TWO_PI * uv.x).sin_cos();
    DVec3::new(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta)
}

#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    image: RgbImage,
    to_world: DMat3,
    to_local: DMat3,
    scale: f64,
    distribution: Distribution2D,
    /// cos θ at the `height + 1` row boundaries, from +1 (top) to −1 (bottom).
    cos_edges: Vec<f64>,
    mean: Spectrum,
}

impl EnvironmentMap {
    /// An environment from a latitude-longitude image of radiance, rotated by `to_world`
    /// (a rotation) and multiplied by `scale` (≥ 0).
    pub fn new(image: RgbImage, to_world: DMat3, scale: f64) -> ParamResult<Self> {
        check_rotation(to_world)?;
        check_scale(scale)?;
        let mut image = image;
        for p in image.data_mut() {
            for c in p.iter_mut() {
                if !(c.is_finite() && *c > 0.0) {
                    *c = 0.0;
                }
            }
        }
        let (w, h) = (image.width(), image.height());
        let cos_edges: Vec<f64> = (0..=h)
            .map(|y| {
                if y == 0 {
                    1.0
                } else if y == h {
                    -1.0
                } else {
                    (PI * y as f64 / h as f64).cos()
                }
            })
            .collect();
        let row_solid_angle = |y: usize| TWO_PI / w as f64 * (cos_edges[y] - cos_edges[y + 1]);

        let lum: Vec<f64> = image
            .data()
            .iter()
            .map(|&p| to_spectrum(p).luminance().max(0.0))
            .collect();
        const TENT: [f64; 3] = [0.125, 0.75, 0.125];
        let mut weights = vec![0.0; w * h];
        for y in 0..h {
            let omega = row_solid_angle(y);
            for x in 0..w {
                let mut s = 0.0;
                for (dy, ky) in TENT.iter().enumerate() {
                    let yy = (y + dy).saturating_sub(1).min(h - 1);
                    for (dx, kx) in TENT.iter().enumerate() {
                        let xx = (x + w + dx - 1) % w;
                        s += ky * kx * lum[yy * w + xx];
                    }
                }
                weights[y * w + x] = s * omega;
            }
        }
        let distribution = Distribution2D::new(w, h, &weights);

        let mut sum = Spectrum::ZERO;
        for y in 0..h {
            let omega = row_solid_angle(y);
            let mut row = Spectrum::ZERO;
            for &p in image.row(y) {
                row += to_spectrum(p);
            }
            sum += row * omega;
        }
        let mean = sum * (scale / (4.0 * PI));

        Ok(EnvironmentMap {
            image,
            to_world,
            to_local: to_world.transpose(),
            scale,
            distribution,
            cos_edges,
            mean,
        })
    }

    pub fn width(&self) -> usize {
        self.image.width()
    }

    pub fn height(&self) -> usize {
        self.image.height()
    }

    pub fn to_world(&self) -> DMat3 {
        self.to_world
    }

    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The stored radiance image (unscaled, negative values zeroed).
    pub fn image(&self) -> &RgbImage {
        &self.image
    }

    /// Texture coordinates of a world direction (need not be normalized); `None` for a zero
    /// or non-finite vector.
    #[inline]
    pub fn uv(&self, d: DVec3) -> Option<DVec2> {
        let v = self.to_local * d;
        let len = v.length();
        if !(len > 0.0) || !len.is_finite() {
            return None;
        }
        Some(direction_to_uv(v / len))
    }

    /// The world direction of texture coordinates `uv`.
    #[inline]
    pub fn direction(&self, uv: DVec2) -> DVec3 {
        self.to_world * uv_to_direction(uv)
    }

    #[inline]
    fn pixel(&self, x: usize, y: usize) -> Spectrum {
        to_spectrum(self.image.data()[y * self.image.width() + x])
    }

    /// Radiance arriving along world direction `d` (bilinear, times `scale`); black for a
    /// degenerate `d`.
    pub fn eval(&self, d: DVec3) -> Spectrum {
        self.uv(d).map_or(Spectrum::ZERO, |uv| self.eval_uv(uv))
    }

    /// Radiance at texture coordinates `uv` ∈ [0, 1)² (bilinear, times `scale`).
    fn eval_uv(&self, uv: DVec2) -> Spectrum {
        let (w, h) = (self.image.width(), self.image.height());
        let x = uv.x * w as f64 - 0.5;
        let y = uv.y * h as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let xa = (x0 as i64).rem_euclid(w as i64) as usize;
        let xb = if xa + 1 == w { 0 } else { xa + 1 };
        let ya = (y0 as i64).clamp(0, h as i64 - 1) as usize;
        let yb = (y0 as i64 + 1).clamp(0, h as i64 - 1) as usize;
        let top = self.pixel(xa, ya) * (1.0 - fx) + self.pixel(xb, ya) * fx;
        let bottom = self.pixel(xa, yb) * (1.0 - fx) + self.pixel(xb, yb) * fx;
        (top * (1.0 - fy) + bottom * fy) * self.scale
    }

    /// Density (per unit solid angle) with which [`EnvironmentMap::sample`] produces `d`.
    pub fn pdf(&self, d: DVec3) -> f64 {
        self.uv(d).map_or(0.0, |uv| self.pdf_uv(uv))
    }

    /// The density of the pixel holding `uv`: P(pixel) / Ω(pixel).
    fn pdf_uv(&self, uv: DVec2) -> f64 {
        let (w, h) = (self.image.width(), self.image.height());
        let x = ((uv.x * w as f64) as usize).min(w - 1);
        let y = ((uv.y * h as f64) as usize).min(h - 1);
        let omega = TWO_PI / w as f64 * (self.cos_edges[y] - self.cos_edges[y + 1]);
        let p = self.distribution.pmf(x, y);
        if p > 0.0 && omega > 0.0 {
            p / omega
        } else {
            0.0
        }
    }

    /// Draws a direction with density proportional to the (filtered) luminance. `None`
    /// when the map is black.
    pub fn sample(&self, u: DVec2) -> Option<EnvSample> {
        let (x, y, _, f) = self.distribution.sample(u)?;
        let w = self.image.width() as f64;
        let cos_theta = self.cos_edges[y] + (self.cos_edges[y + 1] - self.cos_edges[y]) * f.y;
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (TWO_PI * (x as f64 + f.x) / w).sin_cos();
        let local = DVec3::new(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta);
        let direction = (self.to_world * local).normalize();
        // Re-derive uv from the direction, so that the density and radiance equal
        // `pdf(direction)` and `eval(direction)` to the bit, even when rounding puts the
        // direction on a neighbouring pixel's edge.
        let uv = self.uv(direction)?;
        let pdf = self.pdf_uv(uv);
        if !(pdf > 0.0) {
            return None;
        }
        Some(EnvSample {
            direction,
            radiance: self.eval_uv(uv),
            pdf,
        })
    }

    /// Mean radiance over the sphere, (1/4π) ∫ L dω, from the pixel values weighted by
    /// their solid angle (times `scale`).
    pub fn mean_radiance(&self) -> Spectrum {
        self.mean
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec2, b: DVec2) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn uv_convention_is_mitsubas() {
        assert!(close(direction_to_uv(-DVec3::Z), DVec2::new(0.0, 0.5)));
        assert!(close(direction_to_uv(DVec3::X), DVec2::new(0.25, 0.5)));
        assert!(close(direction_to_uv(DVec3::Z), DVec2::new(0.5, 0.5)));
        assert!(close(direction_to_uv(-DVec3::X), DVec2::new(0.75, 0.5)));
        assert_eq!(direction_to_uv(DVec3::Y).y, 0.0);
        assert_eq!(direction_to_uv(-DVec3::Y).y, 1.0);
        // Round trips, including the u wrap.
        for k in 0..100 {
            let uv = DVec2::new(
                (k as f64 * 0.618).fract(),
                (k as f64 * 0.377).fract() * 0.98 + 0.01,
            );
            let back = direction_to_uv(uv_to_direction(uv));
            let du = (back.x - uv.x).abs();
            assert!(
                du.min(1.0 - du) < 1e-12 && (back.y - uv.y).abs() < 1e-12,
                "{uv} {back}"
            );
        }
    }

    #[test]
    fn parameters_are_validated() {
        let img = RgbImage::filled(4, 2, [1.0; 3]).unwrap();
        assert!(
            EnvironmentMap::new(img.clone(), DMat3::from_diagonal(DVec3::splat(2.0)), 1.0).is_err()
        );
        assert!(EnvironmentMap::new(img.clone(), DMat3::IDENTITY, -1.0).is_err());
        assert!(EnvironmentMap::new(img.clone(), DMat3::IDENTITY, f64::NAN).is_err());
        assert!(EnvironmentMap::new(img, DMat3::from_rotation_y(0.3), 1.0).is_ok());
    }

    #[test]
    fn top_row_is_up_and_rotation_applies() {
        // Top half red, bottom half blue.
        let img = RgbImage::from_fn(8, 4, |_, y| {
            if y < 2 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .unwrap();
        let env = EnvironmentMap::new(img.clone(), DMat3::IDENTITY, 2.0).unwrap();
        assert_eq!(env.eval(DVec3::Y), Spectrum::rgb(2.0, 0.0, 0.0));
        assert_eq!(env.eval(-DVec3::Y * 3.0), Spectrum::rgb(0.0, 0.0, 2.0));
        assert_eq!(env.eval(DVec3::ZERO), Spectrum::ZERO);
        // Rotating the map by 90° about x sends its up (+y) to world +z.
        let rot = DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let env = EnvironmentMap::new(img, rot, 1.0).unwrap();
        assert_eq!(env.eval(DVec3::Z), Spectrum::rgb(1.0, 0.0, 0.0));
        assert!((env.direction(DVec2::ZERO) - DVec3::Z).length() < 1e-12);
        assert!(
            (env.mean_radiance() - Spectrum::rgb(0.5, 0.0, 0.5))
                .max_component()
                .abs()
                < 1e-12
        );
    }

    #[test]
    fn a_single_bright_pixel_is_where_the_samples_go() {
        let mut img = RgbImage::filled(16, 8, [0.0; 3]).unwrap();
        img.set(5, 2, [100.0, 100.0, 100.0]);
        let env = EnvironmentMap::new(img, DMat3::IDENTITY, 1.0).unwrap();
        let centre = uv_to_direction(DVec2::new(5.5 / 16.0, 2.5 / 8.0));
        assert!(
            (env.eval(centre) - Spectrum::splat(100.0))
                .max_component()
                .abs()
                < 1e-9
        );
        for k in 0..64 {
            let u = DVec2::new(
                (k as f64 * 0.618_034).fract(),
                (k as f64 * 0.414_214).fract(),
            );
            let s = env.sample(u).unwrap();
            assert_eq!(s.radiance, env.eval(s.direction));
            assert_eq!(s.pdf, env.pdf(s.direction));
            // Within the 3×3 neighbourhood the bilinear radiance can reach.
            let uv = env.uv(s.direction).unwrap();
            let (px, py) = ((uv.x * 16.0) as i64, (uv.y * 8.0) as i64);
            assert!((px - 5).abs() <= 1 && (py - 2).abs() <= 1, "{px} {py}");
        }
        // Black maps cannot be sampled.
        let black = EnvironmentMap::new(
            RgbImage::filled(4, 2, [0.0; 3]).unwrap(),
            DMat3::IDENTITY,
            1.0,
        )
        .unwrap();
        assert!(black.sample(DVec2::splat(0.5)).is_none());
        assert_eq!(black.pdf(DVec3::Y), 0.0);
    }

    #[test]
    fn non_finite_and_negative_pixels_are_zero() {
        let img = RgbImage::new(2, 1, vec![[f32::NAN, -1.0, f32::INFINITY], [1.0; 3]]).unwrap();
        let env = EnvironmentMap::new(img, DMat3::IDENTITY, 1.0).unwrap();
        assert_eq!(env.image().get(0, 0), [0.0; 3]);
        for k in 0..50 {
            let d = uv_to_direction(DVec2::new(k as f64 / 50.0, 0.3));
            assert!(env.eval(d).is_finite() && env.pdf(d).is_finite());
        }
    }
}
