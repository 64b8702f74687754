//! Hemisphere maps: a scalar function of the outgoing direction drawn in false colour over
//! the projected disk (x = sin θ_o cos φ_o, y = sin θ_o sin φ_o — the orthographic view of
//! the hemisphere from above, so equal areas of the disk carry equal projected solid
//! angle), with a colour bar, θ_o circles every 30° and a marker at the light's mirror
//! direction.

use super::line_chart::{fmt_tick, Scale};
use super::output::{draw_err, Figure, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Values on an n × n grid over [−1, 1]²; `None` outside the disk.
#[derive(Clone, Debug)]
pub struct HemisphereMap {
    pub title: String,
    /// What the colours mean, with units.
    pub value_label: String,
    pub n: usize,
    /// Row-major, row 0 at y = −1.
    pub values: Vec<Option<f64>>,
    pub scale: Scale,
    /// Points to mark (x, y on the disk) with labels.
    pub markers: Vec<((f64, f64), String)>,
    /// Axis titles: the direction the disk shows (ω_o by default; ω_h for an NDF).
    pub axes: [String; 2],
    pub size: (u32, u32),
}

impl HemisphereMap {
    /// Samples `f(x, y)` (called only inside the unit disk) on an n × n grid of cell centres.
    pub fn sample(
        title: impl Into<String>,
        value_label: impl Into<String>,
        n: usize,
        f: impl Fn(f64, f64) -> f64 + Sync,
    ) -> Self {
        use rayon::prelude::*;
        let values = (0..n * n)
            .into_par_iter()
            .map(|k| {
                let (x, y) = Self::cell_centre(n, k);
                (x * x + y * y < 1.0).then(|| f(x, y))
            })
            .collect();
        HemisphereMap {
            title: title.into(),
            value_label: value_label.into(),
            n,
            values,
            scale: Scale::Linear,
            markers: Vec::new(),
            axes: [
                "x = sin θ_o cos φ_o".to_string(),
                "y = sin θ_o sin φ_o".to_string(),
            ],
            size: (720, 600),
        }
    }

    /// Centre (x, y) of cell k.
    pub fn cell_centre(n: usize, k: usize) -> (f64, f64) {
        let (r, c) = (k / n, k % n);
        let h = 2.0 / n as f64;
        (-1.0 + (c as f64 + 0.5) * h, -1.0 + (r as f64 + 0.5) * h)
    }

    /// (min, max) of the finite values drawn (positive ones on a log scale).
    pub fn value_range(&self) -> Result<(f64, f64), PlotError> {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for v in self.values.iter().flatten() {
            if v.is_finite() && (self.scale == Scale::Linear || *v > 0.0) {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
        if lo > hi {
            return Err(PlotError::Data(format!("{}: nothing to draw", self.title)));
        }
        if self.scale == Scale::Log {
            lo = lo.max(hi * 1e-6);
        }
        if hi <= lo {
            hi = lo + lo.abs().max(1e-6);
        }
        Ok((lo, hi))
    }

    fn normalized(&self, v: f64, (lo, hi): (f64, f64)) -> f64 {
        let t = match self.scale {
            Scale::Linear => (v - lo) / (hi - lo),
            Scale::Log => (v.max(lo).ln() - lo.ln()) / (hi.ln() - lo.ln()),
        };
        t.clamp(0.0, 1.0)
    }
}

/// The "viridis" colour map as nine anchors, linearly interpolated.
pub fn colormap(t: f64) -> RGBColor {
    const A: [(f64, f64, f64); 9] = [
        (68.0, 1.0, 84.0),
        (71.0, 44.0, 122.0),
        (59.0, 81.0, 139.0),
        (44.0, 113.0, 142.0),
        (33.0, 144.0, 141.0),
        (39.0, 173.0, 129.0),
        (92.0, 200.0, 99.0),
        (170.0, 220.0, 50.0),
        (253.0, 231.0, 37.0),
    ];
    let x = t.clamp(0.0, 1.0) * (A.len() - 1) as f64;
    let k = (x.floor() as usize).min(A.len() - 2);
    let f = x - k as f64;
    let mix = |a: f64, b: f64| (a + (b - a) * f).round() as u8;
    RGBColor(
        mix(A[k].0, A[k + 1].0),
        mix(A[k].1, A[k + 1].1),
        mix(A[k].2, A[k + 1].2),
    )
}

impl Figure for HemisphereMap {
    fn size(&self) -> (u32, u32) {
        self.size
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let range = self.value_range()?;
        let area = root
            .titled(&self.title, ("sans-serif", 20))
            .map_err(draw_err)?;
        let (w, _) = area.dim_in_pixel();
        let (disk_area, bar_area) = area.split_horizontally(w.saturating_sub(150));
        let mut chart = ChartBuilder::on(&disk_area)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(-1.05f64..1.05f64, -1.05f64..1.05f64)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(self.axes[0].as_str())
            .y_desc(self.axes[1].as_str())
            .axis_desc_style(("sans-serif", 15))
            .label_style(("sans-serif", 12))
            .x_label_formatter(&|v: &f64| fmt_tick(if v.abs() < 1e-9 { 0.0 } else { *v }))
            .y_label_formatter(&|v: &f64| fmt_tick(if v.abs() < 1e-9 { 0.0 } else { *v }))
            .draw()
            .map_err(draw_err)?;
        let h = 2.0 / self.n as f64;
        chart
            .draw_series(self.values.iter().enumerate().filter_map(|(k, v)| {
                let v = (*v)?;
                let (x, y) = HemisphereMap::cell_centre(self.n, k);
                let c = if v.is_finite() {
                    colormap(self.normalized(v, range))
                } else {
                    RGBColor(255, 0, 255)
                };
                Some(Rectangle::new(
                    [(x - 0.5 * h, y - 0.5 * h), (x + 0.5 * h, y + 0.5 * h)],
                    c.filled(),
                ))
            }))
            .map_err(draw_err)?;
        let grey = RGBColor(255, 255, 255).mix(0.7);
        for deg in [30.0f64, 60.0, 90.0] {
            let r = deg.to_radians().sin();
            let pts: Vec<(f64, f64)> = (0..=120)
                .map(|k| {
                    let a = k as f64 / 120.0 * std::f64::consts::TAU;
                    (r * a.cos(), r * a.sin())
                })
                .collect();
            chart
                .draw_series(LineSeries::new(pts, grey.stroke_width(1)))
                .map_err(draw_err)?;
            chart
                .draw_series(std::iter::once(Text::new(
                    format!("{deg:.0}°"),
                    (
                        r * std::f64::consts::FRAC_1_SQRT_2 + 0.01,
                        r * std::f64::consts::FRAC_1_SQRT_2 + 0.01,
                    ),
                    ("sans-serif", 12).into_font().color(&WHITE),
                )))
                .map_err(draw_err)?;
        }
        for ((x, y), label) in &self.markers {
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at((*x, *y))
                        + Cross::new((0, 0), 6, ShapeStyle::from(&RED).stroke_width(2))
                        + Text::new(
                            label.clone(),
                            (8, -14),
                            ("sans-serif", 13).into_font().color(&RED),
                        ),
                ))
                .map_err(draw_err)?;
        }
        // Colour bar.
        let (lo, hi) = range;
        let (t0, t1) = match self.scale {
            Scale::Linear => (lo, hi),
            Scale::Log => (lo.log10(), hi.log10()),
        };
        let mut bar = ChartBuilder::on(&bar_area)
            .caption(self.value_label.as_str(), ("sans-serif", 14))
            .margin_top(10)
            .margin_bottom(50)
            .margin_right(10)
            .y_label_area_size(0)
            .right_y_label_area_size(70)
            .build_cartesian_2d(0.0f64..1.0f64, t0..t1)
            .map_err(draw_err)?;
        let scale = self.scale;
        let label = move |v: &f64| match scale {
            Scale::Linear => fmt_tick(*v),
            Scale::Log => fmt_tick(10f64.powf(*v)),
        };
        bar.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_label_formatter(&label)
            .label_style(("sans-serif", 12))
            .draw()
            .map_err(draw_err)?;
        let steps = 100;
        bar.draw_series((0..steps).map(|k| {
            let a = t0 + (t1 - t0) * k as f64 / steps as f64;
            let b = t0 + (t1 - t0) * (k + 1) as f64 / steps as f64;
            Rectangle::new(
                [(0.0, a), (1.0, b)],
                colormap((k as f64 + 0.5) / steps as f64).filled(),
            )
        }))
        .map_err(draw_err)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::output::{render_figure, Format};

    #[test]
    fn samples_the_disk_only_and_renders() {
        let m = HemisphereMap::sample("map", "f (1/sr)", 16, |x, y| 1.0 + x * x + y);
        let inside = m.values.iter().filter(|v| v.is_some()).count();
        // π/4 of the cells, within the pixelation of a 16 × 16 grid.
        assert!((inside as f64 / 256.0 - std::f64::consts::FRAC_PI_4).abs() < 0.05);
        let (lo, hi) = m.value_range().unwrap();
        assert!(lo > 0.0 && hi < 3.0 && lo < hi);
        let svg = String::from_utf8(render_figure(&m, Format::Svg).unwrap()).unwrap();
        assert!(svg.contains("f (1/sr)") && svg.contains("sin θ_o"));
        assert_eq!(colormap(0.0), RGBColor(68, 1, 84));
        assert_eq!(colormap(1.0), RGBColor(253, 231, 37));
    }
}
