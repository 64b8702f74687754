//! # facette-lab
//!
//! What a researcher uses around a BRDF: nonlinear least-squares fitting, the fit of the
//! approximate interfaced-Lambertian body term, and (as they land) plots, measured-data
//! readers and paper reproductions.

pub mod il_approx_fit;
pub mod least_squares;
