//! Images: files in and out, textures, environment maps.
//!
//! - [`RgbImage`]: linear RGB pixels (Rec. 709 primaries) in memory, f32, top row first.
//! - [`read_image`] / [`write_image`]: PNG, OpenEXR and Radiance HDR in; EXR and PNG out,
//!   atomically; [`write_exr_channels`] / [`read_exr_channels`] for named float channels
//!   with string attributes (partial renders).
//! - [`srgb`]: the exact sRGB transfer functions.
//! - [`MipMap`]: image pyramid with bilinear and trilinear lookups, [`WrapMode`]s.
//! - [`Texture`]: constant, image and (filtered) checker textures for materials.
//! - [`EnvironmentMap`]: latitude-longitude radiance in Mitsuba 3's `envmap` convention,
//!   importance-sampled by luminance; [`ConstantEnvironment`] for uniform radiance; both
//!   sample into an [`EnvSample`].
//! - [`Distribution2D`]: the piecewise-constant 2-D distribution behind the sampling.
//! - [`normal_map_file`]: normal maps for glints (PNG 8/16-bit, EXR in; 16-bit PNG, EXR out).
//! - [`sky`]: the procedural sky ([`SkyParams`], [`generate_sky`], [`ensure_sky`]).

// `!(x > 0.0)` is used on purpose, as in facette-bsdf: it is true for NaN, which must be
// rejected too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod constant_environment;
pub mod distribution_2d;
pub mod environment;
pub mod error;
mod exr_file;
pub mod io;
pub mod mipmap;
pub mod normal_map_file;
pub mod rgb_image;
pub mod sky;
pub mod srgb;
pub mod texture;

pub use constant_environment::ConstantEnvironment;
pub use distribution_2d::Distribution2D;
pub use environment::{EnvSample, EnvironmentMap};
pub use error::ImageError;
pub use exr_file::{read_exr_channels, write_exr_channels, ExrChannels};
pub use io::{read_image, write_image, ColorEncoding};
pub use mipmap::{MipMap, WrapMode};
pub use normal_map_file::{write_normal_map, ImageNormalMapReader};
pub use rgb_image::RgbImage;
pub use sky::{ensure_sky, generate_sky, load_or_generate_sky, SkyParams};
pub use texture::Texture;
