//! The one microfacet-integration routine shared by every model whose microfacets are not
//! mirrors: the body term of interfaced Lambertian, the exact Oren–Nayar model (IL with
//! n_i = 1) and Simonot's model.
//!
//! It estimates the microfacet integral of IL18 eq. 3 / TSBRM eq. 5 for a per-facet factor
//! h(m) (T(i,m) T(o,m) for IL, 1 for Lambertian facets):
//!
//!   I(i, o) = ∫ h(m) D(m) G(i,o,m) |i·m| |o·m| / (|i·n| |o·n|) dω_m,
//!
//! by importance sampling m from the distribution's normal sampler — D(m)|m·n|, or the GGX
//! proposal σ̃ = √2 σ for the Gaussian — as TSBRM eq. 37:
//!
//!   I ≈ (1/N) Σ h(m_k) D(m_k) G(i,o,m_k) |i·m_k| |o·m_k| / (|i·n| |o·n| pdf(m_k)).
//!
//! The normals are drawn independently of i and o, so with the same random numbers the
//! estimate is exactly symmetric in i and o: reciprocity holds sample by sample.
//!
//! - [`MicrofacetIntegral::estimate_one`]: one microfacet, unbiased — IL18 §4.1's path-tracer
//!   mode (eq. 28).
//! - [`MicrofacetIntegral::estimate`]: N microfacets as randomized quasi-Monte Carlo (8
//!   Cranley–Patterson rotations of a Hammersley set), with its standard error;
//!   [`MicrofacetIntegral::frozen_set`] draws such a set once (each normal with its
//!   D(m)/pdf(m)) and [`MicrofacetIntegral::estimate_frozen`] evaluates over it, bit for bit
//!   the same value — what the models with `samples = N` keep, since their set never
//!   changes (about 8× less work a call: no sampling, no densities).
//! - [`MicrofacetIntegral::integrate`]: adaptive Gauss–Kronrod quadrature over the
//!   hemisphere of normals, in (φ_m, θ_m) with dω_m = sin θ_m dθ_m dφ_m, to a relative
//!   tolerance, with an error estimate ([`crate::math::adaptive_quadrature`]). The
//!   integrand's kinks are cut exactly (see [`MicrofacetIntegral::integrate`]).

use crate::error::{ParamError, ParamResult};
use crate::finite::guard;
use crate::math::adaptive_quadrature::{integrate_2d, InnerRange, QuadResult, Tolerance};
use crate::math::rng::{Pcg32, RandomSource};
use crate::math::warp::hammersley;
use crate::math::{spherical_direction, PI, TWO_PI};
use crate::math::{Vec2, Vec3};
use crate::microfacet::{Distribution, Masking, Ndf};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct MicrofacetIntegral {
    pub ndf: Ndf,
    pub masking: Masking,
}

/// Seed of the frozen quadrature point sets of the models that evaluate this integral
/// deterministically (`evaluation = "quadrature"`): fixed so that evaluation is
/// deterministic; each model draws its own stream of it.
pub const QUADRATURE_SEED: u64 = 0x005e_ed0f_fac7;

/// Default relative tolerance of the adaptive quadrature (`evaluation = "quadrature"`).
pub const DEFAULT_TOLERANCE: f64 = 1e-6;

/// Range of the `tolerance` key: below 1e-12 the error estimate's rounding floor (50 ε
/// per segment) and the 400-segment budget make it unreachable; above 0.1 it is no longer
/// a quadrature worth the name.
pub const TOLERANCE_RANGE: (f64, f64) = (1e-12, 0.1);

/// Checks a `tolerance` value against [`TOLERANCE_RANGE`].
pub fn check_tolerance(tolerance: f64) -> ParamResult<f64> {
    check_tolerance_named("tolerance", tolerance)
}

