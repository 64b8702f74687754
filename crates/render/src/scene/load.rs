//! Loading a scene: parse the TOML (serde, with spans) — or translate a Mitsuba XML file
//! into the same description (`super::mitsuba`) — then validate every value and build
//! geometry, materials, lights and camera. Every error names the file and line.

use super::description::*;
use super::{FilmSettings, IntegratorSettings, Scene};
use crate::camera::{Camera, FovAxis};
use crate::film::Filter;
use crate::geometry::generate::{cube_mesh_data, TorusKnot};
use crate::geometry::{
    Disk, Rectangle, SceneGeometry, Shape, Sphere, Transform, TriangleMesh, Vec3,
};
use crate::image::{
    generate_sky, load_or_generate_sky, read_image, ColorEncoding, ConstantEnvironment,
    EnvironmentMap, SkyParams,
};
use crate::lights::{Environment, Light, LightSelector};
use crate::materials::SceneMaterial;
use crate::sampler::SamplerKind;
use facette_bsdf::Spectrum;
use glam::DMat3;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A scene error: file, line (when known) and what was expected.
#[derive(Debug, thiserror::Error)]
#[error("{}{}: {message}", file.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
pub struct SceneError {
    pub file: PathBuf,
    pub line: Option<usize>,
    pub message: String,
}

/// A place in a scene file, for descriptions whose elements come from several files
/// (Mitsuba XML with `<include>`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Location {
    pub file: PathBuf,
    pub line: usize,
}

/// What the spans of a [`SceneDesc`] index.
pub(crate) enum Spans<'a> {
    /// Byte ranges of the TOML text of `file`.
    Text { file: &'a Path, source: &'a str },
    /// `i..i + 1` is entry `i` of `locations` (a description translated from Mitsuba XML);
    /// errors without a span name `file`, the main scene file.
    Table {
        file: &'a Path,
        locations: &'a [Location],
    },
}

pub(crate) struct Ctx<'a> {
    pub spans: Spans<'a>,
    /// Directory that relative paths of the description are resolved against.
    pub base_dir: PathBuf,
}

impl Ctx<'_> {
    fn err(&self, span: Option<std::ops::Range<usize>>, message: impl Into<String>) -> SceneError {
        let (file, line) = match (&self.spans, span) {
            (Spans::Text { file, source }, Some(s)) => (
                file.to_path_buf(),
                Some(source[..s.start.min(source.len())].matches('\n').count() + 1),
            ),
            (Spans::Table { file, locations }, Some(s)) => match locations.get(s.start) {
                Some(l) => (l.file.clone(), Some(l.line)),
                None => (file.to_path_buf(), None),
            },
            (Spans::Text { file, .. } | Spans::Table { file, .. }, None) => {
                (file.to_path_buf(), None)
            }
        };
        SceneError {
            file,
            line,
            message: message.into(),
        }
    }
}

/// Loads a TOML scene from its text; `path` names it in errors and anchors relative paths.
pub fn load_scene_str(source: &str, path: &Path) -> Result<Scene, SceneError> {
    let ctx = Ctx {
        spans: Spans::Text { file: path, source },
        base_dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
    };
    let desc: SceneDesc =
        toml::from_str(source).map_err(|e| ctx.err(e.span(), e.message().to_string()))?;
    build(&ctx, desc, fnv1a(source.as_bytes()))
}

fn vec3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

fn finite3(
    ctx: &Ctx,
    span: &std::ops::Range<usize>,
    name: &str,
    a: [f64; 3],
) -> Result<Vec3, SceneError> {
    if a.iter().all(|v| v.is_finite()) {
        Ok(vec3(a))
    } else {
        Err(ctx.err(
            Some(span.clone()),
            format!("`{name}` must be three finite numbers"),
        ))
    }
}

fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(f) => Some(*f),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

fn triple(v: &toml::Value) -> Option<Vec3> {
    match v {
        toml::Value::Array(a) if a.len() == 3 => {
            Some(Vec3::new(number(&a[0])?, number(&a[1])?, number(&a[2])?))
        }
        _ => None,
    }
}

