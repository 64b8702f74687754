//! The previous PLY reader, through `ply-rs`: kept in test builds to compare and time the
//! reader of `ply.rs` against it.
//!
//! PLY (ASCII, binary little- and big-endian) through `ply-rs`.
//!
//! Read: the `vertex` element's `x y z`, optional `nx ny nz`, optional texture
//! coordinates named `u v`, `s t`, `texture_u texture_v` or `texture_s texture_t` (any
//! scalar type); the `face` element's `vertex_indices` (or `vertex_index`) list, polygons
//! fan-triangulated (faces of fewer than three vertices are skipped). Other elements and
//! properties are ignored. For ASCII files, index and finiteness errors report the line
//! of the offending element; `ply-rs` parse errors carry their own line in the message.

use crate::geometry::error::{GeometryError, GeometryResult};
use crate::geometry::mesh_data::MeshData;
use crate::geometry::{Vec2, Vec3};
use facette_bsdf::limits;
use ply_rs::parser::Parser;
use ply_rs::ply::{Encoding, Header, Property, PropertyAccess};
use std::path::Path;

/// Reads a PLY file.
#[allow(dead_code)]
pub fn read_ply(path: &Path) -> GeometryResult<MeshData> {
    let bytes = std::fs::read(path).map_err(|source| GeometryError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_ply(&bytes).map_err(|(e, line)| e.in_file(path, line))
}

const X: usize = 0;
const NX: usize = 3;
const U: usize = 6;
const V: usize = 7;

/// One element of any kind; only the properties we read are kept.
#[derive(Default)]
struct Record {
    values: [f64; 8],
    indices: Vec<i64>,
    non_integer_indices: bool,
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(x) => x as f64,
        Property::UChar(x) => x as f64,
        Property::Short(x) => x as f64,
        Property::UShort(x) => x as f64,
        Property::Int(x) => x as f64,
        Property::UInt(x) => x as f64,
        Property::Float(x) => x as f64,
        Property::Double(x) => x,
        _ => return None,
    })
}

/// Integer list as i64; `None` if a float list holds a non-integer.
fn index_list(p: Property) -> Option<Vec<i64>> {
    fn ints<T: Into<i64> + Copy>(v: &[T]) -> Option<Vec<i64>> {
        Some(v.iter().map(|&x| x.into()).collect())
    }
    fn floats(v: impl Iterator<Item = f64>) -> Option<Vec<i64>> {
        v.map(|x| (x.fract() == 0.0 && x.abs() < 9.0e15).then_some(x as i64))
            .collect()
    }
    match p {
        Property::ListChar(v) => ints(&v),
        Property::ListUChar(v) => ints(&v),
        Property::ListShort(v) => ints(&v),
        Property::ListUShort(v) => ints(&v),
        Property::ListInt(v) => ints(&v),
        Property::ListUInt(v) => ints(&v),
        Property::ListFloat(v) => floats(v.into_iter().map(|x| x as f64)),
        Property::ListDouble(v) => floats(v.into_iter()),
        _ => None,
    }
}

fn slot(name: &str) -> Option<usize> {
    Some(match name {
        "x" => X,
        "y" => X + 1,
        "z" => X + 2,
        "nx" => NX,
        "ny" => NX + 1,
        "nz" => NX + 2,
        "u" | "s" | "texture_u" | "texture_s" => U,
        "v" | "t" | "texture_v" | "texture_t" => V,
        _ => return None,
    })
}

impl PropertyAccess for Record {
    fn new() -> Self {
        Record::default()
    }

    fn set_property(&mut self, name: String, property: Property) {
        if name == "vertex_indices" || name == "vertex_index" {
            match index_list(property) {
                Some(list) => self.indices = list,
                None => self.non_integer_indices = true,
            }
        } else if let (Some(k), Some(x)) = (slot(&name), scalar(&property)) {
            self.values[k] = x;
        }
    }
}

/// Line numbers of an ASCII file's elements.
struct AsciiLines {
    /// Line of the first element of each element kind, in header order.
    first: Vec<(String, usize)>,
}

impl AsciiLines {
    fn new(bytes: &[u8], header: &Header) -> Option<AsciiLines> {
        if header.encoding != Encoding::Ascii {
            return None;
        }
        let end = find(bytes, b"end_header")?;
        let header_lines = bytes[..end].iter().filter(|&&b| b == b'\n').count() + 1;
        let mut line = header_lines + 1;
        let mut first = Vec::new();
        for (name, e) in header.elements.iter() {
            first.push((name.clone(), line));
            line += e.count;
        }
        Some(AsciiLines { first })
    }