/// Checks a tolerance given under the key `name` against [`TOLERANCE_RANGE`] (finite, in
/// [1e-12, 0.1]; the error names the key and the range).
pub fn check_tolerance_named(name: &str, tolerance: f64) -> ParamResult<f64> {
    if !tolerance.is_finite() {
        // The range is part of the message here too.
        return Err(ParamError::OutOfRange {
            name: name.into(),
            value: tolerance,
            expected: format!(
                "a finite number, {} <= {name} <= {}",
                crate::math::fmt_num(TOLERANCE_RANGE.0),
                crate::math::fmt_num(TOLERANCE_RANGE.1)
            ),
        });
    }
    crate::checks::check_range(
        name,
        tolerance,
        TOLERANCE_RANGE.0,
        TOLERANCE_RANGE.1,
        crate::checks::Bounds::Closed,
    )
}

/// How the entries of a table of integrals are computed (KSK01's albedo table, IL body
/// tables).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TableEntries {
    /// Randomized QMC with this many points per entry (8 rotations), with its standard
    /// error.
    Samples(usize),
    /// Adaptive quadrature to this relative tolerance, with its error estimate
    /// ([`crate::math::adaptive_quadrature`]); deterministic.
    Adaptive { tolerance: f64 },
}

/// Number of independent rotations of the QMC point set (gives the standard error).
const QMC_ROTATIONS: usize = 8;

/// The frozen point set of a fixed-N estimate ([`MicrofacetIntegral::frozen_set`]): the
/// normals of the 8 rotations in order, each with D(m)/pdf(m).
#[derive(Debug)]
pub struct FrozenFacets {
    facets: Vec<(Vec3, f64)>,
    /// Normals per rotation.
    per: usize,
}

impl FrozenFacets {
    /// Most normals a model keeps frozen (32 bytes each, 2 MiB): larger `samples` are drawn
    /// at every evaluation instead, with the same values.
    pub const MAX_NORMALS: usize = 1 << 16;

    /// Normals in the set.
    pub fn len(&self) -> usize {
        self.facets.len()
    }

    /// Whether the set holds no normal (never, for a set from `frozen_set`).
    pub fn is_empty(&self) -> bool {
        self.facets.is_empty()
    }
}

/// The mean of the rotations' means and its standard error.
fn mean_and_error(means: &[f64; QMC_ROTATIONS]) -> (f64, f64) {
    let r = QMC_ROTATIONS as f64;
    let mean = means.iter().sum::<f64>() / r;
    let var = means.iter().map(|m| (m - mean) * (m - mean)).sum::<f64>() / (r - 1.0);
    (mean, (var / r).sqrt())
}

impl MicrofacetIntegral {
    pub fn new(ndf: Ndf, masking: Masking) -> ParamResult<Self> {
        if masking.is_smith() && !ndf.supports_smith() {
            return Err(ParamError::Invalid(format!(
                "masking `{}` is not defined for the gaussian distribution (its Smith Λ \
                 diverges); use masking = \"v-cavity\"",
                masking.name()
            )));
        }
        Ok(MicrofacetIntegral { ndf, masking })
    }

    /// Integrand divided by the sampling density for one normal m; i and o in the upper
    /// hemisphere.
    #[inline]
    pub fn weight(&self, i: Vec3, o: Vec3, m: Vec3, h: impl Fn(Vec3) -> f64) -> f64 {
        if i.dot(m) <= 0.0 || o.dot(m) <= 0.0 || i.z <= 0.0 || o.z <= 0.0 {
            return 0.0;
        }
        self.weight_with_ratio(i, o, m, self.density_ratio(m), h)
    }

    /// D(m)/pdf(m) of a sampled normal m, 0 where the sampler's density vanishes: the part
    /// of [`Self::weight`] that depends on m alone.
    #[inline]
    fn density_ratio(&self, m: Vec3) -> f64 {
        let pdf = self.ndf.pdf_normal(m);
        if pdf > 0.0 {
            self.ndf.d(m) / pdf
        } else {
            0.0
        }
    }

    /// [`Self::weight`] with m's D(m)/pdf(m) given (`ratio`, from [`Self::density_ratio`]).
    #[inline]
    fn weight_with_ratio(
        &self,
        i: Vec3,
        o: Vec3,
        m: Vec3,
        ratio: f64,
        h: impl Fn(Vec3) -> f64,
    ) -> f64 {
        let im = i.dot(m);
        let om = o.dot(m);
        if im <= 0.0 || om <= 0.0 || i.z <= 0.0 || o.z <= 0.0 || ratio == 0.0 {
            return 0.0;
        }
        let g = self.masking.g(&self.ndf, i, o, m);
        if g == 0.0 {
            return 0.0;
        }
        // (im om) and (i_z o_z) as products of two: swapping i and o gives the same bits.
        let v = h(m) * ratio * g * (im * om) / (i.z * o.z);
        guard(v, || {
            format!(
                "microfacet integral of {} ({}) at i = {i:?}, o = {o:?}, m = {m:?}",
                self.ndf.describe(),
                self.masking.name()
            )
        })
    }

