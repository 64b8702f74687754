//! Scene materials: a validated [`MaterialRecipe`] and the textures that drive some of its
//! parameters. Untextured materials are built once and shared. A textured material with a
//! lane model gives the packet kernel its texture values per shading point
//! ([`SceneMaterial::lane_texel`]: colors, or the lane model with a textured roughness; no
//! allocation). Otherwise (and in the scalar kernel) it is rebuilt per shading point from
//! the recipe with the textured values substituted (the recipes share their precomputed
//! tables).
//!
//! In a material table any texturable parameter may be a texture instead of a number:
//!
//! ```toml
//! reflectance = { texture = "checker", a = [0.1, 0.1, 0.1], b = 0.9, scale = 8 }
//! kd = { image = "wood.png", uv_scale = [2, 2], wrap = "repeat" }
//! alpha = { image = "roughness.exr", encoding = "linear" }
//! ```
//!
//! Colour images are decoded from sRGB by default; roughness images are read linearly by
//! default (`encoding` overrides). A roughness texture's value is its channel average.

use crate::image::{read_image, ColorEncoding, ImageNormalMapReader, MipMap, Texture, WrapMode};
use facette_bsdf::models::{LaneBsdf, LaneColorParam, LaneColors};
use facette_bsdf::recipe::MaterialRecipe;
use facette_bsdf::{Bsdf, Spectrum};
use glam::DVec2;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// One textured parameter.
#[derive(Clone, Debug)]
struct TexturedParam {
    key: &'static str,
    spectrum: bool,
    texture: Texture,
    /// The range of values the texture takes, validated at load time (a roughness texture's
    /// value is held to it).
    range: (f64, f64),
    /// What the texture drives in the material's lane model, where it has one.
    lane: Option<LaneTarget>,
}

impl TexturedParam {
    /// A colour texture's value at a shading point, held to [0, 1].
    #[inline]
    fn spectrum_at(&self, uv: DVec2, derivs: [f64; 4]) -> Spectrum {
        self.texture.eval(uv, derivs).map(|x| x.clamp(0.0, 1.0))
    }
}

/// A texture's parameter in a lane model.
#[derive(Clone, Copy, Debug)]
enum LaneTarget {
    Color(LaneColorParam),
    /// The roughness key of the parameter.
    Roughness,
}

/// A textured lane material at one shading point.
#[derive(Clone, Debug)]
pub enum LaneTexel {
    /// Textured colors only: the material's lane model with these spectral parameters.
    Colors(LaneColors<f64>),
    /// A textured roughness: the lane model built for this point (colors included).
    Model(LaneBsdf),
}

/// A material of the scene.
#[derive(Clone)]
pub struct SceneMaterial {
    pub name: String,
    recipe: MaterialRecipe,
    fixed: Option<Arc<dyn Bsdf>>,
    /// The lane model of a material that vectorizes (the packet kernel's); a textured
    /// material's holds its untextured parameters, [`lane_texel`](Self::lane_texel) the
    /// textured ones.
    lane: Option<LaneBsdf>,
    textures: Vec<TexturedParam>,
    /// Shading points whose material could not be built from their texture values (their
    /// paths end there); shared by the material's clones, reported after a render.
    failures: Arc<AtomicU64>,
}

impl std::fmt::Debug for SceneMaterial {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneMaterial")
            .field("name", &self.name)
            .field("recipe", &self.recipe)
            .field("textures", &self.textures)
            .finish()
    }
}