    fn line(&self, element: &str, k: usize) -> Option<usize> {
        self.first
            .iter()
            .find(|(n, _)| n == element)
            .map(|(_, l)| l + k)
    }
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

pub(crate) fn parse_ply(bytes: &[u8]) -> Result<MeshData, (GeometryError, Option<usize>)> {
    let malformed = |message: String| {
        (
            GeometryError::Malformed {
                format: "PLY",
                message,
            },
            None,
        )
    };
    // ply-rs panics on numbers it cannot hold and allocates one record per declared
    // element before reading it: the header is validated first, against the file's size.
    check_header(bytes).map_err(|(m, line)| {
        (
            GeometryError::Malformed {
                format: "PLY",
                message: m,
            },
            line,
        )
    })?;
    let parser = Parser::<Record>::new();
    let ply = parser.read_ply(&mut &bytes[..]).map_err(|e| {
        let (message, line) = ply_rs_message(&e.to_string());
        (
            GeometryError::Malformed {
                format: "PLY",
                message,
            },
            line,
        )
    })?;
    let lines = AsciiLines::new(bytes, &ply.header);
    let line_of = |element: &str, k: usize| lines.as_ref().and_then(|l| l.line(element, k));

    let Some(vertex_def) = ply.header.elements.get("vertex") else {
        return Err(malformed("no `vertex` element".into()));
    };
    let has = |names: &[&str]| names.iter().any(|n| vertex_def.properties.contains_key(*n));
    if !(has(&["x"]) && has(&["y"]) && has(&["z"])) {
        return Err(malformed(
            "the `vertex` element lacks one of the properties x, y, z".into(),
        ));
    }
    let has_normals = has(&["nx"]) && has(&["ny"]) && has(&["nz"]);
    let has_uvs =
        has(&["u", "s", "texture_u", "texture_s"]) && has(&["v", "t", "texture_v", "texture_t"]);
    let empty = Vec::new();
    let vertices = ply.payload.get("vertex").unwrap_or(&empty);

    let mut data = MeshData {
        positions: Vec::with_capacity(vertices.len()),
        normals: has_normals.then(|| Vec::with_capacity(vertices.len())),
        uvs: has_uvs.then(|| Vec::with_capacity(vertices.len())),
        indices: Vec::new(),
    };
    for (k, r) in vertices.iter().enumerate() {
        let v = &r.values;
        let p = Vec3::new(v[X], v[X + 1], v[X + 2]);
        let n = Vec3::new(v[NX], v[NX + 1], v[NX + 2]);
        let uv = Vec2::new(v[U], v[V]);
        let bad = if !p.is_finite() {
            Some(("position", format!("{p}")))
        } else if has_normals && !n.is_finite() {
            Some(("normal", format!("{n}")))
        } else if has_uvs && !uv.is_finite() {
            Some(("uv", format!("{uv}")))
        } else {
            None
        };
        if let Some((attribute, value)) = bad {
            return Err((
                GeometryError::NonFiniteVertex {
                    attribute,
                    index: k,
                    value,
                },
                line_of("vertex", k),
            ));
        }
        data.positions.push(p);
        if let Some(ns) = &mut data.normals {
            ns.push(n);
        }
        if let Some(uvs) = &mut data.uvs {
            uvs.push(uv);
        }
    }

    let Some(face_def) = ply.header.elements.get("face") else {
        return Err((GeometryError::NoTriangles, None));
    };
    if !(face_def.properties.contains_key("vertex_indices")
        || face_def.properties.contains_key("vertex_index"))
    {
        return Err(malformed(
            "the `face` element has no `vertex_indices` (or `vertex_index`) list".into(),
        ));
    }
    let faces = ply.payload.get("face").unwrap_or(&empty);
    let n = data.positions.len();
    for (f, r) in faces.iter().enumerate() {
        if r.non_integer_indices {
            return Err((
                GeometryError::Malformed {
                    format: "PLY",
                    message: format!("face {f}: vertex indices must be integers"),
                },
                line_of("face", f),
            ));
        }
        if let Some(&index) = r.indices.iter().find(|&&i| i < 0 || i as u64 >= n as u64) {
            return Err((
                GeometryError::IndexOutOfRange {
                    index,
                    face: f,
                    vertex_count: n,
                },
                line_of("face", f),
            ));
        }
        for k in 1..r.indices.len().saturating_sub(1) {
            data.indices
                .extend([r.indices[0], r.indices[k], r.indices[k + 1]].map(|i| i as u32));
        }
    }
    if data.indices.is_empty() {
        return Err((GeometryError::NoTriangles, None));
    }
    Ok(data)
}

/// ply-rs's messages end in a Debug dump of its parser state (and say "Couln't"): only the
/// first line is kept, in plain words.
/// The line ply-rs names ("Line 12: …") is returned apart, for the file:line of the error.
fn ply_rs_message(m: &str) -> (String, Option<usize>) {
    let mut first = m.lines().next().unwrap_or(m).trim();
    let mut line = None;
    if let Some((n, rest)) = first.strip_prefix("Line ").and_then(|r| r.split_once(": ")) {
        if let Ok(n) = n.parse::<usize>() {
            line = Some(n);
            first = rest;
        }
    }
    let first = first
        .replace("Couln't", "could not")
        .replace("Couldn't", "could not");
    let value = m
        .lines()
        .find_map(|l| l.trim().strip_prefix("Value: "))
        .map(|v| format!(" (value {v})"))
        .unwrap_or_default();
    (format!("{first}{value}"), line)
}

/// Bytes of a scalar type of the header, `None` for an unknown name.
fn scalar_bytes(name: &str) -> Option<u64> {
    Some(match name {
        "char" | "int8" | "uchar" | "uint8" => 1,
        "short" | "int16" | "ushort" | "uint16" => 2,
        "int" | "int32" | "uint" | "uint32" | "float" | "float32" => 4,
        "double" | "float64" => 8,
        _ => return None,
    })
}

/// Validates the header before ply-rs reads the file: the magic line, one known format
/// with a plausible version, known property types, element counts that are numbers within
/// [`limits::MESH_ELEMENTS`] and that the rest of the file can hold (each element takes at
/// least one byte per property in binary, two characters per property in ASCII), and no
/// element that declares a count but no properties (ply-rs would make one empty record per
/// count without reading anything). Errors carry the header line.
fn check_header(bytes: &[u8]) -> Result<(), (String, Option<usize>)> {
    let Some(end) = find(bytes, b"end_header") else {
        return Err((
            "no `end_header` line: not a PLY file, or a truncated header".into(),
            None,
        ));
    };
    let header = std::str::from_utf8(&bytes[..end])
        .map_err(|_| ("the header is not ASCII text".to_string(), None))?;
    let payload = (bytes.len() - end) as u64;
    let mut binary = None;
    // (name, count, minimum binary bytes per element, properties, line) of each element.
    let mut elements: Vec<(String, u64, u64, u64, usize)> = Vec::new();
    for (k, line) in header.lines().enumerate() {
        let n = k + 1;
        let err = |m: String| (m, Some(n));
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first().copied() {
            _ if n == 1 => {
                if line.trim_end() != "ply" {
                    return Err(err("the first line must be `ply`: not a PLY file".into()));
                }
            }
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                let version_ok = words.get(2).is_some_and(|v| {
                    v.split_once('.').is_some_and(|(a, b)| {
                        a.parse::<u16>().is_ok() && b.parse::<u8>().is_ok()
                    })
                });
                binary = match words.get(1).copied() {
                    Some("ascii") => Some(false),
                    Some("binary_little_endian") | Some("binary_big_endian") => Some(true),
                    other => {
                        return Err(err(format!(
                            "unknown format `{}`; valid: ascii, binary_little_endian, binary_big_endian",
                            other.unwrap_or("")
                        )))
                    }
                };
                if !version_ok || words.len() != 3 {
                    return Err(err(format!("`{}`: expected `format <encoding> 1.0`", line.trim())));
                }
            }
            Some("element") => {
                let (Some(name), Some(count), 3) = (words.get(1), words.get(2), words.len()) else {
                    return Err(err(format!("`{}`: expected `element <name> <count>`", line.trim())));
                };
                let count: u64 = count.parse().map_err(|_| {
                    err(format!("element `{name}`: the count `{count}` is not a whole number below 2^64"))
                })?;
                limits::MESH_ELEMENTS
                    .check(count)
                    .map_err(|e| err(format!("element `{name}`: {e}")))?;
                elements.push((name.to_string(), count, 0, 0, n));
            }
            Some("property") => {
                let Some(last) = elements.last_mut() else {
                    return Err(err("a property before any element".into()));
                };
                let (size, len) = match words.get(1).copied() {
                    Some("list") => (
                        words.get(2).and_then(|t| scalar_bytes(t)).zip(words.get(3).and_then(|t| scalar_bytes(t))).map(|(c, _)| c),
                        5,
                    ),
                    Some(t) => (scalar_bytes(t), 3),
                    None => (None, 3),
                };
                if words.len() != len || size.is_none() {
                    return Err(err(format!(
                        "`{}`: expected `property <type> <name>` or `property list <count type> <type> <name>`; types: char, uchar, short, ushort, int, uint, float, double (or int8 … float64)",
                        line.trim()
                    )));
                }
                last.2 += size.unwrap_or(1);
                last.3 += 1;
            }
            Some(other) => {
                return Err(err(format!(
                    "unknown header keyword `{other}`; valid: format, element, property, comment, obj_info, end_header"
                )))
            }
        }
    }
    let Some(binary) = binary else {
        return Err(("the header has no `format` line".into(), None));
    };
    let mut needed: u64 = 0;
    for (name, count, bytes_each, properties, line) in &elements {
        if *properties == 0 && *count > 0 {
            return Err((
                format!("element `{name}` declares {count} elements but no properties"),
                Some(*line),
            ));
        }
        // ASCII: at least one digit and one separator per property.
        let each = if binary { *bytes_each } else { 2 * properties };
        needed = count
            .checked_mul(each)
            .and_then(|b| needed.checked_add(b))
            .unwrap_or(u64::MAX);
        if needed > payload {
            return Err((
                format!(
                    "element `{name}` declares {count} elements, more than the {payload} bytes after the header can hold"
                ),
                Some(*line),
            ));
        }
    }
    Ok(())
}
