//! Wavefront OBJ through `tobj`: polygons fan-triangulated, one index per vertex
//! (position/uv/normal triples de-duplicated), all objects and groups merged into one
//! mesh, points and lines ignored, materials ignored (`mtllib` files are not opened).
//!
//! Normals (uvs) are kept only if every vertex of every group has one. `tobj` reports
//! errors without a location; the reader counts the lines `tobj` consumes to locate parse
//! errors, and scans the text again to locate index and finiteness errors (which
//! `tobj` detects only when a group ends).

use crate::geometry::error::{GeometryError, GeometryResult};
use crate::geometry::mesh_data::MeshData;
use crate::geometry::{Vec2, Vec3};
use facette_bsdf::limits;
use std::io::{BufRead, Read};
use std::path::Path;

/// Reads an OBJ file. `flip_tex_coords` maps `v ↦ 1 − v` (Mitsuba's default).
pub fn read_obj(path: &Path, flip_tex_coords: bool) -> GeometryResult<MeshData> {
    let bytes = super::read_mesh_bytes(path, "OBJ")?;
    parse_obj(&bytes, flip_tex_coords).map_err(|(e, line)| e.in_file(path, line))
}

/// Parses OBJ text; errors carry their line when known.
fn parse_obj(
    bytes: &[u8],
    flip_tex_coords: bool,
) -> Result<MeshData, (GeometryError, Option<usize>)> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    check_element_counts(bytes)?;
    if let Some((line, what)) = face_index_without_data(bytes) {
        return Err((
            GeometryError::Malformed {
                format: "OBJ",
                message: format!(
                    "a face gives {what} indices, but the file has no `{}` lines",
                    if what == "texture coordinate" {
                        "vt"
                    } else {
                        "vn"
                    }
                ),
            },
            Some(line),
        ));
    }
    let mut reader = LineCounter::new(bytes);
    let loaded = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    let models = match loaded {
        Ok((models, _materials)) => models,
        Err(e) => return Err(locate_tobj_error(bytes, e, reader.line())),
    };

    let vertex_total: usize = models.iter().map(|m| m.mesh.positions.len() / 3).sum();
    let all_normals = models
        .iter()
        .all(|m| m.mesh.normals.len() == m.mesh.positions.len());
    let all_uvs = models
        .iter()
        .all(|m| m.mesh.texcoords.len() / 2 == m.mesh.positions.len() / 3);
    let mut data = MeshData {
        positions: Vec::with_capacity(vertex_total),
        normals: all_normals.then(|| Vec::with_capacity(vertex_total)),
        uvs: all_uvs.then(|| Vec::with_capacity(vertex_total)),
        indices: Vec::new(),
    };
    for model in &models {
        let mesh = &model.mesh;
        let base = data.positions.len() as u64;
        data.positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        if let Some(normals) = &mut data.normals {
            normals.extend(
                mesh.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2])),
            );
        }
        if let Some(uvs) = &mut data.uvs {
            uvs.extend(
                mesh.texcoords
                    .chunks_exact(2)
                    .map(|c| Vec2::new(c[0], if flip_tex_coords { 1.0 - c[1] } else { c[1] })),
            );
        }
        for &i in &mesh.indices {
            let idx = base + i as u64;
            if idx > u32::MAX as u64 {
                return Err((
                    GeometryError::TooLarge {
                        what: "vertices",
                        count: idx as usize + 1,
                        max: u32::MAX as usize,
                    },
                    None,
                ));
            }
            data.indices.push(idx as u32);
        }
    }
    if data.indices.is_empty() {
        return Err((GeometryError::NoTriangles, None));
    }
    let text = String::from_utf8_lossy(bytes);
    for (attribute, keyword, arity) in [("position", "v", 3), ("normal", "vn", 3), ("uv", "vt", 2)]
    {
        if let Some(found) = first_non_finite(&text, keyword, arity) {
            return Err((
                GeometryError::NonFiniteVertex {
                    attribute,
                    index: found.ordinal,
                    value: found.text,
                },
                Some(found.line),
            ));
        }
    }
    Ok(data)
}