/// Transform steps, applied in the order listed: `{translate = [x, y, z]}`,
/// `{scale = s | [x, y, z]}`, `{rotate = {axis = [x, y, z], angle = degrees}}`,
/// `{look_at = {origin, target, up}}`, `{matrix = [16 numbers, row-major]}`.
pub fn parse_transform(steps: &[toml::Table]) -> Result<Transform, String> {
    let mut t = Transform::identity();
    for step in steps {
        if step.len() != 1 {
            return Err("each transform step is a table with exactly one of translate, scale, rotate, look_at, matrix".into());
        }
        let (k, v) = step.iter().next().expect("one entry");
        let next = match k.as_str() {
            "translate" => Transform::translate(triple(v).ok_or("`translate` expects [x, y, z]")?),
            "scale" => {
                let s = match v {
                    toml::Value::Array(_) => {
                        triple(v).ok_or("`scale` expects a number or [x, y, z]")?
                    }
                    _ => Vec3::splat(number(v).ok_or("`scale` expects a number or [x, y, z]")?),
                };
                Transform::scale(s)
            }
            "rotate" => {
                let r = v
                    .as_table()
                    .ok_or("`rotate` expects {axis = [x, y, z], angle = degrees}")?;
                let axis = r
                    .get("axis")
                    .and_then(triple)
                    .ok_or("`rotate` needs `axis = [x, y, z]`")?;
                let angle = r
                    .get("angle")
                    .and_then(number)
                    .ok_or("`rotate` needs `angle` (degrees)")?;
                Transform::rotate(axis, angle)
            }
            "look_at" => {
                let r = v
                    .as_table()
                    .ok_or("`look_at` expects {origin, target, up}")?;
                let g = |name: &str| {
                    r.get(name)
                        .and_then(triple)
                        .ok_or(format!("`look_at` needs `{name} = [x, y, z]`"))
                };
                Transform::look_at(g("origin")?, g("target")?, g("up")?)
            }
            "matrix" => {
                let a = v
                    .as_array()
                    .filter(|a| a.len() == 16)
                    .ok_or("`matrix` expects 16 numbers (row-major)")?;
                let mut m = [0.0; 16];
                for (i, x) in a.iter().enumerate() {
                    m[i] = number(x).ok_or("`matrix` expects 16 numbers")?;
                }
                // Row-major in the file, column-major in glam.
                Transform::try_new(glam::DMat4::from_cols_array(&m).transpose())
            }
            other => {
                return Err(format!(
                    "unknown transform `{other}`; valid: translate, scale, rotate, look_at, matrix"
                ))
            }
        }
        .map_err(|e| e.to_string())?;
        t = t.then(&next);
    }
    Ok(t)
}

