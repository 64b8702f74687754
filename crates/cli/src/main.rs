//! `facette`: the command-line front of the library, renderer and lab. Argument parsing and
//! progress reporting only; each subcommand is a thin call into a crate.

mod cmd_albedo;
mod cmd_eval;
mod cmd_il_approx;
mod cmd_normalmap;
mod cmd_render;
mod cmd_tabulate;
mod cmd_validate;
mod material_arg;
mod progress;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "facette",
    version,
    about = "A renderer and lab for microfacet materials",
    long_about = "facette evaluates, samples, validates and renders the microfacet materials of \
                  Walter et al. 2007, Kelemen & Szirmay-Kalos 2001, Simonot / Meneveaux et al. \
                  (interfaced Lambertian) and Chermain et al. 2019 (glints)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file to EXR or PNG.
    Render(cmd_render::RenderArgs),
    /// Evaluate a material on directions read as CSV (theta_i,phi_i,theta_o,phi_o in degrees).
    Eval(cmd_eval::EvalArgs),
    /// Directional reflectance and transmittance of a material, with standard errors.
    Albedo(cmd_albedo::AlbedoArgs),
    /// Statistical validation: the microfacet core suite, one distribution, or a material.
    Validate(cmd_validate::ValidateArgs),
    /// Tabulate the body term of an interfaced-Lambertian material (TSBRM §4.3).
    Tabulate(cmd_tabulate::TabulateArgs),
    /// Fit or measure the approximate interfaced-Lambertian body term (IL18 §4.2).
    IlApprox(cmd_il_approx::IlApproxArgs),
    /// Normal maps for the glint material (CCM19): generate the kinds of CCM19 Fig. 7.
    Normalmap(cmd_normalmap::NormalMapArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(a) => cmd_render::run(a),
        Command::Eval(a) => cmd_eval::run(a),
        Command::Albedo(a) => cmd_albedo::run(a),
        Command::Validate(a) => cmd_validate::run(a),
        Command::Tabulate(a) => cmd_tabulate::run(a),
        Command::IlApprox(a) => cmd_il_approx::run(a),
        Command::Normalmap(a) => cmd_normalmap::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
