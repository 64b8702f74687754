//! Sampling a shape as seen from a reference point: the common part of every shape's
//! solid-angle sampler (area lights' next-event estimation).
//!
//! A light sampled uniformly by area wastes samples on its far side and carries the
//! `r² / cos` conversion's variance; sampled by the solid angle it subtends, every sample
//! is a direction that sees it with a density that varies little. Each shape picks the
//! best sampler it has: the cone of a sphere, the spherical rectangle (Ureña et al. 2013),
//! the spherical triangle (Arvo 1995); area sampling, converted to solid angle, where the
//! spherical constructions lose precision — a subtended solid angle below
//! [`MIN_SPHERICAL_SOLID_ANGLE`] (the shape is far: area sampling is then nearly uniform in
//! solid angle anyway) or above [`MAX_SPHERICAL_SOLID_ANGLE`] (the point almost touches
//! the shape) — the bounds pbrt-v4 uses for the same choice. The choice depends on the
//! reference point only, so `sample` and `pdf` always agree on it.

use super::Vec3;
use facette_bsdf::lanes::{LVec3, Mask, Real};

/// Below this subtended solid angle (sr), spherical sampling gives way to area sampling.
pub const MIN_SPHERICAL_SOLID_ANGLE: f64 = 3e-4;
/// Above this subtended solid angle (sr, just under 2π), spherical sampling gives way to
/// area sampling.
pub const MAX_SPHERICAL_SOLID_ANGLE: f64 = 6.22;

/// Whether a subtended solid angle is in the range where spherical sampling is used.
#[inline]
pub fn use_spherical_sampling(solid_angle: f64) -> bool {
    (MIN_SPHERICAL_SOLID_ANGLE..=MAX_SPHERICAL_SOLID_ANGLE).contains(&solid_angle)
}

/// A point of a shape sampled from a reference point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeSample {
    /// The point on the shape.
    pub point: Vec3,
    /// The geometric normal a ray hitting `point` would report.
    pub normal: Vec3,
    /// Density of the direction from the reference point to `point`, per unit solid angle.
    pub pdf: f64,
}

/// Shape samples from reference points in lanes ([`Shape::sample_from_lanes`](super::shape::Shape::sample_from_lanes)):
/// the render kernel's next-event estimation draws eight at once.
#[derive(Clone, Copy)]
pub struct ShapeSampleLanes<R: Real> {
    /// The lanes that hold a sample; the others are drawn lane by lane in f64
    /// ([`ShapeSample`]), where the shape's sampler may still find one (a sphere's by area
    /// from inside it).
    pub drawn: R::Mask,
    /// The point on the shape.
    pub point: LVec3<R>,
    /// The geometric normal a ray hitting `point` would report.
    pub normal: LVec3<R>,
    /// Density of the direction from the reference point to `point`, per unit solid angle.
    pub pdf: R,
}

impl<R: Real> ShapeSampleLanes<R> {
    /// No lane drawn (a shape without a lane sampler).
    pub fn none() -> Self {
        ShapeSampleLanes {
            drawn: R::Mask::splat(false),
            point: LVec3::zero(),
            normal: LVec3::zero(),
            pdf: R::zero(),
        }
    }

    /// Lane `i` as a [`ShapeSample`], where drawn.
    pub fn lane(&self, i: usize) -> Option<ShapeSample> {
        self.drawn.lane(i).then(|| ShapeSample {
            point: self.point.lane(i),
            normal: self.normal.lane(i),
            pdf: self.pdf.lane(i),
        })
    }
}

/// Converts a density per unit area at `q` (normal `nq`) into a density per unit solid
/// angle of the direction from `p`: `pdf_A · |p − q|² / |cos θ_q|`. Zero where the
/// conversion is undefined (`p` on the shape, a grazing direction, a zero density).
#[inline]
pub fn area_to_solid_angle(pdf_area: f64, p: Vec3, q: Vec3, nq: Vec3) -> f64 {
    area_to_solid_angle_lanes::<f64>(pdf_area, p.into(), q.into(), nq.into())
}

/// [`area_to_solid_angle`] in lanes, its one source.
#[inline(always)]
pub fn area_to_solid_angle_lanes<R: Real>(
    pdf_area: f64,
    p: LVec3<R>,
    q: LVec3<R>,
    nq: LVec3<R>,
) -> R {
    let d = q - p;
    let dist2 = d.length_squared();
    let cos = (nq.dot(d) / dist2.sqrt()).abs();
    let pdf = R::splat(pdf_area) * dist2 / cos;
    let valid = dist2.gt(R::zero()) & cos.gt(R::splat(1e-12)) & pdf.is_finite();
    if pdf_area > 0.0 {
        R::masked(valid, pdf)
    } else {
        R::zero()
    }
}

/// An area sample `(point, normal, pdf per unit area)` as a solid-angle [`ShapeSample`]
/// from `p`; `None` where the conversion is undefined.
#[inline]
pub fn area_sample_from(p: Vec3, area_sample: (Vec3, Vec3, f64)) -> Option<ShapeSample> {
    let (point, normal, pdf_area) = area_sample;
    let pdf = area_to_solid_angle(pdf_area, p, point, normal);
    (pdf > 0.0).then_some(ShapeSample { point, normal, pdf })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_density_converts_by_distance_squared_over_cosine() {
        let p = Vec3::new(0.0, 0.0, 2.0);
        let q = Vec3::ZERO;
        assert!((area_to_solid_angle(0.25, p, q, Vec3::Z) - 1.0).abs() < 1e-15);
        // 60° off the normal: twice the density.
        let q = Vec3::new(2.0 * 3f64.sqrt(), 0.0, 0.0);
        let expect = 0.25 * 16.0 / 0.5;
        assert!((area_to_solid_angle(0.25, p, q, Vec3::Z) - expect).abs() < 1e-12);
        // Degenerate: on the point, grazing, zero density, NaN.
        assert_eq!(area_to_solid_angle(0.25, q, q, Vec3::Z), 0.0);
        assert_eq!(
            area_to_solid_angle(0.25, p, Vec3::new(0.0, 0.0, 2.0) + Vec3::X, Vec3::Z),
            0.0
        );
        assert_eq!(area_to_solid_angle(0.0, p, Vec3::ZERO, Vec3::Z), 0.0);
        assert_eq!(area_to_solid_angle(f64::NAN, p, Vec3::ZERO, Vec3::Z), 0.0);
        assert!(area_sample_from(p, (Vec3::ZERO, Vec3::Z, 0.25)).is_some());
        assert!(area_sample_from(p, (Vec3::ZERO, Vec3::Z, 0.0)).is_none());
    }

    #[test]
    fn spherical_range() {
        assert!(!use_spherical_sampling(1e-5));
        assert!(use_spherical_sampling(1.0));
        assert!(!use_spherical_sampling(6.27));
        assert!(!use_spherical_sampling(f64::NAN));
    }
}
