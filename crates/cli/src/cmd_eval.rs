//! `facette eval`: evaluates a material on directions read as CSV.
//!
//! Input rows `theta_i,phi_i,theta_o,phi_o` in degrees (i: light direction, o: view
//! direction, both pointing away from the surface; z is the normal, φ from the tangent x
//! axis; θ > 90° is below the surface, i.e. transmission). A header line is optional, `#`
//! starts a comment. Output rows `theta_i,phi_i,theta_o,phi_o,r,g,b` with f(i, o) without
//! the cosine factor (delta lobes excluded). With `--with-error`, three more columns
//! `err_r,err_g,err_b`: the adaptive quadrature's error estimate where the value is one
//! (`evaluation = "quadrature"`), the standard error where it is a mean of stochastic
//! estimates (or of a fixed set of `samples = N` microfacets, over its 8 rotations), the
//! root sum of squares where a value adds both (IL with V-cavity inter-reflections), and 0
//! for closed forms and tabulated values (a table's own interpolation error is not
//! known to eval).

use crate::material_arg::parse_material_at;
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use facette_bsdf::math::rng::Pcg32;
use facette_bsdf::math::spherical_direction;
use facette_bsdf::{BsdfContext, TransportMode};
use std::io::{BufRead, BufWriter, Write};
use std::process::ExitCode;

#[derive(Clone, Copy, ValueEnum)]
pub enum ModeArg {
    /// f(i, o) with i the light direction (the default).
    Radiance,
    /// The adjoint: f(o, i).
    Importance,
}

#[derive(Args)]
pub struct EvalArgs {
    /// The material, a TOML inline table, e.g. '{type = "dielectric", distribution = "ggx", alpha = 0.3, ior = 1.5}'.
    #[arg(long, value_name = "TOML")]
    material: String,
    /// CSV file of directions (default: standard input).
    #[arg(long, value_name = "FILE")]
    input: Option<std::path::PathBuf>,
    /// Estimates averaged per value for stochastic models.
    #[arg(long, default_value_t = 100_000, value_parser = crate::counts::count::<1, { crate::counts::SAMPLES }>)]
    samples: usize,
    /// Transport mode (only refraction depends on it).
    #[arg(long, value_enum, default_value = "radiance")]
    mode: ModeArg,
    /// Seed of the stochastic estimates.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Glints: the ray footprint, U,V,SIGMA[,SIGMA_V[,RHO]] (uv centre; standard deviations
    /// in texels; correlation).
    #[arg(long, value_name = "U,V,SIGMA")]
    footprint: Option<String>,
    /// Add columns err_r,err_g,err_b: the quadrature's error estimate, or the standard error
    /// of stochastic values, 0 for closed forms.
    #[arg(long)]
    with_error: bool,
}

/// Parses one data row; `Ok(None)` for blank lines, comments and a header.
pub fn parse_row(line: &str, lineno: usize, source: &str) -> Result<Option<[f64; 4]>> {
    let t = line.trim();
    if t.is_empty() || t.starts_with('#') {
        return Ok(None);
    }
    let fields: Vec<&str> = t.split(',').map(str::trim).collect();
    if lineno == 1 && fields.iter().any(|f| f.parse::<f64>().is_err()) {
        return Ok(None); // header
    }
    if fields.len() != 4 {
        bail!(
            "{source}:{lineno}: expected 4 comma-separated numbers theta_i,phi_i,theta_o,phi_o, got {} fields",
            fields.len()
        );
    }
    let mut v = [0.0; 4];
    for (k, f) in fields.iter().enumerate() {
        v[k] = f
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .with_context(|| {
                format!(
                    "{source}:{lineno}: field {} is not a finite number: `{f}`",
                    k + 1
                )
            })?;
    }
    for (k, name) in [(0, "theta_i"), (2, "theta_o")] {
        if !(0.0..=180.0).contains(&v[k]) {
            bail!(
                "{source}:{lineno}: {name} = {} is outside [0, 180] degrees",
                facette_bsdf::math::fmt_num(v[k])
            );
        }
    }
    Ok(Some(v))
}

pub fn run(a: EvalArgs) -> Result<ExitCode> {
    let bsdf = parse_material_at(&a.material, a.footprint.as_deref())?;
    if a.samples == 0 {
        bail!("--samples must be at least 1");
    }
    let (reader, source): (Box<dyn BufRead>, String) = match &a.input {
        Some(p) => (
            Box::new(std::io::BufReader::new(
                std::fs::File::open(p).with_context(|| format!("cannot open {}", p.display()))?,
            )),
            p.display().to_string(),
        ),
        None => (Box::new(std::io::stdin().lock()), "stdin".to_string()),
    };
    if !bsdf.eval_is_deterministic() {
        eprintln!(
            "note: {} is evaluated stochastically; each value averages {} independent estimates",
            bsdf.describe(),
            a.samples
        );
    }
    let ctx = BsdfContext {
        mode: match a.mode {
            ModeArg::Radiance => TransportMode::Radiance,
            ModeArg::Importance => TransportMode::Importance,
        },
        ..Default::default()
    };
    let mut rng = Pcg32::new(a.seed, 0);
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    if a.with_error {
        writeln!(out, "theta_i,phi_i,theta_o,phi_o,r,g,b,err_r,err_g,err_b")?;
    } else {
        writeln!(out, "theta_i,phi_i,theta_o,phi_o,r,g,b")?;
    }
    for (k, line) in reader.lines().enumerate() {
        let line = line.with_context(|| format!("{source}:{}: unreadable line", k + 1))?;
        let Some([ti, pi, to, po]) = parse_row(&line, k + 1, &source)? else {
            continue;
        };
        let wi = spherical_direction(ti.to_radians(), pi.to_radians());
        let wo = spherical_direction(to.to_radians(), po.to_radians());
        let (f, err) = bsdf.eval_estimate(wo, wi, &ctx, a.samples, &mut rng);
        write!(
            out,
            "{ti},{pi},{to},{po},{:.9e},{:.9e},{:.9e}",
            f[0], f[1], f[2]
        )?;
        if a.with_error {
            write!(out, ",{:.3e},{:.3e},{:.3e}", err[0], err[1], err[2])?;
        }
        writeln!(out)?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}
