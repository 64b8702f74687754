//! The sensor with its film, reconstruction filter and sampler, as facette's camera and
//! film.
//!
//! | Mitsuba | facette |
//! |---|---|
//! | `perspective` (`to_world`, `fov`, `fov_axis` x, or `focal_length` 50mm on the diagonal of 36×24 mm film; `near_clip` 0.01, `far_clip` 10⁴) | camera with the sensor's frame (same axes: +z forward, +y up, image x toward −x) |
//! | `thinlens` (+ `aperture_radius`, `focus_distance` 10⁴) | `aperture_radius`, `focus_distance` |
//! | `hdrfilm` (`width` 768, `height` 576, `rfilter`) | film size |
//! | `rfilter` `box`; `gaussian` (`stddev` 0.5, radius 4 σ) | `box`; `gaussian` with `filter_stddev`, `filter_radius = 4 σ` |
//! | `sampler` (`sample_count` 4) | `spp`, and the nearest of facette's samplers: `independent` → `independent`; `stratified`, `multijitter` → `stratified`; `ldsampler`, `orthogonal` → `sobol` (a warning says so); other parameters (`seed`, `jitter`, `strength`, …) are ignored with a warning |
//!
//! facette has no clipping planes: `near_clip`/`far_clip` are checked against the scene
//! after it is built, with a warning when they would have hidden geometry
//! ([`ClipPlanes::check`]).

use super::plugin::Plugin;
use super::translator::Translator;
use super::xml::Pos;
use crate::camera::FovAxis;
use crate::geometry::{Transform, Vec2, Vec3};
use crate::sampler::SamplerKind;
use crate::scene::description::{CameraDesc, FilmDesc};
use crate::scene::{Scene, SceneError};
use glam::{DMat3, DMat4, DVec3};
use toml::Spanned;

/// Mitsuba's default film and sampler.
const DEFAULT_SIZE: (usize, usize) = (768, 576);
const DEFAULT_SPP: usize = 4;

/// The sensor's clipping distances, checked against the built scene.
pub(crate) struct ClipPlanes {
    pub near: f64,
    pub far: f64,
    pub pos: Pos,
}