/// Validates a description and builds the scene; `source_hash` identifies the scene's
/// source (see [`Scene::source_hash`]).
pub(crate) fn build(ctx: &Ctx, desc: SceneDesc, source_hash: u64) -> Result<Scene, SceneError> {
    // Film and integrator.
    let film_span = desc.film.as_ref().map(|f| f.span());
    let f = desc.film.map(|f| f.into_inner()).unwrap_or_default();
    if f.width == 0 || f.height == 0 || f.width > 65536 || f.height > 65536 {
        return Err(ctx.err(
            film_span.clone(),
            format!("film size {}×{} is outside 1…65536", f.width, f.height),
        ));
    }
    if f.spp == 0 {
        return Err(ctx.err(film_span.clone(), "`spp` must be at least 1"));
    }
    if !f.exposure.is_finite() {
        return Err(ctx.err(film_span.clone(), "`exposure` must be finite"));
    }
    let filter = match f.filter.as_str() {
        "box" => Filter::Box,
        "gaussian" => {
            if !(f.filter_stddev > 0.0
                && f.filter_stddev.is_finite()
                && f.filter_radius > 0.0
                && f.filter_radius.is_finite())
            {
                return Err(ctx.err(
                    film_span.clone(),
                    "`filter_stddev` and `filter_radius` must be positive",
                ));
            }
            Filter::gaussian(f.filter_stddev, f.filter_radius)
        }
        other => {
            return Err(ctx.err(
                film_span,
                format!(
                    "unknown filter `{other}`; valid: {}",
                    Filter::NAMES.join(", ")
                ),
            ));
        }
    };
    let Some(sampler) = SamplerKind::parse(&f.sampler) else {
        return Err(ctx.err(
            film_span,
            format!(
                "unknown sampler `{}`; valid: {}",
                f.sampler,
                SamplerKind::NAMES.join(", ")
            ),
        ));
    };
    let film = FilmSettings {
        width: f.width,
        height: f.height,
        spp: f.spp,
        filter,
        exposure: f.exposure,
        sampler,
    };
    let integ_span = desc.integrator.as_ref().map(|i| i.span());
    let i = desc.integrator.map(|i| i.into_inner()).unwrap_or_default();
    if i.max_depth == 0 || i.max_depth > 1024 {
        return Err(ctx.err(integ_span, "`max_depth` must be in 1…1024"));
    }
    let integrator = IntegratorSettings {
        max_depth: i.max_depth,
        rr_depth: i.rr_depth,
    };

    // Camera.
    let cam_span = desc.camera.span();
    let c = desc.camera.into_inner();
    let position = finite3(ctx, &cam_span, "position", c.position)?;
    let target = finite3(ctx, &cam_span, "target", c.target)?;
    let up = finite3(ctx, &cam_span, "up", c.up)?;
    if !(c.fov > 0.0 && c.fov < 180.0) {
        return Err(ctx.err(
            Some(cam_span),
            format!("camera `fov` = {} must be in (0, 180) degrees", c.fov),
        ));
    }
    let axis = match &c.fov_axis {
        None => FovAxis::X,
        Some(s) => FovAxis::parse(s).ok_or_else(|| {
            ctx.err(
                Some(cam_span.clone()),
                format!(
                    "unknown fov_axis `{s}`; valid: {}",
                    FovAxis::NAMES.join(", ")
                ),
            )
        })?,
    };
    // A translated Mitsuba sensor brings its own frame (which may mirror the image).
    let to_world = match c.to_world {
        Some(t) => t,
        None => Transform::look_at(position, target, up)
            .map_err(|e| ctx.err(Some(cam_span.clone()), format!("camera: {e}")))?,
    };
    if !(c.aperture_radius >= 0.0 && c.aperture_radius.is_finite()) {
        return Err(ctx.err(Some(cam_span), "`aperture_radius` must be ≥ 0"));
    }
    let focus = c.focus_distance.unwrap_or((target - position).length());
    if !(focus > 0.0 && focus.is_finite()) {
        return Err(ctx.err(Some(cam_span), "`focus_distance` must be > 0"));
    }
    let camera = Camera::new(
        to_world,
        c.fov,
        axis,
        film.width,
        film.height,
        c.aperture_radius,
        focus,
    );

    // Materials.
    let mut materials: Vec<SceneMaterial> = Vec::new();
    let mut by_name: BTreeMap<String, u32> = BTreeMap::new();
    for (name, table) in &desc.materials {
        let m = SceneMaterial::parse(name, table.get_ref(), &ctx.base_dir)
            .map_err(|e| ctx.err(Some(table.span()), format!("material `{name}`: {e}")))?;
        by_name.insert(name.clone(), materials.len() as u32);
        materials.push(m);
    }

    // Objects.
    let mut shapes: Vec<Shape> = Vec::new();
    let mut shape_material = Vec::new();
    let mut shape_emission: Vec<Option<(Spectrum, bool)>> = Vec::new();
    for (k, obj) in desc.objects.iter().enumerate() {
        let span = obj.span();
        let o = obj.get_ref();
        let what = format!("object {} ({})", k + 1, o.shape);
        let e = |m: String| ctx.err(Some(span.clone()), format!("{what}: {m}"));
        let to_world = parse_transform(&o.transform).map_err(e)?;
        let allowed: &[&str] = match o.shape.as_str() {
            "sphere" => &["center", "radius"],
            "rectangle" | "disk" | "cube" => &[],
            "obj" | "ply" => &["file"],
            "torus-knot" => &["triangles"],
            other => {
                return Err(e(format!("unknown shape `{other}`; valid: sphere, rectangle, disk, cube, obj, ply, torus-knot")));
            }
        };
        for (key, present) in [
            ("center", o.center.is_some()),
            ("radius", o.radius.is_some()),
            ("file", o.file.is_some()),
            ("triangles", o.triangles.is_some()),
        ] {
            if present && !allowed.contains(&key) {
                return Err(e(format!("`{key}` does not apply to a {}", o.shape)));
            }
        }
        let shape = match o.shape.as_str() {
            "sphere" => {
                let center = o.center.map(vec3).unwrap_or(Vec3::ZERO);
                let radius = o.radius.unwrap_or(1.0);
                Shape::Sphere(
                    Sphere::with_transform(center, radius, &to_world, o.flip_normals)
                        .map_err(|x| e(x.to_string()))?,
                )
            }
            "rectangle" => Shape::Rectangle(
                Rectangle::new(&to_world, o.flip_normals).map_err(|x| e(x.to_string()))?,
            ),
            "disk" => {
                Shape::Disk(Disk::new(&to_world, o.flip_normals).map_err(|x| e(x.to_string()))?)
            }
            "cube" => Shape::Mesh(Arc::new(
                cube_mesh_data()
                    .into_mesh(&to_world, o.flip_normals)
                    .map_err(|x| e(x.to_string()))?,
            )),
            "obj" | "ply" => {
                let file = o.file.as_ref().ok_or_else(|| e("needs `file`".into()))?;
                let path = ctx.base_dir.join(file);
                let mut data = match (o.shape.as_str(), o.flip_tex_coords) {
                    ("obj", Some(flip)) => crate::geometry::mesh_io::read_obj(&path, flip),
                    _ => crate::geometry::mesh_io::read_mesh(&path),
                }
                .map_err(|x| e(x.to_string()))?;
                match o.mesh_normals {
                    MeshNormals::AsStored => {}
                    MeshNormals::Face => data.normals = None,
                    MeshNormals::ComputedIfMissing => {
                        if data.normals.is_none() {
                            super::mitsuba::vertex_normals::add_vertex_normals(
                                &mut data, &to_world,
                            );
                        }
                    }
                }
                let mesh = data
                    .into_mesh(&to_world, o.flip_normals)
                    .map_err(|x| match x {
                        x @ crate::geometry::GeometryError::InFile { .. } => x,
                        x => x.in_file(&path, None),
                    })
                    .map_err(|x| e(x.to_string()))?;
                Shape::Mesh(Arc::new(mesh))
            }
            _ => {
                let n = o.triangles.unwrap_or(100_000);
                if !(100..=20_000_000).contains(&n) {
                    return Err(e(format!("`triangles` = {n} must be in 100…20000000")));
                }
                let mesh: TriangleMesh = TorusKnot::with_triangles(n)
                    .mesh(&to_world)
                    .map_err(|x| e(x.to_string()))?;
                Shape::Mesh(Arc::new(mesh))
            }
        };
        // Material errors point at the `material` line.
        let material = match &o.material {
            None => {
                if o.emission.is_none() {
                    return Err(e(
                        "needs a `material` (a name from [materials] or an inline table)".into(),
                    ));
                }
                // Pure emitters are black.
                let m = SceneMaterial::parse(
                    "black",
                    &toml::from_str("type = \"lambert\"\nreflectance = 0").expect("valid"),
                    &ctx.base_dir,
                )
                .map_err(e)?;
                materials.push(m);
                (materials.len() - 1) as u32
            }
            Some(m) => {
                let em = |msg: String| ctx.err(Some(m.span()), format!("{what}: {msg}"));
                match m.get_ref() {
                    MaterialRef::Name(n) => *by_name.get(n).ok_or_else(|| {
                        em(format!(
                            "unknown material `{n}`; defined: {}",
                            if by_name.is_empty() {
                                "none".to_string()
                            } else {
                                by_name.keys().cloned().collect::<Vec<_>>().join(", ")
                            }
                        ))
                    })?,
                    MaterialRef::Inline(t) => {
                        let m =
                            SceneMaterial::parse(&format!("object {}", k + 1), t, &ctx.base_dir)
                                .map_err(em)?;
                        materials.push(m);
                        (materials.len() - 1) as u32
                    }
                }
            }
        };
        let emission = match &o.emission {
            None => None,
            Some(c) => {
                let s = c.spectrum();
                if !s.is_finite() || s.has_negative() {
                    return Err(e("`emission` must be finite and ≥ 0".into()));
                }
                Some((s, o.two_sided))
            }
        };
        if o.two_sided && emission.is_none() {
            return Err(e(
                "`two_sided` applies to emitters (objects with `emission`)".into(),
            ));
        }
        shapes.push(shape);
        shape_material.push(material);
        shape_emission.push(emission);
    }
    let geometry = SceneGeometry::new(shapes).map_err(|x| ctx.err(None, x.to_string()))?;

    // Lights.
    let mut lights: Vec<Light> = Vec::new();
    let mut shape_light = vec![None; shape_material.len()];
    for (s, em) in shape_emission.iter().enumerate() {
        if let Some((radiance, two_sided)) = em {
            shape_light[s] = Some(lights.len() as u32);
            lights.push(Light::Area {
                shape: s as u32,
                radiance: *radiance,
                two_sided: *two_sided,
            });
        }
    }
    let mut environment = None;
    for l in &desc.lights {
        let span = l.span();
        let d = l.get_ref();
        let e = |m: String| ctx.err(Some(span.clone()), format!("light `{}`: {m}", d.kind));
        let check_color = |name: &str, c: Option<ColorDesc>| -> Result<Spectrum, SceneError> {
            let s = c.ok_or_else(|| e(format!("needs `{name}`")))?.spectrum();
            if !s.is_finite() || s.has_negative() {
                return Err(e(format!("`{name}` must be finite and ≥ 0")));
            }
            Ok(s)
        };
        let allowed: &[&str] = match d.kind.as_str() {
            "point" => &["position", "intensity"],
            "spot" => &[
                "position",
                "target",
                "direction",
                "intensity",
                "cutoff_angle",
                "beam_width",
            ],
            "directional" => &["direction", "irradiance"],
            "environment" => &["file", "sky", "scale", "transform"],
            "constant" => &["radiance"],
            other => {
                return Err(e(format!("unknown light type `{other}`; valid: point, spot, directional, environment, constant")));
            }
        };
        for (key, present) in [
            ("position", d.position.is_some()),
            ("target", d.target.is_some()),
            ("direction", d.direction.is_some()),
            ("intensity", d.intensity.is_some()),
            ("irradiance", d.irradiance.is_some()),
            ("radiance", d.radiance.is_some()),
            ("cutoff_angle", d.cutoff_angle.is_some()),
            ("beam_width", d.beam_width.is_some()),
            ("file", d.file.is_some()),
            ("sky", d.sky.is_some()),
            ("scale", d.scale.is_some()),
            ("transform", !d.transform.is_empty()),
        ] {
            if present && !allowed.contains(&key) {
                return Err(e(format!(
                    "`{key}` does not apply; valid keys: {}",
                    allowed.join(", ")
                )));
            }
        }
        let light = match d.kind.as_str() {
            "point" => Light::Point {
                position: finite3(
                    ctx,
                    &span,
                    "position",
                    d.position.ok_or_else(|| e("needs `position`".into()))?,
                )?,
                intensity: check_color("intensity", d.intensity)?,
            },
            "spot" => {
                let position = finite3(
                    ctx,
                    &span,
                    "position",
                    d.position.ok_or_else(|| e("needs `position`".into()))?,
                )?;
                let dir = match (d.target, d.direction) {
                    (Some(t), None) => vec3(t) - position,
                    (None, Some(dd)) => vec3(dd),
                    (None, None) => return Err(e("needs `target` or `direction`".into())),
                    _ => return Err(e("give `target` or `direction`, not both".into())),
                };
                if !(dir.length() > 0.0) || !dir.is_finite() {
                    return Err(e("the spot direction must be a non-zero vector".into()));
                }
                let cutoff = d.cutoff_angle.unwrap_or(20.0);
                let beam = d.beam_width.unwrap_or(0.75 * cutoff);
                if !(cutoff > 0.0 && cutoff <= 90.0 && beam >= 0.0 && beam <= cutoff) {
                    return Err(e(format!("need 0 < cutoff_angle ≤ 90 and 0 ≤ beam_width ≤ cutoff_angle (degrees), got {cutoff} and {beam}")));
                }
                Light::Spot {
                    position,
                    frame: facette_bsdf::math::Frame::from_normal(dir.normalize()),
                    intensity: check_color("intensity", d.intensity)?,
                    cutoff: cutoff.to_radians(),
                    beam: beam.to_radians(),
                }
            }
            "directional" => {
                let dir = finite3(
                    ctx,
                    &span,
                    "direction",
                    d.direction.ok_or_else(|| e("needs `direction`".into()))?,
                )?;
                if !(dir.length() > 0.0) {
                    return Err(e("`direction` must be non-zero".into()));
                }
                Light::Directional {
                    direction: dir.normalize(),
                    irradiance: check_color("irradiance", d.irradiance)?,
                }
            }
            "constant" => Light::Environment(Environment::Constant(
                ConstantEnvironment::new(check_color("radiance", d.radiance)?)
                    .map_err(|x| e(x.to_string()))?,
            )),
            _ => {
                // With both `file` and `sky`, the file is the sky's cache (written on first use).
                let image = match (&d.file, &d.sky) {
                    (Some(f), None) => read_image(ctx.base_dir.join(f), ColorEncoding::Srgb)
                        .map_err(|x| e(x.to_string()))?,
                    (None, Some(sky)) => {
                        generate_sky(&parse_sky(sky).map_err(e)?).map_err(|x| e(x.to_string()))?
                    }
                    (Some(f), Some(sky)) => {
                        load_or_generate_sky(ctx.base_dir.join(f), &parse_sky(sky).map_err(e)?)
                            .map_err(|x| e(x.to_string()))?
                    }
                    (None, None) => {
                        return Err(e(
                            "needs `file` (an EXR/HDR/PNG lat-long image) or `sky = { … }`".into(),
                        ))
                    }
                };
                let scale = d.scale.unwrap_or(1.0);
                if !(scale >= 0.0 && scale.is_finite()) {
                    return Err(e("`scale` must be finite and ≥ 0".into()));
                }
                let t = parse_transform(&d.transform).map_err(e)?;
                let m = t.matrix();
                let rot = DMat3::from_cols(
                    m.x_axis.truncate(),
                    m.y_axis.truncate(),
                    m.z_axis.truncate(),
                );
                Light::Environment(Environment::Map(Box::new(
                    EnvironmentMap::new(image, rot, scale).map_err(|x| e(x.to_string()))?,
                )))
            }
        };
        if matches!(light, Light::Environment(_)) {
            if environment.is_some() {
                return Err(e(
                    "the scene already has an environment (one `environment` or `constant` light)"
                        .into(),
                ));
            }
            environment = Some(lights.len() as u32);
        }
        lights.push(light);
    }
    let b = geometry.bounds();
    let radius = if b.is_empty() {
        1.0
    } else {
        0.5 * b.extent().length().max(1e-3)
    };
    let powers: Vec<f64> = lights.iter().map(|l| l.power(&geometry, radius)).collect();
    let infinite: Vec<bool> = lights.iter().map(Light::is_infinite).collect();
    let selector = LightSelector::new(&powers, &infinite);
    Ok(Scene {
        geometry,
        shape_material,
        shape_light,
        materials,
        lights,
        selector,
        environment,
        camera,
        film,
        integrator,
        source_hash,
        warnings: Vec::new(),
    })
}

