//! PLY (ASCII, binary little- and big-endian): a bounded reader of our own.
//!
//! Read: the `vertex` element's `x y z`, optional `nx ny nz`, optional texture
//! coordinates named `u v`, `s t`, `texture_u texture_v` or `texture_s texture_t` (any
//! scalar type); the `face` element's `vertex_indices` (or `vertex_index`) list of any
//! count and index type, polygons fan-triangulated (faces of fewer than three vertices are
//! skipped). Other elements and properties, lists included, are skipped. ASCII records
//! are one per line, as the PLY format has them, with exactly the values the header
//! declares; what follows the last declared element is ignored.
//!
//! Why our own reader rather than `ply-rs`: a PLY header declares counts, and a reader
//! that trusts them allocates or loops as told. `ply-rs` 0.1 panicked on a count beyond
//! `u64` and made one record per declared element of an element without properties (a
//! 70-byte file could ask for 10^12); its fork `ply-rs-bw` 4 fixes the panics and caps
//! preallocation, but still loops over such an element (10^8 records of nothing: 11 s,
//! 7 GB) and builds a record per element before the caller sees any (docs/validation.md,
//! "Robustness", has the measurements: this reader is also 2–5 times faster). Here every
//! count is checked against [`limits::MESH_ELEMENTS`] and against the bytes (binary) or
//! lines (ASCII) left after the header before anything is allocated; a binary record's
//! list is checked against the bytes left before it is read; arithmetic on counts is
//! checked; slices are indexed only where a bound was checked. Errors name the file and,
//! for ASCII, the line; for binary, the element and record.

use crate::geometry::error::{GeometryError, GeometryResult};
use crate::geometry::mesh_data::MeshData;
use crate::geometry::{Vec2, Vec3};
use facette_bsdf::limits;
use std::path::Path;

/// Reads a PLY file.
pub fn read_ply(path: &Path) -> GeometryResult<MeshData> {
    let bytes = super::read_mesh_bytes(path, "PLY")?;
    parse_ply(&bytes).map_err(|(e, line)| e.in_file(path, line))
}

/// An error and the line it was found on (ASCII files and headers).
type Failure = (GeometryError, Option<usize>);

fn malformed(message: String, line: Option<usize>) -> Failure {
    (
        GeometryError::Malformed {
            format: "PLY",
            message,
        },
        line,
    )
}

/// The scalar types of the PLY format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    /// Bytes in a binary file.
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// The value at `at` in `bytes`, `None` past the end. Every PLY scalar is exact in
    /// an `f64` (a `float` is widened as it is stored).
    #[inline]
    fn read(self, bytes: &[u8], at: usize, big: bool) -> Option<f64> {
        fn get<const N: usize>(bytes: &[u8], at: usize, big: bool) -> Option<[u8; N]> {
            let mut a: [u8; N] = bytes.get(at..at.checked_add(N)?)?.try_into().ok()?;
            if big {
                a.reverse();
            }
            Some(a)
        }
        Some(match self {
            Scalar::I8 => i8::from_le_bytes(get(bytes, at, big)?) as f64,
            Scalar::U8 => u8::from_le_bytes(get(bytes, at, big)?) as f64,
            Scalar::I16 => i16::from_le_bytes(get(bytes, at, big)?) as f64,
            Scalar::U16 => u16::from_le_bytes(get(bytes, at, big)?) as f64,
            Scalar::I32 => i32::from_le_bytes(get(bytes, at, big)?) as f64,
            Scalar::U32 => u32::from_le_bytes(get(bytes, at, big)?) as f64,
            Scalar::F32 => f32::from_le_bytes(get(bytes, at, big)?) as f64,
            Scalar::F64 => f64::from_le_bytes(get(bytes, at, big)?),
        })
    }

    /// An ASCII value of this type; integers must be whole and in the type's range, a
    /// `float` is parsed as `f32` (as a binary file would hold it), then widened.
    fn parse(self, token: &[u8]) -> Option<f64> {
        let s = std::str::from_utf8(token).ok()?;
        Some(match self {
            Scalar::I8 => s.parse::<i8>().ok()? as f64,
            Scalar::U8 => s.parse::<u8>().ok()? as f64,
            Scalar::I16 => s.parse::<i16>().ok()? as f64,
            Scalar::U16 => s.parse::<u16>().ok()? as f64,
            Scalar::I32 => s.parse::<i32>().ok()? as f64,
            Scalar::U32 => s.parse::<u32>().ok()? as f64,
            Scalar::F32 => s.parse::<f32>().ok()? as f64,
            Scalar::F64 => s.parse::<f64>().ok()?,
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct PropertyDef {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct ElementDef {
    name: String,
    count: u64,
    properties: Vec<PropertyDef>,
    /// Header line of the `element` line.
    line: usize,
}

impl ElementDef {
    /// Bytes of a binary record with every list empty.
    fn min_binary_bytes(&self) -> u64 {
        self.properties
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => s.size() as u64,
                Kind::List { count, .. } => count.size() as u64,
            })
            .sum()
    }

    /// Bytes of every binary record, when it has no list.
    fn fixed_binary_bytes(&self) -> Option<usize> {
        self.properties
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => Some(s.size()),
                Kind::List { .. } => None,
            })
            .sum()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    Binary { big_endian: bool },
}

#[derive(Debug)]
struct Header {
    format: Format,
    elements: Vec<ElementDef>,
    /// Lines of the header, `end_header` included.
    lines: usize,
    /// Offset of the first byte after the `end_header` line.
    payload: usize,
}

/// The next line of `bytes` from `*pos` (without its `\n` and a `\r` before it), and
/// `*pos` moved past it; `None` at the end.
#[inline]
fn next_line<'a>(bytes: &'a [u8], pos: &mut usize) -> Option<&'a [u8]> {
    let rest = bytes.get(*pos..).filter(|r| !r.is_empty())?;
    let (line, advance) = match rest.iter().position(|&b| b == b'\n') {
        Some(k) => (&rest[..k], k + 1),
        None => (rest, rest.len()),
    };
    *pos += advance;
    Some(line.strip_suffix(b"\r").unwrap_or(line))
}