/// Camera and film of a sensor plugin.
pub(crate) fn sensor(
    cx: &mut Translator,
    s: &Plugin,
) -> Result<(Spanned<CameraDesc>, Spanned<FilmDesc>, ClipPlanes), SceneError> {
    let thinlens = match s.kind.as_str() {
        "perspective" => false,
        "thinlens" => true,
        other => {
            return Err(s.err(format!(
                "unsupported sensor `{other}`; supported: perspective, thinlens"
            )))
        }
    };
    let film_plugin = s.object("film", &cx.reg)?;
    let film = match &film_plugin {
        Some(f) => film(cx, f)?,
        None => FilmDesc {
            width: DEFAULT_SIZE.0,
            height: DEFAULT_SIZE.1,
            filter_radius: 2.0,
            ..FilmDesc::default()
        },
    };
    let mut film = film;
    (film.spp, film.sampler) = match s.object("sampler", &cx.reg)? {
        Some(smp) => sampler(cx, &smp)?,
        None => (DEFAULT_SPP, SamplerKind::Independent.name().to_string()),
    };

    let m = s.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
    let lin = DMat3::from_mat4(m);
    let gram = lin.transpose() * lin;
    let orthonormal = (gram - DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .all(|v| v.abs() < 1e-4);
    if !orthonormal || m.row(3) != glam::DVec4::W {
        return Err(s.err(
            "`to_world` must be a rotation and translation (a mirror is allowed): Mitsuba refuses scale factors in a camera transform too",
        ));
    }
    let to_world = Transform::try_new(m).map_err(|e| s.err(format!("`to_world`: {e}")))?;
    let position = m.transform_point3(DVec3::ZERO);
    let forward = m.transform_vector3(DVec3::Z);
    let up = m.transform_vector3(DVec3::Y);

    let (w, h) = (film.width as f64, film.height as f64);
    let (fov, fov_axis) = match (s.float("fov")?, s.string("focal_length")?) {
        (Some(_), Some(_)) => return Err(s.err("give `fov` or `focal_length`, not both")),
        (Some(fov), None) => {
            let axis = s.string("fov_axis")?.unwrap_or("x".into());
            if FovAxis::parse(&axis).is_none() {
                return Err(s.err(format!(
                    "unknown fov_axis `{axis}`; valid: {}",
                    FovAxis::NAMES.join(", ")
                )));
            }
            (fov, axis)
        }
        (None, fl) => {
            let fl = fl.unwrap_or("50mm".into());
            let mm = fl
                .trim()
                .strip_suffix("mm")
                .unwrap_or(fl.trim())
                .parse::<f64>()
                .ok()
                .filter(|v| *v > 0.0 && v.is_finite())
                .ok_or_else(|| {
                    s.err(format!(
                        "`focal_length` = \"{fl}\" must be a positive length in mm, like \"50mm\""
                    ))
                })?;
            // Mitsuba: the diagonal field of view of a 36 × 24 mm film, converted to x.
            let half_diag = (36f64.hypot(24.0) / (2.0 * mm)).atan();
            let tan_x = half_diag.tan() * w / w.hypot(h);
            ((2.0 * tan_x.atan()).to_degrees(), "x".to_string())
        }
    };
    let near = s.float("near_clip")?.unwrap_or(0.01);
    let far = s.float("far_clip")?.unwrap_or(1e4);
    if !(near > 0.0 && far > near && far.is_finite()) {
        return Err(s.err(format!(
            "need 0 < near_clip < far_clip (finite), got {near} and {far}"
        )));
    }
    let (aperture, focus) = if thinlens {
        let a = s
            .float("aperture_radius")?
            .ok_or_else(|| s.err("needs `aperture_radius`"))?;
        (a, Some(s.float("focus_distance")?.unwrap_or(1e4)))
    } else {
        (0.0, None)
    };
    let mut keys = vec![
        "to_world",
        "fov",
        "fov_axis",
        "focal_length",
        "near_clip",
        "far_clip",
        "film",
        "sampler",
    ];
    if thinlens {
        keys.extend(["aperture_radius", "focus_distance"]);
    }
    s.finish(&keys, &cx.reg)?;

    let camera = CameraDesc {
        position: position.to_array(),
        target: (position + forward).to_array(),
        up: up.to_array(),
        fov,
        fov_axis: Some(fov_axis),
        aperture_radius: aperture,
        focus_distance: focus,
        to_world: Some(to_world),
    };
    let cam_span = cx.span(&s.pos);
    let film_span = cx.span(film_plugin.as_ref().map(|f| &f.pos).unwrap_or(&s.pos));
    Ok((
        Spanned::new(cam_span, camera),
        Spanned::new(film_span, film),
        ClipPlanes {
            near,
            far,
            pos: s.pos.clone(),
        },
    ))
}

fn film(cx: &mut Translator, f: &Plugin) -> Result<FilmDesc, SceneError> {
    if f.kind != "hdrfilm" {
        return Err(f.err(format!(
            "unsupported film `{}`; supported: hdrfilm (facette writes EXR or PNG as -o says)",
            f.kind
        )));
    }
    let size = |name: &str, default: usize| -> Result<usize, SceneError> {
        match f.integer(name)? {
            None => Ok(default),
            Some(v) if (1..=65536).contains(&v) => Ok(v as usize),
            Some(v) => Err(f.err(format!("`{name}` = {v} is outside 1…65536"))),
        }
    };
    let mut film = FilmDesc {
        width: size("width", DEFAULT_SIZE.0)?,
        height: size("height", DEFAULT_SIZE.1)?,
        filter_radius: 2.0,
        ..FilmDesc::default()
    };
    for key in [
        "pixel_format",
        "component_format",
        "file_format",
        "banner",
        "high_quality_edges",
        "sample_border",
    ] {
        if let Some(p) = f.get(key) {
            let pos = p.pos.clone();
            cx.warn(
                &pos,
                format!("hdrfilm `{key}` is ignored: facette writes RGB as the output file's extension says"),
            );
        }
    }
    if let Some(r) = f.object("rfilter", &cx.reg)? {
        match r.kind.as_str() {
            "box" => {
                film.filter = "box".into();
                r.finish(&[], &cx.reg)?;
            }
            "gaussian" => {
                let sd = r.float("stddev")?.unwrap_or(0.5);
                if !(sd > 0.0 && sd.is_finite()) {
                    return Err(r.err(format!("`stddev` = {sd} must be > 0")));
                }
                film.filter = "gaussian".into();
                film.filter_stddev = sd;
                film.filter_radius = 4.0 * sd;
                r.finish(&["stddev"], &cx.reg)?;
            }
            other => {
                return Err(r.err(format!(
                    "unsupported rfilter `{other}`; supported: box, gaussian"
                )))
            }
        }
    }
    f.finish(
        &[
            "width",
            "height",
            "rfilter",
            "pixel_format",
            "component_format",
            "file_format",
            "banner",
            "high_quality_edges",
            "sample_border",
        ],
        &cx.reg,
    )?;
    Ok(film)
}

/// The sample count and the nearest of facette's samplers; the sampler's other
/// parameters only change the noise. Mitsuba's `independent` and `stratified` are
/// facette's; `multijitter` (jittered strata) becomes `stratified`; `ldsampler` and
/// `orthogonal` (low-discrepancy points, stratified in every 2D projection) become
/// `sobol`.
fn sampler(cx: &mut Translator, s: &Plugin) -> Result<(usize, String), SceneError> {
    let kind = match s.kind.as_str() {
        "independent" => SamplerKind::Independent,
        "stratified" | "multijitter" => SamplerKind::Stratified,
        "ldsampler" | "orthogonal" => SamplerKind::Sobol,
        other => {
            return Err(s.err(format!(
                "unsupported sampler `{other}`; supported: independent, stratified, multijitter, ldsampler, orthogonal"
            )))
        }
    };
    if s.kind != kind.name() {
        cx.warn(
            &s.pos,
            format!(
                "sampler `{}` is rendered with facette's `{}` sampler",
                s.kind,
                kind.name()
            ),
        );
    }
    let n = s.integer("sample_count")?.unwrap_or(DEFAULT_SPP as i64);
    if n < 1 {
        return Err(s.err(format!("`sample_count` = {n} must be at least 1")));
    }
    for p in &s.props {
        if p.name != "sample_count" {
            s.get(&p.name);
            cx.warn(
                &p.pos,
                format!(
                    "sampler parameter `{}` is ignored (facette's samples come from --seed)",
                    p.name
                ),
            );
        }
    }
    s.finish(&["sample_count"], &cx.reg)?;
    Ok((n as usize, kind.name().to_string()))
}

impl ClipPlanes {
    /// Warns when geometry may lie nearer than `near_clip` or farther than `far_clip`
    /// from the camera, where Mitsuba would not show it (facette does not clip).
    pub fn check(&self, scene: &Scene, warnings: &mut Vec<String>) {
        let cam = &scene.camera;
        let (centre, _) = cam.generate_ray(
            0.5 * cam.width() as f64,
            0.5 * cam.height() as f64,
            Vec2::ZERO,
        );
        let origin = centre.origin;
        // The largest 1/cos between the view axis and a corner ray bounds the distance of
        // the near plane's points from the camera.
        let mut k: f64 = 1.0;
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            let (r, _) =
                cam.generate_ray(x * cam.width() as f64, y * cam.height() as f64, Vec2::ZERO);
            k = k.max(1.0 / r.dir.dot(centre.dir).max(1e-6));
        }
        let geometry = &scene.geometry;
        let mut near_hit = false;
        'shapes: for shape in geometry.shapes() {
            for i in 0..shape.primitive_count() {
                let b = shape.primitive_bounds(i);
                let closest = origin.clamp(b.min, b.max);
                if (closest - origin).length() < self.near * k {
                    near_hit = true;
                    break 'shapes;
                }
            }
        }
        if near_hit {
            warnings.push(format!(
                "{}: near_clip = {}: facette does not clip, and some geometry is within that distance of the camera (Mitsuba would hide it)",
                self.pos, self.near
            ));
        }
        let b = geometry.bounds();
        if !b.is_empty() {
            let farthest = (0..8)
                .map(|c| {
                    let p = Vec3::new(
                        if c & 1 == 0 { b.min.x } else { b.max.x },
                        if c & 2 == 0 { b.min.y } else { b.max.y },
                        if c & 4 == 0 { b.min.z } else { b.max.z },
                    );
                    (p - origin).length()
                })
                .fold(0.0, f64::max);
            if farthest > self.far {
                warnings.push(format!(
                    "{}: far_clip = {}: facette does not clip, and some geometry is farther than that from the camera (Mitsuba would hide it)",
                    self.pos, self.far
                ));
            }
        }
    }
}