/// Procedural sky keys: `zenith`, `horizon`, `ground` (colours), `sun_direction` (toward
/// the sun), `sun_angular_radius` (degrees), `sun_radiance` (colour), `sun_softness`,
/// `gradient_exponent`, `width`, `height`.
fn parse_sky(t: &toml::Table) -> Result<SkyParams, String> {
    let mut p = SkyParams::default();
    let col = |v: &toml::Value, k: &str| -> Result<Spectrum, String> {
        match v {
            toml::Value::Array(_) => triple(v).map(|t| Spectrum::rgb(t.x, t.y, t.z)),
            _ => number(v).map(Spectrum::splat),
        }
        .ok_or(format!("sky `{k}` must be a number or [r, g, b]"))
    };
    for (k, v) in t {
        match k.as_str() {
            "zenith" => p.zenith = col(v, k)?,
            "horizon" => p.horizon = col(v, k)?,
            "ground" => p.ground = col(v, k)?,
            "sun_radiance" => p.sun_radiance = col(v, k)?,
            "sun_direction" => p.sun_direction = triple(v).ok_or("sky `sun_direction` must be [x, y, z]")?,
            "sun_angular_radius" => p.sun_angular_radius = number(v).ok_or("sky `sun_angular_radius` must be a number (degrees)")?.to_radians(),
            "sun_softness" => p.sun_softness = number(v).ok_or("sky `sun_softness` must be a number")?,
            "gradient_exponent" => p.gradient_exponent = number(v).ok_or("sky `gradient_exponent` must be a number")?,
            "width" => p.width = number(v).ok_or("sky `width` must be an integer")? as usize,
            "height" => p.height = number(v).ok_or("sky `height` must be an integer")? as usize,
            other => {
                return Err(format!(
                    "unknown sky key `{other}`; valid: zenith, horizon, ground, sun_direction, sun_angular_radius, sun_radiance, sun_softness, gradient_exponent, width, height"
                ))
            }
        }
    }
    p.validate().map_err(|e| e.to_string())?;
    Ok(p)
}

/// FNV-1a, 64-bit.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}