/// Reads and validates the header: the magic line, one known format with a plausible
/// version, `element` lines with counts within [`limits::MESH_ELEMENTS`], `property` lines
/// of known types, and no element that declares records but no properties (its records
/// would take no bytes, so no file size bounds their count). Errors carry the header line.
fn parse_header(bytes: &[u8]) -> Result<Header, (String, Option<usize>)> {
    let mut pos = 0;
    let mut n = 0;
    let mut format = None;
    let mut elements: Vec<ElementDef> = Vec::new();
    loop {
        let Some(raw) = next_line(bytes, &mut pos) else {
            return Err((
                "no `end_header` line: not a PLY file, or a truncated header".into(),
                None,
            ));
        };
        n += 1;
        let err = |m: String| (m, Some(n));
        let Ok(line) = std::str::from_utf8(raw) else {
            return Err(err("the header is not ASCII text".into()));
        };
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        match words.first().copied() {
            _ if n == 1 => {
                if line.trim_end() != "ply" {
                    return Err(err("the first line must be `ply`: not a PLY file".into()));
                }
            }
            None | Some("comment") | Some("obj_info") => {}
            Some("end_header") if words.len() == 1 => break,
            Some("format") => {
                let version_ok = words.get(2).is_some_and(|v| {
                    v.split_once('.').is_some_and(|(a, b)| {
                        a.parse::<u16>().is_ok() && b.parse::<u8>().is_ok()
                    })
                });
                format = Some(match words.get(1).copied() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::Binary { big_endian: false },
                    Some("binary_big_endian") => Format::Binary { big_endian: true },
                    other => {
                        return Err(err(format!(
                            "unknown format `{}`; valid: ascii, binary_little_endian, binary_big_endian",
                            other.unwrap_or("")
                        )))
                    }
                });
                if !version_ok || words.len() != 3 {
                    return Err(err(format!(
                        "`{}`: expected `format <encoding> 1.0`",
                        line.trim()
                    )));
                }
            }
            Some("element") => {
                let (Some(name), Some(count), 3) = (words.get(1), words.get(2), words.len())
                else {
                    return Err(err(format!(
                        "`{}`: expected `element <name> <count>`",
                        line.trim()
                    )));
                };
                let count: u64 = count.parse().map_err(|_| {
                    err(format!(
                        "element `{name}`: the count `{count}` is not a whole number below 2^64"
                    ))
                })?;
                limits::MESH_ELEMENTS
                    .check(count)
                    .map_err(|e| err(format!("element `{name}`: {e}")))?;
                if elements.iter().any(|e| e.name == *name) {
                    return Err(err(format!("element `{name}` is declared twice")));
                }
                elements.push(ElementDef {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                    line: n,
                });
            }
            Some("property") => {
                let Some(last) = elements.last_mut() else {
                    return Err(err("a property before any element".into()));
                };
                let ty = |k: usize| words.get(k).and_then(|t| Scalar::from_name(t));
                let kind = match (words.get(1).copied(), words.len()) {
                    (Some("list"), 5) => ty(2)
                        .zip(ty(3))
                        .map(|(count, item)| Kind::List { count, item }),
                    (Some(_), 3) => ty(1).map(Kind::Scalar),
                    _ => None,
                };
                let (Some(kind), Some(name)) = (kind, words.last()) else {
                    return Err(err(format!(
                        "`{}`: expected `property <type> <name>` or `property list <count type> <type> <name>`; types: char, uchar, short, ushort, int, uint, float, double (or int8 … float64)",
                        line.trim()
                    )));
                };
                last.properties.push(PropertyDef {
                    name: name.to_string(),
                    kind,
                });
            }
            Some(other) => {
                return Err(err(format!(
                    "unknown header keyword `{other}`; valid: format, element, property, comment, obj_info, end_header"
                )))
            }
        }
    }
    let Some(format) = format else {
        return Err(("the header has no `format` line".into(), None));
    };
    for e in &elements {
        if e.properties.is_empty() && e.count > 0 {
            return Err((
                format!(
                    "element `{}` declares {} elements but no properties",
                    e.name, e.count
                ),
                Some(e.line),
            ));
        }
    }
    Ok(Header {
        format,
        elements,
        lines: n,
        payload: pos,
    })
}

/// Checks that what follows the header can hold every declared element before anything
/// is allocated: in binary, each record takes its scalars and list counts; in ASCII, each
/// record takes one line of at least two characters per property.
fn check_sizes(header: &Header, payload: &[u8]) -> Result<(), (String, Option<usize>)> {
    let bytes = payload.len() as u64;
    let lines = match header.format {
        Format::Binary { .. } => u64::MAX,
        Format::Ascii => {
            let newlines = payload.iter().filter(|&&b| b == b'\n').count() as u64;
            newlines + u64::from(payload.last().is_some_and(|&b| b != b'\n'))
        }
    };
    let (mut needed_bytes, mut needed_lines) = (0u64, 0u64);
    for e in &header.elements {
        let each = match header.format {
            Format::Binary { .. } => e.min_binary_bytes(),
            Format::Ascii => 2 * e.properties.len() as u64,
        };
        needed_bytes = e
            .count
            .checked_mul(each)
            .and_then(|b| needed_bytes.checked_add(b))
            .unwrap_or(u64::MAX);
        needed_lines = needed_lines.saturating_add(e.count);
        if needed_bytes > bytes {
            return Err((
                format!(
                    "element `{}` declares {} elements, more than the {bytes} bytes after the header can hold",
                    e.name, e.count
                ),
                Some(e.line),
            ));
        }
        if needed_lines > lines {
            return Err((
                format!(
                    "element `{}` declares {} elements, more than the {lines} lines after the header hold",
                    e.name, e.count
                ),
                Some(e.line),
            ));
        }
    }
    Ok(())
}

/// Where a vertex property goes in [`VertexValues`].
const X: usize = 0;
const NX: usize = 3;
const U: usize = 6;
const V: usize = 7;

type VertexValues = [f64; 8];

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

