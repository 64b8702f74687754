//! A parameterization of the unit sphere by [0, 1]² that resolves both a narrow lobe around
//! an axis and everything else, so chi-square bins test α = 0.01 lobes and heavy GGX tails
//! alike.
//!
//! Directions are described by s = (1 − cos θ)/2 about the axis (s ∈ [0, 1], uniform in
//! solid angle) and φ = 2π u₂. For a broad lobe (width ≥ 0.14) u₁ = s: the usual equal-area
//! map. For a narrow lobe of angular width w, the first half of u₁ covers the cap
//! θ < θ_c = 10 w with a rational zoom that puts the median of its bins at θ ≈ w, and the
//! second half covers the rest of the sphere uniformly in s:
//!
//! - u₁ < ½: x = 2u₁, s = S k x / (1 − x + k x), S = s(θ_c), k = w²/(S − w²);
//! - u₁ ≥ ½: s = S + (1 − S)(2u₁ − 1).
//!
//! dω = 4π (ds/du₁) du₁ du₂.

use crate::math::{Frame, Vec2, Vec3, PI, TWO_PI};

#[derive(Clone, Copy, Debug)]
pub struct SphereMap {
    frame: Frame,
    /// `None`: the equal-area map; `Some((S, k))`: the two-part zoom.
    zoom: Option<(f64, f64)>,
    width: f64,
}

impl SphereMap {
    /// Map centred on `axis` for a lobe of angular width `width` (radians).
    pub fn new(axis: Vec3, width: f64) -> Self {
        let frame = Frame::from_normal(axis.normalize());
        let w = width.max(1e-5);
        let theta_c = 10.0 * w;
        let zoom = if theta_c >= 1.4 {
            None
        } else {
            let s_cap = 0.5 * (1.0 - theta_c.cos());
            let w2 = (0.5 * (1.0 - w.cos())).min(0.5 * s_cap);
            Some((s_cap, w2 / (s_cap - w2)))
        };
        SphereMap {
            frame,
            zoom,
            width: w,
        }
    }

    /// The uniform (equal-area) map about +z.
    pub fn standard() -> Self {
        Self::new(Vec3::Z, 1.0)
    }

    pub fn width(&self) -> f64 {
        self.width
    }

    #[inline]
    fn s_of_u(&self, u1: f64) -> f64 {
        match self.zoom {
            None => u1,
            Some((sc, k)) => {
                if u1 < 0.5 {
                    let x = 2.0 * u1;
                    sc * k * x / (1.0 - x + k * x)
                } else {
                    sc + (1.0 - sc) * (2.0 * u1 - 1.0)
                }
            }
        }
    }

    #[inline]
    fn u_of_s(&self, s: f64) -> f64 {
        match self.zoom {
            None => s,
            Some((sc, k)) => {
                if s < sc {
                    let y = s / sc;
                    0.5 * y / (y + k * (1.0 - y))
                } else {
                    0.5 + 0.5 * (s - sc) / (1.0 - sc)
                }
            }
        }
    }

    pub fn to_direction(&self, u: Vec2) -> Vec3 {
        let s = self.s_of_u(u.x).clamp(0.0, 1.0);
        let z = 1.0 - 2.0 * s;
        // sin θ = 2 √(s(1−s)), exact also near the poles.
        let r = 2.0 * (s * (1.0 - s)).max(0.0).sqrt();
        let (sp, cp) = (TWO_PI * u.y).sin_cos();
        self.frame.to_world(Vec3::new(r * cp, r * sp, z))
    }

    pub fn to_unit(&self, d: Vec3) -> Vec2 {
        let l = self.frame.to_local(d);
        // s = sin²(θ/2), computed without cancellation near the axis.
        let rxy2 = l.x * l.x + l.y * l.y;
        let s = if l.z > 0.0 {
            0.25 * rxy2 / (0.5 * (1.0 + l.z)).max(1e-300)
        } else {
            0.5 * (1.0 - l.z)
        };
        let mut phi = l.y.atan2(l.x);
        if phi < 0.0 {
            phi += TWO_PI;
        }
        Vec2::new(
            self.u_of_s(s.clamp(0.0, 1.0)).clamp(0.0, 1.0),
            (phi / TWO_PI).clamp(0.0, 1.0),
        )
    }

    /// dω / (du₁ du₂).
    pub fn jacobian(&self, u: Vec2) -> f64 {
        let ds = match self.zoom {
            None => 1.0,
            Some((sc, k)) => {
                if u.x < 0.5 {
                    let x = 2.0 * u.x;
                    let d = 1.0 - x + k * x;
                    2.0 * sc * k / (d * d)
                } else {
                    2.0 * (1.0 - sc)
                }
            }
        };
        4.0 * PI * ds
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roundtrip_and_total_solid_angle() {
        for &(axis, w) in &[
            (Vec3::Z, 1.0),
            (Vec3::new(0.3, -0.2, 0.9).normalize(), 0.005),
            (-Vec3::X, 0.03),
        ] {
            let m = SphereMap::new(axis, w);
            for k in 0..100 {
                let u = Vec2::new((k as f64 + 0.5) / 100.0, ((k * 37) % 100) as f64 / 100.0);
                let d = m.to_direction(u);
                assert!((d.length() - 1.0).abs() < 1e-12);
                let back = m.to_unit(d);
                let dv = (back.y - u.y).abs();
                let dv = dv.min(1.0 - dv); // u₂ is periodic
                assert!(
                    (back.x - u.x).abs() < 1e-9 && dv < 1e-9,
                    "{u:?} -> {back:?}"
                );
            }
            let total =
                crate::math::quadrature::integrate_adaptive(0.0, 0.5, 1e-13, 1e-13, |x| {
                    m.jacobian(Vec2::new(x, 0.0))
                }) + crate::math::quadrature::integrate_adaptive(0.5, 1.0, 1e-13, 1e-13, |x| {
                    m.jacobian(Vec2::new(x, 0.0))
                });
            assert!((total - 4.0 * PI).abs() < 1e-9, "{total}");
        }
    }
}
