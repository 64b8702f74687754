//! Image files in and out: PNG (8/16-bit grey, grey+alpha, RGB, RGBA), OpenEXR and Radiance
//! HDR are read; OpenEXR (linear float) and PNG (sRGB, 8-bit) are written.
//!
//! The format of a file being read is recognized by its first bytes, not its name, so a
//! misnamed file still reads; a file whose name promises a format it does not hold is
//! reported as corrupt. Alpha is dropped (textures are opaque colour; straight PNG alpha
//! would need a separate mask). PNG colour metadata (gAMA, iCCP, cHRM) is ignored: 8/16-bit
//! files are either sRGB-encoded colour or raw data, as the caller says through
//! [`ColorEncoding`]. EXR and HDR files hold linear values by definition.
//!
//! Every write is atomic (temporary file, fsync, rename; see `facette_bsdf::storage::atomic_file`).

use std::fs::File;
use std::io::{BufReader, BufWriter, ErrorKind, Read, Seek, SeekFrom};
use std::path::Path;

use image::{DynamicImage, ImageFormat, ImageReader};

use super::error::ImageError;
use super::exr_file::{read_exr_rgb, write_exr_rgb};
use super::rgb_image::RgbImage;
use super::srgb::{linear_to_srgb8, srgb8_to_linear_table, srgb_to_linear};
use facette_bsdf::storage::atomic_file::{write_atomically_with, Existing};

/// How the integer samples of an 8/16-bit file relate to linear values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ColorEncoding {
    /// Colour textures: decode with the exact sRGB EOTF.
    #[default]
    Srgb,
    /// Data (normal, roughness, displacement maps): keep code/max as is.
    Linear,
}

/// The formats read, recognized by signature.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FileFormat {
    Png,
    Exr,
    Hdr,
}

impl FileFormat {
    fn name(self) -> &'static str {
        match self {
            FileFormat::Png => "PNG",
            FileFormat::Exr => "OpenEXR",
            FileFormat::Hdr => "Radiance HDR",
        }
    }

    fn from_signature(head: &[u8]) -> Option<Self> {
        if head.starts_with(b"\x89PNG\r\n\x1a\n") {
            Some(FileFormat::Png)
        } else if head.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
            Some(FileFormat::Exr)
        } else if head.starts_with(b"#?") {
            // "#?RADIANCE" or "#?RGBE" (the program name is free text).
            Some(FileFormat::Hdr)
        } else {
            None
        }
    }

    fn from_extension(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "png" => Some(FileFormat::Png),
            "exr" => Some(FileFormat::Exr),
            "hdr" | "rgbe" | "pic" => Some(FileFormat::Hdr),
            _ => None,
        }
    }
}

fn read_failure(path: &Path, source: std::io::Error) -> ImageError {
    ImageError::Read {
        path: path.to_path_buf(),
        source,
    }
}

