//! WMLT07 figures: Fig. 8 (D and G1 of Beckmann, Phong and GGX) and a Fig. 2-style plot of
//! the fitted ground glass's transmission (the paper's Fig. 2 is measured data; we draw
//! the model fitted to it, WMLT07 Fig. 12's GGX α = 0.394, n = 1.51).

use super::{argmax, material, plane_curve, single, Quality, Reproduction};
use crate::plot::bsdf_data::{Quantity, Side};
use crate::plot::{Guide, LineChart, Panels, Scale, Series};
use facette_bsdf::math::spherical_direction;
use facette_bsdf::microfacet::{Beckmann, Distribution, Ggx, Phong};
use facette_bsdf::ParamError;

/// WMLT07 Fig. 8: D(m) against θ_m for Beckmann α_b = 0.2, Phong α_p = 48 and GGX
/// α_g = 0.2  [WMLT07 eqs. 25, 30, 33]; Smith G1(v) against θ_v for Beckmann and GGX
/// [WMLT07 eqs. 27, 34].
pub fn fig8(_: Quality) -> Result<Reproduction, ParamError> {
    let b = Beckmann::isotropic(0.2)?;
    let p = Phong::new(48.0)?;
    let g = Ggx::isotropic(0.2)?;
    let thetas: Vec<f64> = (0..=180).map(|k| k as f64 * 0.5).collect();
    let d_curve = |d: &dyn Distribution| -> Vec<(f64, f64)> {
        thetas
            .iter()
            .map(|&t| (t, d.d(spherical_direction(t.to_radians(), 0.0))))
            .collect()
    };
    let g1_curve = |d: &dyn Distribution| -> Vec<(f64, f64)> {
        thetas
            .iter()
            .map(|&t| {
                let v = spherical_direction(t.min(89.99).to_radians(), 0.0);
                (t, d.g1(v, facette_bsdf::Vec3::Z))
            })
            .collect()
    };
    let (db, dp, dg) = (d_curve(&b), d_curve(&p), d_curve(&g));
    let mut left = LineChart::new("D(m), log scale", "θ_m (degrees)", "D (1/sr)");
    left.y_scale = Scale::Log;
    left.x_range = Some((0.0, 90.0));
    left.y_range = Some((1e-6, 20.0));
    left.series
        .push(Series::new("Beckmann α_b = 0.2", db.clone(), 9));
    left.series
        .push(Series::new("Phong α_p = 48", dp.clone(), 0).dashed());
    left.series
        .push(Series::new("GGX α_g = 0.2", dg.clone(), 2));
    let (gb, gg) = (g1_curve(&b), g1_curve(&g));
    let mut right = LineChart::new("Smith G1(v, n)", "θ_v (degrees)", "G1");
    right.x_range = Some((0.0, 90.0));
    right.y_range = Some((0.0, 1.05));
    right
        .series
        .push(Series::new("Beckmann α_b = 0.2", gb.clone(), 9));
    right
        .series
        .push(Series::new("GGX α_g = 0.2", gg.clone(), 2));
    let v = |c: &[(f64, f64)], x: f64| super::at(c, x);
    let numbers = vec![
        format!(
            "D(θ_m = 0): Beckmann {:.4}, Phong {:.4}, GGX {:.4} (all 1/(π α²) = {:.4})",
            v(&db, 0.0),
            v(&dp, 0.0),
            v(&dg, 0.0),
            1.0 / (std::f64::consts::PI * 0.04)
        ),
        format!(
            "D(θ_m = 20°): Beckmann {:.4}, Phong {:.4}, GGX {:.4}; D(45°): Beckmann {:.2e}, Phong {:.2e}, GGX {:.2e}",
            v(&db, 20.0),
            v(&dp, 20.0),
            v(&dg, 20.0),
            v(&db, 45.0),
            v(&dp, 45.0),
            v(&dg, 45.0)
        ),
        format!(
            "G1(θ_v = 80°): Beckmann {:.4}, GGX {:.4}; G1(85°): Beckmann {:.4}, GGX {:.4}",
            v(&gb, 80.0),
            v(&gg, 80.0),
            v(&gb, 85.0),
            v(&gg, 85.0)
        ),
    ];
    let mut fig = Panels::new(
        "WMLT07 Fig. 8: distributions and Smith shadowing",
        vec![left, right],
        2,
    );
    fig.panel_size = (620, 460);
    Ok(Reproduction {
        figure: fig,
        numbers,
    })
}

/// WMLT07 Fig. 2 style: f_t(i, o)|o·n| of the ground glass (GGX fit of Fig. 12) in the
/// incidence plane at 0, 30, 60 and 80° incidence, with the Snell directions of a smooth
/// surface dashed.
pub fn fig2(q: Quality) -> Result<Reproduction, ParamError> {
    let glass = material(r#"{type = "dielectric", preset = "ground", distribution = "ggx"}"#)?;
    let mut c = LineChart::new(
        "transmission through ground glass (GGX α = 0.394, n = 1.51)",
        "θ_o from −n (degrees; > 0 on the refraction side)",
        "f_t·|cos θ_o| (1/sr)",
    );
    c.x_range = Some((-90.0, 90.0));
    let mut numbers = Vec::new();
    for (k, t) in [0.0f64, 30.0, 60.0, 80.0].into_iter().enumerate() {
        let curve = plane_curve(
            glass.as_ref(),
            t,
            Side::Transmission,
            Quantity::FCosO,
            q.points().max(181),
            1,
        );
        let snell = (t.to_radians().sin() / 1.51).asin().to_degrees();
        let (peak, value) = argmax(&curve);
        numbers.push(format!(
            "θ_i = {t}°: peak at θ_o = {peak:.1}° (f_t|cos θ_o| = {value:.3} 1/sr), smooth-surface refraction at {snell:.1}°: shift {:.1}° toward grazing",
            peak - snell
        ));
        c.series.push(Series::new(format!("θ_i = {t}°"), curve, k));
        c.guides.push(Guide {
            x: snell,
            label: if k == 0 {
                "Snell directions".into()
            } else {
                String::new()
            },
        });
    }
    Ok(Reproduction {
        figure: single("WMLT07 Fig. 2 style: rough transmission", c),
        numbers,
    })
}
