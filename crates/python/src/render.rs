//! `facette.render`: a scene (path or TOML text) to an (H, W, 3) float32 array.

use crate::errors::{os_error, value_error};
use facette_render::render::{render as render_scene, RenderOptions};
use facette_render::scene::{load_scene, load_scene_str, Scene};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3, PyReadonlyArray3};
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// A scene argument: TOML text (it contains a newline or starts with `[`) or a path.
pub fn scene_from(scene: &str) -> PyResult<Scene> {
    let text = scene.trim_start();
    if scene.contains('\n') || text.starts_with('[') {
        return load_scene_str(scene, Path::new("<string>")).map_err(value_error);
    }
    let path = PathBuf::from(scene);
    if !path.is_file() {
        return Err(os_error(format!(
            "{scene}: cannot read the scene file: no such file"
        )));
    }
    load_scene(&path).map_err(value_error)
}

pub fn options(spp: Option<usize>, seed: u64, threads: Option<usize>) -> PyResult<RenderOptions> {
    if spp == Some(0) {
        return Err(value_error("`spp` must be at least 1"));
    }
    if threads == Some(0) {
        return Err(value_error("`threads` must be at least 1"));
    }
    Ok(RenderOptions {
        spp,
        seed,
        threads,
        ..Default::default()
    })
}

/// Image of a film as an (H, W, 3) float32 array times 2^exposure (what the CLI's EXR holds).
pub fn film_array(film: &facette_render::film::Film, exposure: f64) -> Array3<f32> {
    let img = film.image();
    let scale = exposure.exp2();
    let mut a = Array3::<f32>::zeros((img.height(), img.width(), 3));
    for (k, p) in img.data().iter().enumerate() {
        let (y, x) = (k / img.width(), k % img.width());
        for c in 0..3 {
            a[[y, x, c]] = (p[c] as f64 * scale) as f32;
        }
    }
    a
}

/// Renders a scene; returns linear radiance as (H, W, 3) float32, times 2^exposure (the
/// scene's film exposure unless given) — the values of the EXR `facette render` writes
/// for the same scene and seed.
#[pyfunction]
#[pyo3(signature = (scene, spp = None, seed = 0, threads = None, exposure = None))]
pub fn render<'py>(
    py: Python<'py>,
    scene: &str,
    spp: Option<usize>,
    seed: u64,
    threads: Option<usize>,
    exposure: Option<f64>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let opts = options(spp, seed, threads)?;
    let scene_str = scene.to_string();
    let array = py.detach(move || -> PyResult<Array3<f32>> {
        let scene = scene_from(&scene_str)?;
        let exposure = exposure.unwrap_or(scene.film.exposure);
        if !exposure.is_finite() {
            return Err(value_error("`exposure` must be finite"));
        }
        let (film, _) = render_scene(&scene, &opts, &AtomicBool::new(false), &|_, _| {})
            .map_err(value_error)?;
        Ok(film_array(&film, exposure))
    })?;
    Ok(array.into_pyarray(py))
}

/// Writes an (H, W, 3) float32 array as EXR (linear) or PNG (sRGB) by extension,
/// atomically.
#[pyfunction]
#[pyo3(signature = (path, image, exposure = 0.0))]
pub fn write_image(path: PathBuf, image: PyReadonlyArray3<'_, f32>, exposure: f64) -> PyResult<()> {
    let v = image.as_array();
    let (h, w, c) = v.dim();
    if c != 3 || h == 0 || w == 0 {
        return Err(value_error(format!(
            "`image` must have shape (H, W, 3), got {:?}",
            v.shape()
        )));
    }
    let data: Vec<[f32; 3]> = (0..h * w)
        .map(|k| [0, 1, 2].map(|ch| v[[k / w, k % w, ch]]))
        .collect();
    let img = facette_render::image::RgbImage::new(w, h, data).map_err(value_error)?;
    facette_render::image::write_image(&path, &img, exposure).map_err(|e| match e {
        facette_render::image::ImageError::Write { .. } => os_error(e),
        other => value_error(other),
    })
}

/// Reads an image file (EXR, HDR, PNG) as an (H, W, 3) float32 array of linear values
/// (8/16-bit files are decoded from sRGB unless `linear`).
#[pyfunction]
#[pyo3(signature = (path, linear = false))]
pub fn read_image<'py>(
    py: Python<'py>,
    path: PathBuf,
    linear: bool,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    use facette_render::image::{ColorEncoding, ImageError};
    let enc = if linear {
        ColorEncoding::Linear
    } else {
        ColorEncoding::Srgb
    };
    let img = facette_render::image::read_image(&path, enc).map_err(|e| match e {
        ImageError::Read { .. } => os_error(e),
        other => value_error(other),
    })?;
    let mut a = Array3::<f32>::zeros((img.height(), img.width(), 3));
    for (k, p) in img.data().iter().enumerate() {
        for c in 0..3 {
            a[[k / img.width(), k % img.width(), c]] = p[c];
        }
    }
    Ok(a.into_pyarray(py))
}
