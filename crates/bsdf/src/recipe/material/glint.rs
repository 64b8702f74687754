//! The `glint` material  [CCM19]: parsing, the recipe the renderer keeps, and the footprint
//! of a shading point.
//!
//! ```toml
//! { type = "glint", generate = "scratched", resolution = 1024, seed = 3, uv_scale = 4,
//!   material = "Al", masking = "approx" }
//! { type = "glint", normal_map = "maps/brushed.png", roughness_floor = 0.01 }
//! ```
//!
//! | key | meaning | range | default |
//! |---|---|---|---|
//! | `normal_map` | tangent-space normal map file (PNG 8/16-bit, EXR), relative to the scene | — | — |
//! | `normal_encoding` | `unsigned` (n = 2c − 1) or `signed` (n = c) | — | `unsigned` for PNG, `signed` for EXR/HDR |
//! | `generate` | procedural map instead of a file: `scratched`, `brushed`, `bumpy`, `flakes` | — | — |
//! | `resolution`, `seed` | size (texels per side) and seed of the generated map | 1–4096; any | 512, 1 |
//! | `uv_scale` | map repetitions per unit of uv (number or [u, v]) | > 0 | 1 |
//! | `roughness_floor` | σ_ε, slope standard deviation added to every lobe | (0, 1] | 0.01 |
//! | `seed_subdivision` | n, seeds of the lobe mixture per texel side (seed spacing h = 1/n texels): 1 is the paper's one lobe per texel; n puts n² lobes in a texel, nearer the map's own slopes where they change within a texel (scratches), at n² times the memory and a query's work (docs/glints.md) | 1–4 | 2 (1 for maps above 2048²) |
//! | `masking` | `exact` (eqs. 10–17) or `approx` (§4.2.2, per mip block: ERRATA 18) | — | `exact` |
//! | `evaluation` | `patch` (the P-BRDF of the footprint) or `reference` (brute force: the map at the shading point's uv as a σ_ε surface, no footprint; converges with samples per pixel) | — | `patch` |
//! | `masking_lobes` | budget of the exact masking sum (0: unlimited) | ≥ 0 | 1024 |
//! | `mis_pdf` | the density reported for multiple importance sampling: `exact` (the sampler's own: one P-NDF query per sampled direction, skipped where the renderer does not weight by MIS — delta lights only) or `filtered` (the footprint's filtered lobe with a 5 % cosine share: no query; unbiased, faster, noisier where BSDF sampling should carry the glints — docs/glints.md) | — | `exact` |
//! | `footprint` | at a camera ray's hit, `ray` (the sample's own ray-differential footprint, scaled by 1/√spp) or `pixel` (the footprint of the whole pixel under the reconstruction filter, in the shading frame of the pixel's centre: every sample of a pixel shades the same patch, so the glints are converged at a few samples per pixel, at 2.8× the cost of a sample; docs/glints.md) | — | `ray` |
//! | `footprint_center` | footprint centre in uv when none is given by a renderer | any | [0.5, 0.5] |
//! | `footprint_size` | footprint standard deviation in texels: σ, [σ_u, σ_v] or [σ_u, σ_v, ρ] | σ ≥ 0, ρ ∈ (−1, 1) | 2 |
//! | `material`, `eta`, `k`, `fresnel` | conductor Fresnel term, as for `conductor` | | F = 1 |
//! | `specular_reflectance` | multiplier (number or RGB) | [0, 1] | 1 |
//!
//! **Image files.** This crate does not decode images (it must not depend on the renderer):
//! [`MaterialRecipe::parse_with_reader`](super::MaterialRecipe::parse_with_reader) takes a
//! [`NormalMapReader`], which the renderer and the CLI implement with their image readers.
//! Without one, `normal_map` is an error that says so; `generate` always works.
//!
//! **Footprints.** A renderer passes the shading point's uv and screen-space derivatives
//! ([`GlintRecipe::footprint_at`]): the footprint is the Gaussian of covariance
//! s²(d_x d_xᵀ + d_y d_yᵀ) with d_x, d_y the texel offsets of one pixel step and
//! s = [`PIXEL_FOOTPRINT_SIGMA`]. With `footprint = "ray"` (the default) they are the
//! sample's own uv and its differentials scaled by 1/√spp; with `"pixel"` the renderer
//! passes, at a camera ray's first hit, the uv and the unscaled derivatives of the pixel's
//! centre, scaled so that s d matches the reconstruction filter's standard deviation, and
//! shades in the frame of the centre's hit (`facette_render::pixel_footprint`). Without derivatives
//! (secondary hits, `facette eval`) it uses `footprint_size` around the given uv (or
//! `footprint_center`).

