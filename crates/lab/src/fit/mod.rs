//! Fitting BRDF models to measured data (MERL files): model families (interfaced
//! Lambertian, plastic = Lambert + Cook–Torrance, KSK01), the choice of measured samples,
//! the least-squares driver with its error metrics, and the measured-vs-fitted slices of
//! IL18 Fig. 19.

pub mod driver;
pub mod family;
pub mod il_family;
pub mod kelemen_family;
pub mod options;
pub mod plastic_family;
pub mod samples;
pub mod slices;

pub use driver::{fit, ErrorMetric, FitReport};
pub use family::{ModelFamily, Parameter};
pub use il_family::{IlDistribution, IlFamily, IlFitEvaluation};
pub use kelemen_family::KelemenFamily;
pub use options::{FitOptions, FittedModel};
pub use plastic_family::PlasticFamily;
pub use samples::{select_samples, FitSample};
