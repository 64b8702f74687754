//! `facette normalmap generate KIND -o FILE`: the procedural normal maps of CCM19 Fig. 7
//! (scratched, brushed, bumpy / very-rough, flakes / metallic-paint), written as a 16-bit
//! PNG (unsigned encoding) or a float EXR (signed encoding), atomically. Deterministic for
//! a (kind, resolution, seed).

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use facette_bsdf::models::glint::generate::MAX_GENERATED_SIZE;
use facette_bsdf::models::glint::{generate, NormalMapKind};
use facette_render::image::write_normal_map;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct NormalMapArgs {
    #[command(subcommand)]
    command: NormalMapCommand,
}

#[derive(Subcommand)]
enum NormalMapCommand {
    /// Generate a tileable normal map: scratched, brushed, bumpy (very-rough) or flakes (metallic-paint).
    Generate {
        /// scratched, brushed, bumpy (alias very-rough) or flakes (alias metallic-paint).
        kind: String,
        /// Output file: .png (16-bit) or .exr.
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
        /// Texels per side (1 to 4096).
        #[arg(long, default_value_t = 1024)]
        resolution: usize,
        /// Seed of the random construction.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

pub fn run(a: NormalMapArgs) -> Result<ExitCode> {
    match a.command {
        NormalMapCommand::Generate {
            kind,
            output,
            resolution,
            seed,
        } => {
            let k = NormalMapKind::parse(&kind)?;
            if resolution == 0 || resolution > MAX_GENERATED_SIZE {
                anyhow::bail!(
                    "--resolution {resolution} is out of range: 1 <= resolution <= {MAX_GENERATED_SIZE}"
                );
            }
            crate::outputs::check_writable(&[("-o", &output)])?;
            let t0 = std::time::Instant::now();
            let map = generate(k, resolution, seed)?;
            write_normal_map(&output, &map)
                .with_context(|| format!("cannot write {}", output.display()))?;
            let rms = map.rms_slope();
            println!(
                "{}: {} {resolution}×{resolution}, seed {seed}, RMS slope ({:.4}, {:.4}), {:.2} s",
                output.display(),
                k.name(),
                rms[0],
                rms[1],
                t0.elapsed().as_secs_f64()
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}
