//! `facette tabulate`: tabulates the body term of an interfaced-Lambertian material on a
//! (θ_i, θ_o, φ) grid [TSBRM §4.3] and writes the documented binary table (see
//! docs/file-formats.md); `--check K` compares K random off-grid pairs with the quadrature.
//! Entries are QMC estimates (`--samples`) or, with `--tolerance`, deterministic adaptive
//! quadratures of IL18 eq. 13 with an error estimate each.

use anyhow::{bail, Context, Result};
use clap::Args;
use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_bsdf::math::spherical_direction;
use facette_bsdf::microfacet::integral::{check_tolerance, TableEntries, TOLERANCE_RANGE};
use facette_bsdf::models::il::il_table::BodyTable;
use facette_bsdf::models::il::il_table_part::{merge_table_parts, TablePart};
use facette_bsdf::models::il::interfaced_lambertian::{BodyEvaluation, Scattering};
use facette_bsdf::models::InterfacedLambertian;
use facette_bsdf::recipe::{parse_inline_table, Params};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

#[derive(Args)]
pub struct TabulateArgs {
    /// An interfaced-Lambertian material, e.g. '{type = "il", ni = 1.2, distribution = "gaussian", sigma = 0.3}'.
    #[arg(long, value_name = "TOML")]
    material: String,
    /// Grid step in degrees (must divide 90).
    #[arg(long, default_value_t = 5.0)]
    step: f64,
    /// Microfacet samples per entry (randomized QMC, with a standard error).
    #[arg(long, default_value_t = 10_000, value_parser = crate::counts::count::<8, { crate::counts::QUADRATURE }>)]
    samples: usize,
    /// Compute each entry by adaptive quadrature to this relative tolerance instead of
    /// `--samples` (deterministic, with an error estimate; 1e-12 to 0.1).
    #[arg(long, value_name = "REL", conflicts_with = "samples", value_parser = tolerance)]
    tolerance: Option<f64>,
    /// Output file (.fctab).
    #[arg(short, long, value_name = "FILE")]
    output: std::path::PathBuf,
    /// Compute part K of N of the table's rows and write it to a `.fctpart` file for
    /// `facette merge` (distributed tabulation; see docs/scale-out.md).
    #[arg(long, value_name = "K/N")]
    part: Option<String>,
    /// Compare the table with the quadrature on this many random off-grid direction pairs.
    #[arg(long, value_name = "K", default_value_t = 0, value_parser = crate::counts::count::<0, { crate::counts::QUADRATURE }>)]
    check: usize,
}

/// Parses `--tolerance`: a finite number in the range of the `tolerance` key (the error
/// gives the range).
fn tolerance(s: &str) -> Result<f64, String> {
    let t: f64 = s.trim().parse().map_err(|_| {
        let (lo, hi) = TOLERANCE_RANGE;
        format!("`{s}` is not a number (expected {lo:e} <= tolerance <= {hi})")
    })?;
    check_tolerance(t).map_err(|e| e.to_string())
}

