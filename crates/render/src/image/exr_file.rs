//! OpenEXR files through the `exr` crate: RGB images in and out, and files of arbitrary named
//! float channels with string header attributes (the renderer's partial renders: per-pixel
//! sums, weights, sample counts, scene hash, seed).
//!
//! Reading an RGB image takes the largest resolution level of the first layer (part) that
//! holds colour, and in it the first channel group that does, in this order of preference:
//! unprefixed `R`,`G`,`B` (alpha ignored), a layer-prefixed `name.R`,`name.G`,`name.B`
//! (groups in alphabetical order), a luminance `Y`, and a lone channel of any name (read as
//! grey). Half, float and uint samples are all converted to f32. The data window is the
//! image; a display window offset is ignored. Non-finite samples (NaN, ±∞ — some HDRIs
//! carry them) are replaced by 0 so no NaN ever reaches a texture or a light.
//!
//! Files are written with ZIP (16-line) compression in scan lines, the most widely readable
//! lossless layout, and atomically (`facette_bsdf::storage::atomic_file`).

use std::collections::HashMap;
use std::io::{BufWriter, ErrorKind};
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    Layers, ReadChannels, ReadLayers, SmallVec, Text, WritableImage,
};

use super::error::ImageError;
use super::rgb_image::RgbImage;
use facette_bsdf::limits;
use facette_bsdf::storage::atomic_file::{write_atomically_with, Existing};

const FORMAT: &str = "OpenEXR";

/// Header attribute names that OpenEXR (or the `exr` crate) gives a fixed meaning and type;
/// custom string attributes may not reuse them.
const RESERVED_ATTRIBUTES: &[&str] = &[
    "tiles",
    "name",
    "type",
    "version",
    "chunkCount",
    "maxSamplesPerPixel",
    "channels",
    "compression",
    "dataWindow",
    "displayWindow",
    "lineOrder",
    "pixelAspectRatio",
    "screenWindowCenter",
    "screenWindowWidth",
    "whiteLuminance",
    "adoptedNeutral",
    "renderingTransform",
    "lookModTransform",
    "xDensity",
    "owner",
    "comments",
    "capDate",
    "utcOffset",
    "longitude",
    "latitude",
    "altitude",
    "focus",
    "expTime",
    "aperture",
    "isoSpeed",
    "envmap",
    "keyCode",
    "timeCode",
    "wrapmodes",
    "framesPerSecond",
    "multiView",
    "worldToCamera",
    "worldToNDC",
    "deepImageState",
    "originalDataWindow",
    "dwaCompressionLevel",
    "preview",
    "view",
    "chromaticities",
    "near",
    "far",
    "fieldOfViewHorizontal",
    "fieldOfViewVertical",
    "software",
];

/// The content of a file of named float channels.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrChannels {
    pub width: usize,
    pub height: usize,
    /// Channels in the file's order (OpenEXR stores them sorted by name), each with
    /// `width · height` samples, row-major, top row first. Values are returned exactly as
    /// stored (half samples widened to f32), non-finite ones included.
    pub channels: Vec<(String, Vec<f32>)>,
    /// String attributes of the header other than OpenEXR's own, sorted by name.
    pub attributes: Vec<(String, String)>,
}

