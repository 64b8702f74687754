//! Textures as materials use them: a value per surface point, looked up by uv and filtered
//! over the pixel's uv footprint `[du/dx, dv/dx, du/dy, dv/dy]` (from ray differentials).
//!
//! - `Constant`: one value.
//! - `Image`: a [`MipMap`] read at `uv · uv_scale + uv_offset` (componentwise), trilinearly
//!   filtered; the footprint is scaled with the coordinates.
//! - `Checker`: squares alternating between `a` (where ⌊u·scale⌋ + ⌊v·scale⌋ is even) and
//!   `b`, `scale` checks per unit of uv. It is box-filtered in closed form over the axis-
//!   aligned bounding box of the footprint — the integral of the checker's square wave,
//!   after pbrt-v3's anti-aliased `Checkerboard2DTexture` — so it fades to (a + b)/2 when a
//!   pixel covers many checks instead of aliasing.
//!
//! Scalar parameters (roughness maps) read the channel average: [`Texture::eval_scalar`].

use std::sync::Arc;

use facette_bsdf::{ParamError, ParamResult, Spectrum};
use glam::DVec2;

use super::mipmap::MipMap;

#[derive(Clone, Debug)]
pub enum Texture {
    Constant(Spectrum),
    Image {
        mipmap: Arc<MipMap>,
        uv_scale: DVec2,
        uv_offset: DVec2,
    },
    Checker {
        a: Spectrum,
        b: Spectrum,
        /// Checks per unit of uv.
        scale: f64,
    },
}

impl Texture {
    /// An image texture with identity uv mapping.
    pub fn image(mipmap: Arc<MipMap>) -> Self {
        Texture::Image {
            mipmap,
            uv_scale: DVec2::ONE,
            uv_offset: DVec2::ZERO,
        }
    }

    /// A checker texture; `scale` must be finite and positive, `a` and `b` finite.
    pub fn checker(a: Spectrum, b: Spectrum, scale: f64) -> ParamResult<Self> {
        if !(scale > 0.0) || !scale.is_finite() {
            return Err(ParamError::OutOfRange {
                name: "scale".into(),
                value: scale,
                expected: "a finite number > 0 (checks per unit of uv)".into(),
            });
        }
        for (name, s) in [("a", a), ("b", b)] {
            if !s.is_finite() {
                return Err(ParamError::NotFinite {
                    name: name.into(),
                    value: s.max_component(),
                });
            }
        }
        Ok(Texture::Checker { a, b, scale })
    }

    /// The filtered value at `uv` for the footprint `derivs = [du/dx, dv/dx, du/dy, dv/dy]`
    /// (all zero for an unfiltered point lookup).
    pub fn eval(&self, uv: DVec2, derivs: [f64; 4]) -> Spectrum {
        match self {
            Texture::Constant(c) => *c,
            Texture::Image {
                mipmap,
                uv_scale,
                uv_offset,
            } => {
                let st = uv * *uv_scale + *uv_offset;
                let d = [
                    derivs[0] * uv_scale.x,
                    derivs[1] * uv_scale.y,
                    derivs[2] * uv_scale.x,
                    derivs[3] * uv_scale.y,
                ];
                mipmap.lookup(st, d)
            }
            Texture::Checker { a, b, scale } => {
                let f = checker_odd_fraction(uv * *scale, derivs.map(|d| d * scale));
                *a * (1.0 - f) + *b * f
            }
        }
    }

    /// [`Texture::eval`] reduced to one number: the channel average.
    pub fn eval_scalar(&self, uv: DVec2, derivs: [f64; 4]) -> f64 {
        self.eval(uv, derivs).average()
    }

    /// The mean over one period of uv (the whole image, or one check pair) — e.g. for an
    /// albedo estimate.
    pub fn average(&self) -> Spectrum {
        match self {
            Texture::Constant(c) => *c,
            Texture::Image { mipmap, .. } => mipmap.average(),
            Texture::Checker { a, b, .. } => (*a + *b) * 0.5,
        }
    }
}

/// ∫₀ˣ p, where p(t) = ⌊t⌋ mod 2 is the checker's square wave along one axis.
#[inline]
fn square_wave_integral(x: f64) -> f64 {
    let half = (x * 0.5).floor();
    half + (x - 2.0 * half - 1.0).max(0.0)
}

/// Average of the square wave over [x − r, x + r] (its point value when r is negligible).
#[inline]
fn square_wave_average(x: f64, r: f64) -> f64 {
    if !(r > 1e-9) || !r.is_finite() {
        if r.is_infinite() {
            return 0.5;
        }
        return x.floor().rem_euclid(2.0);
    }
    (square_wave_integral(x + r) - square_wave_integral(x - r)) / (2.0 * r)
}

