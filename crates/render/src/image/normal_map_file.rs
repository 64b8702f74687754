//! Normal map files for the glint material  [CCM19 §3]: reading (PNG 8/16-bit, OpenEXR,
//! Radiance HDR, decoded without any colour transform) for
//! [`facette_bsdf::recipe::NormalMapReader`], and writing (16-bit PNG with the unsigned
//! encoding n = 2c − 1, or float EXR with the signed encoding n = c), atomically.
//!
//! Validation of the pixels (grey images, non-unit or downward normals) is done by
//! [`facette_bsdf::models::glint::NormalMap::from_pixels`], which names the first bad pixel.

use super::error::ImageError;
use super::exr_file::write_exr_rgb;
use super::io::{read_image, ColorEncoding};
use super::rgb_image::RgbImage;
use facette_bsdf::models::glint::{NormalEncoding, NormalMap};
use facette_bsdf::recipe::{DecodedImage, NormalMapReader};
use facette_bsdf::storage::atomic_file::{write_atomically_with, Existing};
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

/// True for the float formats (their default encoding is signed).
fn is_float_file(path: &Path) -> bool {
    matches!(
        path.extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .as_deref(),
        Some("exr" | "hdr" | "rgbe" | "pic")
    )
}

/// Reads normal map images with the renderer's image reader.
#[derive(Clone, Copy, Debug, Default)]
pub struct ImageNormalMapReader;

impl NormalMapReader for ImageNormalMapReader {
    fn read(&self, path: &Path) -> Result<DecodedImage, String> {
        let img =
            read_image(path, ColorEncoding::Linear).map_err(|e| format!("normal map: {e}"))?;
        Ok(DecodedImage {
            width: img.width(),
            height: img.height(),
            float: is_float_file(path),
            pixels: img.into_data(),
        })
    }
}

/// Writes `map` as a `.png` (16-bit RGB, unsigned encoding) or `.exr` (float RGB, signed
/// encoding), chosen by the extension.
pub fn write_normal_map(path: impl AsRef<Path>, map: &NormalMap) -> Result<(), ImageError> {
    let path = path.as_ref();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("exr") => {
            let img = RgbImage::new(
                map.width(),
                map.height(),
                map.to_pixels(NormalEncoding::Signed),
            )
            .map_err(|e| ImageError::InvalidData {
                path: path.to_path_buf(),
                reason: e.to_string(),
            })?;
            write_exr_rgb(path, &img, 1.0, &[], Existing::Replace).map(|_| ())
        }
        Some("png") => write_png16(path, map),
        other => Err(ImageError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension: match other {
                Some(e) => format!("`.{e}` (normal maps: .png or .exr)"),
                None => "(none; normal maps: .png or .exr)".into(),
            },
        }),
    }
}

fn write_png16(path: &Path, map: &NormalMap) -> Result<(), ImageError> {
    use image::ImageEncoder;
    let (Ok(w), Ok(h)) = (u32::try_from(map.width()), u32::try_from(map.height())) else {
        return Err(ImageError::InvalidData {
            path: path.to_path_buf(),
            reason: "map too large for PNG".into(),
        });
    };
    let bytes: Vec<u8> = map
        .to_pixels(NormalEncoding::Unsigned)
        .iter()
        .flat_map(|p| {
            p.map(|c| (c.clamp(0.0, 1.0) as f64 * 65535.0).round() as u16)
                .into_iter()
                .flat_map(u16::to_ne_bytes)
        })
        .collect();
    write_atomically_with(path, Existing::Replace, |out: &mut BufWriter<&File>| {
        image::codecs::png::PngEncoder::new(out)
            .write_image(&bytes, w, h, image::ExtendedColorType::Rgb16)
            .map_err(|e| format!("PNG encoding failed: {e}"))
    })
    .map(|_| ())
    .map_err(ImageError::from)
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::models::glint::{generate, NormalMapKind};

    fn round_trip(ext: &str) -> f64 {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join(format!("n.{ext}"));
        let map = generate(NormalMapKind::Bumpy, 32, 2).unwrap();
        write_normal_map(&p, &map).unwrap();
        let img = ImageNormalMapReader.read(&p).unwrap();
        let enc = if img.float {
            NormalEncoding::Signed
        } else {
            NormalEncoding::Unsigned
        };
        let back = NormalMap::from_pixels(img.width, img.height, &img.pixels, enc, "t").unwrap();
        map.slopes()
            .iter()
            .zip(back.slopes())
            .map(|(a, b)| ((a[0] - b[0]).abs().max((a[1] - b[1]).abs())) as f64)
            .fold(0.0, f64::max)
    }

    #[test]
    fn png16_and_exr_round_trip() {
        // 16-bit quantization of n (slopes up to ~2): |Δslope| ≲ 1e-4; EXR is exact to f32.
        assert!(round_trip("png") < 2e-4, "{}", round_trip("png"));
        assert!(round_trip("exr") < 1e-5);
    }

    #[test]
    fn bad_extensions_and_files_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let map = generate(NormalMapKind::Flakes, 8, 1).unwrap();
        let e = write_normal_map(dir.path().join("n.jpg"), &map).unwrap_err();
        assert!(e.to_string().contains(".png or .exr"), "{e}");
        let p = dir.path().join("garbage.png");
        std::fs::write(&p, b"not an image").unwrap();
        let e = ImageNormalMapReader.read(&p).unwrap_err();
        assert!(e.contains("garbage.png"), "{e}");
        let e = ImageNormalMapReader
            .read(&dir.path().join("missing.exr"))
            .unwrap_err();
        assert!(e.contains("missing.exr"), "{e}");
    }
}
