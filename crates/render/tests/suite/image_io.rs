//! Image files in and out: round trips, bit depths, corrupt and truncated files, atomic
//! writes, EXR channels with attributes.

use std::path::{Path, PathBuf};

use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_render::image::srgb::{linear_to_srgb, srgb_to_linear};
use facette_render::image::{
    read_exr_channels, read_image, write_exr_channels, write_image, ColorEncoding, ImageError,
    RgbImage,
};
use image::ImageEncoder;

fn random_image(w: usize, h: usize, seed: u64, max: f64) -> RgbImage {
    let mut rng = Pcg32::new(seed, 0);
    RgbImage::from_fn(w, h, |_, _| {
        [
            (rng.next_f64() * max) as f32,
            (rng.next_f64() * max) as f32,
            (rng.next_f64() * max) as f32,
        ]
    })
    .unwrap()
}

fn temp_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

fn write_png_raw(path: &Path, w: u32, h: u32, bytes: &[u8], ty: image::ExtendedColorType) {
    let f = std::fs::File::create(path).unwrap();
    image::codecs::png::PngEncoder::new(f)
        .write_image(bytes, w, h, ty)
        .unwrap();
}

#[test]
fn exr_round_trip_is_exact_and_applies_exposure() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.exr");
    let img = random_image(37, 21, 1, 100.0);
    write_image(&p, &img, 0.0).unwrap();
    let back = read_image(&p, ColorEncoding::Srgb).unwrap();
    assert_eq!(back, img, "float32 EXR must round-trip bit for bit");

    write_image(&p, &img, 1.5).unwrap();
    let back = read_image(&p, ColorEncoding::Linear).unwrap();
    let s = 1.5f64.exp2();
    for (a, b) in back.data().iter().zip(img.data()) {
        for c in 0..3 {
            assert_eq!(a[c], (b[c] as f64 * s) as f32);
        }
    }
}

#[test]
fn png_round_trip_within_quantization_and_exposure() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.png");
    let img = random_image(33, 17, 2, 1.0);
    write_image(&p, &img, 0.0).unwrap();
    let back = read_image(&p, ColorEncoding::Srgb).unwrap();
    assert_eq!((back.width(), back.height()), (33, 17));
    for (a, b) in back.data().iter().zip(img.data()) {
        for c in 0..3 {
            // Half an 8-bit step in the encoded domain, mapped back to linear.
            let e = linear_to_srgb(b[c] as f64);
            let lo = srgb_to_linear((e - 0.5 / 255.0).max(0.0));
            let hi = srgb_to_linear((e + 0.5 / 255.0).min(1.0));
            let v = a[c] as f64;
            assert!(v >= lo - 1e-6 && v <= hi + 1e-6, "{v} not in [{lo}, {hi}]");
        }
    }
    // Linear decoding returns the encoded codes: OETF(x)/255 steps.
    let raw = read_image(&p, ColorEncoding::Linear).unwrap();
    for (a, b) in raw.data().iter().zip(img.data()) {
        let code = (linear_to_srgb(b[0] as f64) * 255.0).round() / 255.0;
        assert!((a[0] as f64 - code).abs() < 1e-6);
    }
    // Exposure: +1 stop doubles the linear value before encoding; overexposure clamps.
    let grey = RgbImage::filled(4, 4, [0.2, 0.4, 3.0]).unwrap();
    write_image(&p, &grey, 1.0).unwrap();
    let back = read_image(&p, ColorEncoding::Srgb).unwrap();
    let px = back.get(2, 3);
    assert!((px[0] - 0.4).abs() < 0.004, "{px:?}");
    assert!((px[1] - 0.8).abs() < 0.008, "{px:?}");
    assert_eq!(px[2], 1.0);
}