    /// One-microfacet unbiased estimate [IL18 eq. 28].
    #[inline]
    pub fn estimate_one(&self, i: Vec3, o: Vec3, u: Vec2, h: impl Fn(Vec3) -> f64) -> f64 {
        let m = self.ndf.sample_normal(u);
        self.weight(i, o, m, h)
    }

    /// Estimate with `n` microfacets and its standard error [TSBRM eq. 37].
    pub fn estimate(
        &self,
        i: Vec3,
        o: Vec3,
        n: usize,
        rng: &mut dyn RandomSource,
        h: impl Fn(Vec3) -> f64,
    ) -> (f64, f64) {
        let per = (n.max(QMC_ROTATIONS) / QMC_ROTATIONS) as u32;
        let mut means = [0.0; QMC_ROTATIONS];
        for mean in means.iter_mut() {
            let shift = rng.next_2d();
            let mut s = 0.0;
            for k in 0..per {
                // `weight` skips the densities of facets facing away from i or o.
                s += self.weight(i, o, self.ndf.sample_normal(hammersley(k, per, shift)), &h);
            }
            *mean = s / per as f64;
        }
        mean_and_error(&means)
    }

    /// The point set that [`Self::estimate`] draws for `n` microfacets from `rng`, drawn
    /// once: each normal with its D(m)/pdf(m). A model that evaluates with a fixed set
    /// (`evaluation = "quadrature"` with `samples`) keeps it, and each evaluation is then
    /// only the masking, the cosines and h — not the normal's sampling and two densities.
    /// [`Self::estimate_frozen`] over it gives [`Self::estimate`]'s value bit for bit.
    pub fn frozen_set(&self, n: usize, rng: &mut dyn RandomSource) -> FrozenFacets {
        let per = (n.max(QMC_ROTATIONS) / QMC_ROTATIONS) as u32;
        let mut facets = Vec::with_capacity(per as usize * QMC_ROTATIONS);
        for _ in 0..QMC_ROTATIONS {
            let shift = rng.next_2d();
            for k in 0..per {
                let m = self.ndf.sample_normal(hammersley(k, per, shift));
                facets.push((m, self.density_ratio(m)));
            }
        }
        FrozenFacets {
            facets,
            per: per as usize,
        }
    }

    /// [`Self::estimate`] over a set drawn by [`Self::frozen_set`] (the same value and
    /// standard error, bit for bit).
    pub fn estimate_frozen(
        &self,
        set: &FrozenFacets,
        i: Vec3,
        o: Vec3,
        h: impl Fn(Vec3) -> f64,
    ) -> (f64, f64) {
        let mut means = [0.0; QMC_ROTATIONS];
        for (mean, rotation) in means.iter_mut().zip(set.facets.chunks_exact(set.per)) {
            let mut s = 0.0;
            for &(m, ratio) in rotation {
                s += self.weight_with_ratio(i, o, m, ratio, &h);
            }
            *mean = s / set.per as f64;
        }
        mean_and_error(&means)
    }

    /// The fixed set of a model's `samples = N` (stream `stream` of [`QUADRATURE_SEED`]),
    /// frozen — or `None` above [`FrozenFacets::MAX_NORMALS`], where
    /// [`Self::estimate_fixed`] draws it at each call instead.
    pub fn freeze(&self, samples: usize, stream: u64) -> Option<Arc<FrozenFacets>> {
        (samples <= FrozenFacets::MAX_NORMALS)
            .then(|| Arc::new(self.frozen_set(samples, &mut Pcg32::new(QUADRATURE_SEED, stream))))
    }

