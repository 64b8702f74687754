//! The standard BSDF figures of `facette plot`, for one or more labelled materials:
//! incidence-plane slices, polar lobes, hemisphere maps and directional albedo.

use super::bsdf_data::{
    albedo_curve, incidence_plane, light_direction, polar_points, quantity_value, signed_angles,
    Channel, Quantity, Side,
};
use super::hemisphere_map::HemisphereMap;
use super::line_chart::{Guide, LineChart, Scale, Series};
use facette_bsdf::math::rng::mix_seed;
use facette_bsdf::{Bsdf, Vec3};
use std::sync::Arc;

/// A material with the name its curves carry in the legend.
#[derive(Clone)]
pub struct LabelledBsdf {
    pub label: String,
    pub bsdf: Arc<dyn Bsdf>,
}

/// Options shared by slices and polar lobes.
#[derive(Clone, Debug)]
pub struct SliceOptions {
    pub thetas_i: Vec<f64>,
    pub side: Side,
    pub quantity: Quantity,
    pub channel: Channel,
    pub scale: Scale,
    /// Points over [−90°, 90°].
    pub points: usize,
    /// Estimates per value for stochastic models.
    pub samples: usize,
    pub seed: u64,
}

impl Default for SliceOptions {
    fn default() -> Self {
        SliceOptions {
            thetas_i: vec![30.0],
            side: Side::Reflection,
            quantity: Quantity::F,
            channel: Channel::Mean,
            scale: Scale::Linear,
            points: 181,
            samples: 20_000,
            seed: 1,
        }
    }
}

fn series_label(m: &LabelledBsdf, theta_i: f64, n_mats: usize, n_thetas: usize) -> String {
    match (n_mats > 1, n_thetas > 1) {
        (true, true) => format!("{}, θ_i = {theta_i}°", m.label),
        (true, false) => m.label.clone(),
        (false, _) => format!("θ_i = {theta_i}°"),
    }
}

fn side_name(side: Side) -> &'static str {
    match side {
        Side::Reflection => "reflection",
        Side::Transmission => "transmission",
    }
}

/// Incidence-plane curves of every material at every θ_i.
pub fn slice_chart(mats: &[LabelledBsdf], o: &SliceOptions) -> LineChart {
    let title = if mats.len() == 1 {
        format!("{} — incidence plane, {}", mats[0].label, side_name(o.side))
    } else {
        format!("Incidence plane, {}", side_name(o.side))
    };
    let mut c = LineChart::new(
        title,
        match o.side {
            Side::Reflection => "θ_o (degrees; > 0 on the mirror side)",
            Side::Transmission => "θ_o from −n (degrees; > 0 on the refraction side)",
        },
        o.quantity.label(),
    );
    c.y_scale = o.scale;
    c.x_range = Some((-90.0, 90.0));
    if o.side == Side::Reflection {
        c.guides = mirror_guides(&o.thetas_i);
    }
    let angles = signed_angles(o.points);
    let mut color = 0;
    for (mi, m) in mats.iter().enumerate() {
        for (ti, &t) in o.thetas_i.iter().enumerate() {
            let seed = mix_seed(o.seed, (mi * 1000 + ti) as u64);
            let data = incidence_plane(
                m.bsdf.as_ref(),
                t,
                o.side,
                o.quantity,
                &angles,
                o.samples,
                seed,
            );
            let pts = data.iter().map(|(x, v)| (*x, o.channel.pick(*v))).collect();
            let mut s = Series::new(series_label(m, t, mats.len(), o.thetas_i.len()), pts, color);
            if mi % 2 == 1 && o.thetas_i.len() > 1 {
                s = s.dashed();
            }
            c.series.push(s);
            color += 1;
        }
    }
    c
}

/// Polar lobes in the incidence plane: the distance from the origin is the plotted
/// quantity in that direction; the light arrives from the right (+x).
pub fn polar_chart(mats: &[LabelledBsdf], o: &SliceOptions) -> LineChart {
    polar_from_slice(slice_chart(mats, o), o)
}

/// The polar view of a chart made by [`slice_chart`] with the same options.
pub fn polar_from_slice(slice: LineChart, o: &SliceOptions) -> LineChart {
    let mut c = slice;
    c.title = c
        .title
        .replace("incidence plane", "polar lobes")
        .replace("Incidence plane", "Polar lobes");
    c.x_label = format!("{} along x (light on the +x side)", o.quantity.label());
    c.y_label = format!("{} along the normal", o.quantity.label());
    c.y_scale = Scale::Linear;
    c.x_range = None;
    c.equal_aspect = true;
    c.guides.clear();
    for s in &mut c.series {
        s.points = polar_points(&s.points, o.side);
    }
    // The light directions, as short rays from the origin.
    let r = c
        .series
        .iter()
        .flat_map(|s| s.points.iter())
        .map(|(x, y)| (x * x + y * y).sqrt())
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    for &t in &o.thetas_i {
        let d = light_direction(t);
        c.series.push(
            Series::new(
                if o.thetas_i.len() == 1 {
                    "light direction".to_string()
                } else {
                    String::new()
                },
                vec![(0.0, 0.0), (0.6 * d.x * r, 0.6 * d.z * r)],
                8,
            )
            .dashed(),
        );
    }
    c
}

