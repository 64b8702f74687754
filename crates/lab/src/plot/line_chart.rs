//! Line charts: curves with a legend, labelled axes, linear or logarithmic y, optional
//! equal aspect (polar lobes drawn in the incidence plane) and vertical guide lines (the
//! mirror or Snell direction). Several charts can share one figure as [`Panels`].

use super::output::{draw_err, Figure, PlotError};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// A closed interval (lo, hi).
pub type Range = (f64, f64);

/// y axis scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    Linear,
    Log,
}

/// Line pattern of a series.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dash {
    Solid,
    Dashed,
    /// Markers only (measured data).
    Points,
}

/// One curve.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Palette index (series with the same colour index share a colour).
    pub color: usize,
    pub dash: Dash,
}

impl Series {
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>, color: usize) -> Self {
        Series {
            label: label.into(),
            points,
            color,
            dash: Dash::Solid,
        }
    }

    pub fn dashed(mut self) -> Self {
        self.dash = Dash::Dashed;
        self
    }

    pub fn points_only(mut self) -> Self {
        self.dash = Dash::Points;
        self
    }
}

/// A categorical palette (colour-blind friendly, after Okabe & Ito, plus greys).
pub const PALETTE: [RGBColor; 10] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
    RGBColor(120, 120, 120),
    RGBColor(150, 40, 40),
];

/// A color of the palette.
pub fn palette(k: usize) -> RGBColor {
    PALETTE[k % PALETTE.len()]
}

/// A vertical guide line at x with a legend label.
#[derive(Clone, Debug)]
pub struct Guide {
    pub x: f64,
    pub label: String,
}

/// A chart of curves.
#[derive(Clone, Debug)]
pub struct LineChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub y_scale: Scale,
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
    /// Same pixel length for one unit on both axes (polar lobes).
    pub equal_aspect: bool,
    pub guides: Vec<Guide>,
    pub size: (u32, u32),
}

