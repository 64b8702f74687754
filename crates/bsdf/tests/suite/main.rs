//! facette-bsdf's validation suites, one module per area, in one binary: the crate links
//! once instead of once per file, and libtest spreads the long tests of every module over
//! the threads.

mod glints;
mod il_multiple_quadrature;
mod il_quadrature_reference;
mod interfaced_lambertian;
mod material_params_proptest;
mod microfacet_core;
mod model_properties;
mod multiple_scattering;
mod reference_bsdfs;
mod table_headers;