/// Fraction of the footprint's bounding box (in check units) covered by odd checks. The
/// box of the pixel parallelogram spanned by ±½ of each derivative vector has half-widths
/// ½(|du/dx| + |du/dy|) and ½(|dv/dx| + |dv/dy|); over a box the two axes are independent,
/// and a point is odd when exactly one coordinate is.
fn checker_odd_fraction(st: DVec2, d: [f64; 4]) -> f64 {
    if !st.is_finite() {
        return 0.0;
    }
    let clean = |v: f64| if v.is_nan() { 0.0 } else { v.abs() };
    let ru = 0.5 * (clean(d[0]) + clean(d[2]));
    let rv = 0.5 * (clean(d[1]) + clean(d[3]));
    let pu = square_wave_average(st.x, ru);
    let pv = square_wave_average(st.y, rv);
    (pu * (1.0 - pv) + pv * (1.0 - pu)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::mipmap::WrapMode;
    use crate::image::rgb_image::RgbImage;

    const A: Spectrum = Spectrum::rgb(1.0, 0.0, 0.0);
    const B: Spectrum = Spectrum::rgb(0.0, 0.0, 1.0);

    #[test]
    fn checker_points_alternate() {
        let t = Texture::checker(A, B, 4.0).unwrap();
        let at = |u, v| t.eval(DVec2::new(u, v), [0.0; 4]);
        assert_eq!(at(0.1, 0.1), A);
        assert_eq!(at(0.3, 0.1), B);
        assert_eq!(at(0.3, 0.3), A);
        assert_eq!(at(-0.1, 0.1), B);
        assert_eq!(t.eval_scalar(DVec2::new(0.3, 0.1), [0.0; 4]), 1.0 / 3.0);
        assert!(Texture::checker(A, B, 0.0).is_err());
        assert!(Texture::checker(A, Spectrum::splat(f64::NAN), 1.0).is_err());
    }

    #[test]
    fn checker_filter_averages_wide_footprints_and_is_exact_on_halves() {
        let t = Texture::checker(A, B, 4.0).unwrap();
        let mid = (A + B) * 0.5;
        // A footprint covering many checks reads the mean, wherever it lands.
        for k in 0..20 {
            let uv = DVec2::new(k as f64 * 0.173, k as f64 * 0.071);
            let v = t.eval(uv, [3.0, 0.0, 0.0, 3.0]);
            assert!((v - mid).max_component().abs() < 0.02, "{v:?}");
        }
        // A box spanning exactly one check along u, centred on a boundary: half and half.
        let v = t.eval(DVec2::new(0.25, 0.1), [0.25, 0.0, 0.0, 0.0]);
        assert!((v - mid).max_component().abs() < 1e-12, "{v:?}");
        // A box inside one check reads that check.
        let v = t.eval(DVec2::new(0.125, 0.125), [0.1, 0.0, 0.0, 0.1]);
        assert_eq!(v, A);
        // Integral by brute force over a box straddling a corner.
        let (uv, d) = (DVec2::new(0.27, 0.21), [0.15, 0.0, 0.0, 0.08]);
        let n = 400;
        let mut s = Spectrum::ZERO;
        for i in 0..n {
            for j in 0..n {
                let p = uv
                    + DVec2::new(
                        (i as f64 + 0.5) / n as f64 - 0.5,
                        (j as f64 + 0.5) / n as f64 - 0.5,
                    ) * DVec2::new(d[0], d[3]);
                s += t.eval(p, [0.0; 4]);
            }
        }
        let brute = s / (n * n) as f64;
        let closed = t.eval(uv, d);
        assert!(
            (brute - closed).max_component().abs() < 5e-3,
            "{brute:?} {closed:?}"
        );
        assert!(t.eval(uv, [f64::NAN, f64::INFINITY, 0.0, 0.0]).is_finite());
        assert!(t.eval(DVec2::new(f64::NAN, 0.0), [0.0; 4]).is_finite());
    }

    #[test]
    fn image_texture_applies_scale_and_offset() {
        let img = RgbImage::from_fn(4, 4, |x, y| [x as f32, y as f32, 0.0]).unwrap();
        let m = Arc::new(MipMap::new(img, WrapMode::Repeat));
        let t = Texture::Image {
            mipmap: m.clone(),
            uv_scale: DVec2::new(2.0, 1.0),
            uv_offset: DVec2::new(0.125, 0.0),
        };
        // uv (0.25, 0.375) → st (0.625, 0.375): texel (2, 1) centre.
        let v = t.eval(DVec2::new(0.25, 0.375), [0.0; 4]);
        assert_eq!(v, Spectrum::rgb(2.0, 1.0, 0.0));
        // The footprint scales too: du/dx = ½ texel in uv is 1 texel after ×2 → level 0;
        // 2 texels in uv → 4 after scaling → level 2 = the 1×1 mean.
        let wide = t.eval(DVec2::new(0.25, 0.375), [0.5, 0.0, 0.0, 0.0]);
        assert_eq!(wide, m.average());
        assert_eq!(Texture::image(m.clone()).average(), m.average());
        assert_eq!(
            Texture::Constant(Spectrum::splat(0.3)).eval_scalar(DVec2::ZERO, [0.0; 4]),
            0.3
        );
    }
}