impl SceneMaterial {
    /// Parses a material table (with textured parameters) whose relative paths are
    /// resolved against `base_dir`. Errors are plain messages; the scene loader adds the
    /// file and line.
    pub fn parse(
        name: &str,
        table: &toml::Table,
        base_dir: &Path,
    ) -> Result<SceneMaterial, String> {
        let mut plain = table.clone();
        let mut pending: Vec<(String, Texture, (f64, f64))> = Vec::new();
        for (key, value) in table {
            if let toml::Value::Table(t) = value {
                if t.contains_key("texture") || t.contains_key("image") {
                    let (texture, range) = parse_texture(key, t, base_dir)?;
                    // Validate the recipe with the texture's mean in place of the value.
                    let avg = texture.average();
                    plain.insert(
                        key.clone(),
                        toml::Value::Array(avg.0.iter().map(|v| toml::Value::Float(*v)).collect()),
                    );
                    pending.push((key.clone(), texture, range));
                }
            }
        }
        // Scalars were replaced by triples above; turn roughness keys back into numbers.
        let mut recipe = MaterialRecipe::parse_with_reader(
            &scalarize(&plain, &pending),
            base_dir,
            Some(&ImageNormalMapReader),
        )
        .map_err(|e| e.to_string())?;
        let mut textures = Vec::new();
        for (key, texture, (lo, hi)) in pending {
            let spectrum_keys = recipe.texturable_spectrum_keys();
            let scalar_keys = recipe.texturable_scalar_keys();
            if let Some(k) = spectrum_keys.iter().find(|k| **k == key) {
                // The texture's extremes must be valid values.
                recipe
                    .set_spectrum(k, Spectrum::splat(lo))
                    .map_err(|e| format!("texture of `{key}`: {e}"))?;
                recipe
                    .set_spectrum(k, Spectrum::splat(hi))
                    .map_err(|e| format!("texture of `{key}`: {e}"))?;
                textures.push(TexturedParam {
                    key: k,
                    spectrum: true,
                    texture,
                    range: (lo, hi),
                    lane: None,
                });
            } else if let Some(k) = scalar_keys.iter().find(|k| **k == key) {
                recipe
                    .set_scalar(k, lo)
                    .map_err(|e| format!("texture of `{key}`: {e}"))?;
                recipe
                    .set_scalar(k, hi)
                    .map_err(|e| format!("texture of `{key}`: {e}"))?;
                textures.push(TexturedParam {
                    key: k,
                    spectrum: false,
                    texture,
                    range: (lo, hi),
                    lane: None,
                });
            } else {
                let mut valid: Vec<&str> = spectrum_keys.to_vec();
                valid.extend_from_slice(scalar_keys);
                return Err(format!(
                    "`{key}` cannot be textured for this material; texturable keys: {}",
                    if valid.is_empty() {
                        "none".into()
                    } else {
                        valid.join(", ")
                    }
                ));
            }
        }
        // Glints depend on each hit's footprint: built per shading point. Build one now
        // anyway so that a material that cannot be built fails at load time.
        let built = recipe.build().map_err(|e| e.to_string())?;
        let fixed = (textures.is_empty() && !recipe.varies_per_hit()).then_some(built);
        let mut lane = (!recipe.varies_per_hit())
            .then(|| recipe.lane_model())
            .flatten();
        if let Some(model) = &lane {
            // Every texture must map onto the lane model, its extremes valid there too;
            // otherwise the material renders through its f64 model.
            for t in &mut textures {
                t.lane = if t.spectrum {
                    model.color_param(t.key).map(LaneTarget::Color)
                } else {
                    let (lo, hi) = t.range;
                    (model.with_roughness(t.key, lo).is_ok()
                        && model.with_roughness(t.key, hi).is_ok())
                    .then_some(LaneTarget::Roughness)
                };
            }
            if textures.iter().any(|t| t.lane.is_none()) {
                lane = None;
            }
        }
        Ok(SceneMaterial {
            name: name.to_string(),
            recipe,
            fixed,
            lane,
            textures,
            failures: Arc::default(),
        })
    }

    /// A material from an already built BSDF (tests, programmatic scenes).
    pub fn from_recipe(name: &str, recipe: MaterialRecipe) -> Result<SceneMaterial, String> {
        let built = recipe.build().map_err(|e| e.to_string())?;
        let fixed = (!recipe.varies_per_hit()).then_some(built);
        let lane = fixed.as_ref().and_then(|_| recipe.lane_model());
        Ok(SceneMaterial {
            name: name.into(),
            recipe,
            fixed,
            lane,
            textures: Vec::new(),
            failures: Arc::default(),
        })
    }

