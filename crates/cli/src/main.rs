//! `facette`: the command-line front of the library, renderer and lab. Argument parsing and
//! progress reporting only; each subcommand is a thin call into a crate.

mod cmd_albedo;
mod cmd_eval;
mod cmd_explore;
mod cmd_fit;
mod cmd_il_approx;
mod cmd_measure;
mod cmd_merge;
mod cmd_normalmap;
mod cmd_plot;
mod cmd_render;
mod cmd_reproduce;
mod cmd_tabulate;
mod cmd_validate;
mod counts;
mod material_arg;
mod outputs;
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
    command: Option<Command>,
    /// Raise a resource limit for this run, KEY=N (repeatable; also FACETTE_LIMITS=KEY=N,…).
    /// `--limit list` prints every limit, its default and how far it can be raised.
    #[arg(long = "limit", global = true, value_name = "KEY=N")]
    limits: Vec<String>,
}

/// Applies `FACETTE_LIMITS`, then each `--limit` (so the flag wins); `list` prints them.
/// Returns the exit code to stop with, if any.
fn apply_limits(assignments: &[String]) -> Option<ExitCode> {
    use facette_bsdf::limits;
    if assignments.iter().any(|a| a == "list") {
        println!("key,default,ceiling,what");
        for l in limits::all() {
            println!("{},{},{},{}", l.key, l.default, l.ceiling, l.what);
        }
        return Some(ExitCode::SUCCESS);
    }
    let applied = limits::set_limits_from_env().and_then(|()| {
        assignments
            .iter()
            .try_for_each(|a| limits::set_limit(a).map_err(|e| format!("--limit: {e}")))
    });
    match applied {
        Ok(()) => None,
        Err(e) => {
            eprintln!("error: {e}");
            Some(ExitCode::from(2))
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file to EXR or PNG.
    Render(cmd_render::RenderArgs),
    /// Merge the parts of a distributed render (.fcpart) or table (.fctpart).
    Merge(cmd_merge::MergeArgs),
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
    /// Plot a material: incidence-plane slices, polar lobes, hemisphere maps, albedo; or an IL body table against its quadrature.
    Plot(cmd_plot::PlotArgs),
    /// Fit IL, plastic (Lambert + Cook–Torrance) or KSK01 to a measured MERL BRDF.
    Fit(cmd_fit::FitArgs),
    /// Write a material as a measured BRDF in the MERL binary format (virtual gonioreflectometer).
    Measure(cmd_measure::MeasureArgs),
    /// Regenerate the papers' figures (SVG and PNG) and print their key numbers.
    Reproduce(cmd_reproduce::ReproduceArgs),
    /// Normal maps for the glint material (CCM19): generate the kinds of CCM19 Fig. 7.
    Normalmap(cmd_normalmap::NormalMapArgs),
    /// The interactive BRDF explorer: a local web server; open the URL it prints.
    Explore(cmd_explore::ExploreArgs),
}

/// Output piped into a reader that stops early (`facette eval … | head`) is not an error:
/// `println!` panics on the closed pipe, and this hook turns that panic into a quiet exit
/// with the shell's status for SIGPIPE. Other panics keep Rust's default report.
fn exit_quietly_on_broken_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("failed printing to stdout") && msg.contains("Broken pipe") {
            std::process::exit(141);
        }
        default(info);
    }));
}

fn main() -> ExitCode {
    exit_quietly_on_broken_pipe();
    let cli = Cli::parse();
    if let Some(code) = apply_limits(&cli.limits) {
        return code;
    }
    let Some(command) = cli.command else {
        use clap::CommandFactory;
        let _ = Cli::command().print_help();
        return ExitCode::from(2);
    };
    let result = match command {
        Command::Render(a) => cmd_render::run(a),
        Command::Merge(a) => cmd_merge::run(a),
        Command::Eval(a) => cmd_eval::run(a),
        Command::Albedo(a) => cmd_albedo::run(a),
        Command::Validate(a) => cmd_validate::run(a),
        Command::Tabulate(a) => cmd_tabulate::run(a),
        Command::IlApprox(a) => cmd_il_approx::run(a),
        Command::Plot(a) => cmd_plot::run(a),
        Command::Fit(a) => cmd_fit::run(a),
        Command::Measure(a) => cmd_measure::run(a),
        Command::Reproduce(a) => cmd_reproduce::run(a),
        Command::Normalmap(a) => cmd_normalmap::run(a),
        Command::Explore(a) => cmd_explore::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e)
            if e.chain().any(|c| {
                c.downcast_ref::<std::io::Error>()
                    .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            }) =>
        {
            ExitCode::from(141)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
