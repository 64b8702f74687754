//! The interfaced-Lambertian family [IL18, TSBRM]: Lambertian microfacets under a flat
//! interface.
//!
//! - [`interfaced_lambertian`]: the model (flat and rough, specular lobe and body term);
//! - [`vcavity`]: its V-cavity inter-reflections (IL18 §3.3);
//! - [`il_table`], [`il_table_part`]: the body integral tabulated on a (θ_i, θ_o, φ_o) grid
//!   (TSBRM §4.3), whole or in parts;
//! - [`il_approx`], [`il_approx_coefficients`]: its approximate closed form (IL18 §4.2)
//!   and the fitted coefficients (a generated table).

pub mod il_approx;
pub mod il_approx_coefficients;
pub mod il_table;
pub mod il_table_part;
pub mod interfaced_lambertian;
pub mod vcavity;
pub mod vcavity_quadrature;

pub use interfaced_lambertian::InterfacedLambertian;