impl ExrChannels {
    /// The samples of the channel called `name`.
    pub fn channel(&self, name: &str) -> Option<&[f32]> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The value of the string attribute called `name`.
    pub fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

/// Maps an `exr` error to ours: malformed data and unexpected ends of file are corruption,
/// other I/O failures are read errors.
fn read_error(path: &Path, e: exr::error::Error) -> ImageError {
    use exr::error::Error as E;
    let path = path.to_path_buf();
    match e {
        E::NotSupported(what) => ImageError::Unsupported {
            path,
            format: FORMAT,
            reason: what.into_owned(),
        },
        E::Invalid(what) => ImageError::Corrupt {
            path,
            format: FORMAT,
            reason: what.into_owned(),
        },
        E::Aborted => ImageError::Corrupt {
            path,
            format: FORMAT,
            reason: "reading was aborted".into(),
        },
        E::Io(io) if io.kind() == ErrorKind::UnexpectedEof => ImageError::Corrupt {
            path,
            format: FORMAT,
            reason: "the file is truncated".into(),
        },
        E::Io(io) if io.kind() == ErrorKind::InvalidData => ImageError::Corrupt {
            path,
            format: FORMAT,
            reason: io.to_string(),
        },
        E::Io(source) => ImageError::Read { path, source },
    }
}

type FlatLayer = Layer<AnyChannels<FlatSamples>>;

/// Reads every layer's largest level with all channels and all attributes, in `exr`'s
/// pedantic mode: the relaxed mode skips validating the chunk offset table and ignores
/// leftover bytes in compressed blocks, so a damaged file could come back with silently
/// zeroed or garbled blocks instead of an error.
fn read_layers(path: &Path) -> Result<Image<Layers<AnyChannels<FlatSamples>>>, ImageError> {
    check_header_plausible(path)?;
    // `catch_unwind` is a last line of defence: a malformed file must never bring down a
    // render, even through a bug in a dependency's decoder.
    let result = std::panic::catch_unwind(|| {
        exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .pedantic()
            .from_file(path)
    });
    match result {
        Ok(Ok(img)) => Ok(img),
        Ok(Err(e)) => Err(read_error(path, e)),
        Err(_) => Err(ImageError::Corrupt {
            path: path.to_path_buf(),
            format: FORMAT,
            reason: "the decoder failed on malformed data".into(),
        }),
    }
}

/// Reads the headers alone and rejects sizes no genuine file of this length can have,
/// before the decoder allocates the pixel buffers: `exr` sizes them from the header, so a
/// damaged data window would otherwise ask for hundreds of gigabytes and abort the process.
fn check_header_plausible(path: &Path) -> Result<(), ImageError> {
    let meta = std::panic::catch_unwind(|| exr::meta::MetaData::read_from_file(path, false));
    let meta = match meta {
        Ok(Ok(m)) => m,
        Ok(Err(e)) => return Err(read_error(path, e)),
        Err(_) => {
            return Err(ImageError::Corrupt {
                path: path.to_path_buf(),
                format: FORMAT,
                reason: "the header is malformed".into(),
            })
        }
    };
    let file_len = std::fs::metadata(path)
        .map_err(|source| ImageError::Read {
            path: path.to_path_buf(),
            source,
        })?
        .len();
    let mut chunks: u64 = 0;
    let mut samples: u64 = 0;
    for header in meta.headers.iter() {
        let (w, h) = (header.layer_size.width(), header.layer_size.height());
        let unsupported = |e: facette_bsdf::limits::LimitError| ImageError::Unsupported {
            path: path.to_path_buf(),
            format: FORMAT,
            reason: format!("{e} (or the header is damaged)"),
        };
        limits::IMAGE_PIXELS
            .check_product(&[w as u64, h as u64])
            .map_err(unsupported)?;
        chunks = chunks.saturating_add(header.chunk_count as u64);
        samples = samples.saturating_add(
            (w as u64 * h as u64).saturating_mul(header.channels.list.len() as u64),
        );
        limits::IMAGE_SAMPLES.check(samples).map_err(unsupported)?;
    }
    // Every chunk has an 8-byte entry in the offset table and at least 8 bytes of its own.
    if chunks.saturating_mul(16) > file_len {
        return Err(ImageError::Corrupt {
            path: path.to_path_buf(),
            format: FORMAT,
            reason: format!(
                "the file is truncated: its header announces {chunks} pixel blocks, which \
                 cannot fit in {file_len} bytes"
            ),
        });
    }
    Ok(())
}

fn samples_to_f32(s: &FlatSamples) -> Vec<f32> {
    match s {
        FlatSamples::F16(v) => v.iter().map(|h| h.to_f32()).collect(),
        FlatSamples::F32(v) => v.clone(),
        FlatSamples::U32(v) => v.iter().map(|&u| u as f32).collect(),
    }
}

fn text_to_string(t: &Text) -> String {
    // OpenEXR text is a byte string; read it as Latin-1 (ASCII is the common case).
    t.as_slice().iter().map(|&b| b as char).collect()
}

/// The indices (into the layer's channel list) of the channels an RGB reading uses:
/// three for colour, one for grey.
fn pick_colour_channels(layer: &FlatLayer) -> Option<Vec<usize>> {
    let names: Vec<String> = layer
        .channel_data
        .list
        .iter()
        .map(|c| text_to_string(&c.name))
        .collect();
    // Group by prefix (all before the last '.').
    let mut groups: Vec<(String, HashMap<String, usize>)> = Vec::new();
    for (i, n) in names.iter().enumerate() {
        let (prefix, suffix) = match n.rfind('.') {
            Some(k) => (n[..k].to_string(), n[k + 1..].to_string()),
            None => (String::new(), n.clone()),
        };
        match groups.iter_mut().find(|(p, _)| *p == prefix) {
            Some((_, g)) => {
                g.insert(suffix, i);
            }
            None => groups.push((prefix, HashMap::from([(suffix, i)]))),
        }
    }
    groups.sort_by(|a, b| a.0.cmp(&b.0)); // the unprefixed group ("") first
    let get = |g: &HashMap<String, usize>, k: &str| {
        g.get(k).or_else(|| g.get(&k.to_ascii_lowercase())).copied()
    };
    for (_, g) in &groups {
        if let (Some(r), Some(gg), Some(b)) = (get(g, "R"), get(g, "G"), get(g, "B")) {
            return Some(vec![r, gg, b]);
        }
    }
    for (_, g) in &groups {
        if let Some(y) = get(g, "Y") {
            // Luminance-chroma files (Y, RY, BY) hold colour we do not decode.
            if get(g, "RY").is_some() || get(g, "BY").is_some() {
                return None;
            }
            return Some(vec![y]);
        }
    }
    if names.len() == 1 {
        return Some(vec![0]);
    }
    None
}

/// Reads an OpenEXR file as an RGB image (see the module documentation for the choice of
/// layer and channels).
pub(crate) fn read_exr_rgb(path: &Path) -> Result<RgbImage, ImageError> {
    let image = read_layers(path)?;
    let mut seen = Vec::new();
    for layer in &image.layer_data {
        let Some(idx) = pick_colour_channels(layer) else {
            seen.extend(
                layer
                    .channel_data
                    .list
                    .iter()
                    .map(|c| text_to_string(&c.name)),
            );
            continue;
        };
        let (w, h) = (layer.size.width(), layer.size.height());
        let n = w.saturating_mul(h);
        let mut planes = Vec::with_capacity(idx.len());
        for &i in &idx {
            let ch = &layer.channel_data.list[i];
            if ch.sampling.x() != 1 || ch.sampling.y() != 1 {
                return Err(ImageError::Unsupported {
                    path: path.to_path_buf(),
                    format: FORMAT,
                    reason: format!("channel `{}` is subsampled", text_to_string(&ch.name)),
                });
            }
            let v = samples_to_f32(&ch.sample_data);
            if v.len() != n {
                return Err(ImageError::Corrupt {
                    path: path.to_path_buf(),
                    format: FORMAT,
                    reason: format!(
                        "channel `{}` holds {} samples for a {w}×{h} image",
                        text_to_string(&ch.name),
                        v.len()
                    ),
                });
            }
            planes.push(v);
        }
        let clean = |v: f32| if v.is_finite() { v } else { 0.0 };
        let data: Vec<[f32; 3]> = (0..n)
            .map(|k| {
                if planes.len() == 3 {
                    [
                        clean(planes[0][k]),
                        clean(planes[1][k]),
                        clean(planes[2][k]),
                    ]
                } else {
                    [clean(planes[0][k]); 3]
                }
            })
            .collect();
        return RgbImage::new(w, h, data).map_err(|e| ImageError::Corrupt {
            path: path.to_path_buf(),
            format: FORMAT,
            reason: e.to_string(),
        });
    }
    Err(ImageError::Unsupported {
        path: path.to_path_buf(),
        format: FORMAT,
        reason: format!(
            "no colour channels (R, G, B), luminance (Y) or single channel found; channels: {}",
            if seen.is_empty() {
                "none".to_string()
            } else {
                seen.join(", ")
            }
        ),
    })
}

/// Reads the first layer of an OpenEXR file as named float channels plus its string
/// attributes — the inverse of [`write_exr_channels`].
pub fn read_exr_channels(path: impl AsRef<Path>) -> Result<ExrChannels, ImageError> {
    let path = path.as_ref();
    let image = read_layers(path)?;
    let Some(layer) = image.layer_data.first() else {
        return Err(ImageError::Corrupt {
            path: path.to_path_buf(),
            format: FORMAT,
            reason: "the file holds no layer".into(),
        });
    };
    let (w, h) = (layer.size.width(), layer.size.height());
    let mut channels = Vec::new();
    for ch in &layer.channel_data.list {
        let name = text_to_string(&ch.name);
        if ch.sampling.x() != 1 || ch.sampling.y() != 1 {
            return Err(ImageError::Unsupported {
                path: path.to_path_buf(),
                format: FORMAT,
                reason: format!("channel `{name}` is subsampled"),
            });
        }
        let v = samples_to_f32(&ch.sample_data);
        if v.len() != w.saturating_mul(h) {
            return Err(ImageError::Corrupt {
                path: path.to_path_buf(),
                format: FORMAT,
                reason: format!("channel `{name}` holds {} samples for {w}×{h}", v.len()),
            });
        }
        channels.push((name, v));
    }
    let mut attributes: Vec<(String, String)> = image
        .attributes
        .other
        .iter()
        .chain(layer.attributes.other.iter())
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((text_to_string(k), text_to_string(t))),
            _ => None,
        })
        .collect();
    attributes.sort();
    attributes.dedup_by(|a, b| a.0 == b.0);
    Ok(ExrChannels {
        width: w,
        height: h,
        channels,
        attributes,
    })
}