use crate::bsdf::Bsdf;
use crate::checks::{check_range, check_reflectance, Bounds};
use crate::error::{ParamError, ParamResult};
use crate::math::spectrum::Spectrum;
use crate::math::Vec2;
use crate::models::glint::generate::{generate, NormalMapKind};
use crate::models::glint::microsurface::DEFAULT_ROUGHNESS_FLOOR;
use crate::models::glint::patch_masking::{MaskingMode, DEFAULT_MASKING_LOBES};
use crate::models::glint::{
    Footprint, GlintBsdf, GlintParams, GlintSurface, MisPdf, NormalEncoding, NormalMap,
    PointReferenceBsdf,
};
use crate::recipe::params::Params;
use crate::two_sided::TwoSided;
use std::path::Path;
use std::sync::Arc;

/// The keys of `type = "glint"` besides `type`.
pub const GLINT_KEYS: &[&str] = &[
    "normal_map",
    "normal_encoding",
    "generate",
    "resolution",
    "seed",
    "uv_scale",
    "roughness_floor",
    "seed_subdivision",
    "masking",
    "masking_lobes",
    "mis_pdf",
    "evaluation",
    "footprint",
    "footprint_center",
    "footprint_size",
    "material",
    "eta",
    "k",
    "fresnel",
    "specular_reflectance",
];

/// Standard deviation of the pixel footprint in units of the ray-differential
/// offsets: the Gaussian spans about one differential step (±2σ).
pub const PIXEL_FOOTPRINT_SIGMA: f64 = 0.5;

/// Default `footprint_size` (texels).
pub const DEFAULT_FOOTPRINT_TEXELS: f64 = 2.0;

/// A decoded image: linear RGB pixels, row-major, top row first.
#[derive(Clone, Debug)]
pub struct DecodedImage {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[f32; 3]>,
    /// True for floating-point files (EXR, HDR): their default encoding is signed.
    pub float: bool,
}

/// Reads image files for materials that reference them (implemented by the renderer).
pub trait NormalMapReader: Sync {
    /// Decodes `path` without any colour transform (8/16-bit codes as code/max).
    fn read(&self, path: &Path) -> Result<DecodedImage, String>;
}

/// A validated glint material: the shared surface and the parameters.
#[derive(Clone, Debug)]
pub struct GlintRecipe {
    pub surface: Arc<GlintSurface>,
    pub params: GlintParams,
    /// Map repetitions per unit of u and v.
    pub uv_scale: [f64; 2],
    /// Footprint used without derivatives: centre (uv) and (σ_u, σ_v, ρ) in texels.
    pub footprint_center: [f64; 2],
    pub footprint_size: [f64; 3],
    /// `evaluation = "reference"`: [`PointReferenceBsdf`] at the shading point instead of
    /// the P-BRDF of its footprint.
    pub reference: bool,
    /// `footprint = "pixel"`: at a camera ray's first hit the renderer passes the pixel's
    /// footprint (module notes).
    pub pixel_footprint: bool,
}

impl GlintRecipe {
    /// The footprint at uv: from the derivatives `[du/dx, dv/dx, du/dy, dv/dy]` when any is
    /// non-zero, else `footprint_size` (module notes).
    pub fn footprint_at(&self, uv: Vec2, derivs: [f64; 4]) -> Footprint {
        let (w, h) = (
            self.surface.width() as f64 * self.uv_scale[0],
            self.surface.height() as f64 * self.uv_scale[1],
        );
        let center = Vec2::new(uv.x * w, uv.y * h);
        if derivs.iter().all(|d| *d == 0.0) || !derivs.iter().all(|d| d.is_finite()) {
            let [su, sv, rho] = self.footprint_size;
            return Footprint::from_sigmas(center, su, sv, rho);
        }
        let dx = Vec2::new(derivs[0] * w, derivs[1] * h);
        let dy = Vec2::new(derivs[2] * w, derivs[3] * h);
        Footprint::from_derivatives(center, dx, dy, PIXEL_FOOTPRINT_SIGMA)
    }

    /// Whether a renderer should pass the pixel's footprint at a camera ray's first hit
    /// (`footprint = "pixel"`, and not the brute-force reference, which has no footprint).
    pub fn reads_pixel_footprint(&self) -> bool {
        self.pixel_footprint && !self.reference
    }

    /// The BSDF at the default footprint.
    pub fn build_default(&self) -> Arc<dyn Bsdf> {
        let c = Vec2::new(self.footprint_center[0], self.footprint_center[1]);
        self.build_at(c, [0.0; 4])
    }

