//! `facette reproduce FIGURE | all [-o DIR]`: regenerates the papers' figures that need
//! no measured data as NAME.svg and NAME.png, and prints their key numbers.

use anyhow::{Context, Result};
use clap::Args;
use facette_lab::figures::{reproduce, Quality, FIGURES};
use facette_lab::plot::save_figure;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Args)]
pub struct ReproduceArgs {
    /// A figure name (see --list) or `all`.
    #[arg(value_name = "FIGURE", required_unless_present = "list")]
    figure: Option<String>,
    /// Output directory (created if missing).
    #[arg(short, long, value_name = "DIR", default_value = "figures")]
    output: PathBuf,
    /// Fewer samples and points: the same curves, noisier, in a fraction of the time.
    #[arg(long)]
    quick: bool,
    /// List the figures.
    #[arg(long)]
    list: bool,
}

pub fn run(a: ReproduceArgs) -> Result<ExitCode> {
    if a.list {
        for (name, what) in FIGURES {
            println!("{name}: {what}");
        }
        return Ok(ExitCode::SUCCESS);
    }
    let which = a.figure.unwrap_or_default();
    let names: Vec<&str> = if which == "all" {
        FIGURES.iter().map(|f| f.0).collect()
    } else {
        vec![which.as_str()]
    };
    let quality = if a.quick {
        Quality::Quick
    } else {
        Quality::Full
    };
    // Validate the name before creating anything.
    if which != "all" && !FIGURES.iter().any(|f| f.0 == which) {
        reproduce(&which, quality)?;
    }
    let files: Vec<String> = names
        .iter()
        .flat_map(|n| [format!("{n}.svg"), format!("{n}.png")])
        .collect();
    crate::outputs::check_output_dir("-o", &a.output, &files)?;
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("cannot create {}", a.output.display()))?;
    let total = Instant::now();
    for name in names {
        let start = Instant::now();
        let r = reproduce(name, quality).with_context(|| name.to_string())?;
        println!("== {name}");
        for line in &r.numbers {
            println!("{line}");
        }
        for ext in ["svg", "png"] {
            let p = a.output.join(format!("{name}.{ext}"));
            save_figure(&r.figure, &p)?;
        }
        println!(
            "wrote {} (.svg, .png) in {:.1} s",
            a.output.join(name).display(),
            start.elapsed().as_secs_f64()
        );
    }
    println!("total {:.1} s", total.elapsed().as_secs_f64());
    Ok(ExitCode::SUCCESS)
}
