//! The brute-force reference of the P-BRDF (CCM19's ground truth for renders): the
//! interpolated normal map at one point as a near-specular microfacet surface — one
//! Beckmann slope lobe whose mean is the map's bilinearly interpolated slope at that point
//! and whose standard deviation is the roughness floor σ_ε — evaluated with the P-BRDF's
//! own formula for a one-lobe patch  [CCM19 eq. 7]:
//!
//!   f(o, i) = F(o·h) χ⁺(o·h) χ⁺(i·h) D(h) / (4 I(o) I(i)),
//!
//! D(h) = P22(h̃)/cos⁴θ_h the lobe  [CCM19 eq. 2], I(v) its visible projected area
//! ([`LobeF64::visible_projected_area`], ERRATA 15). A renderer builds it at each shading
//! point's uv (`evaluation = "reference"` of the `glint` material) and ignores the ray
//! footprint: averaging many samples per pixel integrates the normal map over the pixel by
//! brute force, which the P-NDF does analytically  [CCM19 eqs. 8–9]. No seeds, no
//! hierarchy: it shares only the lobe's closed forms and eq. 7 ([`super::patch_reflection`]).
//!
//! Sampling draws the lobe's (truncated) slope distribution, mirrored; its pdf
//! D(h) cos θ_h / (4 o·h) is the density of that draw  [WMLT07 eqs. 14, 38].

use super::lobe::{normal_of_slope, LobeF64, SlopeLobe};
use super::normal_map::NormalMap;
use super::patch_reflection::{self, PatchReflection};
use crate::bsdf::{BsdfContext, BsdfSample, LobeFlags};
use crate::fresnel::Fresnel;
use crate::math::rng::RandomSource;
use crate::math::spectrum::Spectrum;
use crate::math::{Vec2, Vec3};
use crate::two_sided::OpaqueBsdf;

/// One point of a normal-mapped near-specular conductor.
pub struct PointReferenceBsdf {
    /// Truncated P22 (the sampler's density).
    lobe: SlopeLobe,
    /// Moments for the masking terms and the sampler.
    moments: LobeF64,
    fresnel: Fresnel,
    tint: Spectrum,
}

impl PointReferenceBsdf {
    /// The surface of `map` at the position `texel` (texel units, periodic), with micro-slope
    /// standard deviation `roughness_floor`.
    pub fn new(
        map: &NormalMap,
        texel: Vec2,
        roughness_floor: f64,
        fresnel: Fresnel,
        tint: Spectrum,
    ) -> Self {
        let mean = map.interpolated_slope(texel);
        let v = roughness_floor * roughness_floor;
        let lobe = SlopeLobe::from_moments(mean, [v, 0.0, v]);
        PointReferenceBsdf {
            moments: lobe.to_f64(),
            lobe,
            fresnel,
            tint,
        }
    }

    /// The lobe's mean normal (the interpolated map's normal at the point).
    pub fn mean_normal(&self) -> Vec3 {
        normal_of_slope(self.moments.mean)
    }
}

impl PatchReflection for PointReferenceBsdf {
    /// D(h) of the truncated lobe.
    fn d(&self, h: Vec3) -> f64 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let s = [(-h.x / h.z) as f32, (-h.y / h.z) as f32];
        let z2 = h.z * h.z;
        self.lobe.p22(s) / (z2 * z2)
    }

    fn sample_normal(&self, rng: &mut dyn RandomSource) -> Option<Vec3> {
        Some(normal_of_slope(self.moments.sample_slope(rng.next_2d())))
    }

    fn view_area(&self, o: Vec3) -> f64 {
        self.moments.visible_projected_area(o)
    }

    fn light_area(&self, i: Vec3) -> f64 {
        self.moments.visible_projected_area(i)
    }

    fn fresnel(&self) -> &Fresnel {
        &self.fresnel
    }

    fn tint(&self) -> Spectrum {
        self.tint
    }
}

