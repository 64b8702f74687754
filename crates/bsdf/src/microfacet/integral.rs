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
//!   Cranley–Patterson rotations of a Hammersley set), with its standard error.

use crate::error::{ParamError, ParamResult};
use crate::finite::guard;
use crate::math::rng::RandomSource;
use crate::math::warp::hammersley;
use crate::math::{Vec2, Vec3};
use crate::microfacet::{Distribution, Masking, Ndf};

#[derive(Clone, Debug)]
pub struct MicrofacetIntegral {
    pub ndf: Ndf,
    pub masking: Masking,
}

/// Seed of the frozen quadrature point sets of the models that evaluate this integral
/// deterministically (`evaluation = "quadrature"`): fixed so that evaluation is
/// deterministic; each model draws its own stream of it.
pub const QUADRATURE_SEED: u64 = 0x005e_ed0f_fac7;

/// Number of independent rotations of the QMC point set (gives the standard error).
const QMC_ROTATIONS: usize = 8;

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
        let im = i.dot(m);
        let om = o.dot(m);
        if im <= 0.0 || om <= 0.0 || i.z <= 0.0 || o.z <= 0.0 {
            return 0.0;
        }
        let pdf = self.ndf.pdf_normal(m);
        if !(pdf > 0.0) {
            return 0.0;
        }
        let g = self.masking.g(&self.ndf, i, o, m);
        if g == 0.0 {
            return 0.0;
        }
        let v = h(m) * self.ndf.d(m) * g * im * om / (i.z * o.z * pdf);
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
        let n = n.max(QMC_ROTATIONS);
        let per = (n / QMC_ROTATIONS) as u32;
        let mut means = [0.0; QMC_ROTATIONS];
        for mean in means.iter_mut() {
            let shift = rng.next_2d();
            let mut s = 0.0;
            for k in 0..per {
                s += self.weight(i, o, self.ndf.sample_normal(hammersley(k, per, shift)), &h);
            }
            *mean = s / per as f64;
        }
        let r = QMC_ROTATIONS as f64;
        let mean = means.iter().sum::<f64>() / r;
        let var = means.iter().map(|m| (m - mean) * (m - mean)).sum::<f64>() / (r - 1.0);
        (mean, (var / r).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::Pcg32;
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
}
