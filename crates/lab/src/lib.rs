//! # facette-lab
//!
//! What a researcher uses around a BRDF: nonlinear least-squares fitting, the fit of the
//! approximate interfaced-Lambertian body term, plots, the MERL measured-data format,
//! fitting models to measured data, and the reproductions of the papers' figures.

pub mod figures;
pub mod fit;
pub mod il_approx_fit;
pub mod least_squares;
pub mod measure;
pub mod measured_bsdf;
pub mod merl;
pub mod plot;