#[test]
fn png_bit_depths_and_layouts() {
    let dir = tempfile::tempdir().unwrap();
    // 16-bit RGB.
    let p = dir.path().join("rgb16.png");
    let codes: [u16; 6] = [0, 1000, 65535, 32768, 12345, 54321];
    let bytes: Vec<u8> = codes.iter().flat_map(|c| c.to_ne_bytes()).collect();
    write_png_raw(&p, 2, 1, &bytes, image::ExtendedColorType::Rgb16);
    let lin = read_image(&p, ColorEncoding::Linear).unwrap();
    let srgb = read_image(&p, ColorEncoding::Srgb).unwrap();
    for (k, &code) in codes.iter().enumerate() {
        let (x, c) = (k / 3, k % 3);
        let v = code as f64 / 65535.0;
        assert!((lin.get(x, 0)[c] as f64 - v).abs() < 1e-7);
        assert!((srgb.get(x, 0)[c] as f64 - srgb_to_linear(v)).abs() < 1e-7);
    }
    // 16-bit grey + alpha: grey replicated, alpha dropped.
    let p = dir.path().join("la16.png");
    let bytes: Vec<u8> = [40000u16, 7].iter().flat_map(|c| c.to_ne_bytes()).collect();
    write_png_raw(&p, 1, 1, &bytes, image::ExtendedColorType::La16);
    let img = read_image(&p, ColorEncoding::Linear).unwrap();
    let v = (40000.0 / 65535.0) as f32;
    assert_eq!(img.get(0, 0), [v, v, v]);
    // 8-bit grey and RGBA.
    let p = dir.path().join("l8.png");
    write_png_raw(&p, 2, 1, &[0, 255], image::ExtendedColorType::L8);
    let img = read_image(&p, ColorEncoding::Srgb).unwrap();
    assert_eq!(img.data(), &[[0.0; 3], [1.0; 3]]);
    let p = dir.path().join("rgba8.png");
    write_png_raw(
        &p,
        1,
        1,
        &[10, 128, 255, 0],
        image::ExtendedColorType::Rgba8,
    );
    let img = read_image(&p, ColorEncoding::Linear).unwrap();
    assert_eq!(img.get(0, 0), [10.0 / 255.0, 128.0 / 255.0, 1.0]);
}

#[test]
fn exr_half_rgba_and_luminance_files_read() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("half_rgba.exr");
    write_rgba_file(&p, 3, 2, |x, y| {
        (
            f16::from_f32(x as f32 + 0.5),
            f16::from_f32(y as f32 * 2.0),
            f16::from_f32(0.25),
            f16::from_f32(0.5),
        )
    })
    .unwrap();
    let img = read_image(&p, ColorEncoding::Srgb).unwrap();
    assert_eq!((img.width(), img.height()), (3, 2));
    assert_eq!(img.get(2, 1), [2.5, 2.0, 0.25]);

    // A luminance-only (Y) file reads as grey; a NaN sample reads as 0.
    let p = dir.path().join("y.exr");
    let y = vec![1.0f32, f32::NAN, 3.0, 4.0];
    let image = Image::from_channels(
        (2, 2),
        AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
            "Y",
            FlatSamples::F32(y),
        )])),
    );
    image.write().to_file(&p).unwrap();
    let img = read_image(&p, ColorEncoding::Srgb).unwrap();
    assert_eq!(img.get(0, 1), [3.0; 3]);
    assert_eq!(img.get(1, 0), [0.0; 3]);

    // Layer-prefixed channels are found.
    let p = dir.path().join("prefixed.exr");
    let ch = |n: &str, v: f32| AnyChannel::new(n, FlatSamples::F32(vec![v; 4]));
    let image = Image::from_channels(
        (2, 2),
        AnyChannels::sort(SmallVec::from_vec(vec![
            ch("beauty.B", 3.0),
            ch("beauty.G", 2.0),
            ch("beauty.R", 1.0),
            ch("depth.Z", 9.0),
        ])),
    );
    image.write().to_file(&p).unwrap();
    let img = read_image(&p, ColorEncoding::Srgb).unwrap();
    assert_eq!(img.get(1, 1), [1.0, 2.0, 3.0]);

    // Two unrelated channels are not an image.
    let p = dir.path().join("uv.exr");
    let image = Image::from_channels(
        (2, 2),
        AnyChannels::sort(SmallVec::from_vec(vec![ch("U", 1.0), ch("V", 2.0)])),
    );
    image.write().to_file(&p).unwrap();
    let err = read_image(&p, ColorEncoding::Srgb).unwrap_err();
    assert!(matches!(err, ImageError::Unsupported { .. }), "{err}");
    assert!(err.to_string().contains("U, V"), "{err}");
}

#[test]
fn radiance_hdr_reads_linear() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.hdr");
    let px: Vec<image::Rgb<f32>> = vec![image::Rgb([0.5, 2.0, 100.0]), image::Rgb([0.0; 3])];
    let f = std::fs::File::create(&p).unwrap();
    image::codecs::hdr::HdrEncoder::new(f)
        .encode(&px, 2, 1)
        .unwrap();
    let img = read_image(&p, ColorEncoding::Srgb).unwrap();
    let v = img.get(0, 0);
    // RGBE keeps ~8 bits of mantissa relative to the largest channel.
    assert!((v[0] - 0.5).abs() < 0.4 && (v[1] - 2.0).abs() < 0.4 && (v[2] - 100.0).abs() < 0.4);
    assert_eq!(img.get(1, 0), [0.0; 3]);
}

fn assert_error_names(err: &ImageError, path: &Path) {
    assert_eq!(err.path(), path);
    assert!(
        err.to_string().contains(&path.display().to_string()),
        "message lacks the path: {err}"
    );
}

