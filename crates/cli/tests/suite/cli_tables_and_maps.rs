//! End-to-end tests of `facette tabulate` in parts merged by `facette merge`, and of
//! `facette normalmap` with `eval` reading the maps it writes.

use crate::common::*;

#[test]
fn adaptive_tables_are_deterministic_merge_from_parts_and_validate_the_tolerance() {
    let dir = tempfile::tempdir().unwrap();
    let m = r#"{type = "il", ni = 1.4, distribution = "ggx", alpha = 0.5}"#;
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let tab = |extra: &[&str], out: &str| {
        let mut args = vec!["tabulate", "--material", m, "--step", "30", "-o", out];
        args.extend_from_slice(extra);
        facette(&args, None)
    };
    let full = path("full.fctab");
    let o = tab(&["--tolerance", "1e-4"], &full);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("adaptive quadrature, tolerance 1e-4")
            && stdout(&o).contains("relative error estimate"),
        "{}",
        stdout(&o)
    );
    let mut parts = Vec::new();
    for k in 0..2 {
        let p = path(&format!("t{k}.fctpart"));
        let o = tab(&["--tolerance", "1e-4", "--part", &format!("{k}/2")], &p);
        assert!(o.status.success(), "{}", stderr(&o));
        parts.push(p);
    }
    let merged = path("merged.fctab");
    let o = facette(&["merge", &parts[0], &parts[1], "-o", &merged], None);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&merged).unwrap(),
        std::fs::read(&full).unwrap()
    );
    // The table is read back by an IL material.
    let il = format!(
        r#"{{type = "il", ni = 1.4, distribution = "ggx", alpha = 0.5, table = "{full}"}}"#
    );
    let o = facette(
        &["eval", "--material", &il],
        Some("theta_i,phi_i,theta_o,phi_o\n30,0,40,90\n"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(rows(&o).len(), 1);
    // Out-of-range tolerances and --samples with --tolerance are refused clearly.
    for bad in ["0", "0.5", "nan", "x"] {
        let o = tab(&["--tolerance", bad], &path("bad.fctab"));
        assert!(!o.status.success());
        assert!(
            stderr(&o).contains("tolerance <= 0.1"),
            "{bad}: {}",
            stderr(&o)
        );
    }
    let o = tab(
        &["--tolerance", "1e-4", "--samples", "64"],
        &path("bad.fctab"),
    );
    assert!(
        !o.status.success() && stderr(&o).contains("cannot be used with"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn table_parts_merge_into_the_same_table_file() {
    let dir = tempfile::tempdir().unwrap();
    let m = r#"{type = "il", ni = 1.4, distribution = "beckmann", alpha = 0.5}"#;
    let full = dir.path().join("full.fctab");
    let o = facette(
        &[
            "tabulate",
            "--material",
            m,
            "--step",
            "10",
            "--samples",
            "256",
            "-o",
            full.to_str().unwrap(),
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let mut parts = Vec::new();
    for k in 0..4 {
        let p = dir.path().join(format!("t{k}.fctpart"));
        let o = facette(
            &[
                "tabulate",
                "--material",
                m,
                "--step",
                "10",
                "--samples",
                "256",
                "--part",
                &format!("{k}/4"),
                "-o",
                p.to_str().unwrap(),
            ],
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        parts.push(p.to_str().unwrap().to_string());
    }
    let merged = dir.path().join("merged.fctab");
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(|p| p.as_str()));
    args.extend(["-o", merged.to_str().unwrap()]);
    let o = facette(&args, None);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&merged).unwrap(),
        std::fs::read(&full).unwrap()
    );
    let o = facette(
        &[
            "merge",
            &parts[0],
            &parts[1],
            "-o",
            merged.to_str().unwrap(),
        ],
        None,
    );
    assert!(
        stderr(&o).contains("missing part(s) 2, 3 of 4"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn normalmap_generate_writes_every_kind_and_eval_reads_them_with_a_footprint() {
    let dir = tempfile::tempdir().unwrap();
    for (kind, ext) in [
        ("scratched", "png"),
        ("brushed", "exr"),
        ("very-rough", "png"),
        ("metallic-paint", "exr"),
    ] {
        let f = dir.path().join(format!("{kind}.{ext}"));
        let o = facette(
            &[
                "normalmap",
                "generate",
                kind,
                "-o",
                f.to_str().unwrap(),
                "--resolution",
                "64",
                "--seed",
                "3",
            ],
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stdout(&o).contains("RMS slope"), "{}", stdout(&o));
        let mat = format!(
            r#"{{type = "glint", normal_map = "{}", material = "Al"}}"#,
            f.display()
        );
        let o = facette(
            &["eval", "--material", &mat, "--footprint", "0.3,0.6,4,2,0.2"],
            Some("20,0,20,180\n50,10,40,200\n"),
        );
        assert!(o.status.success(), "{kind}: {}", stderr(&o));
        let r = rows(&o);
        assert_eq!(r.len(), 2);
        assert!(r
            .iter()
            .all(|row| row[4..].iter().all(|v| v.is_finite() && *v >= 0.0)));
        assert!(r[0][4] > 0.0, "{kind}: {r:?}");
    }
    for (args, msg) in [
        (
            vec!["normalmap", "generate", "wood", "-o", "x.png"],
            "scratched, brushed, bumpy, flakes",
        ),
        (
            vec![
                "normalmap",
                "generate",
                "bumpy",
                "-o",
                "x.png",
                "--resolution",
                "5000",
            ],
            "4096",
        ),
        (
            vec![
                "normalmap",
                "generate",
                "bumpy",
                "-o",
                "x.jpg",
                "--resolution",
                "8",
            ],
            ".png or .exr",
        ),
    ] {
        let o = facette(&args, None);
        assert!(!o.status.success());
        assert!(stderr(&o).contains(msg), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn bad_normal_maps_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    // A grey PNG (a height map by mistake), a map whose normals are not unit (all zeros
    // decode: (255, 128, 255) is n ≈ (1, 0, 1), |n| = 1.41), an unreadable file and a missing one.
    let grey = dir.path().join("grey.png");
    image_png(&grey, &[[128, 128, 128]; 16]);
    let zeros = dir.path().join("zeros.png");
    image_png(&zeros, &[[255, 128, 255]; 16]);
    let junk = dir.path().join("junk.png");
    std::fs::write(&junk, b"definitely not a png").unwrap();
    for (file, msg) in [
        (grey.display().to_string(), "greyscale"),
        (
            zeros.display().to_string(),
            "do not decode to a unit normal",
        ),
        (junk.display().to_string(), "junk.png"),
        (
            dir.path().join("none.exr").display().to_string(),
            "none.exr",
        ),
    ] {
        let mat = format!(r#"{{type = "glint", normal_map = "{file}"}}"#);
        let o = facette(&["eval", "--material", &mat], Some("10,0,10,180\n"));
        assert!(!o.status.success(), "{file}");
        assert!(stderr(&o).contains(msg), "{file}: {}", stderr(&o));
    }
}

/// A 4×4 8-bit RGB PNG written by hand (stored, uncompressed deflate).
fn image_png(path: &std::path::Path, px: &[[u8; 3]; 16]) {
    fn crc(data: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for &b in data {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    fn chunk(out: &mut Vec<u8>, ty: &[u8], data: &[u8]) {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut td = ty.to_vec();
        td.extend_from_slice(data);
        out.extend_from_slice(&td);
        out.extend_from_slice(&crc(&td).to_be_bytes());
    }
    let mut raw = Vec::new();
    for y in 0..4 {
        raw.push(0u8);
        for x in 0..4 {
            raw.extend_from_slice(&px[y * 4 + x]);
        }
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &v in &raw {
        a = (a + v as u32) % 65521;
        b = (b + a) % 65521;
    }
    let mut z = vec![0x78, 0x01, 1];
    z.extend_from_slice(&(raw.len() as u16).to_le_bytes());
    z.extend_from_slice(&(!(raw.len() as u16)).to_le_bytes());
    z.extend_from_slice(&raw);
    z.extend_from_slice(&((b << 16) | a).to_be_bytes());
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&4u32.to_be_bytes());
    ihdr.extend_from_slice(&4u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &z);
    chunk(&mut out, b"IEND", &[]);
    std::fs::write(path, out).unwrap();
}
