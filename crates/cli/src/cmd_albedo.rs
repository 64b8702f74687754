//! `facette albedo`: directional reflectance and transmittance for light incident at the
//! given angles, with their standard errors, estimated from the material's sampler.

use crate::material_arg::parse_material;
use anyhow::{bail, Result};
use clap::Args;
use facette_bsdf::math::spherical_direction;
use facette_bsdf::validation::bsdf_checks::directional_albedo;
use facette_bsdf::BsdfContext;
use std::process::ExitCode;

#[derive(Args)]
pub struct AlbedoArgs {
    /// The material, a TOML inline table.
    #[arg(long, value_name = "TOML")]
    material: String,
    /// Incidence angles of the light in degrees (above 90: light from below the surface).
    #[arg(long = "theta-i", value_name = "DEG", num_args = 1.., required = true)]
    theta_i: Vec<f64>,
    /// Azimuth of the light in degrees.
    #[arg(long = "phi-i", value_name = "DEG", default_value_t = 0.0)]
    phi_i: f64,
    /// Samples per angle.
    #[arg(long, default_value_t = 1_000_000, value_parser = crate::counts::count::<1, { crate::counts::SAMPLES }>)]
    samples: usize,
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

pub fn run(a: AlbedoArgs) -> Result<ExitCode> {
    let bsdf = parse_material(&a.material)?;
    if a.samples < 100 {
        bail!("--samples must be at least 100");
    }
    if !a.phi_i.is_finite() {
        bail!("--phi-i must be finite");
    }
    // Every angle is checked before the first row is printed.
    for &t in &a.theta_i {
        if !(t.is_finite() && (0.0..=180.0).contains(&t)) || t == 90.0 {
            bail!(
                "--theta-i {}: expected an angle in [0, 180] degrees other than 90",
                facette_bsdf::math::fmt_num(t)
            );
        }
    }
    println!(
        "theta_i,reflectance_r,reflectance_g,reflectance_b,reflectance_se_r,reflectance_se_g,reflectance_se_b,\
transmittance_r,transmittance_g,transmittance_b,transmittance_se_r,transmittance_se_g,transmittance_se_b"
    );
    for &t in &a.theta_i {
        // The light direction plays the role of `wo` in importance mode: the sampler then
        // draws the outgoing direction with weight f(i, o) |cos θ_o| / pdf.
        let wi = spherical_direction(t.to_radians(), a.phi_i.to_radians());
        let (r, rse, tr, tse) = directional_albedo(
            bsdf.as_ref(),
            wi,
            &BsdfContext::IMPORTANCE,
            a.samples,
            a.seed,
        );
        println!(
            "{t},{:.6},{:.6},{:.6},{:.2e},{:.2e},{:.2e},{:.6},{:.6},{:.6},{:.2e},{:.2e},{:.2e}",
            r[0], r[1], r[2], rse[0], rse[1], rse[2], tr[0], tr[1], tr[2], tse[0], tse[1], tse[2]
        );
    }
    Ok(ExitCode::SUCCESS)
}