#[test]
fn missing_corrupt_and_truncated_files_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope.png");
    let err = read_image(&missing, ColorEncoding::Srgb).unwrap_err();
    assert!(matches!(err, ImageError::Read { .. }), "{err}");
    assert_error_names(&err, &missing);

    let mut rng = Pcg32::new(3, 0);
    for name in ["noise.png", "noise.exr", "noise.hdr", "noise.bin"] {
        let p = dir.path().join(name);
        let bytes: Vec<u8> = (0..4096).map(|_| rng.next_u32() as u8).collect();
        std::fs::write(&p, bytes).unwrap();
        let err = read_image(&p, ColorEncoding::Srgb).unwrap_err();
        assert_error_names(&err, &p);
    }
    let empty = dir.path().join("empty.exr");
    std::fs::write(&empty, b"").unwrap();
    let err = read_image(&empty, ColorEncoding::Srgb).unwrap_err();
    assert!(err.to_string().contains("empty"), "{err}");

    // Valid headers followed by garbage or cut short, at many lengths.
    let img = random_image(64, 48, 4, 4.0);
    for ext in ["png", "exr"] {
        let good = dir.path().join(format!("good.{ext}"));
        write_image(&good, &img, 0.0).unwrap();
        let bytes = std::fs::read(&good).unwrap();
        let cut = dir.path().join(format!("cut.{ext}"));
        for k in 1..24 {
            let len = bytes.len() * k / 24;
            std::fs::write(&cut, &bytes[..len]).unwrap();
            match read_image(&cut, ColorEncoding::Srgb) {
                Err(err) => assert_error_names(&err, &cut),
                Ok(_) => panic!(
                    "{ext} truncated to {len}/{} bytes was accepted",
                    bytes.len()
                ),
            }
        }
        // Garbage after a valid header.
        let mut bad = bytes.clone();
        let keep = 40.min(bad.len());
        for b in bad[keep..].iter_mut() {
            *b = rng.next_u32() as u8;
        }
        std::fs::write(&cut, &bad).unwrap();
        if let Ok(read) = read_image(&cut, ColorEncoding::Srgb) {
            // A decoder may accept scrambled payload; what it returns must be finite.
            assert!(read.is_finite());
        }
    }
}

/// Overwrites the four i32 of the `dataWindow` box of an EXR file.
fn patch_data_window(bytes: &mut [u8], window: [i32; 4]) {
    let key = b"dataWindow\0box2i\0";
    let at = bytes
        .windows(key.len())
        .position(|w| w == key)
        .expect("dataWindow attribute")
        + key.len()
        + 4; // attribute size
    for (k, v) in window.iter().enumerate() {
        bytes[at + 4 * k..at + 4 * k + 4].copy_from_slice(&v.to_le_bytes());
    }
}

#[test]
fn a_damaged_exr_header_is_an_error_not_an_allocation() {
    // `exr` sizes its buffers from the header: a huge data window must be rejected before
    // decoding (an attempt to allocate would abort the process, not return an error).
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.exr");
    write_image(&good, &random_image(4, 4, 9, 1.0), 0.0).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let bad = dir.path().join("bad.exr");
    for window in [
        [0, 0, 200_000, 200_000],
        [0, 0, 9_999, 9_999],
        [0, 0, 3, 70_000],
    ] {
        let mut b = bytes.clone();
        patch_data_window(&mut b, window);
        std::fs::write(&bad, &b).unwrap();
        let err = read_image(&bad, ColorEncoding::Linear).unwrap_err();
        assert_error_names(&err, &bad);
        let err = read_exr_channels(&bad).unwrap_err();
        assert_error_names(&err, &bad);
    }
}

#[test]
fn unsupported_extension_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let img = random_image(2, 2, 5, 1.0);
    for name in ["a.tiff", "a"] {
        let p = dir.path().join(name);
        let err = write_image(&p, &img, 0.0).unwrap_err();
        assert!(
            matches!(err, ImageError::UnsupportedExtension { .. }),
            "{err}"
        );
        let msg = err.to_string();
        assert!(msg.contains(".exr") && msg.contains(".png"), "{msg}");
        assert!(!p.exists());
    }
    let err = write_image(dir.path().join("a.png"), &img, f64::NAN).unwrap_err();
    assert!(matches!(err, ImageError::InvalidData { .. }), "{err}");
}

