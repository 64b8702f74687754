//! Reproductions of the papers' figures that need no measured data (`facette reproduce`):
//! each builds its curves from the library's models, returns the figure and the key
//! numbers it shows, and is documented (what matches, what differs) in
//! docs/reproduction.md. One file per paper.

pub mod il18;
pub mod ksk01;
pub mod tsbrm;
pub mod wmlt07;

use crate::plot::bsdf_data::{incidence_plane, signed_angles, Channel, Quantity, Side};
use crate::plot::{LineChart, Panels};
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::models::InterfacedLambertian;
use facette_bsdf::recipe::{build_material, parse_inline_table};
use facette_bsdf::{Bsdf, ParamError};
use std::sync::Arc;

/// How much work a reproduction may spend: `Full` for the documented figures, `Quick` for
/// tests (fewer samples and points; the same curves, noisier).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    Full,
    Quick,
}

impl Quality {
    /// `full` or a tenth of it (at least `min`).
    pub fn samples(&self, full: usize, min: usize) -> usize {
        match self {
            Quality::Full => full,
            Quality::Quick => (full / 10).max(min),
        }
    }

    pub fn points(&self) -> usize {
        match self {
            Quality::Full => 181,
            Quality::Quick => 61,
        }
    }
}

/// A reproduced figure: the drawing and the numbers to print.
pub struct Reproduction {
    pub figure: Panels,
    pub numbers: Vec<String>,
}

/// Every reproducible figure: (name, what it shows).
pub const FIGURES: &[(&str, &str)] = &[
    ("wmlt07-fig2", "transmission lobes f_t|cos θ_o| of the fitted ground glass at 0/30/60/80° (WMLT07 Fig. 2 style)"),
    ("wmlt07-fig8", "D and Smith G1 for Beckmann, Phong and GGX (WMLT07 Fig. 8)"),
    ("ksk01-fig2", "radiance lobes with the Ward density, F = 1, m = 0.1 (KSK01 Fig. 2)"),
    ("ksk01-fig3", "specular albedo for Ward, Beckmann and Phong densities (KSK01 Fig. 3)"),
    ("ksk01-fig5", "specular + matte albedo = 1 for m = 0.8 (KSK01 Fig. 5)"),
    ("tsbrm-fig14", "Simonot's body term against n_i, K_d = 0.9, σ = 0.5, θ_i = 60° (TSBRM Fig. 14)"),
    ("tsbrm-fig18", "Simonot vs Oren–Nayar + Cook–Torrance against σ, θ_i = 60°, n_i = 1.2 (TSBRM Fig. 18)"),
    ("tsbrm-fig19", "Simonot vs Oren–Nayar + Cook–Torrance against n_i, θ_i = 80°, σ = 0.3 (TSBRM Fig. 19)"),
    ("il18-fig6", "flat interfaced Lambertian, K_d = 0.6, n_i = 1, 1.2, 1.33, 1.5 (IL18 Fig. 6)"),
    ("il18-fig7", "total reflectance against σ with and without inter-reflections, K_d = 1, n_i = 1.5 (IL18 Fig. 7)"),
    ("il18-fig9", "V-cavity inter-reflections f_1, f_2, f_∞ (IL18 Fig. 9)"),
    ("il18-fig10", "distributions and masking functions at θ_i = 60° (IL18 Fig. 10)"),
    ("il18-fig15", "approximate body term against the Monte Carlo one (IL18 Fig. 15)"),
    ("il18-fig18", "Oren–Nayar + specular microfacets vs IL, K_d = 0.6, n_i = 1.5 (IL18 Fig. 18)"),
];

/// Reproduces the figure called `name`.
pub fn reproduce(name: &str, q: Quality) -> Result<Reproduction, ParamError> {
    match name {
        "wmlt07-fig2" => wmlt07::fig2(q),
        "wmlt07-fig8" => wmlt07::fig8(q),
        "ksk01-fig2" => ksk01::fig2(q),
        "ksk01-fig3" => ksk01::fig3(q),
        "ksk01-fig5" => ksk01::fig5(q),
        "tsbrm-fig14" => tsbrm::fig14(q),
        "tsbrm-fig18" => tsbrm::fig18(q),
        "tsbrm-fig19" => tsbrm::fig19(q),
        "il18-fig6" => il18::fig6(q),
        "il18-fig7" => il18::fig7(q),
        "il18-fig9" => il18::fig9(q),
        "il18-fig10" => il18::fig10(q),
        "il18-fig15" => il18::fig15(q),
        "il18-fig18" => il18::fig18(q),
        other => Err(ParamError::UnknownChoice {
            what: "figure".into(),
            given: other.into(),
            valid: FIGURES.iter().map(|f| f.0).collect::<Vec<_>>().join(", ") + ", all",
        }),
    }
}

/// A material from its TOML text.
pub(crate) fn material(toml: &str) -> Result<Arc<dyn Bsdf>, ParamError> {
    build_material(&parse_inline_table(toml)?)
}

/// An incidence-plane curve (channel mean) of a BSDF.
pub(crate) fn plane_curve(
    b: &dyn Bsdf,
    theta_i: f64,
    side: Side,
    q: Quantity,
    points: usize,
    samples: usize,
) -> Vec<(f64, f64)> {
    incidence_plane(b, theta_i, side, q, &signed_angles(points), samples, 7)
        .into_iter()
        .map(|(x, v)| (x, Channel::Mean.pick(v)))
        .collect()
}

/// The body BRDF f_b = K_d/(π n_i² (1 − K_d r_i)) · I  [IL18 eq. 13] of an IL material in
/// the incidence plane (channel mean of K_d), from its evaluation mode.
pub(crate) fn body_curve(
    il: &InterfacedLambertian,
    theta_i: f64,
    points: usize,
) -> Vec<(f64, f64)> {
    use crate::plot::bsdf_data::{light_direction, plane_direction};
    use rayon::prelude::*;
    let kd = il.kd().average();
    let ni = il.ni();
    let prefactor = kd / (std::f64::consts::PI * ni * ni * (1.0 - kd * il.r_i()));
    let wi = light_direction(theta_i);
    signed_angles(points)
        .par_iter()
        .map(|&t| {
            let wo = plane_direction(t, Side::Reflection);
            (
                t,
                prefactor * il.body_integral(wi, wo, 0, &mut Pcg32::new(3, 3)).0,
            )
        })
        .collect()
}

/// The value of a curve nearest to x.
pub(crate) fn at(curve: &[(f64, f64)], x: f64) -> f64 {
    curve
        .iter()
        .min_by(|a, b| (a.0 - x).abs().total_cmp(&(b.0 - x).abs()))
        .map_or(f64::NAN, |p| p.1)
}

/// The abscissa of a curve's maximum.
pub(crate) fn argmax(curve: &[(f64, f64)]) -> (f64, f64) {
    curve
        .iter()
        .copied()
        .filter(|p| p.1.is_finite())
        .fold(
            (f64::NAN, f64::NEG_INFINITY),
            |a, p| if p.1 > a.1 { p } else { a },
        )
}

/// One chart in a figure.
pub(crate) fn single(title: &str, c: LineChart) -> Panels {
    let mut p = Panels::new(title, vec![c], 1);
    p.panel_size = (760, 520);
    p
}
