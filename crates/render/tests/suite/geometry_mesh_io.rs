//! Mesh files written to a temporary directory and loaded back: OBJ, PLY in ASCII and
//! binary (both byte orders), and the errors of missing, malformed, out-of-range and
//! non-finite files.

use facette_render::geometry::mesh_io::{load_mesh, read_mesh, read_obj, read_ply};
use facette_render::geometry::{GeometryError, Ray, Transform, Vec2, Vec3};
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

const CUBE_OBJ: &str = "\
# unit cube, quads, two groups, a material library that does not exist
mtllib missing.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
vt 0 0
vt 1 0
vt 1 1
vt 0.25 0.75
o bottom_and_top
g bottom
f 1/1 4/4 3/3 2/2
g top
f 5/1 6/2 7/3 8/4
o sides
f 1/1 2/2 6/3 5/4
f 2/1 3/2 7/3 6/4
f 3/1 4/2 8/3 7/4
f 4/1 1/2 5/3 8/4
";

#[test]
fn obj_round_trip_merges_groups_and_flips_v() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "cube.obj", CUBE_OBJ.as_bytes());
    let data = read_obj(&path, false).unwrap();
    assert_eq!(data.triangle_count(), 12);
    assert!(data.normals.is_none());
    let uvs = data.uvs.as_ref().unwrap();
    assert!(uvs.contains(&Vec2::new(0.25, 0.75)));
    // Mitsuba's default flips v.
    let flipped = read_mesh(&path).unwrap();
    assert!(flipped
        .uvs
        .as_ref()
        .unwrap()
        .contains(&Vec2::new(0.25, 0.25)));

    // As a placed mesh: closed, outward (the winding above is counter-clockwise seen from
    // outside), area 6·4 after scaling by 2.
    let t = Transform::translate(Vec3::new(10.0, 0.0, 0.0)).unwrap()
        * Transform::scale(Vec3::splat(2.0)).unwrap();
    let mesh = load_mesh(&path, &t, false).unwrap();
    assert!((mesh.area() - 24.0).abs() < 1e-12);
    let h = mesh
        .intersect(&Ray::infinite(Vec3::new(11.0, 1.0, 10.0), -Vec3::Z))
        .unwrap();
    assert!((h.t - 8.0).abs() < 1e-12);
    assert!((h.ng - Vec3::Z).length() < 1e-15);
}

#[test]
fn obj_with_normals_and_negative_indices() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\n\
               f -3/-3/-1 -2/-2/-1 -1/-1/-1\n";
    let path = write(dir.path(), "tri.OBJ", obj.as_bytes());
    let data = read_mesh(&path).unwrap();
    assert_eq!(data.triangle_count(), 1);
    assert_eq!(data.normals.as_ref().unwrap()[0], Vec3::Z);
}

/// A unit square (quad) and a pentagon lifted to z = 1, with normals and uvs.
fn ply_vertices() -> Vec<([f32; 3], [f32; 3], [f32; 2])> {
    let mut v = vec![
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0]),
        ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0]),
        ([1.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0]),
    ];
    for k in 0..5 {
        let a = std::f32::consts::TAU * k as f32 / 5.0;
        v.push(([a.cos(), a.sin(), 1.0], [0.0, 0.0, 1.0], [0.5, 0.5]));
    }
    v
}

const FACES: [&[i32]; 2] = [&[0, 1, 2, 3], &[4, 5, 6, 7, 8]];

fn ply_header(format: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\nelement vertex 9\n\
         property float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         property float texture_u\nproperty float texture_v\n\
         element face 2\nproperty list uchar int vertex_indices\nend_header\n"
    )
}

fn ascii_ply() -> String {
    let mut s = ply_header("ascii");
    for (p, n, uv) in ply_vertices() {
        s += &format!(
            "{} {} {} {} {} {} {} {}\n",
            p[0], p[1], p[2], n[0], n[1], n[2], uv[0], uv[1]
        );
    }
    for f in FACES {
        s += &format!("{}", f.len());
        for i in f {
            s += &format!(" {i}");
        }
        s += "\n";
    }
    s
}