#[test]
fn failed_writes_leave_no_trace_and_keep_the_old_file() {
    let dir = tempfile::tempdir().unwrap();
    let img = random_image(8, 8, 6, 1.0);
    // Nonexistent directory.
    let p: PathBuf = dir.path().join("no/such/dir/out.exr");
    let err = write_image(&p, &img, 0.0).unwrap_err();
    assert!(matches!(err, ImageError::Write { .. }), "{err}");
    assert_error_names(&err, &p);
    assert!(temp_files(dir.path()).is_empty());

    // The target is a directory: the rename fails after the data was written.
    let target = dir.path().join("taken.png");
    std::fs::create_dir(&target).unwrap();
    std::fs::write(target.join("inside"), b"keep").unwrap();
    assert!(write_image(&target, &img, 0.0).is_err());
    assert_eq!(std::fs::read(target.join("inside")).unwrap(), b"keep");
    assert!(
        temp_files(dir.path()).is_empty(),
        "{:?}",
        temp_files(dir.path())
    );

    // Invalid data: the existing file is untouched.
    let out = dir.path().join("out.exr");
    write_image(&out, &img, 0.0).unwrap();
    let before = std::fs::read(&out).unwrap();
    assert!(write_exr_channels(&out, 8, 8, &[("R", &[0.0; 3])], &[]).is_err());
    assert!(write_image(&out, &img, f64::INFINITY).is_err());
    assert_eq!(std::fs::read(&out).unwrap(), before);
    assert!(temp_files(dir.path()).is_empty());
}

#[test]
#[cfg(unix)]
fn read_only_directory_write_fails_cleanly() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("ro");
    std::fs::create_dir(&sub).unwrap();
    let out = sub.join("out.png");
    let img = random_image(4, 4, 7, 1.0);
    write_image(&out, &img, 0.0).unwrap();
    let before = std::fs::read(&out).unwrap();
    std::fs::set_permissions(&sub, std::fs::Permissions::from_mode(0o555)).unwrap();
    // Root ignores directory permissions; the check is then meaningless.
    let probe = sub.join("probe");
    let writable = std::fs::write(&probe, b"x").is_ok();
    let _ = std::fs::remove_file(&probe);
    if !writable {
        let err = write_image(&out, &random_image(4, 4, 8, 1.0), 0.0).unwrap_err();
        assert!(matches!(err, ImageError::Write { .. }), "{err}");
        assert_eq!(std::fs::read(&out).unwrap(), before);
        assert!(temp_files(&sub).is_empty());
    }
    std::fs::set_permissions(&sub, std::fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn exr_channels_and_attributes_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("partial.exr");
    let (w, h) = (5, 3);
    let sum: Vec<f32> = (0..w * h).map(|k| k as f32 * 0.37 + 1e-3).collect();
    let weight: Vec<f32> = (0..w * h).map(|k| (k % 4) as f32).collect();
    let count: Vec<f32> = (0..w * h).map(|k| (16_000_000 + k) as f32).collect();
    let attrs = [
        ("facette.sceneHash", "9f86d081884c7d65".to_string()),
        ("facette.seed", "42".to_string()),
        ("facette.note", String::new()),
    ];
    write_exr_channels(
        &p,
        w,
        h,
        &[("sum.R", &sum), ("weight", &weight), ("count", &count)],
        &attrs,
    )
    .unwrap();
    let back = read_exr_channels(&p).unwrap();
    assert_eq!((back.width, back.height), (w, h));
    assert_eq!(back.channel("sum.R").unwrap(), &sum[..]);
    assert_eq!(back.channel("weight").unwrap(), &weight[..]);
    assert_eq!(back.channel("count").unwrap(), &count[..]);
    assert_eq!(back.channels.len(), 3);
    assert_eq!(
        back.attribute("facette.sceneHash"),
        Some("9f86d081884c7d65")
    );
    assert_eq!(back.attribute("facette.seed"), Some("42"));
    assert_eq!(back.attribute("facette.note"), Some(""));
    assert_eq!(back.attributes.len(), 3);

    // Invalid inputs.
    let bad = |ch: &[(&str, &[f32])], at: &[(&str, String)]| {
        write_exr_channels(dir.path().join("bad.exr"), w, h, ch, at).unwrap_err()
    };
    let e = bad(&[("a", &sum), ("a", &sum)], &[]);
    assert!(e.to_string().contains("twice"), "{e}");
    let e = bad(&[("a", &sum[1..])], &[]);
    assert!(e.to_string().contains("samples"), "{e}");
    let e = bad(&[("a", &sum)], &[("compression", "x".into())]);
    assert!(e.to_string().contains("reserved"), "{e}");
    let e = bad(&[("a", &sum)], &[("ok", "☃".into())]);
    assert!(e.to_string().contains("Latin-1"), "{e}");
    let e = bad(&[], &[]);
    assert!(e.to_string().contains("no channels"), "{e}");
    assert!(!dir.path().join("bad.exr").exists());
}
