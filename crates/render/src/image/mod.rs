//! Images: files in and out, textures, environment maps.
//!
//! - [`RgbImage`]: linear RGB pixels in memory.
//! - [`read_image`] / [`write_image`]: PNG, OpenEXR and Radiance HDR in; EXR and PNG out,
//!   atomically; [`write_exr_channels`] / [`read_exr_channels`] for named float channels
//!   with string attributes (partial renders).
//! - [`srgb`]: the exact sRGB transfer functions.

mod atomic_write;
pub mod error;
mod exr_file;
pub mod io;
pub mod rgb_image;
pub mod srgb;

pub use error::ImageError;
pub use exr_file::{read_exr_channels, write_exr_channels, ExrChannels};
pub use io::{read_image, write_image, ColorEncoding};
pub use rgb_image::RgbImage;
