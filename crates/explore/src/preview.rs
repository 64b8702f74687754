//! The live preview: the material on a sphere standing on a checkered floor under a
//! procedural sky, rendered by the path tracer. Each request renders one pass of a few
//! samples per pixel with its own seed; the app averages the passes while the parameters
//! stay still, so the image refines without the server keeping any state but the loaded
//! scenes (a small cache keyed by material and size: moving on to the next pass does not
//! reload the sky or rebuild the material).

use crate::cancel::Cancel;
use crate::frame::Frame;
use facette_render::render::{render, RenderOptions};
use facette_render::scene::{load_scene_str, Scene};
use serde::Deserialize;
use std::sync::{Arc, Mutex};

/// A pass of the preview.
#[derive(Clone, Debug, Deserialize)]
pub struct PreviewRequest {
    pub material: String,
    pub width: usize,
    pub height: usize,
    /// Samples per pixel of this pass.
    pub spp: usize,
    /// The pass's index: its seed.
    pub pass: u64,
}

/// Sizes a preview request may ask for.
pub const MAX_SIDE: usize = 512;
pub const MAX_SPP: usize = 64;

impl PreviewRequest {
    pub fn check(&self) -> Result<(), String> {
        for (name, v, hi) in [
            ("width", self.width, MAX_SIDE),
            ("height", self.height, MAX_SIDE),
            ("spp", self.spp, MAX_SPP),
        ] {
            if !(1..=hi).contains(&v) {
                return Err(format!(
                    "`{name}` = {v} is out of range: expected 1 <= {name} <= {hi}"
                ));
            }
        }
        if self
            .material
            .trim_start()
            .starts_with(crate::material::MEASURED_PREFIX)
        {
            return Err(
                "the preview renders materials written as TOML tables, not measured files".into(),
            );
        }
        Ok(())
    }
}

/// The preview scene's source with `material` (a TOML inline table) on the sphere.
pub fn scene_source(material: &str, width: usize, height: usize) -> String {
    format!(
        r#"[camera]
position = [0, 1.15, 3.3]
target = [0, 0.45, 0]
fov = 32

[film]
width = {width}
height = {height}
spp = 1

[integrator]
max_depth = 8

[materials]
preview = {material}
floor = {{ type = "lambert", reflectance = {{ texture = "checker", a = 0.18, b = 0.5, scale = 12 }} }}

[[objects]]
shape = "sphere"
center = [0, 0.5, 0]
radius = 0.5
material = "preview"

[[objects]]
shape = "rectangle"
transform = [{{ rotate = {{ axis = [1, 0, 0], angle = -90 }} }}, {{ scale = 6 }}]
material = "floor"

[[lights]]
type = "environment"
sky = {{ sun_direction = [0.6, 0.55, 0.6], sun_angular_radius = 2.0, width = 256, height = 128 }}
"#
    )
}

/// Loaded preview scenes, by material text and size.
#[derive(Default)]
pub struct PreviewScenes {
    scenes: Mutex<Vec<(String, Arc<Scene>)>>,
}

impl PreviewScenes {
    const SIZE: usize = 4;

    /// The scene for `material` at `width` × `height`, loaded once; the error is the
    /// scene loader's message (the material's grammar error among them).
    pub fn get(&self, material: &str, width: usize, height: usize) -> Result<Arc<Scene>, String> {
        let key = format!("{width}x{height} {material}");
        if let Some((_, s)) = self.lock().iter().find(|(k, _)| *k == key) {
            return Ok(s.clone());
        }
        // The material goes into the scene's text only as the grammar writes a parsed
        // inline table back: a string that closes the table and adds lights or files to
        // the scene (an environment `file` would be written) is refused here.
        let table =
            facette_bsdf::recipe::parse_inline_table(material).map_err(|e| e.to_string())?;
        let source = scene_source(&crate::material::canonical_text(&table), width, height);
        let scene = load_scene_str(&source, std::path::Path::new("./preview.toml"))
            .map_err(|e| e.to_string())?;
        let scene = Arc::new(scene);
        let mut scenes = self.lock();
        scenes.insert(0, (key, scene.clone()));
        scenes.truncate(Self::SIZE);
        Ok(scene)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<(String, Arc<Scene>)>> {
        self.scenes.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// One pass: arrays `r`, `g`, `b` (mean radiance per pixel, row-major from the top row).
pub fn render_pass(
    scene: &Scene,
    q: &PreviewRequest,
    cancel: &Cancel,
) -> Result<Option<Frame>, String> {
    let options = RenderOptions {
        spp: Some(q.spp),
        seed: q.pass,
        ..RenderOptions::default()
    };
    let (film, stats) = render(scene, &options, cancel.flag(), &|_, _| {})?;
    if cancel.is_cancelled() {
        return Ok(None);
    }
    let image = film.image();
    let channel = |c: usize| image.data().iter().map(|p| p[c] as f64).collect::<Vec<_>>();
    Ok(Some(
        Frame::default()
            .field("width", image.width())
            .field("height", image.height())
            .field("pass", q.pass)
            .field("spp", q.spp)
            .field("msamples_per_second", stats.msamples_per_second())
            .array("r", channel(0))
            .array("g", channel(1))
            .array("b", channel(2)),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pass_renders_the_material_and_a_bad_one_is_refused() {
        let scenes = PreviewScenes::default();
        let q = PreviewRequest {
            material: r#"{type = "conductor", distribution = "ggx", alpha = 0.3, material = "Au"}"#
                .into(),
            width: 24,
            height: 16,
            spp: 2,
            pass: 3,
        };
        let scene = scenes.get(&q.material, q.width, q.height).unwrap();
        let f = render_pass(&scene, &q, &Cancel::default())
            .unwrap()
            .unwrap();
        let r = f.get("r").unwrap();
        assert_eq!(r.len(), 24 * 16);
        assert!(r.iter().all(|v| v.is_finite() && *v >= 0.0));
        assert!(r.iter().sum::<f64>() > 0.0);
        let e = scenes
            .get(r#"{type = "conductor", alpha = -1}"#, 8, 8)
            .err()
            .unwrap();
        assert!(e.contains("alpha"), "{e}");
        let injected =
            "{type = \"lambert\"}\n[[lights]]\ntype = \"environment\"\nfile = \"sky.exr\"";
        assert!(scenes.get(injected, 8, 8).is_err());
        let quoted =
            r#"{type = "glint", generate = "bumpy", resolution = 16, normal_encoding = "x\"}"}"#;
        assert!(scenes
            .get(quoted, 8, 8)
            .err()
            .unwrap()
            .contains("unknown normal encoding `x\"}`"));
        let bad = PreviewRequest { spp: 0, ..q };
        assert!(bad.check().unwrap_err().contains("spp"));
    }
}
