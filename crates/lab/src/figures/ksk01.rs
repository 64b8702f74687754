//! KSK01 figures: Fig. 2 (radiance lobes and the off-specular peak), Fig. 3 (specular
//! albedo for three half-vector densities) and Fig. 5 (specular + matte albedo = 1).

use super::{argmax, single, Quality, Reproduction};
use crate::plot::bsdf_charts::{polar_from_slice, slice_chart, LabelledBsdf, SliceOptions};
use crate::plot::bsdf_data::{light_direction, Channel, Quantity, Side};
use crate::plot::{LineChart, Scale, Series};
use facette_bsdf::fresnel::Fresnel;
use facette_bsdf::math::quadrature::GaussLegendre;
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::math::spherical_direction;
use facette_bsdf::microfacet::half_vector_density::HalfVectorDensity;
use facette_bsdf::models::Kelemen;
use facette_bsdf::two_sided::TwoSided;
use facette_bsdf::validation::bsdf_checks::directional_albedo;
use facette_bsdf::{Bsdf, BsdfContext, ParamError, Spectrum};
use std::sync::Arc;

/// The two-sided Kelemen BRDF (the figures query the upper hemisphere; `inner()` is the
/// model with its tables).
fn kelemen(
    density: &str,
    rough: f64,
    kd: f64,
    q: Quality,
) -> Result<TwoSided<Kelemen>, ParamError> {
    Kelemen::new(
        HalfVectorDensity::new(density, rough)?,
        Fresnel::One,
        Spectrum::splat(kd),
        q.samples(16384, 1024),
    )
    .map(TwoSided::new)
}

/// KSK01 Fig. 2: reflected radiance lobes f_s cos θ' of the specular term with the Ward
/// density, F = 1, m = 0.1, for θ' = 22.5, 45 and 67.5° (polar, in the incidence plane).
pub fn fig2(q: Quality) -> Result<Reproduction, ParamError> {
    let k = Arc::new(kelemen("ward", 0.1, 0.0, q)?);
    let o = SliceOptions {
        thetas_i: vec![22.5, 45.0, 67.5],
        side: Side::Reflection,
        quantity: Quantity::FCosI,
        channel: Channel::Mean,
        scale: Scale::Linear,
        points: 721,
        samples: 1,
        seed: 1,
    };
    let slice = slice_chart(
        &[LabelledBsdf {
            label: "Ward m = 0.1".into(),
            bsdf: k,
        }],
        &o,
    );
    let numbers = slice
        .series
        .iter()
        .zip(&o.thetas_i)
        .map(|(s, t)| {
            let (peak, v) = argmax(&s.points);
            format!(
                "θ' = {t}°: maximum f·cos θ' = {v:.3} 1/sr at θ = {peak:.2}°, ideal reflection at {t}°: off-specular by {:.2}°",
                peak - t
            )
        })
        .collect();
    let mut c = polar_from_slice(slice, &o);
    c.title = "Ward density, F = 1, m = 0.1 (polar: distance = f·cos θ')".into();
    c.x_label = "along the surface (1/sr)".into();
    c.y_label = "along the normal (1/sr)".into();
    Ok(Reproduction {
        figure: single("KSK01 Fig. 2: reflected radiance lobes", c),
        numbers,
    })
}

/// KSK01 Fig. 3: the specular albedo a_s(θ) [KSK01 §2.1.5] with F = 1 for the Ward,
/// Beckmann and Phong densities at m = 0.2 and 0.5, the Phong exponent n = 2/m² − 1
/// matching the lobes' maxima at normal incidence (P_H(N) = 1/(π m²) = (n + 1)/(2π)).
pub fn fig3(q: Quality) -> Result<Reproduction, ParamError> {
    let mut c = LineChart::new("specular albedo, F = 1", "θ (degrees)", "a_s(θ)");
    c.x_range = Some((0.0, 90.0));
    let mut numbers = Vec::new();
    for (j, m) in [0.2f64, 0.5].into_iter().enumerate() {
        let n = 2.0 / (m * m) - 1.0;
        for (k, (density, rough, label)) in [
            ("ward", m, format!("Ward m = {m}")),
            ("beckmann", m, format!("Beckmann m = {m}")),
            ("phong", n, format!("Phong n = {n}")),
        ]
        .into_iter()
        .enumerate()
        {
            let model = kelemen(density, rough, 0.0, q)?;
            let model = model.inner();
            let curve: Vec<(f64, f64)> = (0..=90)
                .map(|d| (d as f64, model.albedo_at((d as f64).to_radians()).average()))
                .collect();
            numbers.push(format!(
                "{label}: a_s(0°) = {:.4}, a_s(60°) = {:.4}, a_s(85°) = {:.4}, average {:.4}",
                curve[0].1,
                curve[60].1,
                curve[85].1,
                model.average_albedo().average()
            ));
            let mut s = Series::new(label, curve, 3 * j + k);
            if j == 1 {
                s = s.dashed();
            }
            c.series.push(s);
        }
    }
    Ok(Reproduction {
        figure: single("KSK01 Fig. 3: albedo of the specular term", c),
        numbers,
    })
}

