//! `facette plot`: BSDF figures (SVG or PNG by the output's extension) — incidence-plane
//! slices, polar lobes, hemisphere maps, a glint footprint's patch NDF, directional albedo, and an IL body table against
//! its quadrature (TSBRM Fig. 10). Prints one summary line per curve; `--csv` writes the
//! plotted numbers.

use crate::material_arg::{parse_glint_at, parse_material};
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use facette_bsdf::models::il::il_table::BodyTable;
use facette_bsdf::models::il::interfaced_lambertian::{BodyEvaluation, Scattering};
use facette_bsdf::models::InterfacedLambertian;
use facette_bsdf::recipe::{parse_inline_table, MaterialRecipe};
use facette_lab::plot::bsdf_charts::{
    albedo_chart, chart_csv, hemisphere_chart, polar_from_slice, slice_chart, summarize,
    LabelledBsdf, SliceOptions,
};
use facette_lab::plot::bsdf_data::{Channel, Quantity, Side};
use facette_lab::plot::ndf_map::patch_ndf_map;
use facette_lab::plot::table_comparison::compare_table;
use facette_lab::plot::{save_figure, Format, HemisphereMap, LineChart, Scale};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

#[derive(Args)]
pub struct PlotArgs {
    #[command(subcommand)]
    kind: PlotKind,
}

#[derive(Args)]
struct MaterialsArgs {
    /// A material as a TOML inline table; repeat for several materials in one plot.
    #[arg(long = "material", value_name = "TOML", required = true)]
    materials: Vec<String>,
    /// Legend names of the materials, in order (default: the TOML text).
    #[arg(long = "label", value_name = "NAME")]
    labels: Vec<String>,
    /// Estimates averaged per value for stochastic models.
    #[arg(long, default_value_t = 20_000, value_parser = crate::counts::count::<1, { crate::counts::SAMPLES }>)]
    samples: usize,
    /// Seed of the stochastic estimates.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output figure (.svg or .png).
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Also write the plotted numbers as CSV (series,x,y).
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
}

#[derive(Args)]
struct SliceArgs {
    #[command(flatten)]
    m: MaterialsArgs,
    /// Incidence angles in degrees (one curve each).
    #[arg(long = "theta-i", value_name = "DEG", num_args = 1.., default_values_t = [30.0])]
    theta_i: Vec<f64>,
    /// What to plot: f, fcos (f·|cos θ_o|) or fcos-i (f·cos θ_i).
    #[arg(long, default_value = "f")]
    quantity: String,
    /// reflection or transmission.
    #[arg(long, default_value = "reflection")]
    side: String,
    /// Which colour channel: mean, r, g or b.
    #[arg(long, default_value = "mean")]
    channel: String,
    /// Logarithmic y axis.
    #[arg(long)]
    log: bool,
    /// Points over −90°…90°.
    #[arg(long, default_value_t = 181, value_parser = crate::counts::count::<2, { crate::counts::POINTS }>)]
    points: usize,
}