/// Turns a `tobj` error into ours, with the line where it happened.
fn locate_tobj_error(
    bytes: &[u8],
    e: tobj::LoadError,
    line: usize,
) -> (GeometryError, Option<usize>) {
    use tobj::LoadError as L;
    let attribute = match e {
        L::FaceVertexOutOfBounds => Some("vertex"),
        L::FaceTexCoordOutOfBounds => Some("texture coordinate"),
        L::FaceNormalOutOfBounds => Some("normal"),
        _ => None,
    };
    if let Some(attribute) = attribute {
        let text = String::from_utf8_lossy(bytes);
        if let Some((line, index, count)) = first_bad_face_index(&text, attribute) {
            return (
                GeometryError::ObjIndexOutOfRange {
                    attribute,
                    index,
                    count,
                },
                Some(line),
            );
        }
    }
    let message = match e {
        L::ReadError => "cannot read the line (is the file UTF-8 text?)".to_string(),
        e => e.to_string(),
    };
    (
        GeometryError::Malformed {
            format: "OBJ",
            message,
        },
        Some(line.max(1)),
    )
}

/// The first face (1-based line) that gives `v/vt` or `v/vt/vn` indices for a kind of data
/// the file never declares: `tobj` would silently drop them (or index nothing).
fn face_index_without_data(bytes: &[u8]) -> Option<(usize, &'static str)> {
    let text = String::from_utf8_lossy(bytes);
    let has = |kw: &str| {
        text.lines()
            .any(|l| l.split_whitespace().next() == Some(kw))
    };
    let (has_vt, has_vn) = (has("vt"), has("vn"));
    if has_vt && has_vn {
        return None;
    }
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("f") {
            continue;
        }
        for w in words {
            // `v`, `v/vt`, `v//vn` or `v/vt/vn`.
            let mut parts = w.split('/').skip(1);
            let (vt, vn) = (parts.next(), parts.next());
            if !has_vt && vt.is_some_and(|t| !t.is_empty()) {
                return Some((k + 1, "texture coordinate"));
            }
            if !has_vn && vn.is_some_and(|n| !n.is_empty()) {
                return Some((k + 1, "normal"));
            }
        }
    }
    None
}

/// Counts the vertex lines of each kind and the face corners and triangles before `tobj`
/// allocates for them, and holds each to [`limits::MESH_ELEMENTS`]: the file-size bound
/// alone would let a 4 GiB file of `f` lines with thousands of corners ask for far more
/// triangles than 32-bit indices can name. The error is at the line that crossed the
/// limit.
fn check_element_counts(bytes: &[u8]) -> Result<(), (GeometryError, Option<usize>)> {
    let (mut positions, mut uvs, mut normals, mut corners, mut triangles) =
        (0u64, 0u64, 0u64, 0u64, 0u64);
    for (k, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let mut words = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty());
        let (count, what) = match words.next() {
            Some(b"v") => (&mut positions, "vertex positions (`v` lines)"),
            Some(b"vt") => (&mut uvs, "texture coordinates (`vt` lines)"),
            Some(b"vn") => (&mut normals, "normals (`vn` lines)"),
            Some(b"f") => {
                let n = words.count() as u64;
                corners += n;
                triangles += n.saturating_sub(2);
                let over = limits::MESH_ELEMENTS
                    .check(corners)
                    .and_then(|_| limits::MESH_ELEMENTS.check(triangles))
                    .map_err(|e| {
                        e.to_string()
                            .replace(limits::MESH_ELEMENTS.what, "face corners or triangles")
                    });
                if let Err(message) = over {
                    return Err((
                        GeometryError::Malformed {
                            format: "OBJ",
                            message,
                        },
                        Some(k + 1),
                    ));
                }
                continue;
            }
            _ => continue,
        };
        *count += 1;
        if let Err(e) = limits::MESH_ELEMENTS.check(*count) {
            let message = e.to_string().replace(limits::MESH_ELEMENTS.what, what);
            return Err((
                GeometryError::Malformed {
                    format: "OBJ",
                    message,
                },
                Some(k + 1),
            ));
        }
    }
    Ok(())
}

/// A `v`/`vn`/`vt` line with a non-finite value: its line, its 0-based ordinal among
/// lines of that keyword, and its text.
struct NonFinite {
    line: usize,
    ordinal: usize,
    text: String,
}

fn first_non_finite(text: &str, keyword: &str, arity: usize) -> Option<NonFinite> {
    let mut ordinal = 0;
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some(keyword) {
            continue;
        }
        let bad = words
            .take(arity)
            .any(|w| w.parse::<f64>().is_ok_and(|x| !x.is_finite()));
        if bad {
            return Some(NonFinite {
                line: k + 1,
                ordinal,
                text: line.trim().to_string(),
            });
        }
        ordinal += 1;
    }
    None
}