/// What the reader does with each property of an element.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Use {
    Skip,
    /// A vertex value, stored in this slot.
    Slot(usize),
    /// The face's vertex index list.
    Indices,
}

/// The mesh being read, with what the header says of it.
struct Builder {
    data: MeshData,
    has_normals: bool,
    has_uvs: bool,
    /// Vertex count declared by the header; face indices are checked against it.
    vertex_count: usize,
    /// Largest index count: [`limits::MESH_ELEMENTS`] triangles.
    max_indices: usize,
}

impl Builder {
    /// Stores vertex `k` after checking that what is used is finite.
    fn vertex(&mut self, k: usize, v: &VertexValues) -> Result<(), GeometryError> {
        let p = Vec3::new(v[X], v[X + 1], v[X + 2]);
        let n = Vec3::new(v[NX], v[NX + 1], v[NX + 2]);
        let uv = Vec2::new(v[U], v[V]);
        let bad = if !p.is_finite() {
            Some(("position", format!("{p}")))
        } else if self.has_normals && !n.is_finite() {
            Some(("normal", format!("{n}")))
        } else if self.has_uvs && !uv.is_finite() {
            Some(("uv", format!("{uv}")))
        } else {
            None
        };
        if let Some((attribute, value)) = bad {
            return Err(GeometryError::NonFiniteVertex {
                attribute,
                index: k,
                value,
            });
        }
        self.data.positions.push(p);
        if let Some(ns) = &mut self.data.normals {
            ns.push(n);
        }
        if let Some(uvs) = &mut self.data.uvs {
            uvs.push(uv);
        }
        Ok(())
    }
}

/// The vertex indices of one face as they are read: checked, then fan-triangulated.
struct Fan {
    face: usize,
    first: u32,
    previous: u32,
    seen: usize,
}

impl Fan {
    fn new(face: usize) -> Fan {
        Fan {
            face,
            first: 0,
            previous: 0,
            seen: 0,
        }
    }

    fn push(&mut self, value: f64, mesh: &mut Builder) -> Result<(), GeometryError> {
        // Integral and small enough to be exact as an i64 (float lists may hold anything).
        if value.fract() != 0.0 || value.abs() >= 9.0e15 {
            return Err(GeometryError::Malformed {
                format: "PLY",
                message: format!("face {}: vertex indices must be integers", self.face),
            });
        }
        let index = value as i64;
        if index < 0 || index as u64 >= mesh.vertex_count as u64 {
            return Err(GeometryError::IndexOutOfRange {
                index,
                face: self.face,
                vertex_count: mesh.vertex_count,
            });
        }
        let i = index as u32;
        match self.seen {
            0 => self.first = i,
            1 => {}
            _ => {
                let indices = &mut mesh.data.indices;
                if indices.len() >= mesh.max_indices {
                    let triangles = indices.len() as u64 / 3 + 1;
                    if let Err(e) = limits::MESH_ELEMENTS.check(triangles) {
                        return Err(GeometryError::Malformed {
                            format: "PLY",
                            message: format!("face {}: triangles: {e}", self.face),
                        });
                    }
                }
                indices.extend_from_slice(&[self.first, self.previous, i]);
            }
        }
        self.previous = i;
        self.seen += 1;
        Ok(())
    }
}

fn parse_ply(bytes: &[u8]) -> Result<MeshData, Failure> {
    let header = parse_header(bytes).map_err(|(m, line)| malformed(m, line))?;
    let payload = bytes.get(header.payload..).unwrap_or_default();
    check_sizes(&header, payload).map_err(|(m, line)| malformed(m, line))?;

    let Some(vertex_def) = header.elements.iter().find(|e| e.name == "vertex") else {
        return Err(malformed("no `vertex` element".into(), None));
    };
    let has = |names: &[&str]| {
        vertex_def
            .properties
            .iter()
            .any(|p| names.contains(&p.name.as_str()))
    };
    if !(has(&["x"]) && has(&["y"]) && has(&["z"])) {
        return Err(malformed(
            "the `vertex` element lacks one of the properties x, y, z".into(),
            Some(vertex_def.line),
        ));
    }
    if let Some(p) = vertex_def
        .properties
        .iter()
        .find(|p| slot(&p.name).is_some() && matches!(p.kind, Kind::List { .. }))
    {
        return Err(malformed(
            format!(
                "the `vertex` property `{}` is a list; expected a number",
                p.name
            ),
            Some(vertex_def.line),
        ));
    }
    let has_normals = has(&["nx"]) && has(&["ny"]) && has(&["nz"]);
    let has_uvs =
        has(&["u", "s", "texture_u", "texture_s"]) && has(&["v", "t", "texture_v", "texture_t"]);

    let Some(face_def) = header.elements.iter().find(|e| e.name == "face") else {
        return Err((GeometryError::NoTriangles, None));
    };
    // The last index list of the face element is the one read (as `ply-rs` did).
    let Some(index_list) = face_def
        .properties
        .iter()
        .rposition(|p| p.name == "vertex_indices" || p.name == "vertex_index")
    else {
        return Err(malformed(
            "the `face` element has no `vertex_indices` (or `vertex_index`) list".into(),
            Some(face_def.line),
        ));
    };
    if let Kind::Scalar(_) = face_def.properties[index_list].kind {
        return Err(malformed(
            format!(
                "the `face` property `{}` is a number; expected a list",
                face_def.properties[index_list].name
            ),
            Some(face_def.line),
        ));
    }

    // Counts are within limits::MESH_ELEMENTS (so they fit a usize and a u32), and the
    // payload can hold them: these allocations are bounded by the file's size.
    let vertex_count = vertex_def.count as usize;
    let face_count = face_def.count as usize;
    let mut mesh = Builder {
        data: MeshData {
            positions: Vec::with_capacity(vertex_count),
            normals: has_normals.then(|| Vec::with_capacity(vertex_count)),
            uvs: has_uvs.then(|| Vec::with_capacity(vertex_count)),
            // A triangle's indices take at least a byte each in the file: a header that
            // declares faces without them gets no more than the file's size reserved.
            indices: Vec::with_capacity((3 * face_count).min(payload.len())),
        },
        has_normals,
        has_uvs,
        vertex_count,
        max_indices: 3 * limits::MESH_ELEMENTS.max() as usize,
    };
    let mut at = Cursor {
        pos: 0,
        line: header.lines + 1,
    };
    for e in &header.elements {
        let uses: Vec<Use> = e
            .properties
            .iter()
            .enumerate()
            .map(|(k, p)| match e.name.as_str() {
                "vertex" => slot(&p.name).map_or(Use::Skip, Use::Slot),
                "face" if k == index_list => Use::Indices,
                _ => Use::Skip,
            })
            .collect();
        match header.format {
            Format::Ascii => read_ascii(e, &uses, payload, &mut at, &mut mesh)?,
            Format::Binary { big_endian } => {
                read_binary(e, &uses, payload, big_endian, &mut at, &mut mesh)?
            }
        }
    }
    if mesh.data.indices.is_empty() {
        return Err((GeometryError::NoTriangles, None));
    }
    Ok(mesh.data)
}