#[derive(Subcommand)]
enum PlotKind {
    /// Curves in the incidence plane against signed θ_o (> 0 on the mirror side).
    Slice(SliceArgs),
    /// Polar lobes in the incidence plane.
    Polar(SliceArgs),
    /// False-colour map of f over the projected hemisphere for one θ_i.
    Hemisphere {
        #[command(flatten)]
        m: MaterialsArgs,
        /// Incidence angle in degrees.
        #[arg(long = "theta-i", value_name = "DEG", default_value_t = 30.0)]
        theta_i: f64,
        /// What to plot: f, fcos or fcos-i.
        #[arg(long, default_value = "f")]
        quantity: String,
        #[arg(long, default_value = "mean")]
        channel: String,
        /// Logarithmic colour scale.
        #[arg(long)]
        log: bool,
        /// Cells across the disk.
        #[arg(long, default_value_t = 96)]
        resolution: usize,
    },
    /// Glints: false-colour map of the patch NDF D_P(ω_h) of one footprint over the
    /// projected disk of half vectors [CCM19 eq. 9]; each cell averages D_P over
    /// SUPERSAMPLE² points.
    Ndf {
        /// A `type = "glint"` material as a TOML inline table.
        #[arg(long, value_name = "TOML")]
        material: String,
        /// The footprint, U,V,SIGMA[,SIGMA_V[,RHO]] (uv centre; standard deviations in
        /// texels; correlation), as for `facette eval` (default: the material's
        /// `footprint_center` and `footprint_size`).
        #[arg(long, value_name = "U,V,SIGMA")]
        footprint: Option<String>,
        /// Logarithmic colour scale.
        #[arg(long)]
        log: bool,
        /// Cells across the disk.
        #[arg(long, default_value_t = 128)]
        resolution: usize,
        /// Points per cell side averaged for each cell (the lobes are narrower than a cell).
        #[arg(long, default_value_t = 4)]
        supersample: usize,
        /// Output figure (.svg or .png).
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
        /// Also write the cell values as CSV (x,y,value).
        #[arg(long, value_name = "FILE")]
        csv: Option<PathBuf>,
    },
    /// Directional reflectance (and transmittance) against θ_i.
    Albedo {
        #[command(flatten)]
        m: MaterialsArgs,
        /// Step of θ_i in degrees over 0…89.
        #[arg(long, default_value_t = 5.0)]
        step: f64,
    },
    /// An IL body table (from `facette tabulate`) against the quadrature (TSBRM Fig. 10).
    Table {
        /// The IL material the table was built for.
        #[arg(long, value_name = "TOML")]
        material: String,
        /// The table file (.fctab).
        #[arg(long, value_name = "FILE")]
        table: PathBuf,
        #[arg(long = "theta-i", value_name = "DEG", default_value_t = 60.0)]
        theta_i: f64,
        /// Microfacets of the reference quadrature.
        #[arg(long, default_value_t = 65_536, value_parser = crate::counts::count::<1, { crate::counts::QUADRATURE }>)]
        samples: usize,
        #[arg(long, default_value_t = 181, value_parser = crate::counts::count::<2, { crate::counts::POINTS }>)]
        points: usize,
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
        #[arg(long, value_name = "FILE")]
        csv: Option<PathBuf>,
    },
}

fn materials(m: &MaterialsArgs) -> Result<Vec<LabelledBsdf>> {
    if m.labels.len() > m.materials.len() {
        bail!(
            "{} --label values for {} --material values",
            m.labels.len(),
            m.materials.len()
        );
    }
    if m.samples == 0 {
        bail!("--samples must be at least 1");
    }
    Format::of(&m.output)?;
    m.materials
        .iter()
        .enumerate()
        .map(|(k, text)| {
            let bsdf = parse_material(text)
                .with_context(|| format!("material {} of {}", k + 1, m.materials.len()))?;
            if !bsdf.eval_is_deterministic() {
                eprintln!(
                    "note: {} is evaluated stochastically; each value averages {} estimates",
                    bsdf.describe(),
                    m.samples
                );
            }
            Ok(LabelledBsdf {
                label: m
                    .labels
                    .get(k)
                    .cloned()
                    .unwrap_or_else(|| text.trim().to_string()),
                bsdf,
            })
        })
        .collect()
}

fn parse_choice<T>(
    what: &str,
    s: &str,
    f: impl Fn(&str) -> Option<T>,
    names: &[&str],
) -> Result<T> {
    f(s).with_context(|| format!("unknown {what} `{s}`; valid values: {}", names.join(", ")))
}

fn check_theta(t: f64) -> Result<()> {
    if !(t.is_finite() && (0.0..90.0).contains(&t)) {
        bail!(
            "--theta-i {}: expected an angle in [0, 90) degrees",
            facette_bsdf::math::fmt_num(t)
        );
    }
    Ok(())
}

fn slice_options(a: &SliceArgs) -> Result<SliceOptions> {
    for &t in &a.theta_i {
        check_theta(t)?;
    }
    if a.points < 2 {
        bail!("--points must be at least 2");
    }
    Ok(SliceOptions {
        thetas_i: a.theta_i.clone(),
        side: match a.side.as_str() {
            "reflection" => Side::Reflection,
            "transmission" => Side::Transmission,
            s => bail!("unknown --side `{s}`; valid values: reflection, transmission"),
        },
        quantity: parse_choice("--quantity", &a.quantity, Quantity::parse, Quantity::NAMES)?,
        channel: parse_choice("--channel", &a.channel, Channel::parse, Channel::NAMES)?,
        scale: if a.log { Scale::Log } else { Scale::Linear },
        points: a.points,
        samples: a.m.samples,
        seed: a.m.seed,
    })
}