impl LineChart {
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        LineChart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            y_scale: Scale::Linear,
            x_range: None,
            y_range: None,
            equal_aspect: false,
            guides: Vec::new(),
            size: (800, 560),
        }
    }

    fn finite_points(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .filter(move |&(_, y)| self.y_scale == Scale::Linear || y > 0.0)
    }

    /// The x and y ranges to draw: the given ones, or the data's with a margin.
    pub fn ranges(&self) -> Result<(Range, Range), PlotError> {
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for (x, y) in self.finite_points() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        let xr = match self.x_range {
            Some(r) => r,
            None if x0 <= x1 => pad(x0, x1, if self.equal_aspect { 0.04 } else { 0.0 }),
            None => {
                return Err(PlotError::Data(format!(
                    "{}: no finite data to plot",
                    self.title
                )))
            }
        };
        let yr = match (self.y_range, self.y_scale) {
            (Some(r), _) => r,
            (None, _) if y0 > y1 => {
                return Err(PlotError::Data(format!(
                    "{}: no {} data to plot",
                    self.title,
                    if self.y_scale == Scale::Log {
                        "positive"
                    } else {
                        "finite"
                    }
                )))
            }
            (None, Scale::Linear) => {
                let lo = if y0 >= 0.0 && !self.equal_aspect {
                    0.0
                } else {
                    y0
                };
                pad(lo, y1, 0.05)
            }
            (None, Scale::Log) => {
                // Keep at most eight decades below the maximum: zeros of the data would
                // otherwise squash the curves.
                let lo = y0.max(y1 * 1e-8);
                // Start at a power of ten: plotters places the sub-decade ticks (2…9 ×
                // 10^k) upward from the first decade inside the range.
                let start = 10f64.powf(lo.log10().floor());
                let top = 10f64.powf(y1.log10() + 0.1);
                (start, top)
            }
        };
        if self.equal_aspect {
            // Grow the shorter range so that one unit has the same length on both axes.
            let (w, h) = self.plot_area_size();
            let (xs, ys) = ((xr.1 - xr.0) / w, (yr.1 - yr.0) / h);
            if xs > ys {
                let c = 0.5 * (yr.0 + yr.1);
                let half = 0.5 * xs * h;
                return Ok((xr, (c - half, c + half)));
            }
            let c = 0.5 * (xr.0 + xr.1);
            let half = 0.5 * ys * w;
            return Ok(((c - half, c + half), yr));
        }
        Ok((xr, yr))
    }

    /// Approximate plotting-area size in pixels (figure less label areas and margins).
    fn plot_area_size(&self) -> (f64, f64) {
        (
            self.size.0 as f64 - MARGIN * 2.0 - Y_LABEL_AREA,
            self.size.1 as f64 - MARGIN * 2.0 - X_LABEL_AREA - CAPTION,
        )
    }

    /// Draws the chart into an area of any size.
    pub fn draw_in<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError> {
        let (xr, yr) = self.ranges()?;
        let mut b = ChartBuilder::on(area);
        b.caption(&self.title, ("sans-serif", CAPTION as u32 - 10))
            .margin(MARGIN as u32)
            .x_label_area_size(X_LABEL_AREA as u32)
            .y_label_area_size(Y_LABEL_AREA as u32);
        match self.y_scale {
            Scale::Linear => {
                let mut chart = b
                    .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
                    .map_err(draw_err)?;
                self.draw_body(&mut chart, yr)
            }
            Scale::Log => {
                // Drawn as log10(y) on a linear axis labelled with 10^v: plotters' log
                // axis labels only whole decades and sub-decades above the first decade,
                // which leaves short ranges unlabelled.
                let mut chart = b
                    .build_cartesian_2d(xr.0..xr.1, yr.0.log10()..yr.1.log10())
                    .map_err(draw_err)?;
                self.draw_body(&mut chart, yr)
            }
        }
    }

    fn draw_body<'a, DB: DrawingBackend + 'a, Y>(
        &self,
        chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, Y>>,
        yr: (f64, f64),
    ) -> Result<(), PlotError>
    where
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let log = self.y_scale == Scale::Log;
        let fmt_y = move |v: &f64| {
            if log {
                fmt_tick(10f64.powf(*v))
            } else {
                fmt_tick(*v)
            }
        };
        let ty = move |y: f64| if log { y.log10() } else { y };
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .y_label_formatter(&fmt_y)
            .x_label_formatter(&|v: &f64| fmt_tick(*v))
            .axis_desc_style(("sans-serif", 16))
            .label_style(("sans-serif", 13))
            .light_line_style(RGBColor(235, 235, 235))
            .y_labels(if log { 8 } else { 10 })
            .draw()
            .map_err(draw_err)?;
        let clip = |y: f64| match self.y_scale {
            // Below the axis on a log scale: a gap, not a line along the bottom edge.
            Scale::Log => y >= yr.0 && y.is_finite(),
            Scale::Linear => y.is_finite(),
        };
        let mut legend = false;
        for g in &self.guides {
            let style = ShapeStyle::from(&RGBColor(90, 90, 90)).stroke_width(1);
            let pts = vec![(g.x, ty(yr.0)), (g.x, ty(yr.1))];
            let s = chart
                .draw_series(DashedLineSeries::new(pts, 4, 4, style))
                .map_err(draw_err)?;
            if !g.label.is_empty() {
                legend = true;
                s.label(g.label.clone()).legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (4, 0)], style)
                        + PathElement::new(vec![(8, 0), (12, 0)], style)
                        + PathElement::new(vec![(16, 0), (20, 0)], style)
                });
            }
        }
        for s in &self.series {
            let color = palette(s.color);
            let style = ShapeStyle::from(&color).stroke_width(2);
            // Split at gaps (non-finite or, on a log axis, non-positive values).
            let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
            for &(x, y) in &s.points {
                if x.is_finite() && clip(y) {
                    segments.last_mut().expect("non-empty").push((x, ty(y)));
                } else if !segments.last().expect("non-empty").is_empty() {
                    segments.push(Vec::new());
                }
            }
            let mut labelled = false;
            for seg in segments.into_iter().filter(|s| !s.is_empty()) {
                let anno = match s.dash {
                    Dash::Solid => chart.draw_series(LineSeries::new(seg, style)),
                    Dash::Dashed => chart.draw_series(DashedLineSeries::new(seg, 7, 5, style)),
                    Dash::Points => chart.draw_series(
                        seg.into_iter()
                            .map(move |p| Circle::new(p, 2, ShapeStyle::from(&color).filled())),
                    ),
                }
                .map_err(draw_err)?;
                if !labelled && !s.label.is_empty() {
                    labelled = true;
                    legend = true;
                    let label = s.label.clone();
                    match s.dash {
                        Dash::Points => anno.label(label).legend(move |(x, y)| {
                            Circle::new((x + 8, y), 3, ShapeStyle::from(&color).filled())
                        }),
                        Dash::Dashed => anno.label(label).legend(move |(x, y)| {
                            EmptyElement::at((x, y))
                                + PathElement::new(vec![(0, 0), (6, 0)], style)
                                + PathElement::new(vec![(10, 0), (16, 0)], style)
                        }),
                        Dash::Solid => anno.label(label).legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 16, y)], style)
                        }),
                    };
                }
            }
        }
        if legend {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(160, 160, 160))
                .label_font(("sans-serif", 13))
                .position(self.legend_corner(yr))
                .draw()
                .map_err(draw_err)?;
        }
        Ok(())
    }
}

