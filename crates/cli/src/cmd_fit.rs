//! `facette fit`: fits a model to a measured BRDF in the MERL binary format and plots
//! measured against fitted slices at θ_i = 30° and 70° (IL18 Fig. 19).

use anyhow::{Context, Result};
use clap::Args;
use facette_lab::fit::slices::fit_slices;
use facette_lab::fit::FitOptions;
use facette_lab::merl::MerlBrdf;
use facette_lab::plot::{save_figure, Format};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct FitArgs {
    /// A measured BRDF in the MERL binary format.
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// Model to fit: il, plastic or kelemen.
    #[arg(long, default_value = "il")]
    model: String,
    /// Distribution: beckmann, ggx or gaussian for il (σ is reported as the Gaussian-equivalent width, α = √2σ); beckmann or ggx for plastic.
    #[arg(long, default_value = "beckmann")]
    distribution: String,
    /// IL body term while fitting: quadrature (deterministic, --il-samples microfacets) or approx (IL18 §4.2).
    #[arg(long = "il-evaluation", default_value = "quadrature")]
    il_evaluation: String,
    /// Microfacets of the IL quadrature.
    #[arg(long = "il-samples", default_value_t = 128, value_parser = crate::counts::count::<1, { crate::counts::QUADRATURE }>)]
    il_samples: usize,
    /// Error metric: log (ln(1 + f cos θ_i) differences) or cosine ((f̂ − f) cos θ_i).
    #[arg(long, default_value = "log")]
    error: String,
    /// Measured values used by the fit (a fixed random subset of the valid bins).
    #[arg(long, default_value_t = 4000, value_parser = crate::counts::count::<1, { crate::counts::QUADRATURE }>)]
    samples: usize,
    /// Ignore bins with θ_i or θ_o above this angle (degrees).
    #[arg(long = "max-theta", default_value_t = 80.0)]
    max_theta: f64,
    /// Seed of the sample selection.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Figure of measured vs fitted slices at θ_i = 30° and 70° (.svg or .png).
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
}

pub fn run(a: FitArgs) -> Result<ExitCode> {
    if let Some(o) = &a.output {
        Format::of(o)?;
        crate::outputs::check_writable(&[("-o", o)])?;
    }
    let options = FitOptions {
        model: a.model.clone(),
        distribution: a.distribution.clone(),
        il_evaluation: a.il_evaluation.clone(),
        il_samples: a.il_samples,
        error: a.error.clone(),
        samples: a.samples,
        max_theta_deg: a.max_theta,
        seed: a.seed,
    };
    // Names and ranges are checked before the file is read.
    options.check()?;
    options.metric()?;
    options.family()?;
    let merl = MerlBrdf::load(&a.file)?;
    let fitted = options.fit(&merl).context("fit")?;
    let r = &fitted.report;
    println!(
        "{}: {} valid bins of {}, fitted {} values with θ ≤ {}°",
        a.file.display(),
        fitted.valid_bins,
        facette_lab::merl::BINS,
        fitted.used_samples,
        a.max_theta
    );
    println!("model: {}", r.family);
    println!("error metric: {}", r.metric.name());
    for (p, v) in r.parameters.iter().zip(&r.values) {
        println!(
            "{} = {v:.6}{}",
            p.name,
            if p.unit.is_empty() {
                String::new()
            } else {
                format!(" {}", p.unit)
            }
        );
    }
    if let Some(s) = r.value("sigma") {
        if a.distribution != "gaussian" {
            println!("alpha = {:.6} (= √2 σ)", std::f64::consts::SQRT_2 * s);
        }
    }
    println!("rms residual = {:.6e}", r.rms_residual);
    println!("rms relative error = {:.4}", r.rms_relative_error);
    println!(
        "{} Levenberg–Marquardt steps in {:.2} s ({})",
        r.evaluations,
        r.seconds,
        if r.converged {
            "converged"
        } else {
            "stopped before convergence"
        }
    );
    if let Some(t) = fitted.material_toml() {
        println!("material: {t}");
    }
    if let Some(o) = &a.output {
        let name = a
            .file
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("measured");
        let fig = fit_slices(
            &merl,
            fitted.family.as_ref(),
            &r.values,
            &format!("{name}: measured vs {} fit", a.model),
            &[30.0, 70.0],
        )?;
        save_figure(&fig, o)?;
        println!("wrote {}", o.display());
    }
    Ok(ExitCode::SUCCESS)
}
