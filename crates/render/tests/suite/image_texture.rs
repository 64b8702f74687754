//! Textures end to end: an sRGB PNG decoded to linear, mip-mapped and filtered.

use std::sync::Arc;

use facette_bsdf::Spectrum;
use facette_render::image::srgb::srgb_to_linear;
use facette_render::image::{
    read_image, write_image, ColorEncoding, MipMap, RgbImage, Texture, WrapMode,
};
use glam::DVec2;

#[test]
fn a_png_checker_filters_to_its_linear_mean() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("checker.png");
    // 1-texel checks of sRGB codes 255 and 64: the mean must be taken in linear.
    let lo = srgb_to_linear(64.0 / 255.0) as f32;
    let img = RgbImage::from_fn(
        32,
        32,
        |x, y| if (x + y) % 2 == 0 { [1.0; 3] } else { [lo; 3] },
    )
    .unwrap();
    write_image(&path, &img, 0.0).unwrap();
    let decoded = read_image(&path, ColorEncoding::Srgb).unwrap();
    let tex = Texture::image(Arc::new(MipMap::new(decoded, WrapMode::Repeat)));
    let mean = Spectrum::splat(0.5 * (1.0 + lo as f64));
    // A footprint of 4 texels or more reads the linear mean (not the sRGB-code mean).
    let v = tex.eval(DVec2::new(0.37, 0.61), [4.0 / 32.0, 0.0, 0.0, 4.0 / 32.0]);
    assert!((v - mean).max_component().abs() < 1e-3, "{v:?} vs {mean:?}");
    assert!((tex.average() - mean).max_component().abs() < 1e-3);
    // A point lookup at a texel centre reads the texel.
    let v = tex.eval(DVec2::new(0.5 / 32.0, 0.5 / 32.0), [0.0; 4]);
    assert!((v[0] - 1.0).abs() < 1e-6);
    // Roughness maps read raw codes as a scalar.
    let raw = read_image(&path, ColorEncoding::Linear).unwrap();
    let rough = Texture::image(Arc::new(MipMap::new(raw, WrapMode::Clamp)));
    let r = rough.eval_scalar(DVec2::new(1.5 / 32.0, 0.5 / 32.0), [0.0; 4]);
    assert!((r - 64.0 / 255.0).abs() < 1e-6, "{r}");
}