impl LineChart {
    /// The corner of the plot with the fewest data points under a legend-sized box.
    fn legend_corner(&self, yr: (f64, f64)) -> SeriesLabelPosition {
        let Ok((xr, _)) = self.ranges() else {
            return SeriesLabelPosition::UpperRight;
        };
        let ty = |y: f64| match self.y_scale {
            Scale::Linear => (y - yr.0) / (yr.1 - yr.0),
            Scale::Log => (y.max(1e-300).ln() - yr.0.ln()) / (yr.1.ln() - yr.0.ln()),
        };
        let rows = self.series.iter().filter(|s| !s.label.is_empty()).count() + self.guides.len();
        let h = (0.07 * rows as f64 + 0.04).min(0.6);
        let w = 0.42;
        let corners = [
            (SeriesLabelPosition::UpperRight, 1.0 - w, 1.0 - h),
            (SeriesLabelPosition::UpperLeft, 0.0, 1.0 - h),
            (SeriesLabelPosition::LowerRight, 1.0 - w, 0.0),
            (SeriesLabelPosition::LowerLeft, 0.0, 0.0),
        ];
        let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
        for (pos, x0, y0) in corners {
            let n = self
                .finite_points()
                .filter(|&(x, y)| {
                    let (u, v) = ((x - xr.0) / (xr.1 - xr.0), ty(y));
                    u >= x0 && u <= x0 + w && v >= y0 && v <= y0 + h
                })
                .count();
            if n < best.0 {
                best = (n, pos);
            }
        }
        best.1
    }
}

const MARGIN: f64 = 12.0;
const X_LABEL_AREA: f64 = 48.0;
const Y_LABEL_AREA: f64 = 72.0;
const CAPTION: f64 = 30.0;

fn pad(lo: f64, hi: f64, frac: f64) -> (f64, f64) {
    if hi > lo {
        let d = (hi - lo) * frac;
        (lo - if lo == 0.0 { 0.0 } else { d }, hi + d)
    } else {
        let d = lo.abs().max(1e-3) * 0.1;
        (lo - d, hi + d)
    }
}

