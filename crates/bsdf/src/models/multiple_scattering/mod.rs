//! What single scattering loses: light that meets several microfacets.
//!
//! - [`smith_microsurface`]: the random walk on the Smith microsurface [HHdD16], shared by
//!   [`multiple_scattering_conductor`] and [`multiple_scattering_dielectric`];
//! - [`random_walk`]: what the two walk models share — the lobe they extend and their MIS
//!   proxy density;
//! - [`albedo_tables`]: directional albedos of the single-scattering lobes, shared by the
//!   energy-compensated [`compensated_conductor`] and [`compensated_dielectric`] [KC17]
//!   (and the walk models' proxy), their entries integrated by [`albedo_quadrature`];
//!   [`albedo_row`]: a table's row at a material's α, what those models read per call.

pub mod albedo_quadrature;
pub mod albedo_row;
pub mod albedo_tables;
pub mod compensated_conductor;
pub mod compensated_dielectric;
pub mod multiple_scattering_conductor;
pub mod multiple_scattering_dielectric;
pub mod random_walk;
pub mod smith_microsurface;

pub use compensated_conductor::CompensatedConductor;
pub use compensated_dielectric::CompensatedDielectric;
pub use multiple_scattering_conductor::MultipleScatteringConductor;
pub use multiple_scattering_dielectric::MultipleScatteringDielectric;