/// The first face referring to a missing `attribute` ("vertex", "texture coordinate"
/// or "normal"): `(line, index as written, number defined)`. Positive indices are
/// checked against the whole file's count (OBJ allows forward references), negative ones
/// against the count so far.
fn first_bad_face_index(text: &str, attribute: &str) -> Option<(usize, i64, usize)> {
    let (keyword, slot) = match attribute {
        "vertex" => ("v", 0),
        "texture coordinate" => ("vt", 1),
        _ => ("vn", 2),
    };
    let total = text
        .lines()
        .filter(|l| l.split_whitespace().next() == Some(keyword))
        .count();
    let mut so_far = 0usize;
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some(w) if w == keyword => so_far += 1,
            Some("f") => {
                for w in words {
                    let Some(field) = w.split('/').nth(slot) else {
                        continue;
                    };
                    if field.is_empty() {
                        continue;
                    }
                    let Ok(index) = field.parse::<i64>() else {
                        continue;
                    };
                    let ok = if index > 0 {
                        index as usize <= total
                    } else {
                        index < 0 && index.unsigned_abs() as usize <= so_far
                    };
                    if !ok {
                        let count = if index > 0 { total } else { so_far };
                        return Some((k + 1, index, count));
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// A `BufRead` over bytes that counts the lines consumed, so that a parser reading line
/// by line can be told where it stopped.
struct LineCounter<'a> {
    rest: &'a [u8],
    newlines: usize,
    partial: bool,
}

impl<'a> LineCounter<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        LineCounter {
            rest: bytes,
            newlines: 0,
            partial: false,
        }
    }

    /// 1-based number of the last line (partly) consumed.
    fn line(&self) -> usize {
        self.newlines + usize::from(self.partial)
    }
}

impl Read for LineCounter<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = buf.len().min(self.rest.len());
        buf[..n].copy_from_slice(&self.rest[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for LineCounter<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        Ok(self.rest)
    }

    fn consume(&mut self, amt: usize) {
        let amt = amt.min(self.rest.len());
        let (used, rest) = self.rest.split_at(amt);
        let nl = used.iter().filter(|&&b| b == b'\n').count();
        self.newlines += nl;
        if amt > 0 {
            self.partial = used.last() != Some(&b'\n');
        }
        self.rest = rest;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<MeshData, (GeometryError, Option<usize>)> {
        parse_obj(s.as_bytes(), false)
    }

    #[test]
    fn quads_groups_and_attributes() {
        let d = parse(
            "# a quad and a triangle in two groups\n\
             v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n\
             vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
             vn 0 0 1\n\
             g a\nf 1/1/1 2/2/1 3/3/1 4/4/1\n\
             g b\nf 1/1/1 2/2/1 5/4/1\n",
        )
        .unwrap();
        assert_eq!(d.triangle_count(), 3);
        assert!(d.normals.is_some() && d.uvs.is_some());
        assert_eq!(d.positions.len(), d.uvs.as_ref().unwrap().len());
        for &i in &d.indices {
            assert!((i as usize) < d.positions.len());
        }
    }

    #[test]
    fn normals_dropped_unless_everywhere() {
        let d =
            parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\ng b\nf 1 2 3\n").unwrap();
        assert!(d.normals.is_none());
        assert!(d.uvs.is_none());
        assert_eq!(d.triangle_count(), 2);
    }

    #[test]
    fn errors_have_lines() {
        let (e, line) = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap_err();
        assert!(
            matches!(
                e,
                GeometryError::ObjIndexOutOfRange {
                    index: 7,
                    count: 3,
                    ..
                }
            ),
            "{e}"
        );
        assert_eq!(line, Some(4));
        let (e, line) = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n").unwrap_err();
        assert!(
            matches!(e, GeometryError::ObjIndexOutOfRange { index: -4, .. }),
            "{e}"
        );
        assert_eq!(line, Some(4));
        let (e, line) = parse("v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n").unwrap_err();
        assert!(matches!(e, GeometryError::Malformed { .. }), "{e}");
        assert_eq!(line, Some(2));
        let (e, line) = parse("v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3").unwrap_err();
        assert!(
            matches!(e, GeometryError::NonFiniteVertex { index: 2, .. }),
            "{e}"
        );
        assert_eq!(line, Some(3));
        let (e, _) = parse("v 0 0 0\nv 1 0 0\n").unwrap_err();
        assert!(matches!(e, GeometryError::NoTriangles));
    }

    #[test]
    fn line_counter_counts_consumed_lines() {
        let mut r = LineCounter::new(b"a\nbb\nccc");
        let mut s = String::new();
        r.read_line(&mut s).unwrap();
        assert_eq!(r.line(), 1);
        s.clear();
        r.read_line(&mut s).unwrap();
        assert_eq!(r.line(), 2);
        s.clear();
        r.read_line(&mut s).unwrap();
        assert_eq!((r.line(), s.as_str()), (3, "ccc"));
    }
}