/// Compact tick labels: plain numbers in [1e-3, 1e4), scientific notation otherwise.
pub fn fmt_tick(v: f64) -> String {
    // Three significant digits: removes the float noise of computed tick positions.
    let v = if v != 0.0 && v.is_finite() {
        let e = 10f64.powf(v.abs().log10().floor() - 2.0);
        (v / e).round() * e
    } else {
        v
    };
    let a = v.abs();
    if a < 1e-12 {
        "0".into()
    } else if !(1e-3..1e4).contains(&a) {
        let e = a.log10().floor();
        let m = v / 10f64.powf(e);
        if (m.abs() - 1.0).abs() < 1e-6 {
            format!("{}1e{e}", if v < 0.0 { "-" } else { "" })
        } else {
            format!("{m:.1}e{e}")
        }
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    }
}

impl Figure for LineChart {
    fn size(&self) -> (u32, u32) {
        self.size
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        self.draw_in(root)
    }
}

/// Several charts in a grid under one title.
#[derive(Clone, Debug)]
pub struct Panels {
    pub title: String,
    pub charts: Vec<LineChart>,
    pub columns: usize,
    /// Size of one panel.
    pub panel_size: (u32, u32),
}

impl Panels {
    pub fn new(title: impl Into<String>, charts: Vec<LineChart>, columns: usize) -> Self {
        Panels {
            title: title.into(),
            charts,
            columns: columns.max(1),
            panel_size: (640, 460),
        }
    }

    fn rows(&self) -> usize {
        self.charts.len().div_ceil(self.columns).max(1)
    }
}

impl Figure for Panels {
    fn size(&self) -> (u32, u32) {
        let title = if self.title.is_empty() { 0 } else { 36 };
        (
            self.panel_size.0 * self.columns.min(self.charts.len().max(1)) as u32,
            self.panel_size.1 * self.rows() as u32 + title,
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let area = if self.title.is_empty() {
            root.clone()
        } else {
            root.titled(&self.title, ("sans-serif", 22))
                .map_err(draw_err)?
        };
        let cols = self.columns.min(self.charts.len().max(1));
        let cells = area.split_evenly((self.rows(), cols));
        for (chart, cell) in self.charts.iter().zip(cells.iter()) {
            let mut c = chart.clone();
            c.size = self.panel_size;
            c.draw_in(cell)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::output::{render_figure, Format};

    #[test]
    fn ranges_and_ticks() {
        let mut c = LineChart::new("t", "x", "y");
        c.series
            .push(Series::new("a", vec![(0.0, 1.0), (1.0, 3.0)], 0));
        let ((x0, x1), (y0, y1)) = c.ranges().unwrap();
        assert_eq!((x0, x1), (0.0, 1.0));
        assert!(y0 == 0.0 && y1 > 3.0);
        c.y_scale = Scale::Log;
        c.series
            .push(Series::new("b", vec![(0.5, 0.0), (0.7, 1e-3)], 1));
        let (_, (y0, y1)) = c.ranges().unwrap();
        assert!(y0 <= 1e-3 && y0 > 0.0 && y1 >= 3.0, "{y0} {y1}");
        assert_eq!(fmt_tick(0.25), "0.25");
        assert_eq!(fmt_tick(1e-5), "1e-5");
        assert_eq!(fmt_tick(2.5e5), "2.5e5");
        let empty = LineChart::new("empty", "x", "y");
        assert!(empty
            .ranges()
            .unwrap_err()
            .to_string()
            .contains("no finite data"));
    }

    #[test]
    fn svg_has_labels_and_legend() {
        let mut c = LineChart::new("Title here", "θ_o (degrees)", "f (1/sr)");
        c.series
            .push(Series::new("curve one", vec![(0.0, 1.0), (1.0, 2.0)], 0));
        c.series
            .push(Series::new("curve two", vec![(0.0, 2.0), (1.0, 0.5)], 1).dashed());
        let svg = String::from_utf8(render_figure(&c, Format::Svg).unwrap()).unwrap();
        for s in [
            "Title here",
            "θ_o (degrees)",
            "f (1/sr)",
            "curve one",
            "curve two",
        ] {
            assert!(svg.contains(s), "missing {s}");
        }
        let png = render_figure(&c, Format::Png).unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }
}
