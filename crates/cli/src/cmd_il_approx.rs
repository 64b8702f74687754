//! `facette il-approx`: fits the approximate interfaced-Lambertian body term (IL18 §4.2,
//! ERRATA 1) and measures its accuracy against the quadrature.

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use facette_bsdf::models::il::il_approx::ApproxFamily;
use facette_lab::il_approx_fit::{accuracy, coefficients_source, fit_family};
use std::process::ExitCode;

#[derive(Args)]
pub struct IlApproxArgs {
    #[command(subcommand)]
    command: IlApproxCommand,
}

#[derive(Subcommand)]
enum IlApproxCommand {
    /// Fit the coefficients on the (σ, n_i) grid and write them as Rust source.
    Fit {
        /// Microfacets per quadrature value.
        #[arg(long, default_value_t = 4096, value_parser = crate::counts::count::<1, { crate::counts::QUADRATURE }>)]
        samples: usize,
        /// Output file (default: print to stdout).
        #[arg(short, long)]
        output: Option<std::path::PathBuf>,
    },
    /// Mean and maximum relative error of the shipped approximation against the quadrature,
    /// over σ, n_i and off-grid directions.
    Accuracy {
        /// Microfacets per quadrature value.
        #[arg(long, default_value_t = 16384, value_parser = crate::counts::count::<1, { crate::counts::QUADRATURE }>)]
        samples: usize,
    },
}

pub fn run(a: IlApproxArgs) -> Result<ExitCode> {
    match a.command {
        IlApproxCommand::Fit { samples, output } => {
            if let Some(p) = &output {
                crate::outputs::check_writable(&[("-o", p)])?;
            }
            let mut fits = Vec::new();
            for fam in ApproxFamily::ALL {
                let pb = crate::progress::bar(0, fam.name());
                let f = fit_family(fam, samples, &|d, t| {
                    pb.set_length(t as u64);
                    pb.set_position(d as u64);
                });
                pb.finish_and_clear();
                let worst = f
                    .nodes
                    .iter()
                    .flatten()
                    .map(|n| n.mean_rel)
                    .fold(0.0, f64::max);
                eprintln!(
                    "{}: fitted, worst node mean relative error {:.3}",
                    fam.name(),
                    worst
                );
                fits.push(f);
            }
            let src = coefficients_source(&fits, samples);
            match output {
                Some(p) => facette_bsdf::storage::atomic_file::write_atomically(&p, src.as_bytes())
                    .with_context(|| format!("cannot write {}", p.display()))?,
                None => print!("{src}"),
            }
        }
        IlApproxCommand::Accuracy { samples } => {
            println!("family,sigma,ni,mean_relative_error,p95_relative_error,max_relative_error");
            for fam in ApproxFamily::ALL {
                let (mut sum, mut n, mut max) = (0.0, 0usize, 0.0f64);
                for sigma in [0.1, 0.25, 0.5, 0.9, 1.3] {
                    for ni in [1.0, 1.25, 1.5, 2.2, 3.0] {
                        let e = accuracy(fam, sigma, ni, samples);
                        println!(
                            "{},{sigma},{ni},{:.4},{:.4},{:.4}",
                            fam.name(),
                            e.mean,
                            e.p95,
                            e.max
                        );
                        sum += e.mean;
                        n += 1;
                        max = max.max(e.max);
                    }
                }
                println!(
                    "# {}: mean relative error {:.4}, max {:.4}",
                    fam.name(),
                    sum / n as f64,
                    max
                );
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