/// Where the reader is in the payload: the byte offset and, for ASCII, the file line of
/// the next record.
struct Cursor {
    pos: usize,
    line: usize,
}

/// A list count read as a number: whole and not negative.
fn list_count(c: f64, property: &str) -> Result<usize, String> {
    if c >= 0.0 && c.fract() == 0.0 && c <= u32::MAX as f64 {
        Ok(c as usize)
    } else {
        Err(format!(
            "the list count {c} of property `{property}` is not a whole number ≥ 0"
        ))
    }
}

/// The next ASCII value of a record, of type `ty`.
fn ascii_value<'a>(
    tokens: &mut impl Iterator<Item = &'a [u8]>,
    ty: Scalar,
    what: &dyn Fn() -> String,
) -> Result<f64, String> {
    let Some(t) = tokens.next() else {
        return Err(format!("the line ends before {}", what()));
    };
    ty.parse(t).ok_or_else(|| {
        format!(
            "`{}` is not a {} ({})",
            String::from_utf8_lossy(t),
            ty.name(),
            what()
        )
    })
}

/// Reads the ASCII records of element `e`, one a line. Lines of elements the mesh does
/// not use are skipped unread.
fn read_ascii(
    e: &ElementDef,
    uses: &[Use],
    payload: &[u8],
    at: &mut Cursor,
    mesh: &mut Builder,
) -> Result<(), Failure> {
    let count = e.count as usize;
    let is_vertex = e.name == "vertex";
    let skip_only = uses.iter().all(|&u| u == Use::Skip);
    for k in 0..count {
        let line = at.line;
        let context = |m: String| {
            malformed(
                format!("element `{}`, record {k} of {count}: {m}", e.name),
                Some(line),
            )
        };
        let Some(text) = next_line(payload, &mut at.pos) else {
            return Err(context("the file ends before it".into()));
        };
        at.line += 1;
        if skip_only {
            continue;
        }
        let mut tokens = text
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty());
        let mut values: VertexValues = [0.0; 8];
        let mut fan = Fan::new(k);
        for (p, &u) in e.properties.iter().zip(uses) {
            match p.kind {
                Kind::Scalar(ty) => {
                    let v = ascii_value(&mut tokens, ty, &|| format!("property `{}`", p.name))
                        .map_err(context)?;
                    if let Use::Slot(s) = u {
                        values[s] = v;
                    }
                }
                Kind::List { count: cty, item } => {
                    let what = || format!("the list count of property `{}`", p.name);
                    let c = ascii_value(&mut tokens, cty, &what)
                        .and_then(|c| list_count(c, &p.name))
                        .map_err(context)?;
                    for j in 0..c {
                        let what = || format!("item {j} of the {c} of list `{}`", p.name);
                        let v = ascii_value(&mut tokens, item, &what).map_err(context)?;
                        if u == Use::Indices {
                            fan.push(v, mesh).map_err(|e| (e, Some(line)))?;
                        }
                    }
                }
            }
        }
        if tokens.next().is_some() {
            return Err(context(format!(
                "more values than its {} properties",
                e.properties.len()
            )));
        }
        if is_vertex {
            mesh.vertex(k, &values).map_err(|e| (e, Some(line)))?;
        }
    }
    Ok(())
}

