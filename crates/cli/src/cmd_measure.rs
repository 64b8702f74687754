//! `facette measure`: a material written as a measured BRDF in the MERL binary format (a
//! virtual gonioreflectometer), for testing fits and for tools that read MERL files.

use crate::material_arg::parse_material;
use anyhow::{bail, Result};
use clap::Args;
use facette_lab::measure::measure_material;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct MeasureArgs {
    /// The material, a TOML inline table. MERL files are isotropic: an anisotropic
    /// material is recorded at the bins' azimuths (half vector at φ_h = 0).
    #[arg(long, value_name = "TOML")]
    material: String,
    /// Relative standard deviation of multiplicative Gaussian noise added to every value.
    #[arg(long, default_value_t = 0.0)]
    noise: f64,
    /// Seed of the noise and of stochastic evaluations.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output MERL file (written atomically).
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
}

pub fn run(a: MeasureArgs) -> Result<ExitCode> {
    let bsdf = parse_material(&a.material)?;
    if !(a.noise.is_finite() && (0.0..=1.0).contains(&a.noise)) {
        bail!(
            "--noise {}: expected a relative deviation in [0, 1]",
            facette_bsdf::math::fmt_num(a.noise)
        );
    }
    crate::outputs::check_writable(&[("-o", &a.output)])?;
    let merl = measure_material(bsdf.as_ref(), a.noise, a.seed);
    merl.save(&a.output)?;
    println!(
        "wrote {} ({} valid bins of {})",
        a.output.display(),
        merl.valid_bins(),
        facette_lab::merl::BINS
    );
    Ok(ExitCode::SUCCESS)
}