    /// The BSDF of a shading point: the P-BRDF of its footprint, or with `evaluation =
    /// "reference"` the brute-force reference at the footprint's centre.
    pub fn build_at(&self, uv: Vec2, derivs: [f64; 4]) -> Arc<dyn Bsdf> {
        if self.reference {
            let center = self.footprint_at(uv, [0.0; 4]).center;
            return Arc::new(TwoSided::new(PointReferenceBsdf::new(
                self.surface.map(),
                center,
                self.surface.roughness_floor(),
                self.params.fresnel,
                self.params.tint,
            )));
        }
        Arc::new(TwoSided::new(self.bsdf_at(uv, derivs)))
    }

    /// The concrete model of a shading point, for the upper hemisphere (what
    /// [`build_at`](Self::build_at) wraps in [`TwoSided`]).
    pub fn bsdf_at(&self, uv: Vec2, derivs: [f64; 4]) -> GlintBsdf {
        GlintBsdf::new(
            self.surface.clone(),
            self.footprint_at(uv, derivs),
            &self.params,
        )
    }
}

fn pair(p: &Params, key: &str, default: [f64; 2]) -> ParamResult<[f64; 2]> {
    match p.numbers(key)? {
        None => Ok(default),
        Some(v) if v.len() == 1 => Ok([v[0], v[0]]),
        Some(v) if v.len() == 2 => Ok([v[0], v[1]]),
        Some(v) => Err(ParamError::Invalid(format!(
            "`{key}` takes one or two numbers, got {}",
            v.len()
        ))),
    }
}

/// The default seed lattice: n = 2, h = ½ (four lobes a texel), where the P-NDF is 4.5×
/// nearer the interpolated map than at the paper's h = 1 (docs/glints.md), unless that
/// exceeds the [`GLINT_LOBES`](crate::limits::GLINT_LOBES) limit (by default, maps above
/// 2048²): then n = 1.
pub fn default_seed_subdivision(texels: usize) -> usize {
    if (texels as u64).saturating_mul(4) <= crate::limits::GLINT_LOBES.max() {
        2
    } else {
        1
    }
}

/// Parses a `type = "glint"` table (the key check against [`GLINT_KEYS`] is done by the
/// caller).
pub fn parse_glint(
    p: &Params,
    base_dir: &Path,
    reader: Option<&dyn NormalMapReader>,
) -> ParamResult<GlintRecipe> {
    let floor = p.f64_or("roughness_floor", DEFAULT_ROUGHNESS_FLOOR)?;
    crate::models::glint::microsurface::check_roughness_floor(floor)?;
    let (map, label) = parse_map(p, base_dir, reader)?;
    let uv_scale = pair(p, "uv_scale", [1.0, 1.0])?;
    for (k, v) in ["uv_scale (u)", "uv_scale (v)"].iter().zip(uv_scale) {
        check_range(k, v, 0.0, 1e6, Bounds::OpenClosed)?;
    }
    let (footprint_center, footprint_size) = parse_footprint(p)?;
    let masking = MaskingMode::parse(p.str("masking")?.unwrap_or("exact"))?;
    let masking_lobes = p.count("masking_lobes")?.unwrap_or(DEFAULT_MASKING_LOBES);
    let mis_pdf = MisPdf::parse(p.str("mis_pdf")?.unwrap_or("exact"))?;
    let reference = match p.str("evaluation")?.unwrap_or("patch") {
        "patch" => false,
        "reference" => true,
        other => {
            return Err(ParamError::UnknownChoice {
                what: "glint evaluation".into(),
                given: other.into(),
                valid: "patch, reference".into(),
            })
        }
    };
    let pixel_footprint = match p.str("footprint")?.unwrap_or("ray") {
        "ray" => false,
        "pixel" => true,
        other => {
            return Err(ParamError::UnknownChoice {
                what: "glint footprint".into(),
                given: other.into(),
                valid: "ray, pixel".into(),
            })
        }
    };
    let fresnel = super::microfacet_models::parse_conductor_fresnel(p)?;
    let tint = check_reflectance(
        "specular_reflectance",
        p.spectrum("specular_reflectance")?.unwrap_or(Spectrum::ONE),
    )?;
    let per_texel = match p.count("seed_subdivision")? {
        Some(n) => crate::models::glint::microsurface::check_seed_subdivision(n)?,
        None => default_seed_subdivision(map.texels()),
    };
    let surface = Arc::new(GlintSurface::build_with_seeds(
        map, floor, per_texel, label,
    )?);
    Ok(GlintRecipe {
        surface,
        params: GlintParams {
            fresnel,
            tint,
            masking,
            masking_lobes,
            mis_pdf,
        },
        uv_scale,
        footprint_center,
        footprint_size,
        reference,
        pixel_footprint,
    })
}

