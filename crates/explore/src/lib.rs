//! `facette explore`: an interactive BRDF explorer in the browser. A local web server
//! (axum on tokio) serves a single-page app embedded in the binary and evaluates materials
//! in `f64` through the bsdf crate, streaming the numbers as binary arrays:
//!
//! - [`server`]: the routes, the loopback-only guard and graceful shutdown;
//! - [`schema_json`]: the material schema ([`facette_bsdf::recipe::schema`]) as JSON, from
//!   which the app generates its controls;
//! - [`material`]: a material table parsed by the grammar, with its error messages;
//! - [`views`]: the numbers behind each view (incidence-plane slice, hemisphere map,
//!   directional albedo), computed in parallel and abandoned when the request is;
//! - [`preview`]: the live preview, path-traced passes of a sphere under a sky;
//! - [`patch_ndf`]: the patch NDF of a glint material's footprint;
//! - [`fitting`]: a measured file fitted by a model, with the comparison slices;
//! - [`validation`]: the material's `validate` checks;
//! - [`frame`]: the binary encoding of a view's arrays;
//! - [`assets`]: the app's files, embedded at compile time.

pub mod assets;
pub mod cancel;
pub mod fitting;
pub mod frame;
pub mod material;
pub mod patch_ndf;
pub mod preview;
pub mod schema_json;
pub mod server;
pub mod validation;
pub mod views;

pub use server::{serve, ExploreOptions};
