//! The patch NDF of a glint footprint as a hemisphere map  [CCM19 eq. 9, Fig. 4]: D_P(ω_h)
//! over the projected disk of half vectors (x, y) = (sin θ_h cos φ_h, sin θ_h sin φ_h).
//!
//! A footprint's D_P is a sum of narrow lobes (slope standard deviation σ_ε, often 0.01),
//! far narrower than a plotted cell: sampling the cell centres would miss most of them. Each
//! cell therefore shows the *average* of D_P over k × k stratified points of the cell, and
//! the sum of the averages times the cell area estimates the projected-area normalization
//!
//!   ∫ D_P(ω_h) cos θ_h dω_h = ∫∫_disk D_P dx dy = 1  [CCM19 eq. 1; WMLT07 eq. 4],
//!
//! since dx dy = cos θ_h dω_h on the orthographic disk. The printed integral is a check of
//! the plot's resolution (and of the P-NDF's normalization): it approaches 1 as k grows.

use super::hemisphere_map::HemisphereMap;
use facette_bsdf::math::Vec3;
use facette_bsdf::models::glint::GlintBsdf;

/// A D_P map and its integral over the disk.
pub struct NdfMap {
    pub map: HemisphereMap,
    /// ∫ D_P cos θ_h dω_h estimated from the cell averages (≈ 1).
    pub integral: f64,
    /// Largest cell average.
    pub max: f64,
}

/// D_P of `bsdf`'s footprint on an n × n grid over the disk, each cell averaged over
/// `supersample`² stratified points.
pub fn patch_ndf_map(
    bsdf: &GlintBsdf,
    title: impl Into<String>,
    n: usize,
    supersample: usize,
) -> NdfMap {
    let k = supersample.max(1);
    let cell = 2.0 / n as f64;
    let ndf = bsdf.ndf();
    let map = HemisphereMap::sample(title, "D_P (1/sr)", n, |cx, cy| {
        let mut sum = 0.0;
        for a in 0..k {
            for b in 0..k {
                let x = cx + cell * ((a as f64 + 0.5) / k as f64 - 0.5);
                let y = cy + cell * ((b as f64 + 0.5) / k as f64 - 0.5);
                let r2 = x * x + y * y;
                if r2 < 1.0 {
                    sum += ndf.d(Vec3::new(x, y, (1.0 - r2).sqrt()));
                }
            }
        }
        sum / (k * k) as f64
    });
    let values = map.values.iter().flatten();
    let integral = values.clone().sum::<f64>() * cell * cell;
    let max = values.copied().fold(0.0, f64::max);
    let mut map = map;
    map.axes = [
        "x = sin θ_h cos φ_h".to_string(),
        "y = sin θ_h sin φ_h".to_string(),
    ];
    NdfMap { map, integral, max }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::math::Vec2;
    use facette_bsdf::models::glint::{
        generate, Footprint, GlintParams, GlintSurface, MaskingMode, NormalMapKind,
    };
    use std::sync::Arc;

    fn bsdf(sigma: f64, floor: f64) -> GlintBsdf {
        let map = generate(NormalMapKind::Bumpy, 64, 2).unwrap();
        let surface = Arc::new(GlintSurface::build(map, floor, "bumpy 64²").unwrap());
        let params = GlintParams {
            fresnel: facette_bsdf::fresnel::Fresnel::One,
            tint: facette_bsdf::math::spectrum::Spectrum::splat(1.0),
            masking: MaskingMode::Approx,
            masking_lobes: 0,
            mis_pdf: facette_bsdf::models::glint::MisPdf::Filtered,
        };
        GlintBsdf::new(
            surface,
            Footprint::isotropic(Vec2::new(20.0, 30.0), sigma),
            &params,
        )
    }

    #[test]
    fn cell_averages_integrate_to_one() {
        // σ_ε = 0.05: 8 × 8 points per 1/32-wide cell resolve every lobe.
        let m = patch_ndf_map(&bsdf(4.0, 0.05), "t", 64, 8);
        assert!((m.integral - 1.0).abs() < 0.02, "{}", m.integral);
        assert!(m.max > 0.0 && m.map.values.iter().flatten().all(|v| v.is_finite()));
        assert!(m.map.axes[0].contains("θ_h"));
    }

    #[test]
    fn a_wider_footprint_is_smoother() {
        // More lobes in the footprint: a lower peak of D_P.
        let narrow = patch_ndf_map(&bsdf(0.5, 0.02), "n", 48, 4);
        let wide = patch_ndf_map(&bsdf(16.0, 0.02), "w", 48, 4);
        assert!(wide.max < narrow.max, "{} vs {}", wide.max, narrow.max);
    }
}
