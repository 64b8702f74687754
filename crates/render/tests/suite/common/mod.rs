//! Helpers of the Mitsuba scene tests (`scene_mitsuba*.rs`): a standard sensor, scenes
//! written to a temporary directory and loaded, errors with the directory stripped, and
//! materials compared with the BSDF their TOML equivalent builds.

// Each test file uses a different subset of the helpers.
#![allow(dead_code)]

use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::recipe::build_material_in;
use facette_bsdf::BsdfContext;
use facette_render::geometry::{Vec2, Vec3};
use facette_render::scene::{load_scene_with, LoadOptions, Scene};
use std::path::{Path, PathBuf};

/// A small pinhole sensor looking down −z from (0, 0, 5), 40° across x, 16×12 pixels.
pub const SENSOR: &str = r#"<sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film>
    </sensor>"#;

pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// `<scene>` with the standard sensor and `body`.
pub fn scene_xml(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n    {SENSOR}\n{body}\n</scene>\n")
}

pub fn load_in(dir: &Path, xml: &str, defines: &[(&str, &str)]) -> Result<Scene, String> {
    let path = write(dir, "scene.xml", xml);
    let options = LoadOptions {
        defines: defines
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
    };
    load_scene_with(&path, &options).map_err(|e| e.to_string())
}

pub fn load(xml: &str) -> Scene {
    let dir = tempfile::tempdir().unwrap();
    load_in(dir.path(), xml, &[]).unwrap_or_else(|e| panic!("{e}"))
}

pub fn error(xml: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    match load_in(dir.path(), xml, &[]) {
        Ok(_) => panic!("loaded, expected an error:\n{xml}"),
        Err(e) => e.replace(&format!("{}/", dir.path().display()), ""),
    }
}

/// Evaluates material `m` of `s` at uv and compares it with the BSDF the TOML table
/// `expected` builds, at several direction pairs (same random stream for stochastic ones).
pub fn assert_material(s: &Scene, m: usize, expected: &str, uv: Vec2) {
    let table: toml::Table = toml::from_str(expected).unwrap();
    let want = build_material_in(&table, Path::new(".")).unwrap();
    let got = s.materials[m].bsdf(uv, [0.0; 4]).expect("valid material");
    let dirs = [
        (Vec3::new(0.3, 0.1, 0.9), Vec3::new(-0.2, 0.4, 0.8)),
        (Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.6, 0.0, 0.8)),
        (Vec3::new(0.7, -0.3, 0.3), Vec3::new(0.1, 0.6, -0.6)),
        (Vec3::new(-0.5, 0.5, 0.5), Vec3::new(0.5, -0.5, 0.5)),
    ];
    for (wo, wi) in dirs {
        let (wo, wi) = (wo.normalize(), wi.normalize());
        let a = got.eval(wo, wi, &BsdfContext::RADIANCE, &mut Pcg32::new(7, 1));
        let b = want.eval(wo, wi, &BsdfContext::RADIANCE, &mut Pcg32::new(7, 1));
        for c in 0..3 {
            assert!(
                (a[c] - b[c]).abs() <= 1e-12 * b[c].abs().max(1.0),
                "material {} ({}) vs {expected}: {a:?} != {b:?} at {wo} {wi}",
                m,
                s.materials[m].name
            );
        }
    }
}

pub fn material_index(s: &Scene, name: &str) -> usize {
    s.materials
        .iter()
        .position(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name}"))
}

pub fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-9
}
