//! `facette validate`: runs the validation harness and prints one line per check with its
//! measured figure, then `N passed, M failed`; exits non-zero when anything fails.

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use facette_bsdf::recipe::microfacet::{parse_distribution, MICROFACET_KEYS};
use facette_bsdf::recipe::{parse_inline_table, Params};
use facette_bsdf::validation::bsdf_checks::{check_bsdf, BsdfCheckOptions};
use facette_bsdf::validation::chi2::Chi2Config;
use facette_bsdf::validation::distribution_checks::{check_distribution, DistributionCheckOptions};
use facette_bsdf::validation::suites::{core_suite, Family, SuiteOptions};
use facette_bsdf::validation::Report;
use std::process::ExitCode;

#[derive(Clone, Copy, ValueEnum)]
pub enum FamilyArg {
    Beckmann,
    Ggx,
    Gaussian,
    Phong,
}

#[derive(Args)]
pub struct ValidateArgs {
    /// A material as a TOML inline table: runs every BSDF check on it.
    #[arg(long, value_name = "TOML", conflicts_with_all = ["distribution", "family"])]
    material: Option<String>,
    /// One distribution as a TOML inline table, e.g. '{distribution = "ggx", alpha_u = 0.05, alpha_v = 0.5}'.
    #[arg(long, value_name = "TOML")]
    distribution: Option<String>,
    /// Restrict the core suite to one distribution family.
    #[arg(long, value_enum)]
    family: Option<FamilyArg>,
    /// Samples per chi-square test.
    #[arg(long, default_value_t = 1_000_000, value_parser = crate::counts::count::<1, { crate::counts::SAMPLES }>)]
    samples: usize,
    /// Seed of every random stream (results are reproducible for a given seed).
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// Print only failing checks and the summary.
    #[arg(long)]
    quiet: bool,
}

pub fn run(a: ValidateArgs) -> Result<ExitCode> {
    if a.samples < 1000 {
        anyhow::bail!("--samples must be at least 1000 (got {})", a.samples);
    }
    let report = if let Some(text) = &a.material {
        let bsdf = crate::material_arg::parse_material(text)?;
        let opts = BsdfCheckOptions {
            chi2: Chi2Config {
                samples: a.samples,
                seed: a.seed,
                ..Chi2Config::default()
            },
            ..BsdfCheckOptions::default()
        };
        let mut r = Report::new();
        r.extend(check_bsdf(bsdf.as_ref(), &opts));
        r
    } else if let Some(text) = &a.distribution {
        let table = parse_inline_table(text).context("--distribution")?;
        let p = Params::new(&table, "distribution");
        let ndf = parse_distribution(&p, false).context("--distribution")?;
        p.finish(MICROFACET_KEYS).context("--distribution")?;
        let ndf = ndf.expect("smooth distributions are rejected above");
        let opts = DistributionCheckOptions {
            chi2: Chi2Config {
                samples: a.samples,
                seed: a.seed,
                ..Chi2Config::default()
            },
            ..DistributionCheckOptions::default()
        };
        let mut r = Report::new();
        r.extend(check_distribution(&ndf, &opts));
        r
    } else {
        let only = a.family.map(|f| match f {
            FamilyArg::Beckmann => Family::Beckmann,
            FamilyArg::Ggx => Family::Ggx,
            FamilyArg::Gaussian => Family::Gaussian,
            FamilyArg::Phong => Family::Phong,
        });
        core_suite(
            &SuiteOptions {
                chi2_samples: a.samples,
                seed: a.seed,
            },
            only,
        )
    };
    Ok(print_report(&report, a.quiet))
}

/// Prints the report and returns the exit status (1 when a check failed).
pub fn print_report(r: &Report, quiet: bool) -> ExitCode {
    for line in r.lines() {
        if !quiet || line.starts_with("[FAIL]") {
            println!("{line}");
        }
    }
    println!("{}", r.summary_line());
    if r.all_passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}