impl OpaqueBsdf for PointReferenceBsdf {
    fn flags(&self) -> LobeFlags {
        LobeFlags::GLOSSY_REFLECTION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _: &BsdfContext, _: &mut dyn RandomSource) -> Spectrum {
        patch_reflection::eval(self, wo, wi)
    }

    fn sample(&self, wo: Vec3, _: &BsdfContext, rng: &mut dyn RandomSource) -> Option<BsdfSample> {
        patch_reflection::sample(self, wo, true, rng)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _: &BsdfContext) -> f64 {
        patch_reflection::pdf(self, wo, wi)
    }

    /// At least 0.15 so that validation bins cover the lobe's neighbourhood.
    fn lobe_width(&self) -> f64 {
        (self.moments.cov[0].sqrt() * 2.0).max(0.15)
    }

    fn describe(&self) -> String {
        let n = self.mean_normal();
        format!(
            "glint reference point (mean normal [{:.4}, {:.4}, {:.4}], σ_ε = {:.4})",
            n.x,
            n.y,
            n.z,
            self.moments.cov[0].sqrt()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::glint::generate::{generate, NormalMapKind};
    use crate::two_sided::TwoSided;
    use crate::validation::bsdf_checks::{check_bsdf, BsdfCheckOptions};
    use crate::validation::Report;

    /// Sampling (chi-square), pdf/sample/eval consistency, reciprocity and the NaN sweep
    /// at tilted points of a bumpy map; the albedo bound w.r.t. cos θ_i on a flat map only:
    /// a tilted facet intercepts more than cos θ_i (its albedo w.r.t. cos θ_i exceeds 1 —
    /// the same property as the P-BRDF's, docs/glints.md), which cancels over the map.
    #[test]
    fn a_point_of_a_bumpy_map_passes_the_bsdf_checks() {
        let map = generate(NormalMapKind::Bumpy, 32, 2).unwrap();
        let flat = NormalMap::from_slopes(4, 4, vec![[0.0, 0.0]; 16]).unwrap();
        let mut r = Report::new();
        for (texel, floor) in [(Vec2::new(7.3, 11.8), 0.05), (Vec2::new(20.1, 3.6), 0.2)] {
            let b = TwoSided::new(PointReferenceBsdf::new(
                &map,
                texel,
                floor,
                Fresnel::One,
                Spectrum::ONE,
            ));
            r.extend(
                check_bsdf(&b, &BsdfCheckOptions::default())
                    .into_iter()
                    .filter(|c| !c.name.starts_with("directional albedo")),
            );
        }
        let b = TwoSided::new(PointReferenceBsdf::new(
            &flat,
            Vec2::new(1.5, 2.5),
            0.1,
            Fresnel::One,
            Spectrum::ONE,
        ));
        r.extend(check_bsdf(&b, &BsdfCheckOptions::default()));
        assert!(r
            .checks
            .iter()
            .any(|c| c.name.starts_with("directional albedo")));
        assert!(
            r.all_passed(),
            "{}\n{}",
            r.lines().join("\n"),
            r.summary_line()
        );
    }

    #[test]
    fn the_lobe_follows_the_interpolated_map() {
        let map = generate(NormalMapKind::Scratched, 64, 4).unwrap();
        let p = Vec2::new(10.25, 40.75);
        let b = PointReferenceBsdf::new(&map, p, 0.01, Fresnel::One, Spectrum::ONE);
        let s = map.interpolated_slope(p);
        let n = normal_of_slope(s);
        assert!((b.mean_normal() - n).length() < 1e-6);
        // Mirror direction about the mean normal: the peak of f for a view along n.
        let o = n;
        let peak = b.eval(
            o,
            o,
            &BsdfContext::RADIANCE,
            &mut crate::math::rng::Pcg32::new(1, 1),
        );
        let off = b.eval(
            o,
            (o + Vec3::new(0.1, 0.0, 0.0)).normalize(),
            &BsdfContext::RADIANCE,
            &mut crate::math::rng::Pcg32::new(1, 1),
        );
        assert!(peak[0] > 100.0 * off[0].max(1e-30), "{peak:?} {off:?}");
    }
}