/// ∫ f(i, o) cos θ_o dω_o by Gauss–Legendre quadrature (θ_o in 4 panels, φ_o), for smooth
/// lobes.
fn quadrature_albedo(b: &dyn Bsdf, theta_i: f64) -> f64 {
    let gl = GaussLegendre::new(32);
    let wi = light_direction(theta_i);
    let mut rng = Pcg32::new(1, 1);
    let mut total = 0.0;
    for seg in 0..4 {
        let (t0, t1) = (
            seg as f64 * 22.5f64.to_radians(),
            (seg + 1) as f64 * 22.5f64.to_radians(),
        );
        total += gl.integrate(t0, t1, |t| {
            gl.integrate(0.0, 2.0 * std::f64::consts::PI, |p| {
                let wo = spherical_direction(t, p);
                b.eval(wo, wi, &BsdfContext::RADIANCE, &mut rng).average() * t.cos() * t.sin()
            })
        });
    }
    total
}

/// KSK01 Fig. 5: specular and matte albedo against θ' for the Ward density with m = 0.8
/// (F = 1, k = 1). The specular albedo is measured from the sampler (Monte Carlo), the
/// matte albedo by quadrature of the matte BRDF (the model with k = 1 minus the model with
/// k = 0) — independently of the table the matte term is built from — and their sum is
/// checked against 1 [KSK01 eq. 7].
pub fn fig5(q: Quality) -> Result<Reproduction, ParamError> {
    let spec_only = kelemen("ward", 0.8, 0.0, q)?;
    let full = kelemen("ward", 0.8, 1.0, q)?;
    let thetas: Vec<f64> = (0..=17).map(|k| k as f64 * 5.0).chain([89.0]).collect();
    let n = q.samples(400_000, 20_000);
    let rows: Vec<(f64, f64, f64)> = thetas
        .iter()
        .map(|&t| {
            let wi = light_direction(t);
            let (s, _, _, _) = directional_albedo(&spec_only, wi, &BsdfContext::IMPORTANCE, n, 3);
            let matte = quadrature_albedo(&full, t) - quadrature_albedo(&spec_only, t);
            (t, s.average(), matte)
        })
        .collect();
    let worst = rows
        .iter()
        .map(|r| (r.1 + r.2 - 1.0).abs())
        .fold(0.0, f64::max);
    let mut c = LineChart::new(
        "Ward density, m = 0.8, F = 1, k = 1",
        "θ' (degrees)",
        "albedo",
    );
    c.x_range = Some((0.0, 90.0));
    c.y_range = Some((0.0, 1.1));
    c.series.push(Series::new(
        "specular a_s (Monte Carlo)",
        rows.iter().map(|r| (r.0, r.1)).collect(),
        0,
    ));
    c.series.push(Series::new(
        "matte (quadrature)",
        rows.iter().map(|r| (r.0, r.2)).collect(),
        1,
    ));
    c.series
        .push(Series::new("total", rows.iter().map(|r| (r.0, r.1 + r.2)).collect(), 6).dashed());
    let mut numbers: Vec<String> = rows
        .iter()
        .filter(|r| [0.0, 30.0, 60.0, 85.0].contains(&r.0))
        .map(|r| {
            format!(
                "θ' = {}°: specular {:.4} + matte {:.4} = {:.4}",
                r.0,
                r.1,
                r.2,
                r.1 + r.2
            )
        })
        .collect();
    numbers.push(format!(
        "largest |specular + matte − 1| over θ' ∈ [0°, 89°]: {worst:.4}"
    ));
    Ok(Reproduction {
        figure: single("KSK01 Fig. 5: specular and matte albedo", c),
        numbers,
    })
}
