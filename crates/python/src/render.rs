//! `facette.render`: a scene (a path, TOML text, a dict, Mitsuba XML text) to an
//! (H, W, 3) float32 array; Ctrl-C keeps the image rendered so far.

use crate::errors::{os_error, value_error};
use crate::interrupt::{self, Outcome};
use crate::toml_value::dict_to_table;
use facette_render::render::{render as render_scene, RenderOptions};
use facette_render::scene::{load_scene_str, load_scene_with, LoadOptions, Scene};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3, PyReadonlyArray3};
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// Where a scene comes from. The Python wrapper decides which (docs/python.md: a str that
/// names an existing file, or has neither a newline, `=`, `[` nor `<`, is a path).
#[derive(Clone)]
pub enum Source {
    Path(PathBuf),
    Toml(String),
    Xml(String),
}

/// A scene argument with its load-time settings.
#[derive(Clone)]
pub struct SceneArg {
    source: Source,
    defines: Vec<(String, String)>,
    width: Option<usize>,
    height: Option<usize>,
}

/// A dict scene as TOML text (the grammar of docs/scene-format.md).
pub fn dict_scene_toml(d: &Bound<'_, PyDict>) -> PyResult<String> {
    let table = dict_to_table(d, "scene")?;
    toml::to_string(&toml::Value::Table(table))
        .map_err(|e| value_error(format!("scene: cannot write the dict as TOML: {e}")))
}

impl SceneArg {
    /// `kind` is "path", "toml", "xml" or "dict" (then `value` is a dict).
    pub fn new(
        kind: &str,
        value: &Bound<'_, PyAny>,
        defines: Option<Vec<(String, String)>>,
        width: Option<usize>,
        height: Option<usize>,
    ) -> PyResult<SceneArg> {
        let text = || -> PyResult<String> { value.cast::<PyString>()?.extract() };
        let source = match kind {
            "path" => Source::Path(PathBuf::from(text()?)),
            "toml" => Source::Toml(text()?),
            "xml" => Source::Xml(text()?),
            "dict" => Source::Toml(dict_scene_toml(value.cast::<PyDict>()?)?),
            other => return Err(value_error(format!("unknown scene kind `{other}`"))),
        };
        for (name, v) in [("width", width), ("height", height)] {
            if v == Some(0) {
                return Err(value_error(format!("`{name}` must be at least 1")));
            }
        }
        Ok(SceneArg {
            source,
            defines: defines.unwrap_or_default(),
            width,
            height,
        })
    }

    fn is_xml(&self) -> bool {
        match &self.source {
            Source::Xml(_) => true,
            Source::Path(p) => p
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| e.eq_ignore_ascii_case("xml")),
            Source::Toml(_) => false,
        }
    }

    /// TOML text with the film size overridden (the camera's aspect follows the film).
    fn resized(&self, text: &str, name: &Path) -> PyResult<String> {
        let mut t: toml::Table = text
            .parse()
            .map_err(|e| value_error(format!("{}: {e}", name.display())))?;
        let film = t
            .entry("film")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let film = film
            .as_table_mut()
            .ok_or_else(|| value_error(format!("{}: `film` is not a table", name.display())))?;
        for (key, v) in [("width", self.width), ("height", self.height)] {
            if let Some(v) = v {
                film.insert(key.into(), toml::Value::Integer(v as i64));
            }
        }
        toml::to_string(&t).map_err(value_error)
    }

    /// Loads the scene (the file, with its assets relative to its folder; text, with its
    /// assets relative to the current directory).
    pub fn load(&self) -> PyResult<Scene> {
        let resize = self.width.is_some() || self.height.is_some();
        if self.is_xml() {
            if resize {
                return Err(value_error(
                    "`width` and `height` apply to TOML scenes; a Mitsuba scene's film size \
                     comes from its XML (set it through `defines` when the file reads $parameters)",
                ));
            }
        } else if !self.defines.is_empty() {
            return Err(value_error(
                "`defines` apply to Mitsuba XML scenes only; this is a TOML scene",
            ));
        }
        let opts = LoadOptions {
            defines: self.defines.clone(),
        };
        match &self.source {
            Source::Path(p) => {
                if !p.is_file() {
                    return Err(os_error(format!(
                        "{}: cannot read the scene file: no such file",
                        p.display()
                    )));
                }
                if resize {
                    let text = std::fs::read_to_string(p).map_err(|e| {
                        os_error(format!("{}: cannot read the scene file: {e}", p.display()))
                    })?;
                    return load_scene_str(&self.resized(&text, p)?, p).map_err(value_error);
                }
                load_scene_with(p, &opts).map_err(value_error)
            }
            Source::Toml(text) => {
                let name = Path::new("<string>");
                if resize {
                    return load_scene_str(&self.resized(text, name)?, name).map_err(value_error);
                }
                load_scene_str(text, name).map_err(value_error)
            }
            Source::Xml(text) => {
                // The Mitsuba reader reads files (it resolves <include>s and relative
                // references against the file's folder): the text goes through a
                // temporary file, so its file references must be absolute (documented).
                static COUNTER: AtomicU64 = AtomicU64::new(0);
                let path = std::env::temp_dir().join(format!(
                    "facette-scene-{}-{}.xml",
                    std::process::id(),
                    COUNTER.fetch_add(1, Ordering::Relaxed)
                ));
                std::fs::write(&path, text)
                    .map_err(|e| os_error(format!("{}: {e}", path.display())))?;
                let r = load_scene_with(&path, &opts);
                let _ = std::fs::remove_file(&path);
                r.map_err(value_error)
            }
        }
    }
}

