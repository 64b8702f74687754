//! Parsing of `--material` (a TOML inline table) shared by the subcommands. Image files a
//! material names (a glint `normal_map`) are read relative to the working directory.

use anyhow::{bail, Context, Result};
use facette_bsdf::models::glint::GlintBsdf;
use facette_bsdf::recipe::{build_material_with_reader, parse_inline_table, MaterialRecipe};
use facette_bsdf::two_sided::TwoSided;
use facette_bsdf::{Bsdf, Vec2};
use facette_render::image::ImageNormalMapReader;
use std::sync::Arc;

pub fn parse_material(text: &str) -> Result<Arc<dyn Bsdf>> {
    parse_material_at(text, None)
}

/// Parses `--material`, with `--footprint U,V,SIGMA[,SIGMA_V[,RHO]]` (uv centre, standard
/// deviations in texels, correlation) for glints: it sets the material's
/// `footprint_center` and `footprint_size` keys [CCM19 §4.1].
pub fn parse_material_at(text: &str, footprint: Option<&str>) -> Result<Arc<dyn Bsdf>> {
    let table = material_table(text, footprint)?;
    build_material_with_reader(&table, std::path::Path::new("."), &ImageNormalMapReader)
        .context("--material")
}

/// Parses a glint `--material` (with an optional `--footprint`) into the concrete P-BRDF of
/// that footprint (two-sided; its own methods through the adapter); any other material type
/// is an error that says which one it got.
pub fn parse_glint_at(text: &str, footprint: Option<&str>) -> Result<TwoSided<GlintBsdf>> {
    let ty = parse_inline_table(text)
        .context("--material")?
        .get("type")
        .and_then(|t| t.as_str().map(str::to_string));
    if ty.as_deref() != Some("glint") {
        bail!(
            "--material: a patch NDF needs a `type = \"glint\"` material, got {}",
            ty.map_or("no type".to_string(), |t| format!("`type = \"{t}\"`"))
        );
    }
    let table = material_table(text, footprint)?;
    let recipe = MaterialRecipe::parse_with_reader(
        &table,
        std::path::Path::new("."),
        Some(&ImageNormalMapReader),
    )
    .context("--material")?;
    let MaterialRecipe::Glint(g) = recipe else {
        bail!("--material: a patch NDF needs a `type = \"glint\"` material");
    };
    Ok(TwoSided::new(
        g.bsdf_at(Vec2::from(g.footprint_center), [0.0; 4]),
    ))
}

/// The `--material` table with `--footprint` applied as `footprint_center` and
/// `footprint_size`.
fn material_table(text: &str, footprint: Option<&str>) -> Result<toml::Table> {
    let mut table = parse_inline_table(text).context("--material")?;
    if let Some(fp) = footprint {
        let v: Vec<f64> = fp
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .ok()
            .filter(|v: &Vec<f64>| (3..=5).contains(&v.len()) && v.iter().all(|x| x.is_finite()))
            .with_context(|| {
                format!(
                    "--footprint `{fp}`: expected U,V,SIGMA[,SIGMA_V[,RHO]] (uv centre, standard \
                     deviations in texels, correlation in (-1, 1))"
                )
            })?;
        if table.get("type").and_then(|t| t.as_str()) != Some("glint") {
            bail!("--footprint applies to `type = \"glint\"` materials only");
        }
        let arr =
            |xs: &[f64]| toml::Value::Array(xs.iter().map(|x| toml::Value::Float(*x)).collect());
        table.insert("footprint_center".into(), arr(&v[..2]));
        let size = match v.len() {
            3 => vec![v[2]],
            4 => vec![v[2], v[3]],
            _ => vec![v[2], v[3], v[4]],
        };
        table.insert("footprint_size".into(), arr(&size));
    }
    Ok(table)
}
