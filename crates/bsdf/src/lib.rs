//! # facette-bsdf
//!
//! The material library of facette: microfacet distributions, masking and Fresnel terms
//! (the *microfacet core*), the BSDF models of the papers facette implements, and the
//! statistical harness that verifies them. It does not depend on any renderer code.
//!
//! - [`math`]: vectors and frames, the [`Spectrum`](math::spectrum::Spectrum) type, a
//!   bit-stable RNG, special functions, quadrature and sampling warps.
//! - [`microfacet`]: Beckmann, GGX (anisotropic), the Gaussian of Oren–Nayar/Simonot and
//!   Phong, with Smith Λ/G1, samplers of D(m)|m·n| and of visible normals; masking choices;
//!   KSK01's half-vector densities; the shared specular microfacet lobe.
//! - [`fresnel`]: exact dielectric and conductor Fresnel, Schlick, r_e and r_i.
//! - [`checks`]: the valid range of every shared parameter, defined once.
//! - [`limits`]: every resource bound (film size, samples, table grid, XML nesting and
//!   includes, mesh sizes, radiance and exposure), stated once with its checker.
//! - [`finite`]: the one guard that keeps non-finite values from a renderer (and fails
//!   loudly in tests).
//! - [`bsdf`]: the BSDF interface (`eval`, `sample`, `pdf`, flags, transport mode,
//!   stochastic evaluation).
//! - [`models`]: one file per model.
//! - [`recipe`]: materials written as TOML tables (`{type = "dielectric", …}`), parsed and
//!   validated into recipes (`MaterialRecipe`), which build BSDFs.
//! - [`storage`]: the atomic file writer and the framed binary container that every
//!   file facette writes goes through.
//! - [`validation`]: chi-square goodness of fit, normalization, reciprocity, energy and
//!   NaN sweeps — the checks behind `facette validate` and the test suite.
//!
//! Paper references in doc comments use the short names listed, with full references, in
//! `docs/references.md`: WMLT07, KSK01, IL18, TSBRM, CCM19 (and HHdD16, KC17, …). "ERRATA N"
//! refers to erratum N of the numbered errata list in `docs/references.md`.

// `!(x > 0.0)` is used on purpose throughout: it is true for NaN, which must be rejected too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bsdf;
pub mod checks;
pub mod error;
pub mod finite;
pub mod fresnel;
pub mod lanes;
pub mod limits;
pub mod math;
pub mod microfacet;
pub mod models;
pub mod recipe;
pub mod storage;
pub mod two_sided;

pub mod validation;

pub use bsdf::{Bsdf, BsdfContext, BsdfSample, LobeFlags, TransportMode};
pub use error::{ParamError, ParamResult};
pub use math::spectrum::Spectrum;
pub use math::{Vec2, Vec3};
