//! Sampling warps from [0, 1)² to directions, and low-discrepancy point sets.

use super::{Vec2, Vec3, INV_PI, PI, TWO_PI};
use crate::lanes::{LVec3, Real};

/// Concentric map of the unit square to the unit disk (Shirley & Chiu 1997).
#[inline]
pub fn square_to_disk_concentric(u: Vec2) -> Vec2 {
    let (x, y) = square_to_disk_concentric_lanes(u.x, u.y);
    Vec2::new(x, y)
}

/// [`square_to_disk_concentric`] over lanes, its one source: both wedges' angles are
/// computed and one selected per lane (the other may divide by zero and is discarded).
#[inline(always)]
pub fn square_to_disk_concentric_lanes<R: Real>(u0: R, u1: R) -> (R, R) {
    let a = R::splat(2.0) * u0 - R::one();
    let b = R::splat(2.0) * u1 - R::one();
    let quarter = R::splat(PI / 4.0);
    let first = (a * a).gt(b * b);
    let r = R::select(first, a, b);
    let phi = R::select(
        first,
        quarter * (b / a),
        R::splat(PI / 2.0) - quarter * (a / b),
    );
    let (s, c) = phi.sin_cos();
    let centre = a.eq(R::zero()) & b.eq(R::zero());
    (
        R::select(centre, R::zero(), r * c),
        R::select(centre, R::zero(), r * s),
    )
}

/// Cosine-weighted hemisphere sample (pdf = cos θ / π), Malley's method.
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = square_to_disk_concentric(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

#[inline]
pub fn cosine_hemisphere_pdf(v: Vec3) -> f64 {
    v.z.max(0.0) * INV_PI
}

/// Uniform sample of the unit sphere (pdf = 1/4π).
#[inline]
pub fn square_to_uniform_sphere(u: Vec2) -> Vec3 {
    square_to_uniform_sphere_lanes(u.x, u.y).into()
}

/// [`square_to_uniform_sphere`] over lanes, its one source.
#[inline(always)]
pub fn square_to_uniform_sphere_lanes<R: Real>(u0: R, u1: R) -> LVec3<R> {
    let z = R::one() - R::splat(2.0) * u0;
    let r = (R::one() - z * z).max(R::zero()).sqrt();
    let (s, c) = (R::splat(TWO_PI) * u1).sin_cos();
    LVec3::new(r * c, r * s, z)
}

/// Uniform sample of the upper hemisphere (pdf = 1/2π).
#[inline]
pub fn square_to_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (TWO_PI * u.y).sin_cos();
    Vec3::new(r * c, r * s, z)
}

/// Van der Corput radical inverse in base 2.
#[inline]
pub fn radical_inverse_base2(i: u32) -> f64 {
    i.reverse_bits() as f64 * (1.0 / 4_294_967_296.0)
}

/// Point k of an n-point Hammersley set in [0, 1)², shifted by a Cranley–Patterson
/// rotation (`shift`) so that independent shifts give independent randomized-QMC estimates.
#[inline]
pub fn hammersley(k: u32, n: u32, shift: Vec2) -> Vec2 {
    let x = (k as f64 + 0.5) / n as f64 + shift.x;
    let y = radical_inverse_base2(k) + shift.y;
    Vec2::new(x - x.floor(), y - y.floor())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warps_produce_unit_vectors_in_their_domain() {
        let mut r = crate::math::rng::Pcg32::new(3, 0);
        use crate::math::rng::RandomSource;
        for _ in 0..10_000 {
            let u = r.next_2d();
            let c = square_to_cosine_hemisphere(u);
            assert!((c.length() - 1.0).abs() < 1e-12 && c.z >= 0.0);
            let s = square_to_uniform_sphere(u);
            assert!((s.length() - 1.0).abs() < 1e-12);
            let h = square_to_uniform_hemisphere(u);
            assert!((h.length() - 1.0).abs() < 1e-12 && h.z >= 0.0);
        }
    }

    #[test]
    fn hammersley_integrates_smooth_functions_accurately() {
        let n = 4096;
        let mut s = 0.0;
        for k in 0..n {
            let p = hammersley(k, n, Vec2::new(0.3, 0.7));
            s += (p.x * 3.0).sin() * p.y * p.y;
        }
        let exact = (1.0 - 3f64.cos()) / 3.0 / 3.0;
        assert!((s / n as f64 - exact).abs() < 1e-4);
    }
}