/// A false-colour map of the quantity over the outgoing hemisphere for one θ_i.
#[allow(clippy::too_many_arguments)]
pub fn hemisphere_chart(
    m: &LabelledBsdf,
    theta_i: f64,
    quantity: Quantity,
    channel: Channel,
    scale: Scale,
    resolution: usize,
    samples: usize,
    seed: u64,
) -> HemisphereMap {
    let wi = light_direction(theta_i);
    let bsdf = m.bsdf.clone();
    let mut map = HemisphereMap::sample(
        format!("{} — θ_i = {theta_i}°", m.label),
        quantity.label(),
        resolution,
        move |x, y| {
            let z = (1.0 - x * x - y * y).max(1e-6).sqrt();
            let wo = Vec3::new(x, y, z);
            let k = ((x + 2.0) * 1e6) as u64 ^ (((y + 2.0) * 1e6) as u64) << 24;
            channel.pick(quantity_value(
                bsdf.as_ref(),
                quantity,
                wi,
                wo,
                samples,
                mix_seed(seed, k),
            ))
        },
    );
    map.scale = scale;
    map.markers.push(((-wi.x, -wi.y), "mirror".to_string()));
    map
}

/// Directional reflectance (and transmittance where the material transmits) against θ_i.
pub fn albedo_chart(mats: &[LabelledBsdf], thetas: &[f64], samples: usize, seed: u64) -> LineChart {
    let mut c = LineChart::new(
        "Directional albedo",
        "θ_i (degrees)",
        "albedo (fraction of the incident flux)",
    );
    c.x_range = Some((0.0, 90.0));
    for (k, m) in mats.iter().enumerate() {
        let data = albedo_curve(m.bsdf.as_ref(), thetas, samples, seed);
        let transmits = data.iter().any(|d| d.3.average() > 0.0);
        let r: Vec<(f64, f64)> = data.iter().map(|d| (d.0, d.1.average())).collect();
        let name = |what: &str| {
            if mats.len() == 1 {
                what.to_string()
            } else {
                format!("{}: {what}", m.label)
            }
        };
        c.series.push(Series::new(name("reflectance R"), r, k));
        if transmits {
            let t: Vec<(f64, f64)> = data.iter().map(|d| (d.0, d.3.average())).collect();
            let rt: Vec<(f64, f64)> = data
                .iter()
                .map(|d| (d.0, d.1.average() + d.3.average()))
                .collect();
            c.series
                .push(Series::new(name("transmittance T"), t, k).dashed());
            c.series
                .push(Series::new(name("R + T"), rt, k).points_only());
        }
    }
    if mats.len() == 1 {
        c.title = format!("{} — directional albedo", mats[0].label);
    }
    c
}

/// A vertical guide at the mirror direction of each θ_i (reflection slices).
pub fn mirror_guides(thetas: &[f64]) -> Vec<Guide> {
    thetas
        .iter()
        .enumerate()
        .map(|(k, &t)| Guide {
            x: t,
            label: if k == 0 {
                "mirror direction".into()
            } else {
                String::new()
            },
        })
        .collect()
}

/// Per-series summary lines: the maximum and where it is, the minimum, the mean.
pub fn summarize(c: &LineChart) -> Vec<String> {
    c.series
        .iter()
        .filter(|s| !s.label.is_empty())
        .map(|s| {
            let finite: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|p| p.1.is_finite())
                .collect();
            let (xm, ym) = finite
                .iter()
                .copied()
                .fold(
                    (f64::NAN, f64::NEG_INFINITY),
                    |a, p| if p.1 > a.1 { p } else { a },
                );
            let ymin = finite.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
            let mean = finite.iter().map(|p| p.1).sum::<f64>() / finite.len().max(1) as f64;
            format!(
                "{}: max {:.6e} at x = {:.2}, min {:.6e}, mean {:.6e} over {} points",
                s.label,
                ym,
                xm,
                ymin,
                mean,
                finite.len()
            )
        })
        .collect()
}

/// The chart's data as CSV: `series,x,y`.
pub fn chart_csv(c: &LineChart) -> String {
    let mut s = format!(
        "series,{},{}\n",
        csv_field(&c.x_label),
        csv_field(&c.y_label)
    );
    for ser in &c.series {
        for (x, y) in &ser.points {
            s += &format!("{},{x:.9e},{y:.9e}\n", csv_field(&ser.label));
        }
    }
    s
}

fn csv_field(s: &str) -> String {
    if s.contains(',') || s.contains('"') {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}