pub fn run(a: TabulateArgs) -> Result<ExitCode> {
    crate::outputs::check_writable(&[("-o", &a.output)])?;
    let table = parse_inline_table(&a.material).context("--material")?;
    let ty = table.get("type").and_then(|v| v.as_str()).unwrap_or("");
    if ty != "il" && ty != "interfaced-lambertian" {
        bail!("--material: tabulate needs an interfaced-Lambertian material (type = \"il\"), got type `{ty}`");
    }
    let bsdf = facette_bsdf::recipe::build_material(&table).context("--material")?;
    let _ = Params::new(&table, "material");
    // Rebuild the concrete model to reach its microfacet lobe.
    let il = match (bsdf.describe(), find_il(&table)?) {
        (_, Some(il)) => il,
        (d, None) => bail!(
            "--material: {d} is flat (alpha = 0): its body term is closed-form and needs no table"
        ),
    };
    let lobe = il.lobe().expect("rough").clone();
    let entries = match a.tolerance {
        Some(tolerance) => TableEntries::Adaptive { tolerance },
        None => TableEntries::Samples(a.samples),
    };
    if let Some(part) = &a.part {
        let (k, n) = crate::cmd_render::parse_part(part)?;
        if a.output.extension().is_none_or(|e| e != "fctpart") {
            bail!(
                "-o {}: a table part is written to a `.fctpart` file",
                a.output.display()
            );
        }
        if a.check > 0 {
            bail!("--check applies to whole tables (after `facette merge`)");
        }
        let pb = crate::progress::bar(0, "tabulating");
        let start = Instant::now();
        let p = TablePart::build_with(&lobe, il.ni(), a.step, entries, k, n, &|done, total| {
            pb.set_length(total as u64);
            pb.set_position(done as u64);
        })
        .context("tabulate")?;
        pb.finish_and_clear();
        p.save(&a.output)
            .with_context(|| format!("cannot write {}", a.output.display()))?;
        println!(
            "wrote {} (part {k}/{n}: {} θ_i rows, {:.2} s)",
            a.output.display(),
            p.row_count(),
            start.elapsed().as_secs_f64()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let pb = crate::progress::bar(0, "tabulating");
    let start = Instant::now();
    let t = BodyTable::build_with(&lobe, il.ni(), a.step, entries, &|done, total| {
        pb.set_length(total as u64);
        pb.set_position(done as u64);
    })
    .context("tabulate")?;
    pb.finish_and_clear();
    let secs = start.elapsed().as_secs_f64();
    t.save(&a.output)
        .with_context(|| format!("cannot write {}", a.output.display()))?;
    println!(
        "wrote {} ({}×{}×{} entries, {}, {:.2} s; {} of the entries with θ < 90°: mean {:.2e}, max {:.2e})",
        a.output.display(),
        t.n_theta,
        t.n_theta,
        t.n_phi,
        entries_text(&t),
        secs,
        error_text(&t),
        t.mean_stderr,
        t.max_stderr
    );
    if a.check > 0 {
        let quad = InterfacedLambertian::new(
            il.kd(),
            il.ni(),
            Some(lobe.clone()),
            BodyEvaluation::Adaptive { tolerance: 1e-7 },
            Scattering::Single,
        )?;
        let tab = InterfacedLambertian::new(
            il.kd(),
            il.ni(),
            Some(lobe),
            BodyEvaluation::Table(Arc::new(t)),
            Scattering::Single,
        )?;
        let mut rng = Pcg32::new(17, 0);
        let (mut sum, mut max) = (0.0f64, 0.0f64);
        for _ in 0..a.check {
            let wi = spherical_direction(
                rng.next_f64() * 80f64.to_radians(),
                rng.next_f64() * std::f64::consts::TAU,
            );
            let wo = spherical_direction(
                rng.next_f64() * 80f64.to_radians(),
                rng.next_f64() * std::f64::consts::TAU,
            );
            let (x, _) = tab.body_integral(wi, wo, 0, &mut rng);
            let (y, _) = quad.body_integral(wi, wo, 0, &mut rng);
            let e = ((x - y) / y).abs();
            sum += e;
            max = max.max(e);
        }
        println!(
            "table vs adaptive quadrature (tolerance 1e-7) on {} random pairs with θ ≤ 80°: mean relative error {:.3e}, max {:.3e}",
            a.check,
            sum / a.check as f64,
            max
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// The rough IL model described by `table` (None when flat).
fn find_il(table: &toml::Table) -> Result<Option<InterfacedLambertian>> {
    use facette_bsdf::microfacet::specular_lobe::SpecularLobe;
    use facette_bsdf::recipe::microfacet::{parse_distribution, parse_masking, parse_sampling};
    let p = Params::new(table, "material \"il\"");
    let kd = p
        .spectrum("kd")?
        .unwrap_or(facette_bsdf::Spectrum::splat(0.5));
    let ni = p.f64_or("ni", 1.5)?;
    let Some(ndf) = parse_distribution(&p, true)? else {
        return Ok(None);
    };
    let masking = parse_masking(&p, Some(&ndf))?;
    let lobe = SpecularLobe::new(ndf, masking, parse_sampling(&p)?)?;
    Ok(Some(InterfacedLambertian::new(
        kd,
        ni,
        Some(lobe),
        BodyEvaluation::Stochastic,
        Scattering::Single,
    )?))
}

/// `facette merge` for table parts: all N parts of one table into a `.fctab` file.
pub fn merge(parts: &[std::path::PathBuf], output: &std::path::Path) -> Result<ExitCode> {
    if output.extension().is_none_or(|e| e != "fctab") {
        bail!(
            "-o {}: table parts merge into a `.fctab` file",
            output.display()
        );
    }
    crate::outputs::check_writable(&[("-o", output)])?;
    let parts: Vec<TablePart> = parts
        .iter()
        .map(|p| TablePart::load(p))
        .collect::<Result<_, _>>()?;
    let table = merge_table_parts(&parts).map_err(|e| anyhow::anyhow!("cannot merge: {e}"))?;
    table
        .save(output)
        .with_context(|| format!("cannot write {}", output.display()))?;
    println!(
        "wrote {} (merged {} parts: {}×{}×{} entries, {}; {} mean {:.2e}, max {:.2e})",
        output.display(),
        parts.len(),
        table.n_theta,
        table.n_theta,
        table.n_phi,
        entries_text(&table),
        error_text(&table),
        table.mean_stderr,
        table.max_stderr
    );
    Ok(ExitCode::SUCCESS)
}

/// "10000 samples each" or "adaptive, tolerance 1e-6".
fn entries_text(t: &BodyTable) -> String {
    match t.tolerance {
        Some(tol) => format!("adaptive quadrature, tolerance {tol:e}"),
        None => format!("{} samples each", t.samples),
    }
}

/// What the table's error figures are.
fn error_text(t: &BodyTable) -> &'static str {
    if t.tolerance.is_some() {
        "relative error estimate"
    } else {
        "relative standard error"
    }
}
