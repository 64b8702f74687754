//! `facette merge`: combines the parts of a distributed job — partial renders (`.fcpart`,
//! from `facette render --part K/N`) into an EXR/PNG image, or partial IL tables
//! (`.fctpart`, from `facette tabulate --part K/N`) into a table. The merge is exact: the
//! result is bit for bit that of the same parts computed in one process.

use anyhow::{bail, Context, Result};
use clap::Args;
use facette_render::partial_film::{merge_parts, PartialFilm};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct MergeArgs {
    /// The parts (all N of one job, in any order).
    #[arg(required = true, value_name = "PART")]
    parts: Vec<PathBuf>,
    /// Output: `.exr`/`.png` for render parts, `.fctab` for table parts.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Exposure in stops for the image (default: the scene's, recorded in the parts).
    #[arg(long)]
    exposure: Option<f64>,
}

pub fn run(a: MergeArgs) -> Result<ExitCode> {
    let is_table = |p: &PathBuf| p.extension().is_some_and(|e| e == "fctpart");
    if a.parts.iter().all(is_table) {
        return crate::cmd_tabulate::merge(&a.parts, &a.output);
    }
    if a.parts.iter().any(is_table) {
        bail!("cannot mix table parts (.fctpart) and render parts (.fcpart)");
    }
    crate::cmd_render::check_output(&a.output, false)?;
    let parts: Vec<PartialFilm> = a
        .parts
        .iter()
        .map(|p| PartialFilm::load(p))
        .collect::<Result<_, _>>()?;
    let film = merge_parts(&parts)?;
    let exposure = a.exposure.unwrap_or(parts[0].exposure);
    if !exposure.is_finite() {
        bail!("--exposure must be finite");
    }
    facette_render::image::write_image(&a.output, &film.image(), exposure)
        .with_context(|| format!("writing {}", a.output.display()))?;
    eprintln!(
        "{}: merged {} parts ({}×{}, {} samples, {} discarded)",
        a.output.display(),
        parts.len(),
        film.width,
        film.height,
        film.total_samples(),
        film.discarded
    );
    Ok(ExitCode::SUCCESS)
}
