//! The fuzz suite of every reader (issue 17), on stable Rust: a deterministic mutation
//! fuzzer (`fuzz_support/`) over a corpus seeded from `scenes/` and the formats' own
//! writers, one target per format — scene TOML, Mitsuba XML, OBJ, PLY, MERL, `.fctab`,
//! `.fctpart`, `.fcpart` (payload mutated and re-framed with a valid CRC, so the header
//! and data checks are reached, and raw framed bytes). A case fails with the seed and
//! case number, its input saved for a regression test, when it panics, is slow, or is
//! refused with an unclear message or one that does not name its culprit (the file, and
//! for text formats the line). `FACETTE_FUZZ_CASES=20000 cargo test --profile
//! optimized-tests --workspace --test suite fuzz_readers::` runs a longer campaign
//! (docs/validation.md, "Robustness").

use crate::fuzz_support;

use facette_bsdf::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use facette_bsdf::microfacet::{Beckmann, Masking, Ndf};
use facette_bsdf::models::il::il_table::BodyTable;
use facette_bsdf::models::il::il_table_part::{merge_table_parts, TablePart};
use facette_bsdf::storage::framed::Framed;
use facette_lab::merl::MerlBrdf;
use facette_render::geometry::mesh_io::{read_obj, read_ply};
use facette_render::partial_film::{merge_parts, render_part, PartialFilm};
use facette_render::render::RenderOptions;
use facette_render::scene::{load_scene, load_scene_str};
use fuzz_support::{cases, run, Culprit::File, Culprit::FileLine, Culprit::FileLineOrWhole};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn report(name: &str, n: usize, (accepted, refused): (usize, usize)) {
    println!("{name}: {n} cases, {accepted} accepted, {refused} refused");
    assert_eq!(accepted + refused, n);
}

/// Scenes of `scenes/` that load quickly and write nothing (the ones with `file =
/// "assets/sky.exr"` generate that file when it is missing).
const TOML_SCENES: &[&str] = &[
    "bench-sphere.toml",
    "comparison.toml",
    "furnace-ms.toml",
    "glass.toml",
    "glint-brushed-plate.toml",
    "glint-rough-furnace.toml",
    "glint-scratched-sphere.toml",
];

#[test]
fn fuzz_scene_toml() {
    let corpus: Vec<Vec<u8>> = TOML_SCENES
        .iter()
        .map(|n| read(&repo().join("scenes").join(n)))
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fuzz.toml");
    let n = cases(150);
    let r = run(
        "scene-toml",
        17,
        &corpus,
        n,
        20.0,
        FileLine("fuzz.toml"),
        &|b| {
            std::fs::write(&path, b).unwrap();
            load_scene(&path).map(|_| ()).map_err(|e| e.to_string())
        },
    );
    report("scene-toml", n, r);
}

#[test]
fn fuzz_mitsuba_xml() {
    // Every XML scene of the repository, flattened into one directory with the files they
    // name (meshes, images, included parts), so that references resolve.
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("parts")).unwrap();
    let mut corpus = Vec::new();
    for sub in ["bench", "efficiency", "mitsuba", "mitsuba/parts"] {
        for e in std::fs::read_dir(repo().join("scenes").join(sub)).unwrap() {
            let p = e.unwrap().path();
            if !p.is_file() {
                continue;
            }
            let to = if sub.ends_with("parts") {
                dir.path().join("parts")
            } else {
                dir.path().to_path_buf()
            };
            std::fs::copy(&p, to.join(p.file_name().unwrap())).unwrap();
            if p.extension().is_some_and(|x| x == "xml") && !sub.ends_with("parts") {
                corpus.push(read(&p));
            }
        }
    }
    let path = dir.path().join("fuzz.xml");
    let n = cases(250);
    let r = run(
        "mitsuba-xml",
        18,
        &corpus,
        n,
        20.0,
        FileLine("fuzz.xml"),
        &|b| {
            std::fs::write(&path, b).unwrap();
            load_scene(&path).map(|_| ()).map_err(|e| e.to_string())
        },
    );
    report("mitsuba-xml", n, r);
}

const PLY_ASCII: &str = "ply\nformat ascii 1.0\ncomment a unit quad\n\
    element vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
    property float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n\
    element face 1\nproperty list uchar int vertex_indices\nend_header\n\
    0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n4 0 1 2 3\n";

