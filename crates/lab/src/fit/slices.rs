//! Measured against fitted BRDF in the incidence plane at θ_i = 30° and 70° (IL18
//! Fig. 19), log scale, one colour per channel: measured values as points (nearest MERL
//! bin), the fit as lines.

use super::driver::predict_at;
use super::family::ModelFamily;
use crate::merl::MerlBrdf;
use crate::plot::bsdf_data::{light_direction, plane_direction, signed_angles, Side};
use crate::plot::{LineChart, Panels, Scale, Series};
use facette_bsdf::ParamError;

/// Palette indices for the R, G, B channels.
const CHANNEL_COLOURS: [usize; 3] = [9, 2, 0];
const CHANNEL_NAMES: [&str; 3] = ["red", "green", "blue"];

/// The two-panel comparison figure.
pub fn fit_slices(
    merl: &MerlBrdf,
    family: &dyn ModelFamily,
    values: &[f64],
    title: &str,
    thetas_i: &[f64],
) -> Result<Panels, ParamError> {
    let angles = signed_angles(179);
    let mut charts = Vec::new();
    for &t in thetas_i {
        let wi = light_direction(t);
        let pairs: Vec<_> = angles
            .iter()
            .map(|&a| (wi, plane_direction(a, Side::Reflection)))
            .collect();
        let fitted = predict_at(family, values, &pairs)?;
        let mut c = LineChart::new(
            format!("θ_i = {t}°"),
            "θ_o (degrees; > 0 on the mirror side)",
            "f (1/sr)",
        );
        c.y_scale = Scale::Log;
        c.x_range = Some((-90.0, 90.0));
        for ch in 0..3 {
            let measured: Vec<(f64, f64)> = angles
                .iter()
                .zip(&pairs)
                .map(|(&a, &(i, o))| (a, merl.lookup(i, o).map_or(f64::NAN, |v| v[ch])))
                .collect();
            c.series.push(
                Series::new(
                    format!("measured, {}", CHANNEL_NAMES[ch]),
                    measured,
                    CHANNEL_COLOURS[ch],
                )
                .points_only(),
            );
            let fit: Vec<(f64, f64)> = angles
                .iter()
                .zip(&fitted)
                .map(|(&a, f)| (a, f[ch]))
                .collect();
            c.series.push(Series::new(
                format!("fit, {}", CHANNEL_NAMES[ch]),
                fit,
                CHANNEL_COLOURS[ch],
            ));
        }
        charts.push(c);
    }
    Ok(Panels::new(title, charts, 2))
}