/// Reads a PNG, OpenEXR or Radiance HDR file into linear RGB. `encoding` applies to PNG
/// only; float formats are linear already.
pub fn read_image(path: impl AsRef<Path>, encoding: ColorEncoding) -> Result<RgbImage, ImageError> {
    let path = path.as_ref();
    let mut head = [0u8; 16];
    let got = {
        let mut f = File::open(path).map_err(|e| read_failure(path, e))?;
        let mut n = 0;
        loop {
            match f.read(&mut head[n..]) {
                Ok(0) => break,
                Ok(k) => {
                    n += k;
                    if n == head.len() {
                        break;
                    }
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(read_failure(path, e)),
            }
        }
        n
    };
    let format = match FileFormat::from_signature(&head[..got]) {
        Some(f) => f,
        None => {
            return Err(match FileFormat::from_extension(path) {
                Some(f) => ImageError::Corrupt {
                    path: path.to_path_buf(),
                    format: f.name(),
                    reason: if got == 0 {
                        "the file is empty".into()
                    } else {
                        format!("the file does not start with the {} signature", f.name())
                    },
                },
                None => ImageError::UnknownFormat {
                    path: path.to_path_buf(),
                },
            })
        }
    };
    match format {
        FileFormat::Exr => read_exr_rgb(path),
        FileFormat::Png | FileFormat::Hdr => {
            let decoded = decode_with_image_crate(path, format)?;
            convert_decoded(path, format, decoded, encoding)
        }
    }
}

fn decode_with_image_crate(path: &Path, format: FileFormat) -> Result<DynamicImage, ImageError> {
    let file = File::open(path).map_err(|e| read_failure(path, e))?;
    let image_format = match format {
        FileFormat::Png => ImageFormat::Png,
        _ => ImageFormat::Hdr,
    };
    // The header's size is held to the image limits before any pixel is decoded, and
    // the decoder may then allocate what that size needs (16 bytes per pixel covers
    // 16-bit RGBA and f32 RGB), so raising `--limit image-pixels` reaches PNG and HDR too.
    let dims = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        ImageReader::with_format(BufReader::new(&file), image_format).into_dimensions()
    }));
    let mut limits = image::Limits::default();
    if let Ok(Ok((w, h))) = dims {
        let too_large = |e: facette_bsdf::limits::LimitError| ImageError::Unsupported {
            path: path.to_path_buf(),
            format: format.name(),
            reason: format!("{e} (or the header is damaged)"),
        };
        let pixels = facette_bsdf::limits::IMAGE_PIXELS
            .check_product(&[w as u64, h as u64])
            .map_err(too_large)?;
        facette_bsdf::limits::IMAGE_SAMPLES
            .check_product(&[pixels, 4])
            .map_err(too_large)?;
        limits.max_alloc = Some(limits.max_alloc.unwrap_or(0).max(pixels.saturating_mul(16)));
    }
    // The same file, rewound after the header probe.
    let mut file = file;
    file.seek(SeekFrom::Start(0))
        .map_err(|e| read_failure(path, e))?;
    let mut reader = ImageReader::with_format(BufReader::new(file), image_format);
    reader.limits(limits);
    // A decoder panic on malformed input must not take a render down with it.
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| reader.decode()));
    let corrupt = |reason: String| ImageError::Corrupt {
        path: path.to_path_buf(),
        format: format.name(),
        reason,
    };
    match result {
        Ok(Ok(img)) => Ok(img),
        Ok(Err(e)) => Err(match e {
            image::ImageError::IoError(io) if io.kind() == ErrorKind::UnexpectedEof => {
                corrupt("the file is truncated".into())
            }
            image::ImageError::IoError(io) if io.kind() == ErrorKind::InvalidData => {
                corrupt(io.to_string())
            }
            image::ImageError::IoError(io) => read_failure(path, io),
            image::ImageError::Unsupported(u) => ImageError::Unsupported {
                path: path.to_path_buf(),
                format: format.name(),
                reason: u.to_string(),
            },
            image::ImageError::Limits(l) => ImageError::Unsupported {
                path: path.to_path_buf(),
                format: format.name(),
                reason: format!("the image exceeds the decoder's limits ({l})"),
            },
            other => corrupt(other.to_string()),
        }),
        Err(_) => Err(corrupt("the decoder failed on malformed data".into())),
    }
}

/// Samples of one pixel (1 to 4 channels) → RGB; grey is replicated, alpha dropped.
#[inline]
fn to_rgb<T: Copy>(px: &[T], f: impl Fn(T) -> f32) -> [f32; 3] {
    match px.len() {
        1 | 2 => [f(px[0]); 3],
        _ => [f(px[0]), f(px[1]), f(px[2])],
    }
}