fn finish(chart: &LineChart, output: &Path, csv: &Option<PathBuf>) -> Result<()> {
    crate::outputs::check_with_csv(output, csv)?;
    for line in summarize(chart) {
        println!("{line}");
    }
    save_figure(chart, output)?;
    if let Some(p) = csv {
        facette_bsdf::storage::atomic_file::write_atomically(p, chart_csv(chart).as_bytes())
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    println!("wrote {}", output.display());
    Ok(())
}

/// Writes a hemisphere map and, with `--csv`, its cell values.
fn save_map(map: &HemisphereMap, output: &Path, csv: &Option<PathBuf>) -> Result<()> {
    crate::outputs::check_with_csv(output, csv)?;
    save_figure(map, output)?;
    if let Some(p) = csv {
        let mut s = String::from("x,y,value\n");
        for (k, v) in map.values.iter().enumerate() {
            if let Some(v) = v {
                let (x, y) = HemisphereMap::cell_centre(map.n, k);
                s += &format!("{x:.6},{y:.6},{v:.9e}\n");
            }
        }
        facette_bsdf::storage::atomic_file::write_atomically(p, s.as_bytes())
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    println!("wrote {}", output.display());
    Ok(())
}

pub fn run(a: PlotArgs) -> Result<ExitCode> {
    match a.kind {
        PlotKind::Slice(s) => {
            crate::outputs::check_with_csv(&s.m.output, &s.m.csv)?;
            let mats = materials(&s.m)?;
            let chart = slice_chart(&mats, &slice_options(&s)?);
            finish(&chart, &s.m.output, &s.m.csv)?;
        }
        PlotKind::Polar(s) => plot_polar(&s)?,
        PlotKind::Hemisphere {
            m,
            theta_i,
            quantity,
            channel,
            log,
            resolution,
        } => plot_hemisphere(&m, theta_i, &quantity, &channel, log, resolution)?,
        PlotKind::Ndf {
            material,
            footprint,
            log,
            resolution,
            supersample,
            output,
            csv,
        } => plot_ndf(
            &material,
            footprint.as_deref(),
            log,
            resolution,
            supersample,
            &output,
            &csv,
        )?,
        PlotKind::Albedo { m, step } => plot_albedo(&m, step)?,
        PlotKind::Table {
            material,
            table,
            theta_i,
            samples,
            points,
            output,
            csv,
        } => plot_table(&material, &table, theta_i, samples, points, &output, &csv)?,
    }
    Ok(ExitCode::SUCCESS)
}

/// `plot polar`: the slice drawn in polar form, with its summary lines.
fn plot_polar(s: &SliceArgs) -> Result<()> {
    let mats = materials(&s.m)?;
    let o = slice_options(s)?;
    let slice = slice_chart(&mats, &o);
    for line in summarize(&slice) {
        println!("{line}");
    }
    let chart = polar_from_slice(slice, &o);
    crate::outputs::check_with_csv(&s.m.output, &s.m.csv)?;
    save_figure(&chart, &s.m.output)?;
    if let Some(p) = &s.m.csv {
        facette_bsdf::storage::atomic_file::write_atomically(p, chart_csv(&chart).as_bytes())
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    println!("wrote {}", s.m.output.display());
    Ok(())
}

/// `plot hemisphere`: one material's values over the outgoing hemisphere.
fn plot_hemisphere(
    m: &MaterialsArgs,
    theta_i: f64,
    quantity: &str,
    channel: &str,
    log: bool,
    resolution: usize,
) -> Result<()> {
    check_theta(theta_i)?;
    if !(8..=512).contains(&resolution) {
        bail!("--resolution {resolution}: expected 8…512 cells");
    }
    let mats = materials(m)?;
    if mats.len() != 1 {
        bail!("a hemisphere map shows one material; got {}", mats.len());
    }
    let map = hemisphere_chart(
        &mats[0],
        theta_i,
        parse_choice("--quantity", quantity, Quantity::parse, Quantity::NAMES)?,
        parse_choice("--channel", channel, Channel::parse, Channel::NAMES)?,
        if log { Scale::Log } else { Scale::Linear },
        resolution,
        m.samples,
        m.seed,
    );
    map.value_range()?;
    let vals = map
        .values
        .iter()
        .flatten()
        .copied()
        .filter(|v| v.is_finite());
    let (lo, hi) = vals.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    println!("hemisphere map, θ_i = {theta_i}°: min {lo:.6e}, max {hi:.6e}");
    save_map(&map, &m.output, &m.csv)
}

/// `plot ndf`: the patch NDF of one glint footprint.
fn plot_ndf(
    material: &str,
    footprint: Option<&str>,
    log: bool,
    resolution: usize,
    supersample: usize,
    output: &Path,
    csv: &Option<PathBuf>,
) -> Result<()> {
    if !(8..=512).contains(&resolution) {
        bail!("--resolution {resolution}: expected 8…512 cells");
    }
    if !(1..=16).contains(&supersample) {
        bail!("--supersample {supersample}: expected 1…16 points per cell side");
    }
    Format::of(output)?;
    let bsdf = parse_glint_at(material, footprint)?;
    let fp = bsdf.query();
    let title = format!(
        "D_P of {} — footprint centre ({:.1}, {:.1}) texels",
        bsdf.surface().label(),
        fp.center.x,
        fp.center.y
    );
    let mut m = patch_ndf_map(&bsdf, title, resolution, supersample);
    m.map.scale = if log { Scale::Log } else { Scale::Linear };
    m.map.value_range()?;
    println!("{}", facette_bsdf::Bsdf::describe(&bsdf));
    println!(
        "patch NDF map ({resolution}² cells, {supersample}² points each): max {:.6e} 1/sr, ∫ D_P cos θ_h dω_h ≈ {:.4}",
        m.max, m.integral
    );
    save_map(&m.map, output, csv)
}

/// `plot albedo`: directional albedo against θ_i, every `step` degrees up to 89°.
fn plot_albedo(m: &MaterialsArgs, step: f64) -> Result<()> {
    if !(0.5..=45.0).contains(&step) {
        bail!(
            "--step {}: expected 0.5…45 degrees",
            facette_bsdf::math::fmt_num(step)
        );
    }
    let mats = materials(m)?;
    let n = (89.0 / step).floor() as usize;
    let mut thetas: Vec<f64> = (0..=n).map(|k| k as f64 * step).collect();
    if *thetas.last().expect("non-empty") < 89.0 {
        thetas.push(89.0);
    }
    let chart = albedo_chart(&mats, &thetas, m.samples.max(1000), m.seed);
    finish(&chart, &m.output, &m.csv)
}

/// `plot table`: an IL body table against the quadrature it tabulates.
fn plot_table(
    material: &str,
    table: &Path,
    theta_i: f64,
    samples: usize,
    points: usize,
    output: &Path,
    csv: &Option<PathBuf>,
) -> Result<()> {
    check_theta(theta_i)?;
    Format::of(output)?;
    let t = parse_inline_table(material).context("--material")?;
    let recipe = MaterialRecipe::parse(&t, std::path::Path::new(".")).context("--material")?;
    let MaterialRecipe::Il {
        kd,
        ni,
        lobe: Some(lobe),
        ..
    } = recipe
    else {
        bail!("--material: `plot table` needs a rough interfaced-Lambertian material (type = \"il\" with a roughness)");
    };
    let body =
        Arc::new(BodyTable::load(table).with_context(|| format!("--table {}", table.display()))?);
    let tabled = InterfacedLambertian::new(
        kd,
        ni,
        Some(lobe.clone()),
        BodyEvaluation::Table(body.clone()),
        Scattering::Single,
    )
    .with_context(|| format!("--table {} does not match --material", table.display()))?;
    let quad = InterfacedLambertian::new(
        kd,
        ni,
        Some(lobe),
        BodyEvaluation::Quadrature { samples },
        Scattering::Single,
    )?;
    let cmp = compare_table(&body, &tabled, &quad, theta_i, points.max(2));
    println!(
        "table vs quadrature at θ_i = {theta_i}°, |θ_o| ≤ 80°: interpolated mean relative error {:.3e}, max {:.3e}; nearest entry mean {:.3e}, max {:.3e}",
        cmp.interpolated_error.0, cmp.interpolated_error.1, cmp.nearest_error.0, cmp.nearest_error.1
    );
    finish(&cmp.chart, output, csv)
}
