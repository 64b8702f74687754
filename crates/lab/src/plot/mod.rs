//! Plots (plotters; SVG or PNG by the file's extension): line charts with legends and
//! labelled axes (incidence-plane slices, polar lobes, albedo curves, paper figures) and
//! false-colour hemisphere maps (of f, and of a glint footprint's patch NDF), plus the BSDF measurements they show.

pub mod bsdf_data;
pub mod hemisphere_map;
pub mod line_chart;
pub mod ndf_map;
pub mod output;

pub use hemisphere_map::HemisphereMap;
pub use line_chart::{Dash, Guide, LineChart, Panels, Scale, Series};
pub use output::{render_figure, save_figure, Figure, Format, PlotError};
pub mod bsdf_charts;
pub mod table_comparison;