fn convert_decoded(
    path: &Path,
    format: FileFormat,
    img: DynamicImage,
    encoding: ColorEncoding,
) -> Result<RgbImage, ImageError> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    let channels = img.color().channel_count() as usize;
    let table = srgb8_to_linear_table();
    let srgb = encoding == ColorEncoding::Srgb && format == FileFormat::Png;
    let data: Vec<[f32; 3]> = match &img {
        DynamicImage::ImageLuma8(_)
        | DynamicImage::ImageLumaA8(_)
        | DynamicImage::ImageRgb8(_)
        | DynamicImage::ImageRgba8(_) => {
            let bytes = img.as_bytes();
            bytes
                .chunks_exact(channels)
                .map(|px| {
                    if srgb {
                        to_rgb(px, |c| table[c as usize])
                    } else {
                        to_rgb(px, |c| c as f32 / 255.0)
                    }
                })
                .collect()
        }
        DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_) => {
            let samples: Vec<u16> = match &img {
                DynamicImage::ImageLuma16(b) => b.as_raw().clone(),
                DynamicImage::ImageLumaA16(b) => b.as_raw().clone(),
                DynamicImage::ImageRgb16(b) => b.as_raw().clone(),
                DynamicImage::ImageRgba16(b) => b.as_raw().clone(),
                _ => unreachable!("matched 16-bit variants above"),
            };
            samples
                .chunks_exact(channels)
                .map(|px| {
                    to_rgb(px, |c| {
                        let v = c as f64 / 65535.0;
                        (if srgb { srgb_to_linear(v) } else { v }) as f32
                    })
                })
                .collect()
        }
        DynamicImage::ImageRgb32F(b) => b
            .as_raw()
            .chunks_exact(3)
            .map(|px| to_rgb(px, |v| if v.is_finite() { v } else { 0.0 }))
            .collect(),
        DynamicImage::ImageRgba32F(b) => b
            .as_raw()
            .chunks_exact(4)
            .map(|px| to_rgb(px, |v| if v.is_finite() { v } else { 0.0 }))
            .collect(),
        other => {
            return Err(ImageError::Unsupported {
                path: path.to_path_buf(),
                format: format.name(),
                reason: format!("pixel type {:?}", other.color()),
            })
        }
    };
    RgbImage::new(w, h, data).map_err(|e| ImageError::Corrupt {
        path: path.to_path_buf(),
        format: format.name(),
        reason: e.to_string(),
    })
}

/// Writes an image, the format chosen by the extension: `.exr` stores linear float32 RGB
/// multiplied by 2^`exposure_stops`; `.png` multiplies by 2^`exposure_stops`, applies the
/// sRGB OETF, clamps to [0, 1] and quantizes to 8 bits (NaN becomes 0). The write is
/// atomic: on any failure an existing file is untouched and no temporary file remains.
pub fn write_image(
    path: impl AsRef<Path>,
    image: &RgbImage,
    exposure_stops: f64,
) -> Result<(), ImageError> {
    let path = path.as_ref();
    let invalid = |reason: String| ImageError::InvalidData {
        path: path.to_path_buf(),
        reason,
    };
    facette_bsdf::limits::check_exposure(exposure_stops)
        .map_err(|m| invalid(format!("exposure: {m}")))?;
    let scale = exposure_stops.exp2();
    // An exposure that would turn a finite pixel into +Inf is refused, naming the pixel,
    // instead of writing an image of infinities (checked before anything is written).
    if let Some((k, v)) = image.data().iter().enumerate().find_map(|(k, p)| {
        p.iter()
            .find(|v| v.is_finite() && !((**v as f64 * scale) as f32).is_finite())
            .map(|v| (k, *v))
    }) {
        return Err(invalid(format!(
            "exposure {exposure_stops} stops makes pixel ({}, {}) = {v:e} overflow a 32-bit float; lower the exposure",
            k % image.width().max(1),
            k / image.width().max(1)
        )));
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("exr") => write_exr_rgb(path, image, scale, &[], Existing::Replace).map(|_| ()),
        Some("png") => write_png(path, image, scale),
        other => Err(ImageError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension: match other {
                Some(e) => format!("`.{e}`"),
                None => "(none)".into(),
            },
        }),
    }
}

fn write_png(path: &Path, image: &RgbImage, scale: f64) -> Result<(), ImageError> {
    use image::ImageEncoder;
    let (Ok(w), Ok(h)) = (u32::try_from(image.width()), u32::try_from(image.height())) else {
        return Err(ImageError::InvalidData {
            path: path.to_path_buf(),
            reason: format!("{}×{} is too large for PNG", image.width(), image.height()),
        });
    };
    let bytes: Vec<u8> = image
        .data()
        .iter()
        .flat_map(|p| p.map(|v| linear_to_srgb8(v as f64 * scale)))
        .collect();
    write_atomically_with(path, Existing::Replace, |out: &mut BufWriter<&File>| {
        image::codecs::png::PngEncoder::new(out)
            .write_image(&bytes, w, h, image::ExtendedColorType::Rgb8)
            .map_err(|e| format!("PNG encoding failed: {e}"))
    })
    .map(|_| ())
    .map_err(ImageError::from)
}