    /// A model's fixed-N estimate: over its frozen set where [`Self::freeze`] made one,
    /// otherwise over the same set drawn now (the same value either way).
    pub fn estimate_fixed(
        &self,
        frozen: Option<&FrozenFacets>,
        samples: usize,
        stream: u64,
        i: Vec3,
        o: Vec3,
        h: impl Fn(Vec3) -> f64,
    ) -> (f64, f64) {
        match frozen {
            Some(set) => self.estimate_frozen(set, i, o, h),
            None => self.estimate(i, o, samples, &mut Pcg32::new(QUADRATURE_SEED, stream), h),
        }
    }

    /// The integral by adaptive quadrature to relative tolerance `rel_tol` (with its error
    /// estimate and cost), i and o in the upper hemisphere.
    ///
    /// Over the azimuth φ_m ∈ [0, 2π] of adaptive integrals over the polar angle θ_m. At a
    /// given φ_m, with c_v = cos(φ_m − φ_v) and s_v = sin θ_v for v ∈ {i, o}:
    /// - the facet faces v while tan θ_m < v_z/(−s_v c_v) (when s_v c_v < 0): the inner
    ///   integral stops at the first such limit (the integrand is zero beyond, with a kink);
    /// - the V-cavity masking G = min(1, 2 m_z v_z/(v·m)) [IL18 eq. 15] leaves 1 at
    ///   tan θ_m = v_z/(s_v c_v) (when s_v c_v > 0): break points;
    /// - its two branches swap where o_z(i·m) = i_z(o·m), i.e. o_z s_i c_i = i_z s_o c_o,
    ///   independent of θ_m: break points of the outer integral, with the azimuths where one
    ///   direction's limits cross the other's (o_z s_i c_i = −i_z s_o c_o) and where a limit
    ///   appears (c_v = 0);
    /// - the distribution's width w: breaks at θ_m = w/4 … 4w, so that a narrow peak at the
    ///   normal is seen by the first rules.
    ///
    /// The break points are symmetric in i and o and the integrand is evaluated in an order
    /// symmetric in them, so the result is exactly reciprocal.
    pub fn integrate(&self, i: Vec3, o: Vec3, rel_tol: f64, h: impl Fn(Vec3) -> f64) -> QuadResult {
        if i.z <= 0.0 || o.z <= 0.0 {
            return QuadResult {
                converged: true,
                ..Default::default()
            };
        }
        let polar = |v: Vec3| ((v.x * v.x + v.y * v.y).sqrt(), v.y.atan2(v.x));
        let ((si, pi), (so, po)) = (polar(i), polar(o));
        // Zeros of k_i s_i cos(φ − φ_i) + k_o s_o cos(φ − φ_o) = A cos φ + B sin φ; the sign of
        // (A, B) is normalized so that swapping i and o gives bit-identical zeros.
        let zeros = |ki: f64, ko: f64, out: &mut Vec<f64>| {
            let (mut a, mut b) = (
                ki * si * pi.cos() + ko * so * po.cos(),
                ki * si * pi.sin() + ko * so * po.sin(),
            );
            if a < 0.0 || (a == 0.0 && b < 0.0) {
                a = -a;
                b = -b;
            }
            if a.hypot(b) <= 1e-14 {
                return;
            }
            let psi = b.atan2(a);
            for z in [psi - 0.5 * PI, psi + 0.5 * PI] {
                out.push(z.rem_euclid(TWO_PI));
            }
        };
        let mut outer = Vec::with_capacity(8);
        zeros(1.0, 0.0, &mut outer);
        zeros(0.0, 1.0, &mut outer);
        zeros(o.z, -i.z, &mut outer);
        zeros(o.z, i.z, &mut outer);
        let w = self.ndf.typical_width();
        let inner = |phi: f64| {
            let mut hi = 0.5 * PI;
            let mut breaks = Vec::with_capacity(9);
            for (v, s, p) in [(i, si, pi), (o, so, po)] {
                let sc = s * (phi - p).cos();
                if sc < 0.0 {
                    hi = hi.min(v.z.atan2(-sc));
                } else if sc > 0.0 {
                    breaks.push(v.z.atan2(sc));
                }
            }
            breaks.extend([0.25, 0.5, 1.0, 2.0, 4.0].map(|k| k * w));
            InnerRange {
                lo: 0.0,
                hi,
                breaks,
            }
        };
        let izoz = i.z * o.z;
        let f = |phi: f64, theta: f64| {
            let m = spherical_direction(theta, phi);
            let (im, om) = (i.dot(m), o.dot(m));
            if im <= 0.0 || om <= 0.0 {
                return 0.0;
            }
            let g = self.masking.g(&self.ndf, i, o, m);
            if g == 0.0 {
                return 0.0;
            }
            // [IL18 eq. 13] (TSBRM eq. 5) with dω = sin θ dθ dφ; (im·om) and (iz·oz) as
            // products of symmetric pairs keep the value bit-identical under i ↔ o.
            h(m) * self.ndf.d(m) * g * (im * om) / izoz * theta.sin()
        };
        let r = integrate_2d(0.0, TWO_PI, &outer, Tolerance::relative(rel_tol), inner, f);
        guard(r.value, || {
            format!(
                "adaptive microfacet integral of {} ({}) at i = {i:?}, o = {o:?}",
                self.ndf.describe(),
                self.masking.name()
            )
        });
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::spherical_direction;
    use crate::microfacet::{Beckmann, Gaussian};

    #[test]
    fn flat_limit_and_symmetry() {
        // A very smooth surface: the integral with h = 1 tends to 1 (all facets face n).
        let mi = MicrofacetIntegral::new(
            Ndf::Beckmann(Beckmann::isotropic(1e-3).unwrap()),
            Masking::SmithSeparable,
        )
        .unwrap();
        let (i, o) = (spherical_direction(0.4, 0.0), spherical_direction(0.9, 2.0));
        let (v, se) = mi.estimate(i, o, 4096, &mut Pcg32::new(1, 1), |_| 1.0);
        assert!((v - 1.0).abs() < 1e-2 && se < 1e-2, "{v} ± {se}");
        // Same random numbers, swapped directions: identical estimates.
        let mi =
            MicrofacetIntegral::new(Ndf::Gaussian(Gaussian::new(0.5).unwrap()), Masking::VCavity)
                .unwrap();
        let a = mi.estimate(i, o, 512, &mut Pcg32::new(5, 5), |_| 1.0);
        let b = mi.estimate(o, i, 512, &mut Pcg32::new(5, 5), |_| 1.0);
        assert_eq!(a.0, b.0);
        assert!((a.1 - b.1).abs() < 1e-15);
    }

    #[test]
    fn a_frozen_set_gives_the_streamed_estimate_bit_for_bit() {
        let models = [
            MicrofacetIntegral::new(Ndf::Gaussian(Gaussian::new(0.5).unwrap()), Masking::VCavity)
                .unwrap(),
            MicrofacetIntegral::new(
                Ndf::Beckmann(Beckmann::new(0.7, 0.2).unwrap()),
                Masking::SmithSeparable,
            )
            .unwrap(),
        ];
        let h = |m: Vec3| 1.0 - 0.3 * (1.0 - m.z).powi(3);
        let mut rng = Pcg32::new(9, 3);
        for mi in &models {
            for n in [8, 100, 256] {
                let set = mi.frozen_set(n, &mut Pcg32::new(QUADRATURE_SEED, 1));
                assert_eq!(set.len(), (n / QMC_ROTATIONS) * QMC_ROTATIONS);
                for _ in 0..50 {
                    let i = spherical_direction(rng.next_f64() * 1.55, rng.next_f64() * TWO_PI);
                    let o = spherical_direction(rng.next_f64() * 1.55, rng.next_f64() * TWO_PI);
                    let streamed = mi.estimate(i, o, n, &mut Pcg32::new(QUADRATURE_SEED, 1), h);
                    let frozen = mi.estimate_frozen(&set, i, o, h);
                    assert_eq!(streamed.0.to_bits(), frozen.0.to_bits(), "{i:?} {o:?}");
                    assert_eq!(streamed.1.to_bits(), frozen.1.to_bits());
                    // Reciprocal bit for bit.
                    assert_eq!(
                        mi.estimate_frozen(&set, o, i, h).0.to_bits(),
                        frozen.0.to_bits()
                    );
                }
            }
        }
    }
}