/// The quad of `PLY_ASCII` as binary little-endian.
fn ply_binary() -> Vec<u8> {
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
    for p in [[0f32, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]] {
        for c in p {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in [[0u32, 1, 2], [0, 2, 3]] {
        b.push(3);
        for i in f {
            b.extend_from_slice(&i.to_le_bytes());
        }
    }
    b
}

#[test]
fn fuzz_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("fuzz.obj");
    let corpus = vec![
        read(&repo().join("scenes/efficiency/torus.obj")),
        b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n".to_vec(),
    ];
    let n = cases(300);
    let r = run(
        "obj",
        19,
        &corpus,
        n,
        10.0,
        FileLineOrWhole("fuzz.obj", &["mesh has no triangles"]),
        &|b| {
            std::fs::write(&obj, b).unwrap();
            read_obj(&obj, false).map(|_| ()).map_err(|e| e.to_string())
        },
    );
    report("obj", n, r);

    let ply = dir.path().join("fuzz.ply");
    let corpus = vec![PLY_ASCII.as_bytes().to_vec(), ply_binary()];
    let n = cases(300);
    let r = run("ply", 20, &corpus, n, 10.0, File("fuzz.ply"), &|b| {
        std::fs::write(&ply, b).unwrap();
        read_ply(&ply).map(|_| ()).map_err(|e| e.to_string())
    });
    report("ply", n, r);
}

#[test]
fn fuzz_merl() {
    // A valid file (dimensions, then three channels of constant values); mutations land
    // mostly in the header and the first values, where the checks are.
    const BINS: usize = 90 * 90 * 180;
    let mut valid = Vec::with_capacity(12 + 24 * BINS);
    for d in [90i32, 90, 180] {
        valid.extend_from_slice(&d.to_le_bytes());
    }
    for _ in 0..3 * BINS {
        valid.extend_from_slice(&0.01f64.to_le_bytes());
    }
    let head = valid[..4096].to_vec();
    let corpus = vec![head];
    let n = cases(200);
    let r = run("merl", 21, &corpus, n, 10.0, File("fuzz.binary"), &|b| {
        // The mutated head, then the rest of a valid file (so that sizes still match
        // unless the mutation changed the head's length).
        let mut file = b.to_vec();
        if b.len() <= valid.len() {
            file.extend_from_slice(&valid[4096.min(valid.len())..]);
        }
        MerlBrdf::from_bytes(&file, "fuzz.binary")
            .map(|_| ())
            .map_err(|e| e.to_string())
    });
    report("merl", n, r);
}

fn lobe() -> SpecularLobe {
    SpecularLobe::new(
        Ndf::Beckmann(Beckmann::new(0.4, 0.4).unwrap()),
        Masking::SmithSeparable,
        NormalSampling::Visible,
    )
    .unwrap()
}

const TABLE: Framed = Framed {
    magic: b"FCTBODY1",
    version: 2,
    legacy_version: Some(1),
    what: "facette IL body table",
};
const TABLE_PART: Framed = Framed {
    magic: b"FCTPART1",
    version: 2,
    legacy_version: Some(1),
    what: "facette IL table part",
};
const RENDER_PART: Framed = Framed {
    magic: b"FCRPART1",
    version: 3,
    legacy_version: Some(2),
    what: "facette partial render",
};

fn payload(frame: &Framed, bytes: &[u8]) -> Vec<u8> {
    frame.unframe(bytes).unwrap().payload.to_vec()
}

/// Two table parts, the table, and two render parts of a tiny scene, as files.
fn binary_files() -> (Vec<u8>, Vec<Vec<u8>>, Vec<Vec<u8>>) {
    let table = BodyTable::build(&lobe(), 1.3, 30.0, 16, &|_, _| {})
        .unwrap()
        .to_bytes();
    let parts = (0..2)
        .map(|k| {
            TablePart::build(&lobe(), 1.3, 30.0, 16, k, 2, &|_, _| {})
                .unwrap()
                .to_bytes()
        })
        .collect();
    let scene = load_scene_str(
        "[camera]\nposition = [0, 0, 4]\ntarget = [0, 0, 0]\n[film]\nwidth = 6\nheight = 4\nspp = 2\n\
         [[objects]]\nshape = \"sphere\"\nmaterial = { type = \"lambert\" }\n\
         [[lights]]\ntype = \"constant\"\nradiance = 1\n",
        Path::new("tiny.toml"),
    )
    .unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let renders = (0..2)
        .map(|k| {
            render_part(&scene, &RenderOptions::default(), k, 2, &cancel, &|_, _| {})
                .unwrap()
                .0
                .to_bytes()
        })
        .collect();
    (table, parts, renders)
}

#[test]
fn fuzz_tables_and_parts() {
    let (table, tparts, rparts) = binary_files();
    let tparts_ok: Vec<TablePart> = tparts
        .iter()
        .map(|b| TablePart::from_bytes(b, "p.fctpart").unwrap())
        .collect();
    let rparts_ok: Vec<PartialFilm> = rparts
        .iter()
        .map(|b| PartialFilm::from_bytes(b, Path::new("p.fcpart")).unwrap())
        .collect();

    let n = cases(300);
    let r = run(
        "fctab",
        22,
        &[payload(&TABLE, &table)],
        n,
        10.0,
        File("fuzz.fctab"),
        &|b| {
            let t =
                BodyTable::from_bytes(&TABLE.frame(b), "fuzz.fctab").map_err(|e| e.to_string())?;
            // An accepted table answers lookups with finite values.
            let v = t.lookup(
                facette_bsdf::Vec3::new(0.3, 0.1, 0.9).normalize(),
                facette_bsdf::Vec3::new(-0.2, 0.4, 0.8).normalize(),
            );
            assert!(v.is_finite(), "lookup {v}");
            Ok(())
        },
    );
    report("fctab", n, r);

    let corpus: Vec<Vec<u8>> = tparts.iter().map(|b| payload(&TABLE_PART, b)).collect();
    let n = cases(300);
    let r = run(
        "fctpart",
        23,
        &corpus,
        n,
        10.0,
        File("fuzz.fctpart"),
        &|b| {
            let p = TablePart::from_bytes(&TABLE_PART.frame(b), "fuzz.fctpart")
                .map_err(|e| e.to_string())?;
            // Merged with the genuine other part, the result is a table its loader accepts.
            let other = tparts_ok.iter().find(|q| q.part != p.part).cloned();
            if let Some(o) = other {
                if let Ok(t) = merge_table_parts(&[p, o]) {
                    BodyTable::from_bytes(&t.to_bytes(), "merged.fctab")
                        .map_err(|e| format!("merge wrote what its loader refuses: {e}"))
                        .unwrap();
                }
            }
            Ok(())
        },
    );
    report("fctpart", n, r);

    let corpus: Vec<Vec<u8>> = rparts.iter().map(|b| payload(&RENDER_PART, b)).collect();
    let n = cases(300);
    let r = run("fcpart", 24, &corpus, n, 10.0, File("fuzz.fcpart"), &|b| {
        let p = PartialFilm::from_bytes(&RENDER_PART.frame(b), Path::new("fuzz.fcpart"))
            .map_err(|e| e.to_string())?;
        // Merged with the genuine other part: an error, or an image of finite pixels.
        let other = rparts_ok.iter().find(|q| q.part != p.part).cloned();
        if let Some(o) = other {
            if let Ok(film) = merge_parts(&[p, o]) {
                let img = film.image();
                assert!(img.data().iter().flatten().all(|v| v.is_finite()));
            }
        }
        Ok(())
    });
    report("fcpart", n, r);

    // Raw framed bytes: the container's own checks (magic, version, length, CRC).
    let corpus = vec![table.clone(), tparts[0].clone(), rparts[0].clone()];
    let n = cases(300);
    let r = run("framed", 25, &corpus, n, 10.0, File("f.fc"), &|b| {
        let t = BodyTable::from_bytes(b, "f.fctab").map(|_| ());
        let p = TablePart::from_bytes(b, "f.fctpart").map(|_| ());
        let f = PartialFilm::from_bytes(b, Path::new("f.fcpart")).map(|_| ());
        match (t, p, f) {
            (Err(a), Err(b), Err(c)) => Err(format!("{a}; {b}; {c}")),
            _ => Ok(()),
        }
    });
    report("framed", n, r);
}