fn binary_ply(
    big_endian: bool,
    mangle: impl Fn(&mut Vec<([f32; 3], [f32; 3], [f32; 2])>),
) -> Vec<u8> {
    let format = if big_endian {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let mut out = ply_header(format).into_bytes();
    let f32b = |x: f32| {
        if big_endian {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    let i32b = |x: i32| {
        if big_endian {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    let mut verts = ply_vertices();
    mangle(&mut verts);
    for (p, n, uv) in verts {
        for x in p.into_iter().chain(n).chain(uv) {
            out.extend_from_slice(&f32b(x));
        }
    }
    for f in FACES {
        out.push(f.len() as u8);
        for &i in f {
            out.extend_from_slice(&i32b(i));
        }
    }
    out
}

#[test]
fn ply_ascii_and_binary_load_the_same_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let ascii = read_ply(&write(dir.path(), "a.ply", ascii_ply().as_bytes())).unwrap();
    let le = read_ply(&write(dir.path(), "le.ply", &binary_ply(false, |_| {}))).unwrap();
    let be = read_mesh(&write(dir.path(), "be.PLY", &binary_ply(true, |_| {}))).unwrap();
    // Quad → 2 triangles, pentagon → 3 (fans).
    assert_eq!(
        le.indices,
        vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 4, 7, 8]
    );
    assert_eq!(le, be);
    assert_eq!(ascii.indices, le.indices);
    for (a, b) in ascii.positions.iter().zip(&le.positions) {
        // ASCII went through decimal printing of f32 values.
        assert!((*a - *b).length() < 1e-6);
    }
    assert_eq!(le.normals.as_ref().unwrap()[5], Vec3::Z);
    assert_eq!(le.uvs.as_ref().unwrap()[2], Vec2::ONE);
    let mesh = le.into_mesh(&Transform::IDENTITY, false).unwrap();
    let pentagon = 2.5 * (std::f64::consts::TAU / 5.0).sin();
    assert!((mesh.area() - 1.0 - pentagon).abs() < 1e-6);
}

fn error_of(path: &Path) -> (GeometryError, String) {
    let e = read_mesh(path).unwrap_err();
    let msg = e.to_string();
    (e, msg)
}

#[test]
fn missing_and_unknown_files() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere.obj");
    let (e, msg) = error_of(&missing);
    assert!(matches!(e, GeometryError::Io { .. }), "{msg}");
    assert!(
        msg.contains("nowhere.obj") && msg.contains("cannot read"),
        "{msg}"
    );
    let (e, msg) = error_of(&dir.path().join("nowhere.ply"));
    assert!(matches!(e, GeometryError::Io { .. }), "{msg}");
    let stl = write(dir.path(), "mesh.stl", b"solid x\n");
    let (e, msg) = error_of(&stl);
    assert!(
        matches!(e, GeometryError::UnknownMeshFormat { .. }),
        "{msg}"
    );
    assert!(msg.contains("mesh.stl") && msg.contains(".obj"), "{msg}");
}

#[test]
fn obj_errors_name_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &str, &str); 5] = [
        (
            "range.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 7\n",
            ":5: face refers to vertex 7, but the file defines 3",
        ),
        (
            "uvrange.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/2\n",
            ":5: face refers to texture coordinate 2",
        ),
        (
            "parse.obj",
            "v 0 0 0\nv 1 0 0\nv 0 one 0\nf 1 2 3\n",
            ":3: malformed OBJ data: position parse error",
        ),
        (
            "nan.obj",
            "v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n",
            ":2: mesh vertex 1 has a non-finite position",
        ),
        (
            "empty.obj",
            "# nothing\nv 0 0 0\n",
            ": mesh has no triangles",
        ),
    ];
    for (name, text, expected) in cases {
        let path = write(dir.path(), name, text.as_bytes());
        let (e, msg) = error_of(&path);
        assert!(matches!(e, GeometryError::InFile { .. }), "{msg}");
        let want = format!("{}{expected}", path.display());
        assert!(
            msg.starts_with(&want),
            "{name}: got `{msg}`, want `{want}…`"
        );
    }
}

#[test]
fn ply_errors_name_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    // ASCII: out-of-range index on the second face (line 25: 14 header lines, 9 vertices).
    let bad = ascii_ply().replace("5 4 5 6 7 8", "5 4 5 6 7 9");
    let path = write(dir.path(), "range.ply", bad.as_bytes());
    let (_, msg) = error_of(&path);
    let want = format!(
        "{}:25: vertex index 9 of face 1 is out of range: the mesh has 9 vertices",
        path.display()
    );
    assert!(msg.starts_with(&want), "got `{msg}`");
    // Negative index.
    let bad = ascii_ply().replace("4 0 1 2 3", "4 0 -1 2 3");
    let (_, msg) = error_of(&write(dir.path(), "neg.ply", bad.as_bytes()));
    assert!(
        msg.contains(":24: vertex index -1 of face 0"),
        "got `{msg}`"
    );
    // Malformed payload: the parser's message with its line.
    let bad = ascii_ply().replace("\n1 0 0 0 0 1 1 0\n", "\n1 0 zero 0 0 1 1 0\n");
    let (e, msg) = error_of(&write(dir.path(), "parse.ply", bad.as_bytes()));
    assert!(
        matches!(e.root(), GeometryError::Malformed { format: "PLY", .. }),
        "{msg}"
    );
    assert!(msg.contains("parse.ply:16:"), "{msg}");
    // Truncated binary file.
    let mut short = binary_ply(false, |_| {});
    short.truncate(short.len() - 6);
    let (e, msg) = error_of(&write(dir.path(), "short.ply", &short));
    assert!(matches!(e.root(), GeometryError::Malformed { .. }), "{msg}");
    // Non-finite binary coordinate: no line in a binary file, but the vertex is named.
    let nan = binary_ply(true, |v| v[3].0[1] = f32::NAN);
    let path = write(dir.path(), "nan.ply", &nan);
    let (_, msg) = error_of(&path);
    let want = format!(
        "{}: mesh vertex 3 has a non-finite position",
        path.display()
    );
    assert!(msg.starts_with(&want), "got `{msg}`");
    // No face element.
    let no_faces = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n\
                    property float y\nproperty float z\nend_header\n0 0 0\n";
    let (e, msg) = error_of(&write(dir.path(), "nofaces.ply", no_faces.as_bytes()));
    assert!(matches!(e.root(), GeometryError::NoTriangles), "{msg}");
    // Missing coordinates.
    let no_z = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n\
                property float y\nend_header\n0 0\n";
    let (_, msg) = error_of(&write(dir.path(), "noz.ply", no_z.as_bytes()));
    assert!(msg.contains("lacks one of the properties x, y, z"), "{msg}");
}