/// Reads the binary records of element `e`. Records of a fixed size are bounds-checked
/// once for the whole element; a record with lists is checked list by list, before the
/// list is read.
fn read_binary(
    e: &ElementDef,
    uses: &[Use],
    payload: &[u8],
    big: bool,
    at: &mut Cursor,
    mesh: &mut Builder,
) -> Result<(), Failure> {
    let count = e.count as usize;
    if count == 0 {
        return Ok(());
    }
    let is_vertex = e.name == "vertex";
    let truncated = |k: usize| {
        malformed(
            format!(
                "element `{}`, record {k} of {count}: the file ends inside it",
                e.name
            ),
            None,
        )
    };
    if let Some(size) = e.fixed_binary_bytes().filter(|&s| s > 0) {
        let left = payload.len().saturating_sub(at.pos);
        let end = size
            .checked_mul(count)
            .filter(|&len| len <= left)
            .map(|len| at.pos + len)
            .ok_or_else(|| truncated(left / size))?;
        if is_vertex {
            // (offset in the record, type, slot) of each property the mesh uses.
            let mut reads = Vec::new();
            let mut offset = 0;
            for (p, &u) in e.properties.iter().zip(uses) {
                if let (Kind::Scalar(ty), Use::Slot(s)) = (p.kind, u) {
                    reads.push((offset, ty, s));
                }
                if let Kind::Scalar(ty) = p.kind {
                    offset += ty.size();
                }
            }
            let records = payload.get(at.pos..end).unwrap_or_default();
            for (k, record) in records.chunks_exact(size).enumerate() {
                let mut values: VertexValues = [0.0; 8];
                for &(offset, ty, s) in &reads {
                    values[s] = ty.read(record, offset, big).ok_or_else(|| truncated(k))?;
                }
                mesh.vertex(k, &values).map_err(|e| (e, None))?;
            }
        }
        at.pos = end;
        return Ok(());
    }
    for k in 0..count {
        let mut values: VertexValues = [0.0; 8];
        let mut fan = Fan::new(k);
        for (p, &u) in e.properties.iter().zip(uses) {
            match p.kind {
                Kind::Scalar(ty) => {
                    let v = ty.read(payload, at.pos, big).ok_or_else(|| truncated(k))?;
                    if let Use::Slot(s) = u {
                        values[s] = v;
                    }
                    at.pos += ty.size();
                }
                Kind::List { count: cty, item } => {
                    let c = cty.read(payload, at.pos, big).ok_or_else(|| truncated(k))?;
                    at.pos += cty.size();
                    let c = list_count(c, &p.name).map_err(|m| {
                        malformed(
                            format!("element `{}`, record {k} of {count}: {m}", e.name),
                            None,
                        )
                    })?;
                    let left = payload.len().saturating_sub(at.pos);
                    let end = c
                        .checked_mul(item.size())
                        .filter(|&len| len <= left)
                        .map(|len| at.pos + len)
                        .ok_or_else(|| truncated(k))?;
                    if u == Use::Indices {
                        for j in 0..c {
                            let v = item
                                .read(payload, at.pos + j * item.size(), big)
                                .ok_or_else(|| truncated(k))?;
                            fan.push(v, mesh).map_err(|e| (e, None))?;
                        }
                    }
                    at.pos = end;
                }
            }
        }
        if is_vertex {
            mesh.vertex(k, &values).map_err(|e| (e, None))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

    /// A unit quad and a pentagon lifted to z = 1, with normals and uvs (as in
    /// `tests/suite/geometry_mesh_io.rs`).
    fn vertices() -> Vec<([f32; 3], [f32; 3], [f32; 2])> {
        let mut v = vec![
            ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0]),
            ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0]),
            ([1.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0]),
            ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0]),
        ];
        for k in 0..5 {
            let a = std::f32::consts::TAU * k as f32 / 5.0;
            v.push(([a.cos(), a.sin(), 1.0], [0.6, 0.0, 0.8], [0.5, 0.25]));
        }
        v
    }

    /// A quad, a pentagon and a two-vertex face (skipped).
    const FACES: [&[u32]; 3] = [&[0, 1, 2, 3], &[4, 5, 6, 7, 8], &[0, 1]];

    /// What every fixture must load as.
    fn expected(normals: bool, uvs: bool) -> MeshData {
        let v = vertices();
        let wide = |a: &[f32]| a.iter().map(|&x| x as f64).collect::<Vec<_>>();
        MeshData {
            positions: v.iter().map(|p| Vec3::from_slice(&wide(&p.0))).collect(),
            normals: normals.then(|| v.iter().map(|p| Vec3::from_slice(&wide(&p.1))).collect()),
            uvs: uvs.then(|| v.iter().map(|p| Vec2::from_slice(&wide(&p.2))).collect()),
            indices: vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 4, 7, 8],
        }
    }

    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Enc {
        Ascii,
        Le,
        Be,
    }

    /// How a fixture lays the mesh out.
    #[derive(Clone, Copy, Debug)]
    struct Layout {
        enc: Enc,
        position: Scalar,
        normal: Option<Scalar>,
        /// Type and names of the texture coordinates.
        uv: Option<(Scalar, &'static str, &'static str)>,
        count: Scalar,
        index: Scalar,
        index_name: &'static str,
        /// Elements and properties the reader must skip.
        extras: bool,
    }

    const PLAIN: Layout = Layout {
        enc: Enc::Ascii,
        position: Scalar::F32,
        normal: Some(Scalar::F32),
        uv: Some((Scalar::F32, "u", "v")),
        count: Scalar::U8,
        index: Scalar::I32,
        index_name: "vertex_indices",
        extras: false,
    };

    /// One record's values, written in the layout's encoding.
    struct Record<'a> {
        enc: Enc,
        out: &'a mut Vec<u8>,
        first: bool,
    }

    impl Record<'_> {
        fn put(&mut self, ty: Scalar, v: f64) {
            let be = self.enc == Enc::Be;
            macro_rules! bin {
                ($t:ty) => {{
                    let x = v as $t;
                    self.out
                        .extend_from_slice(&if be { x.to_be_bytes() } else { x.to_le_bytes() });
                }};
            }
            match self.enc {
                Enc::Ascii => {
                    if !self.first {
                        self.out.push(b' ');
                    }
                    let text = match ty {
                        Scalar::F32 => format!("{}", v as f32),
                        Scalar::F64 => format!("{v}"),
                        _ => format!("{}", v as i64),
                    };
                    self.out.extend_from_slice(text.as_bytes());
                }
                Enc::Le | Enc::Be => match ty {
                    Scalar::I8 => bin!(i8),
                    Scalar::U8 => bin!(u8),
                    Scalar::I16 => bin!(i16),
                    Scalar::U16 => bin!(u16),
                    Scalar::I32 => bin!(i32),
                    Scalar::U32 => bin!(u32),
                    Scalar::F32 => bin!(f32),
                    Scalar::F64 => bin!(f64),
                },
            }
            self.first = false;
        }

        fn end(self) {
            if self.enc == Enc::Ascii {
                self.out.push(b'\n');
            }
        }
    }

    fn fixture(l: Layout) -> Vec<u8> {
        let format = match l.enc {
            Enc::Ascii => "ascii",
            Enc::Le => "binary_little_endian",
            Enc::Be => "binary_big_endian",
        };
        let mut h = format!("ply\nformat {format} 1.0\ncomment a fixture\n");
        if l.extras {
            h += "element material 2\nproperty uchar red\nproperty list uchar float weights\n";
        }
        h += "element vertex 9\n";
        for c in ["x", "y", "z"] {
            h += &format!("property {} {c}\n", l.position.name());
        }
        if l.extras {
            h += "property uchar confidence\n";
        }
        if let Some(t) = l.normal {
            for c in ["nx", "ny", "nz"] {
                h += &format!("property {} {c}\n", t.name());
            }
        }
        if let Some((t, u, v)) = l.uv {
            h += &format!("property {} {u}\nproperty {} {v}\n", t.name(), t.name());
        }
        if l.extras {
            h += "property list uint8 int32 neighbours\n";
        }
        h += "element face 3\n";
        if l.extras {
            h += "property uchar flags\n";
        }
        h += &format!(
            "property list {} {} {}\n",
            l.count.name(),
            l.index.name(),
            l.index_name
        );
        if l.extras {
            h += "property list uchar float texcoord\nelement edge 2\nproperty int a\nproperty short b\n";
        }
        h += "end_header\n";
        let mut out = h.into_bytes();
        let record = |out: &mut Vec<u8>, f: &dyn Fn(&mut Record)| {
            let mut r = Record {
                enc: l.enc,
                out,
                first: true,
            };
            f(&mut r);
            r.end();
        };
        if l.extras {
            for k in 0..2 {
                record(&mut out, &|r| {
                    r.put(Scalar::U8, 200.0);
                    r.put(Scalar::U8, k as f64);
                    for _ in 0..k {
                        r.put(Scalar::F32, 0.5);
                    }
                });
            }
        }
        for (p, n, uv) in vertices() {
            record(&mut out, &|r| {
                for c in p {
                    r.put(l.position, c as f64);
                }
                if l.extras {
                    r.put(Scalar::U8, 7.0);
                }
                if let Some(t) = l.normal {
                    for c in n {
                        r.put(t, c as f64);
                    }
                }
                if let Some((t, _, _)) = l.uv {
                    for c in uv {
                        r.put(t, c as f64);
                    }
                }
                if l.extras {
                    r.put(Scalar::U8, 2.0);
                    r.put(Scalar::I32, -1.0);
                    r.put(Scalar::I32, 3.0);
                }
            });
        }
        for f in FACES {
            record(&mut out, &|r| {
                if l.extras {
                    r.put(Scalar::U8, 1.0);
                }
                r.put(l.count, f.len() as f64);
                for &i in f {
                    r.put(l.index, i as f64);
                }
                if l.extras {
                    r.put(Scalar::U8, 1.0);
                    r.put(Scalar::F32, 0.25);
                }
            });
        }
        if l.extras {
            for _ in 0..2 {
                record(&mut out, &|r| {
                    r.put(Scalar::I32, 1.0);
                    r.put(Scalar::I16, 2.0);
                });
            }
        }
        out
    }

    fn layouts() -> Vec<Layout> {
        let mut all = Vec::new();
        for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
            for extras in [false, true] {
                all.push(Layout {
                    enc,
                    extras,
                    ..PLAIN
                });
                all.push(Layout {
                    enc,
                    extras,
                    position: Scalar::F64,
                    normal: None,
                    uv: Some((Scalar::F64, "texture_s", "texture_t")),
                    count: Scalar::I32,
                    index: Scalar::U16,
                    index_name: "vertex_index",
                });
                all.push(Layout {
                    enc,
                    extras,
                    normal: Some(Scalar::F64),
                    uv: None,
                    count: Scalar::U16,
                    index: Scalar::I8,
                    ..PLAIN
                });
                all.push(Layout {
                    enc,
                    extras,
                    uv: Some((Scalar::F32, "s", "t")),
                    count: Scalar::I8,
                    index: Scalar::F32,
                    ..PLAIN
                });
                all.push(Layout {
                    enc,
                    extras,
                    uv: Some((Scalar::F32, "texture_u", "texture_v")),
                    count: Scalar::U32,
                    index: Scalar::F64,
                    ..PLAIN
                });
                all.push(Layout {
                    enc,
                    extras,
                    count: Scalar::I16,
                    index: Scalar::U32,
                    ..PLAIN
                });
            }
        }
        all
    }

    #[test]
    fn every_format_and_type_loads_the_same_mesh() {
        for l in layouts() {
            let bytes = fixture(l);
            let got = parse_ply(&bytes).unwrap_or_else(|(e, line)| panic!("{l:?}: {e} ({line:?})"));
            assert_eq!(got, expected(l.normal.is_some(), l.uv.is_some()), "{l:?}");
        }
    }

    fn error(bytes: &[u8]) -> (String, Option<usize>) {
        let (e, line) = parse_ply(bytes).expect_err("an error");
        (e.to_string(), line)
    }

    fn ascii() -> String {
        String::from_utf8(fixture(PLAIN)).unwrap()
    }

    fn binary(enc: Enc) -> Vec<u8> {
        fixture(Layout { enc, ..PLAIN })
    }

    /// 15 header lines: the first vertex is on line 16, the first face on line 25.
    #[test]
    fn ascii_errors_have_lines() {
        let bad = ascii().replace("\n5 4 5 6 7 8\n", "\n5 4 5 6 7 9\n");
        let (e, line) = error(bad.as_bytes());
        assert!(
            e.contains("vertex index 9 of face 1 is out of range"),
            "{e}"
        );
        assert_eq!(line, Some(26));
        let (e, line) = error(
            ascii()
                .replace("\n4 0 1 2 3\n", "\n4 0 -1 2 3\n")
                .as_bytes(),
        );
        assert!(e.contains("vertex index -1 of face 0"), "{e}");
        assert_eq!(line, Some(25));
        let third = "\n1 1 0 0 0 1 1 1\n";
        assert!(ascii().contains(third));
        for (bad, what) in [
            (
                "\n1 one 0 0 0 1 1 1\n",
                "`one` is not a float (property `y`)",
            ),
            ("\n1 1 0 0 0 1 1\n", "the line ends before property `v`"),
            ("\n1 1 0 0 0 1 1 1 1\n", "more values than its 8 properties"),
            (
                "\n1 1 nan 0 0 1 1 1\n",
                "mesh vertex 2 has a non-finite position",
            ),
            ("\n1 1 0 0 0 1 inf 1\n", "mesh vertex 2 has a non-finite uv"),
            (
                "\n1 1 0 0 0 1e39 1 1\n",
                "mesh vertex 2 has a non-finite normal",
            ),
            ("\n1 1 0 0 0 1 1 \u{ff}\n", "is not a float"),
        ] {
            let (e, line) = error(ascii().replace(third, bad).as_bytes());
            assert!(e.contains(what), "{bad}: {e}");
            assert_eq!(line, Some(18), "{e}");
            assert!(
                e.starts_with("malformed PLY data: element `vertex`, record 2 of 9")
                    || e.starts_with("mesh vertex"),
                "{e}"
            );
        }
        let face = "\n4 0 1 2 3\n";
        for (bad, what) in [
            (
                "\n300 0 1 2 3\n",
                "`300` is not a uchar (the list count of property `vertex_indices`)",
            ),
            (
                "\n4 0 1 2\n",
                "the line ends before item 3 of the 4 of list `vertex_indices`",
            ),
            ("\n4 0 1 2 3.5\n", "`3.5` is not a int"),
        ] {
            let (e, line) = error(ascii().replace(face, bad).as_bytes());
            assert!(e.contains(what), "{bad}: {e}");
            assert_eq!(line, Some(25), "{e}");
        }
        // The file ends before the last face.
        let text = ascii();
        let cut = text.trim_end().rfind('\n').unwrap() + 1;
        let (e, line) = error(&text.as_bytes()[..cut]);
        assert!(
            e.contains("more than the 11 lines after the header hold"),
            "{e}"
        );
        assert_eq!(line, Some(13));
    }

    #[test]
    fn binary_errors_name_element_and_record() {
        for enc in [Enc::Le, Enc::Be] {
            let good = binary(enc);
            // Cut in the last face: the sizes still fit (a face takes at least its count).
            let (e, line) = error(&good[..good.len() - 6]);
            assert!(
                e.contains("element `face`, record 2 of 3: the file ends inside it"),
                "{e}"
            );
            assert_eq!(line, None);
            // Cut in the vertices: records of a fixed size are checked with the header.
            let header = good.len() - 9 * 32 - (1 + 16) - (1 + 20) - (1 + 8);
            let (e, line) = error(&good[..header + 9 * 32 - 1]);
            assert!(
                e.contains("element `vertex` declares 9 elements, more than the 287 bytes"),
                "{e}"
            );
            assert_eq!(line, Some(4));
            // A count of 2^32 - 1 indices after the first face.
            let mut huge = good.clone();
            let face0 = header + 9 * 32;
            huge[face0] = 255;
            let (e, _) = error(&huge);
            assert!(
                e.contains("vertex index") || e.contains("the file ends"),
                "{e}"
            );
            // A NaN coordinate.
            let mut nan = good.clone();
            let at = header + 3 * 32 + 4;
            let bits = if enc == Enc::Be {
                f32::NAN.to_be_bytes()
            } else {
                f32::NAN.to_le_bytes()
            };
            nan[at..at + 4].copy_from_slice(&bits);
            let (e, line) = error(&nan);
            assert!(
                e.starts_with("mesh vertex 3 has a non-finite position"),
                "{e}"
            );
            assert_eq!(line, None);
            // An out-of-range index.
            let mut range = good.clone();
            range[face0 + 1..face0 + 5].copy_from_slice(&if enc == Enc::Be {
                9i32.to_be_bytes()
            } else {
                9i32.to_le_bytes()
            });
            let (e, _) = error(&range);
            assert!(
                e.contains("vertex index 9 of face 0 is out of range"),
                "{e}"
            );
        }
        // A list count of 2^32 - 1 in a uint count: refused before it is read; a negative
        // count in an int count.
        let face = |count_type: &str, count: [u8; 4]| {
            let mut b = format!("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty uchar x\nproperty uchar y\nproperty uchar z\nelement face 1\nproperty list {count_type} uint vertex_indices\nend_header\n").into_bytes();
            b.extend_from_slice(&[0, 0, 0, 1, 0, 0, 0, 1, 0]);
            b.extend_from_slice(&count);
            b.extend_from_slice(&[0; 12]);
            b
        };
        let (e, _) = error(&face("uint", u32::MAX.to_le_bytes()));
        assert!(
            e.contains("element `face`, record 0 of 1: the file ends inside it"),
            "{e}"
        );
        let (e, _) = error(&face("int", (-1i32).to_le_bytes()));
        assert!(
            e.contains("record 0 of 1: the list count -1 of property `vertex_indices` is not a whole number"),
            "{e}"
        );
        assert!(parse_ply(&face("int", 3i32.to_le_bytes())).is_ok());
    }

    #[test]
    fn headers_are_checked_before_anything_is_allocated() {
        let xyz = "property float x\nproperty float y\nproperty float z\n";
        let cases: Vec<(String, &str, Option<usize>)> = vec![
            ("".into(), "no `end_header` line", None),
            ("ply\nformat ascii 1.0\nelement vertex 3\n".into(), "no `end_header` line", None),
            ("\u{7f}ELF\0\0\nend_header\n".into(), "the first line must be `ply`", Some(1)),
            ("ply\nformat ascii 1.0\nelement vertex 100000000000000000000\nend_header\n".into(), "100000000000000000000` is not a whole number", Some(3)),
            ("ply\nformat ascii 1.0\nelement vertex 268435457\nend_header\n".into(), "mesh elements (vertices or faces) = 268435457 exceeds the limit", Some(3)),
            ("ply\nformat ascii 1.0\nelement vertex -1\nend_header\n".into(), "not a whole number", Some(3)),
            (format!("ply\nformat binary_little_endian 1.0\nelement vertex 200000000\n{xyz}end_header\n"), "more than the 0 bytes after the header can hold", Some(3)),
            (format!("ply\nformat ascii 1.0\nelement vertex 3\n{xyz}end_header\n0.0 0.0 0.0\n1.0 0.0 0.0\n"), "more than the 2 lines after the header hold", Some(3)),
            (format!("ply\nformat ascii 1.0\nelement vertex 3\n{xyz}element junk 100000000\nend_header\n"), "element `junk` declares 100000000 elements but no properties", Some(7)),
            ("ply\nformat ascii 99999999999999999999.0\nend_header\n".into(), "expected `format <encoding> 1.0`", Some(2)),
            ("ply\nformat utf8 1.0\nend_header\n".into(), "unknown format `utf8`", Some(2)),
            ("ply\nend_header\n".into(), "no `format` line", None),
            ("ply\nformat ascii 1.0\nproperty float x\nend_header\n".into(), "a property before any element", Some(3)),
            ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float64x x\nend_header\n".into(), "expected `property <type> <name>`", Some(4)),
            ("ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar x\nend_header\n".into(), "expected `property <type> <name>`", Some(4)),
            ("ply\nformat ascii 1.0\nelement vertex 0\nelement vertex 0\nend_header\n".into(), "element `vertex` is declared twice", Some(4)),
            ("ply\nformat ascii 1.0\nvertices 3\nend_header\n".into(), "unknown header keyword `vertices`", Some(3)),
            ("ply\nformat ascii 1.0\ncomment \u{e9}\nend_header\n".into(),
                "no `vertex` element",
                None),
            ("ply\nformat ascii 1.0\nend_header\n".into(), "no `vertex` element", None),
            ("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nend_header\n".into(), "lacks one of the properties x, y, z", Some(3)),
            (format!("ply\nformat ascii 1.0\nelement vertex 0\n{xyz}property list uchar float u\nend_header\n"), "the `vertex` property `u` is a list", Some(3)),
            (format!("ply\nformat ascii 1.0\nelement vertex 0\n{xyz}end_header\n"), "mesh has no triangles", None),
            (format!("ply\nformat ascii 1.0\nelement vertex 0\n{xyz}element face 0\nproperty int vertex_indices\nend_header\n"), "the `face` property `vertex_indices` is a number", Some(7)),
            (format!("ply\nformat ascii 1.0\nelement vertex 0\n{xyz}element face 0\nproperty list uchar int indices\nend_header\n"), "no `vertex_indices` (or `vertex_index`) list", Some(7)),
            (format!("ply\nformat ascii 1.0\nelement vertex 0\n{xyz}element face 0\nproperty list uchar int vertex_indices\nend_header\n"), "mesh has no triangles", None),
        ];
        for (text, want, want_line) in cases {
            let (e, line) = error(text.as_bytes());
            assert!(e.contains(want), "{text:?}: {e}");
            assert_eq!(line, want_line, "{text:?}: {e}");
        }
        // A header line that is not UTF-8.
        let (e, line) = error(b"ply\nformat ascii 1.0\ncomment \xff\nend_header\n");
        assert!(e.contains("not ASCII text"), "{e}");
        assert_eq!(line, Some(3));
    }

    #[test]
    fn line_endings_and_whitespace() {
        let crlf = ascii().replace('\n', "\r\n");
        assert_eq!(parse_ply(crlf.as_bytes()).unwrap(), expected(true, true));
        let tabs = ascii().replace("\n4 0 1 2 3\n", "\n\t4  0\t1 2 3  \n");
        assert_eq!(parse_ply(tabs.as_bytes()).unwrap(), expected(true, true));
        // What follows the last element is ignored; so is the missing final newline.
        let more = ascii() + "trailing junk\n";
        assert_eq!(parse_ply(more.as_bytes()).unwrap(), expected(true, true));
        let text = ascii();
        let last = text.trim_end();
        assert_eq!(parse_ply(last.as_bytes()).unwrap(), expected(true, true));
    }

    /// Valid fixtures mutated at random (bytes overwritten, inserted, deleted, the file
    /// cut, header numbers replaced by extremes): every case is read or refused, never a
    /// panic. Fixed seed: a failure replays.
    #[test]
    fn mutated_files_never_panic() {
        let corpus: Vec<Vec<u8>> = [
            PLAIN,
            Layout {
                extras: true,
                ..PLAIN
            },
            Layout {
                enc: Enc::Le,
                extras: true,
                ..PLAIN
            },
            Layout {
                enc: Enc::Be,
                count: Scalar::I32,
                index: Scalar::F64,
                ..PLAIN
            },
            Layout {
                enc: Enc::Le,
                count: Scalar::U32,
                index: Scalar::U8,
                ..PLAIN
            },
        ]
        .into_iter()
        .map(fixture)
        .collect();
        let extremes: [&[u8]; 9] = [
            b"0",
            b"-1",
            b"255",
            b"4294967295",
            b"4294967296",
            b"18446744073709551616",
            b"268435456",
            b"1e308",
            b"nan",
        ];
        let config = Config {
            cases: 3000,
            failure_persistence: None,
            ..Config::default()
        };
        let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[23; 32]);
        let mut runner = TestRunner::new_with_rng(config, rng);
        let edits = prop::collection::vec((0u8..5, any::<usize>(), any::<u8>()), 1..6);
        runner
            .run(&(0..corpus.len(), edits), |(which, edits)| {
                let mut b = corpus[which].clone();
                for (op, at, byte) in edits {
                    let n = b.len().max(1);
                    match op {
                        0 if !b.is_empty() => b[at % n] = byte,
                        1 => b.insert(at % (b.len() + 1), byte),
                        2 if !b.is_empty() => {
                            b.remove(at % n);
                        }
                        3 => b.truncate(at % n),
                        _ => {
                            // Replace the digits at a position by an extreme number.
                            let start = at % n;
                            let end = b[start.min(b.len())..]
                                .iter()
                                .position(|c| !c.is_ascii_digit())
                                .map_or(b.len(), |k| start + k);
                            let start = start.min(end);
                            let x = extremes[byte as usize % extremes.len()];
                            b.splice(start..end, x.iter().copied());
                        }
                    }
                }
                match parse_ply(&b) {
                    Ok(d) => {
                        prop_assert!(d.indices.len() % 3 == 0);
                        prop_assert!(d.indices.iter().all(|&i| (i as usize) < d.positions.len()));
                        prop_assert!(d.positions.iter().all(|p| p.is_finite()));
                    }
                    Err((e, _)) => prop_assert!(!e.to_string().is_empty()),
                }
                Ok(())
            })
            .unwrap();
    }
}