fn latin1(s: &str) -> Option<Text> {
    Text::new_or_none(s)
}

/// Writes named float channels and string header attributes to an OpenEXR file,
/// atomically. Every channel holds `width · height` samples (row-major, top row first);
/// names must be non-empty, distinct and Latin-1; attribute names may not be OpenEXR's own
/// (`channels`, `compression`, `owner`, …). Values are stored as 32-bit floats — exact for
/// integers up to 2²⁴ (sample counts), ~7 significant digits otherwise.
pub fn write_exr_channels(
    path: impl AsRef<Path>,
    width: usize,
    height: usize,
    channels: &[(&str, &[f32])],
    attributes: &[(&str, String)],
) -> Result<(), ImageError> {
    write_channels(
        path.as_ref(),
        width,
        height,
        channels,
        attributes,
        Existing::Replace,
    )
    .map(|_| ())
}

/// [`write_exr_channels`] with a choice for an existing target; returns whether it wrote.
fn write_channels(
    path: &Path,
    width: usize,
    height: usize,
    channels: &[(&str, &[f32])],
    attributes: &[(&str, String)],
    existing: Existing,
) -> Result<bool, ImageError> {
    let invalid = |reason: String| ImageError::InvalidData {
        path: path.to_path_buf(),
        reason,
    };
    if width == 0 || height == 0 {
        return Err(invalid(format!(
            "an image needs at least one pixel, got {width}×{height}"
        )));
    }
    // OpenEXR windows are i32 coordinates.
    if width > i32::MAX as usize || height > i32::MAX as usize {
        return Err(invalid(format!(
            "{width}×{height} is too large for OpenEXR"
        )));
    }
    if channels.is_empty() {
        return Err(invalid("no channels to write".into()));
    }
    let n = width * height;
    let mut list = SmallVec::<[AnyChannel<FlatSamples>; 4]>::new();
    for (k, (name, data)) in channels.iter().enumerate() {
        if name.is_empty() || name.contains('\0') {
            return Err(invalid(format!("channel {k} has an empty or invalid name")));
        }
        if channels[..k].iter().any(|(other, _)| other == name) {
            return Err(invalid(format!("channel `{name}` appears twice")));
        }
        if data.len() != n {
            return Err(invalid(format!(
                "channel `{name}` has {} samples, a {width}×{height} image needs {n}",
                data.len()
            )));
        }
        let text = latin1(name)
            .ok_or_else(|| invalid(format!("channel name `{name}` is not Latin-1 text")))?;
        list.push(AnyChannel::new(text, FlatSamples::F32(data.to_vec())));
    }
    let mut layer_attributes = LayerAttributes {
        software_name: Some(Text::from("facette")),
        ..LayerAttributes::default()
    };
    for (k, (name, value)) in attributes.iter().enumerate() {
        if name.is_empty() || name.contains('\0') {
            return Err(invalid(format!(
                "attribute {k} has an empty or invalid name"
            )));
        }
        if RESERVED_ATTRIBUTES.contains(name) {
            return Err(invalid(format!(
                "attribute name `{name}` is reserved by OpenEXR; choose another (e.g. \
                 `facette.{name}`)"
            )));
        }
        if attributes[..k].iter().any(|(other, _)| other == name) {
            return Err(invalid(format!("attribute `{name}` appears twice")));
        }
        let key = latin1(name)
            .ok_or_else(|| invalid(format!("attribute name `{name}` is not Latin-1 text")))?;
        let val = latin1(value).ok_or_else(|| {
            invalid(format!(
                "the value of attribute `{name}` is not Latin-1 text"
            ))
        })?;
        layer_attributes
            .other
            .insert(key, AttributeValue::Text(val));
    }
    let layer = Layer::new(
        (width, height),
        layer_attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    let image = Image::from_layer(layer);
    write_atomically_with(path, existing, |w: &mut BufWriter<&std::fs::File>| {
        image
            .write()
            .to_buffered(w)
            .map_err(|e| format!("OpenEXR encoding failed: {e}"))
    })
    .map_err(ImageError::from)
}

/// Writes an RGB image as 32-bit float `R`, `G`, `B` channels, each value multiplied by
/// `scale` — with `existing` deciding whether an existing file is replaced.
pub(crate) fn write_exr_rgb(
    path: &Path,
    image: &RgbImage,
    scale: f64,
    attributes: &[(&str, String)],
    existing: Existing,
) -> Result<bool, ImageError> {
    let plane = |c: usize| -> Vec<f32> {
        image
            .data()
            .iter()
            .map(|p| (p[c] as f64 * scale) as f32)
            .collect()
    };
    let (r, g, b) = (plane(0), plane(1), plane(2));
    write_channels(
        path,
        image.width(),
        image.height(),
        &[("R", &r), ("G", &g), ("B", &b)],
        attributes,
        existing,
    )
}