/// The scene argument of every scene function's signature.
pub fn scene_arg(
    kind: &str,
    scene: &Bound<'_, PyAny>,
    defines: Option<Vec<(String, String)>>,
    width: Option<usize>,
    height: Option<usize>,
) -> PyResult<SceneArg> {
    SceneArg::new(kind, scene, defines, width, height)
}

pub fn options(
    spp: Option<usize>,
    seed: u64,
    threads: Option<usize>,
    time_limit: Option<f64>,
) -> PyResult<RenderOptions> {
    if spp == Some(0) {
        return Err(value_error("`spp` must be at least 1"));
    }
    if threads == Some(0) {
        return Err(value_error("`threads` must be at least 1"));
    }
    if let Some(t) = time_limit {
        if !(t.is_finite() && t > 0.0) {
            return Err(value_error(format!(
                "time_limit = {t}: expected a positive number of seconds"
            )));
        }
    }
    Ok(RenderOptions {
        spp,
        seed,
        threads,
        time_limit,
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

/// Loads a scene and returns (width, height, spp): the driver-side check of a
/// distributed render, before any task is submitted.
#[pyfunction]
#[pyo3(signature = (kind, scene, defines = None, width = None, height = None))]
pub fn check_scene(
    py: Python<'_>,
    kind: &str,
    scene: &Bound<'_, PyAny>,
    defines: Option<Vec<(String, String)>>,
    width: Option<usize>,
    height: Option<usize>,
) -> PyResult<(usize, usize, usize)> {
    let arg = scene_arg(kind, scene, defines, width, height)?;
    let s = interrupt::run_all(py, "facette.check_scene", None, move |_| arg.load())??;
    Ok((s.film.width, s.film.height, s.film.spp))
}

/// A dict scene as TOML text.
#[pyfunction]
pub fn scene_toml(scene: &Bound<'_, PyDict>) -> PyResult<String> {
    dict_scene_toml(scene)
}

/// Renders a scene; returns linear radiance as (H, W, 3) float32, times 2^exposure (the
/// scene's film exposure unless given) — the values of the EXR `facette render` writes
/// for the same scene and seed. Ctrl-C raises `KeyboardInterrupt` with the image so far
/// as its `image` attribute.
#[pyfunction]
#[pyo3(signature = (kind, scene, spp = None, seed = 0, threads = None, exposure = None,
    defines = None, width = None, height = None, time_limit = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    kind: &str,
    scene: &Bound<'py, PyAny>,
    spp: Option<usize>,
    seed: u64,
    threads: Option<usize>,
    exposure: Option<f64>,
    defines: Option<Vec<(String, String)>>,
    width: Option<usize>,
    height: Option<usize>,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let opts = options(spp, seed, threads, time_limit)?;
    if let Some(e) = exposure {
        if !e.is_finite() {
            return Err(value_error("`exposure` must be finite"));
        }
    }
    let arg = scene_arg(kind, scene, defines, width, height)?;
    // The render stops within a row of a tile once the flag is set: waiting 2 s for it
    // to hand back the image so far is a bound, not a delay.
    let outcome = interrupt::run(
        py,
        "facette.render",
        progress,
        Duration::from_secs(2),
        move |c| -> PyResult<Array3<f32>> {
            let scene = arg.load()?;
            let exposure = exposure.unwrap_or(scene.film.exposure);
            let (film, _) = render_scene(&scene, &opts, c.flag(), &|d, t| c.progress(d, t))
                .map_err(value_error)?;
            Ok(film_array(&film, exposure))
        },
    )?;
    match outcome {
        Outcome::Done(a) => Ok(a?.into_pyarray(py)),
        Outcome::Interrupted(e, partial) => {
            if let Some(Ok(a)) = partial {
                if e.is_instance_of::<PyKeyboardInterrupt>(py) {
                    e.value(py).setattr("image", a.into_pyarray(py))?;
                }
            }
            Err(e)
        }
    }
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
    interrupt::guard("facette.write_image", || {
        let img = facette_render::image::RgbImage::new(w, h, data).map_err(value_error)?;
        facette_render::image::write_image(&path, &img, exposure).map_err(|e| match e {
            facette_render::image::ImageError::Write { .. } => os_error(e),
            other => value_error(other),
        })
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
    let img = interrupt::run_all(py, "facette.read_image", None, move |_| {
        facette_render::image::read_image(&path, enc).map_err(|e| match e {
            ImageError::Read { .. } => os_error(e),
            other => value_error(other),
        })
    })??;
    let mut a = Array3::<f32>::zeros((img.height(), img.width(), 3));
    for (k, p) in img.data().iter().enumerate() {
        for c in 0..3 {
            a[[k / img.width(), k % img.width(), c]] = p[c];
        }
    }
    Ok(a.into_pyarray(py))
}