/// The normal map and its label: a file (`normal_map`, read with `reader`) or a procedural
/// map (`generate`, `resolution`, `seed`).
fn parse_map(
    p: &Params,
    base_dir: &Path,
    reader: Option<&dyn NormalMapReader>,
) -> ParamResult<(NormalMap, String)> {
    let file = p.str("normal_map")?;
    let kind = p.str("generate")?;
    let resolution = p.count("resolution")?;
    let seed = p.usize("seed")?;
    let encoding = p
        .str("normal_encoding")?
        .map(NormalEncoding::parse)
        .transpose()?;
    match (file, kind) {
        (Some(_), Some(_)) => Err(ParamError::Invalid(
            "give either `normal_map` (a file) or `generate` (a procedural map), not both".into(),
        )),
        (None, None) => Err(ParamError::MissingKey {
            key: format!(
                "normal_map (a file) or generate (one of: {})",
                NormalMapKind::NAMES.join(", ")
            ),
            context: p.context().into(),
        }),
        (Some(path), None) => {
            if resolution.is_some() || seed.is_some() {
                return Err(ParamError::Invalid(
                    "`resolution` and `seed` apply to `generate`, not to a `normal_map` file"
                        .into(),
                ));
            }
            read_map_file(path, base_dir, reader, encoding)
        }
        (None, Some(k)) => {
            if encoding.is_some() {
                return Err(ParamError::Invalid(
                    "`normal_encoding` applies to a `normal_map` file".into(),
                ));
            }
            let kind = NormalMapKind::parse(k)?;
            let res = resolution.unwrap_or(512);
            let seed = seed.unwrap_or(1) as u64;
            let map = generate(kind, res, seed)?;
            Ok((map, format!("{} {res}² seed {seed}", kind.name())))
        }
    }
}

/// A normal map file, decoded by `reader`; its label is the file name.
fn read_map_file(
    path: &str,
    base_dir: &Path,
    reader: Option<&dyn NormalMapReader>,
    encoding: Option<NormalEncoding>,
) -> ParamResult<(NormalMap, String)> {
    let reader = reader.ok_or_else(|| {
        ParamError::Invalid(format!(
            "normal_map \"{path}\": this entry point cannot read image files (facette-bsdf \
             does not decode images); use the facette CLI or renderer, or `generate`"
        ))
    })?;
    let full = base_dir.join(path);
    let img = reader.read(&full).map_err(ParamError::Invalid)?;
    let enc = encoding.unwrap_or(if img.float {
        NormalEncoding::Signed
    } else {
        NormalEncoding::Unsigned
    });
    let map = NormalMap::from_pixels(
        img.width,
        img.height,
        &img.pixels,
        enc,
        &full.display().to_string(),
    )?;
    let name = Path::new(path)
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| path.to_string());
    Ok((map, name))
}

/// `footprint_center` (uv) and `footprint_size` (σ_u, σ_v, ρ in texels).
fn parse_footprint(p: &Params) -> ParamResult<([f64; 2], [f64; 3])> {
    let footprint_center = pair(p, "footprint_center", [0.5, 0.5])?;
    for v in footprint_center {
        if !v.is_finite() {
            return Err(ParamError::NotFinite {
                name: "footprint_center".into(),
                value: v,
            });
        }
    }
    let footprint_size = match p.numbers("footprint_size")? {
        None => [DEFAULT_FOOTPRINT_TEXELS, DEFAULT_FOOTPRINT_TEXELS, 0.0],
        Some(v) if v.len() == 1 => [v[0], v[0], 0.0],
        Some(v) if v.len() == 2 => [v[0], v[1], 0.0],
        Some(v) if v.len() == 3 => [v[0], v[1], v[2]],
        Some(v) => {
            return Err(ParamError::Invalid(format!(
                "`footprint_size` takes σ, [σ_u, σ_v] or [σ_u, σ_v, ρ] (texels), got {} numbers",
                v.len()
            )))
        }
    };
    check_range(
        "footprint_size (σ_u)",
        footprint_size[0],
        0.0,
        1e9,
        Bounds::Closed,
    )?;
    check_range(
        "footprint_size (σ_v)",
        footprint_size[1],
        0.0,
        1e9,
        Bounds::Closed,
    )?;
    check_range(
        "footprint_size (ρ)",
        footprint_size[2],
        -1.0,
        1.0,
        Bounds::Open,
    )?;
    Ok((footprint_center, footprint_size))
}
