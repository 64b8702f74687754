//! The tabulated IL body term against its quadrature [TSBRM §4.3, Fig. 10]: the body
//! BRDF f_b in the incidence plane from the table with trilinear interpolation, from the
//! table's nearest entry (no interpolation, TSBRM Fig. 10 (a)/(c)), and from the
//! quadrature it approximates, with the relative errors printed.

use super::bsdf_data::{light_direction, plane_direction, signed_angles, Side};
use super::line_chart::{LineChart, Series};
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::models::il::il_table::BodyTable;
use facette_bsdf::models::InterfacedLambertian;
use facette_bsdf::Vec3;
use rayon::prelude::*;

/// The curves and their agreement.
#[derive(Clone, Debug)]
pub struct TableComparison {
    pub chart: LineChart,
    /// Mean and maximum relative error of the interpolated table against the quadrature
    /// over the plotted directions with |θ_o| ≤ 80°.
    pub interpolated_error: (f64, f64),
    /// The same for the nearest table entry.
    pub nearest_error: (f64, f64),
}

/// The table's nearest entry (no interpolation).
pub fn nearest_entry(t: &BodyTable, i: Vec3, o: Vec3) -> f64 {
    let step = t.step_deg.to_radians();
    let idx = |v: f64, n: usize| ((v / step).round().max(0.0) as usize).min(n - 1);
    let (si, so) = (i.truncate().length(), o.truncate().length());
    let cos_dphi = if si > 1e-12 && so > 1e-12 {
        ((i.x * o.x + i.y * o.y) / (si * so)).clamp(-1.0, 1.0)
    } else {
        1.0
    };
    let a = idx(i.z.clamp(-1.0, 1.0).acos(), t.n_theta);
    let b = idx(o.z.clamp(-1.0, 1.0).acos(), t.n_theta);
    let c = idx(cos_dphi.acos(), t.n_phi);
    t.values()[(a * t.n_theta + b) * t.n_phi + c]
}

/// Compares `tabled` (an IL material evaluated by `table`) with `quadrature` (the same
/// material evaluated by quadrature) at incidence `theta_i` over `points` directions.
pub fn compare_table(
    table: &BodyTable,
    tabled: &InterfacedLambertian,
    quadrature: &InterfacedLambertian,
    theta_i: f64,
    points: usize,
) -> TableComparison {
    let kd = tabled.kd().average();
    let ni = tabled.ni();
    // f_b = K_d/(π n_i² (1 − K_d r_i)) · I  [IL18 eq. 13].
    let prefactor = kd / (std::f64::consts::PI * ni * ni * (1.0 - kd * tabled.r_i()));
    let wi = light_direction(theta_i);
    let angles = signed_angles(points);
    let rows: Vec<(f64, f64, f64, f64)> = angles
        .par_iter()
        .map(|&t| {
            let wo = plane_direction(t, Side::Reflection);
            let mut rng = Pcg32::new(1, 1);
            let q = quadrature.body_integral(wi, wo, 0, &mut rng).0;
            let interp = tabled.body_integral(wi, wo, 0, &mut rng).0;
            let near = nearest_entry(table, wi, wo);
            (t, prefactor * q, prefactor * interp, prefactor * near)
        })
        .collect();
    let err = |k: usize| {
        let e: Vec<f64> = rows
            .iter()
            .filter(|r| r.0.abs() <= 80.0 && r.1 > 0.0)
            .map(|r| {
                let v = [r.1, r.2, r.3][k];
                ((v - r.1) / r.1).abs()
            })
            .collect();
        (
            e.iter().sum::<f64>() / e.len().max(1) as f64,
            e.iter().copied().fold(0.0, f64::max),
        )
    };
    let mut chart = LineChart::new(
        format!(
            "Tabulated IL body term ({}° grid) vs quadrature, θ_i = {theta_i}°",
            table.step_deg
        ),
        "θ_o (degrees; > 0 on the mirror side)",
        "body BRDF f_b (1/sr)",
    );
    chart.x_range = Some((-90.0, 90.0));
    let col = |k: usize| {
        rows.iter()
            .map(|r| (r.0, [r.1, r.2, r.3][k]))
            .collect::<Vec<_>>()
    };
    chart.series.push(Series::new(
        match quadrature.evaluation() {
            facette_bsdf::models::il::interfaced_lambertian::BodyEvaluation::Quadrature {
                samples,
            } => {
                format!("quadrature ({samples} microfacets)")
            }
            _ => "reference".to_string(),
        },
        col(0),
        6,
    ));
    chart
        .series
        .push(Series::new("table, trilinear interpolation", col(1), 1).dashed());
    chart
        .series
        .push(Series::new("table, nearest entry", col(2), 0));
    TableComparison {
        chart,
        interpolated_error: err(1),
        nearest_error: err(2),
    }
}