    /// Why this material is far slower to render than expected, if it is (see
    /// `MaterialRecipe::render_cost_warning`).
    pub fn render_cost_warning(&self) -> Option<&'static str> {
        self.recipe.render_cost_warning()
    }

    /// The material's lane model, where it has one (see `facette_bsdf::lanes`); a textured
    /// material's takes its textured values from [`lane_texel`](Self::lane_texel).
    #[inline]
    pub fn lane_bsdf(&self) -> Option<&LaneBsdf> {
        self.lane.as_ref()
    }

    /// A textured lane material's parameters at a shading point with texture coordinates
    /// `uv` and footprint `derivs` (as [`bsdf`](Self::bsdf) reads them): its textured
    /// colors, or its lane model built with a textured roughness. `None` for a material
    /// without a lane model, or where a texture's value is not a valid parameter (which the
    /// load-time checks of the textures' ranges rule out; such a point would be counted,
    /// see [`failed_shading_points`](Self::failed_shading_points)).
    pub fn lane_texel(&self, uv: DVec2, derivs: [f64; 4]) -> Option<LaneTexel> {
        let model = self.lane.as_ref()?;
        let mut colors = model.colors();
        let mut rough: Option<LaneBsdf> = None;
        for t in &self.textures {
            match t.lane? {
                LaneTarget::Color(param) => {
                    let v = t.spectrum_at(uv, derivs);
                    if !v.0.iter().all(|x| x.is_finite()) {
                        return self.failed();
                    }
                    param.set(&mut colors, v);
                }
                LaneTarget::Roughness => {
                    // Held to the range validated at load time (filtering stays inside it
                    // but for rounding).
                    // (A NaN stays NaN, which `with_roughness` refuses.)
                    let (lo, hi) = t.range;
                    let v = t.texture.eval_scalar(uv, derivs).clamp(lo, hi);
                    let base = rough.as_ref().unwrap_or(model);
                    match base.with_roughness(t.key, v) {
                        Ok(m) => rough = Some(m),
                        Err(_) => return self.failed(),
                    }
                }
            }
        }
        Some(match rough {
            Some(m) => LaneTexel::Model(m.with_colors(&colors)),
            None => LaneTexel::Colors(colors),
        })
    }

    /// Counts a shading point whose material could not be built.
    #[cold]
    fn failed<T>(&self) -> Option<T> {
        self.failures.fetch_add(1, Ordering::Relaxed);
        None
    }

    /// How many shading points so far could not be built from their texture values (their
    /// paths ended there); the renderer reports them after a render.
    pub fn failed_shading_points(&self) -> u64 {
        self.failures.load(Ordering::Relaxed)
    }

    pub fn is_textured(&self) -> bool {
        !self.textures.is_empty()
    }

    /// Whether [`bsdf`](Self::bsdf) reads its `uv` and `derivs` arguments (textures,
    /// glints): only then does the integrator compute them at a hit.
    #[inline]
    pub fn reads_surface_details(&self) -> bool {
        self.fixed.is_none()
    }

    /// Whether a camera ray's first hit on this material shades with the pixel's footprint
    /// ([`crate::pixel_footprint`]: glints with `footprint = "pixel"`).
    #[inline]
    pub fn reads_pixel_footprint(&self) -> bool {
        self.recipe.reads_pixel_footprint()
    }

    /// The BSDF at a shading point with texture coordinates `uv` and footprint `derivs`
    /// (`[du/dx, dv/dx, du/dy, dv/dy]`, zeros when unknown): the shared one for an
    /// untextured material (borrowed: no reference-count traffic between threads), a
    /// freshly built one otherwise. Glints [CCM19] take their ray footprint from `uv` and
    /// `derivs` here.
    #[inline]
    pub fn bsdf(&self, uv: DVec2, derivs: [f64; 4]) -> Option<MaterialBsdf<'_>> {
        if let Some(f) = &self.fixed {
            return Some(MaterialBsdf::Shared(f.as_ref()));
        }
        if self.textures.is_empty() {
            return match self.recipe.build_at(uv, derivs) {
                Ok(b) => Some(MaterialBsdf::Textured(b)),
                Err(_) => self.failed(),
            };
        }
        let mut r = self.recipe.clone();
        for t in &self.textures {
            let ok = if t.spectrum {
                r.set_spectrum(t.key, t.spectrum_at(uv, derivs)).is_ok()
            } else {
                r.set_scalar(t.key, t.texture.eval_scalar(uv, derivs))
                    .is_ok()
            };
            if !ok {
                return self.failed();
            }
        }
        match r.build_at(uv, derivs) {
            Ok(b) => Some(MaterialBsdf::Textured(b)),
            Err(_) => self.failed(),
        }
    }
}

/// The BSDF of a shading point: shared by the material, or built for this point.
pub enum MaterialBsdf<'a> {
    Shared(&'a (dyn Bsdf + 'static)),
    Textured(Arc<dyn Bsdf>),
}

impl std::ops::Deref for MaterialBsdf<'_> {
    type Target = dyn Bsdf;

    #[inline]
    fn deref(&self) -> &(dyn Bsdf + 'static) {
        match self {
            MaterialBsdf::Shared(b) => *b,
            MaterialBsdf::Textured(b) => b.as_ref(),
        }
    }
}

/// Replaces textured roughness keys (given as triples for validation) by their channel
/// average.
fn scalarize(table: &toml::Table, pending: &[(String, Texture, (f64, f64))]) -> toml::Table {
    let mut t = table.clone();
    for (key, tex, _) in pending {
        if matches!(
            key.as_str(),
            "alpha" | "alpha_u" | "alpha_v" | "sigma" | "exponent"
        ) {
            t.insert(key.clone(), toml::Value::Float(tex.average().average()));
        }
    }
    t
}

