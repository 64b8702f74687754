//! `facette fit`: fits a model to a measured BRDF in the MERL binary format and plots
//! measured against fitted slices at θ_i = 30° and 70° (IL18 Fig. 19).

use anyhow::{bail, Context, Result};
use clap::Args;
use facette_lab::fit::slices::fit_slices;
use facette_lab::fit::{
    fit, select_samples, ErrorMetric, IlDistribution, IlFamily, IlFitEvaluation, KelemenFamily,
    ModelFamily, PlasticFamily,
};
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
    #[arg(long = "il-samples", default_value_t = 128)]
    il_samples: usize,
    /// Error metric: log (ln(1 + f cos θ_i) differences) or cosine ((f̂ − f) cos θ_i).
    #[arg(long, default_value = "log")]
    error: String,
    /// Measured values used by the fit (a fixed random subset of the valid bins).
    #[arg(long, default_value_t = 4000)]
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
    }
    if a.samples < 10 {
        bail!("--samples must be at least 10");
    }
    if !(a.max_theta > 10.0 && a.max_theta <= 90.0) {
        bail!("--max-theta {}: expected (10, 90] degrees", a.max_theta);
    }
    let metric = ErrorMetric::parse(&a.error).with_context(|| {
        format!(
            "unknown --error `{}`; valid values: {}",
            a.error,
            ErrorMetric::NAMES.join(", ")
        )
    })?;
    let family: Box<dyn ModelFamily> = match a.model.as_str() {
        "il" => {
            let d = IlDistribution::parse(&a.distribution).with_context(|| {
                format!(
                    "unknown --distribution `{}` for il; valid values: {}",
                    a.distribution,
                    IlDistribution::NAMES.join(", ")
                )
            })?;
            let ev = match a.il_evaluation.as_str() {
                "quadrature" => {
                    if a.il_samples < 8 {
                        bail!("--il-samples must be at least 8");
                    }
                    IlFitEvaluation::Quadrature(a.il_samples)
                }
                "approx" => IlFitEvaluation::Approx,
                other => {
                    bail!("unknown --il-evaluation `{other}`; valid values: quadrature, approx")
                }
            };
            Box::new(IlFamily::new(d, ev))
        }
        "plastic" => Box::new(PlasticFamily {
            ggx: match a.distribution.as_str() {
                "beckmann" => false,
                "ggx" => true,
                other => bail!(
                    "unknown --distribution `{other}` for plastic; valid values: beckmann, ggx"
                ),
            },
        }),
        "kelemen" => Box::new(KelemenFamily::default()),
        other => bail!("unknown --model `{other}`; valid values: il, plastic, kelemen"),
    };
    let merl = MerlBrdf::load(&a.file)?;
    let samples = select_samples(&merl, a.max_theta, a.samples, a.seed);
    println!(
        "{}: {} valid bins of {}, fitting {} values with θ ≤ {}°",
        a.file.display(),
        merl.valid_bins(),
        facette_lab::merl::BINS,
        samples.len(),
        a.max_theta
    );
    let r = fit(family.as_ref(), &samples, metric).context("fit")?;
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
    if let Some(t) = family.material_toml(&r.values) {
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
            family.as_ref(),
            &r.values,
            &format!("{name}: measured vs {} fit", a.model),
            &[30.0, 70.0],
        )?;
        save_figure(&fig, o)?;
        println!("wrote {}", o.display());
    }
    Ok(ExitCode::SUCCESS)
}