fn spectrum_value(key: &str, v: &toml::Value) -> Result<Spectrum, String> {
    match v {
        toml::Value::Float(f) => Ok(Spectrum::splat(*f)),
        toml::Value::Integer(i) => Ok(Spectrum::splat(*i as f64)),
        toml::Value::Array(a) if a.len() == 3 => {
            let mut s = Spectrum::ZERO;
            for (k, x) in a.iter().enumerate() {
                s[k] = match x {
                    toml::Value::Float(f) => *f,
                    toml::Value::Integer(i) => *i as f64,
                    _ => return Err(format!("`{key}` must be a number or [r, g, b]")),
                };
            }
            Ok(s)
        }
        _ => Err(format!("`{key}` must be a number or [r, g, b]")),
    }
}

fn pair(key: &str, v: Option<&toml::Value>, default: DVec2) -> Result<DVec2, String> {
    match v {
        None => Ok(default),
        Some(toml::Value::Array(a)) if a.len() == 2 => {
            let f = |x: &toml::Value| match x {
                toml::Value::Float(f) => Ok(*f),
                toml::Value::Integer(i) => Ok(*i as f64),
                _ => Err(format!("`{key}` must be two numbers")),
            };
            Ok(DVec2::new(f(&a[0])?, f(&a[1])?))
        }
        Some(toml::Value::Float(f)) => Ok(DVec2::splat(*f)),
        Some(toml::Value::Integer(i)) => Ok(DVec2::splat(*i as f64)),
        _ => Err(format!("`{key}` must be a number or two numbers")),
    }
}

/// Parses a texture table; returns it with the smallest and largest channel value it can
/// produce.
fn parse_texture(
    param: &str,
    t: &toml::Table,
    base_dir: &Path,
) -> Result<(Texture, (f64, f64)), String> {
    let scalar_param = matches!(
        param,
        "alpha" | "alpha_u" | "alpha_v" | "sigma" | "exponent"
    );
    if let Some(image) = t.get("image") {
        let valid = ["image", "uv_scale", "uv_offset", "wrap", "encoding"];
        if let Some(k) = t.keys().find(|k| !valid.contains(&k.as_str())) {
            return Err(format!(
                "unknown key `{k}` in the image texture of `{param}`; valid keys: {}",
                valid.join(", ")
            ));
        }
        let path = image
            .as_str()
            .ok_or_else(|| format!("`{param}`: `image` must be a file path"))?;
        let encoding = match t.get("encoding").and_then(|v| v.as_str()) {
            None => {
                if scalar_param {
                    ColorEncoding::Linear
                } else {
                    ColorEncoding::Srgb
                }
            }
            Some("srgb") => ColorEncoding::Srgb,
            Some("linear") => ColorEncoding::Linear,
            Some(o) => {
                return Err(format!(
                    "`{param}`: unknown encoding `{o}`; valid values: srgb, linear"
                ))
            }
        };
        let wrap = match t.get("wrap").and_then(|v| v.as_str()) {
            None => WrapMode::Repeat,
            Some(w) => WrapMode::parse(w).map_err(|e| format!("`{param}`: {e}"))?,
        };
        let img = read_image(base_dir.join(path), encoding).map_err(|e| e.to_string())?;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for px in img.data() {
            for &c in px {
                lo = lo.min(c as f64);
                hi = hi.max(c as f64);
            }
        }
        let tex = Texture::Image {
            mipmap: Arc::new(MipMap::new(img, wrap)),
            uv_scale: pair("uv_scale", t.get("uv_scale"), DVec2::ONE)?,
            uv_offset: pair("uv_offset", t.get("uv_offset"), DVec2::ZERO)?,
        };
        return Ok((tex, (lo, hi)));
    }
    match t.get("texture").and_then(|v| v.as_str()) {
        Some("checker") => {
            let valid = ["texture", "a", "b", "scale"];
            if let Some(k) = t.keys().find(|k| !valid.contains(&k.as_str())) {
                return Err(format!(
                    "unknown key `{k}` in the checker texture of `{param}`; valid keys: {}",
                    valid.join(", ")
                ));
            }
            let a = spectrum_value("a", t.get("a").unwrap_or(&toml::Value::Float(0.2)))?;
            let b = spectrum_value("b", t.get("b").unwrap_or(&toml::Value::Float(0.8)))?;
            let scale = match t.get("scale") {
                None => 8.0,
                Some(toml::Value::Float(f)) => *f,
                Some(toml::Value::Integer(i)) => *i as f64,
                _ => return Err("`scale` must be a number".into()),
            };
            let lo = a.min_component().min(b.min_component());
            let hi = a.max_component().max(b.max_component());
            Ok((
                Texture::checker(a, b, scale).map_err(|e| e.to_string())?,
                (lo, hi),
            ))
        }
        Some(other) => Err(format!(
            "unknown texture `{other}` for `{param}`; valid: checker (or give `image = \"file\"`)"
        )),
        None => Err(format!(
            "`{param}`: a texture table needs `texture = \"checker\"` or `image = \"file\"`"
        )),
    }
}
