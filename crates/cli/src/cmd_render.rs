//! `facette render`: loads a scene, renders it with a progress bar, stops cleanly on Ctrl-C
//! or a time limit (the image so far is written), writes EXR or PNG atomically and prints a
//! summary line.

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use facette_bsdf::limits;
use facette_render::integrator::Strategy;
use facette_render::kernel::Kernel;
use facette_render::render::{render, RenderOptions, RenderStats};
use facette_render::sampler::SamplerKind;
use facette_render::scene::{load_scene_with, LoadOptions, Scene};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

#[derive(Clone, Copy, Debug, ValueEnum)]
enum StrategyArg {
    /// Next-event estimation and BSDF sampling combined by MIS (the default).
    Mis,
    /// Light sampling only (for testing the estimators).
    Nee,
    /// BSDF sampling only (for testing the estimators).
    Bsdf,
}

#[derive(Args)]
pub struct RenderArgs {
    /// Scene file: facette TOML or Mitsuba 3 XML, `.xml` (docs/scene-format.md, the
    /// latter in its section "Mitsuba scenes").
    scene: PathBuf,
    /// Mitsuba XML scenes: gives `$NAME` a value, overriding the scene's
    /// `<default name="NAME">` (repeatable).
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define)]
    define: Vec<(String, String)>,
    /// Output image: `.exr` (linear float) or `.png` (sRGB, 8 bit, film exposure applied).
    /// Defaults to the scene's name with `.exr`, in the current directory.
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
    /// Samples per pixel (overrides the scene's film `spp`).
    #[arg(long)]
    spp: Option<usize>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Seed of the random streams: the same seed gives the same image.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Stop after this many seconds and write the image rendered so far.
    #[arg(long, value_name = "SECS")]
    time_limit: Option<f64>,
    /// Exposure in stops (overrides the scene's film `exposure`).
    #[arg(long)]
    exposure: Option<f64>,
    /// Which estimators to use.
    #[arg(long, value_enum, default_value = "mis")]
    strategy: StrategyArg,
    /// Pixel sampler (overrides the scene's film `sampler`): `sobol` (Owen-scrambled
    /// Sobol in Morton order, the default), `independent` or `stratified`.
    #[arg(long, value_name = "NAME", value_parser = parse_sampler)]
    sampler: Option<SamplerKind>,
    /// Render kernel (overrides the scene's `[integrator] kernel`): `auto` (the default:
    /// `packet`, or `scalar` for a hierarchy too large to traverse as packets), `scalar`
    /// (one camera sample at a time, f64) or `packet` (eight in flight per thread,
    /// materials in f32 lanes; see docs/performance.md).
    #[arg(long, value_name = "NAME", value_parser = parse_kernel)]
    kernel: Option<Kernel>,
    /// Render part K of N of the samples (K from 0) and write the exact partial result to
    /// a `.fcpart` file for `facette merge` (distributed rendering; see docs/scale-out.md).
    #[arg(long, value_name = "K/N")]
    part: Option<String>,
    /// No progress bar and no summary.
    #[arg(long, short)]
    quiet: bool,
}

/// Parses a sampler name, listing the valid ones when it is unknown.
fn parse_sampler(s: &str) -> Result<SamplerKind, String> {
    SamplerKind::parse(s).ok_or_else(|| {
        format!(
            "unknown sampler `{s}`; valid: {}",
            SamplerKind::NAMES.join(", ")
        )
    })
}

/// Parses a kernel name, listing the valid ones when it is unknown.
fn parse_kernel(s: &str) -> Result<Kernel, String> {
    Kernel::parse(s)
        .ok_or_else(|| format!("unknown kernel `{s}`; valid: {}", Kernel::NAMES.join(", ")))
}

/// Parses `K/N` with 0 ≤ K < N.
pub fn parse_part(s: &str) -> Result<(u32, u32)> {
    let parsed = s
        .split_once('/')
        .and_then(|(k, n)| Some((k.trim().parse::<u32>().ok()?, n.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((k, n)) if n > 0 && k < n => Ok((k, n)),
        _ => bail!("--part {s}: expected K/N with 0 ≤ K < N, e.g. 0/8"),
    }
}

pub fn run(a: RenderArgs) -> Result<ExitCode> {
    let part = a.part.as_deref().map(parse_part).transpose()?;
    let output = a
        .output
        .clone()
        .unwrap_or_else(|| default_output(&a.scene, part));
    check_output(&output, part.is_some())?;
    check_args(&a, part.is_some())?;

    let load_start = Instant::now();
    let options = LoadOptions {
        defines: a.define.clone(),
    };
    let scene = load_scene_with(&a.scene, &options)?;
    let load_secs = load_start.elapsed().as_secs_f64();
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let spp = a.spp.unwrap_or(scene.film.spp);
    let (w, h) = (scene.film.width, scene.film.height);
    // The scene's film was checked when loaded; --spp may make the product too large.
    let total = limits::RENDER_SAMPLES
        .check_product(&[w as u64, h as u64, spp as u64])
        .map_err(|e| anyhow::anyhow!("--spp {spp} on a {w}×{h} film: {e}"))?;

    let cancel = Arc::new(AtomicBool::new(false));
    install_interrupt_handler(&cancel);
    let pb = progress_bar(total, a.quiet);
    let start = Instant::now();
    let progress = |done: u64, total: u64| {
        pb.set_length(total);
        pb.set_position(done);
        let secs = start.elapsed().as_secs_f64().max(1e-9);
        pb.set_message(format!("{:.2} Msamples/s", done as f64 / secs / 1e6));
    };
    let opts = RenderOptions {
        spp: Some(spp),
        seed: a.seed,
        threads: a.threads,
        time_limit: a.time_limit,
        part: None,
        sampler: a.sampler,
        kernel: a.kernel,
        strategy: match a.strategy {
            StrategyArg::Mis => Strategy::Mis,
            StrategyArg::Nee => Strategy::NeeOnly,
            StrategyArg::Bsdf => Strategy::BsdfOnly,
        },
    };
    if let Some((k, n)) = part {
        let res =
            facette_render::partial_film::render_part(&scene, &opts, k, n, &cancel, &progress);
        pb.finish_and_clear();
        if cancel.load(Ordering::SeqCst) {
            eprintln!("interrupted: part {k}/{n} is incomplete and was not written");
            return Ok(ExitCode::from(130));
        }
        let (partial, stats) = res.map_err(anyhow::Error::msg)?;
        for w in scene.shading_warnings() {
            eprintln!("warning: {w}");
        }
        start_writing();
        partial.save(&output)?;
        if !a.quiet {
            eprintln!(
                "{} (part {k}/{n}, {w}×{h}, {} samples of {spp} spp): rendered in {:.2} s, {:.2} Msamples/s, {} discarded samples",
                output.display(),
                stats.samples,
                stats.seconds,
                stats.msamples_per_second(),
                stats.discarded
            );
        }
        return Ok(ExitCode::SUCCESS);
    }
    let (film, stats) = render(&scene, &opts, &cancel, &progress).map_err(anyhow::Error::msg)?;
    pb.finish_and_clear();
    for w in scene.shading_warnings() {
        eprintln!("warning: {w}");
    }

    let exposure = a.exposure.unwrap_or(scene.film.exposure);
    let image = film.image();
    start_writing();
    facette_render::image::write_image(&output, &image, exposure)
        .with_context(|| format!("writing {}", output.display()))?;

    if !a.quiet {
        let empty = film.counts.iter().filter(|&&c| c == 0).count();
        eprintln!(
            "{}",
            summary(&output, &scene, spp, &stats, load_secs, empty)
        );
    }
    Ok(if cancel.load(Ordering::SeqCst) {
        ExitCode::from(130)
    } else {
        ExitCode::SUCCESS
    })
}

/// The output named after the scene: `STEM.exr`, or `STEM.partKofN.fcpart` for a part.
fn default_output(scene: &Path, part: Option<(u32, u32)>) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    match part {
        Some((k, n)) => PathBuf::from(format!("{stem}.part{k}of{n}.fcpart")),
        None => PathBuf::from(stem).with_extension("exr"),
    }
}

/// The checks of the numeric options, before the scene is loaded.
fn check_args(a: &RenderArgs, is_part: bool) -> Result<()> {
    if is_part && a.time_limit.is_some() {
        bail!("--time-limit cannot be used with --part: a part must hold all its samples for an exact merge");
    }
    if let Some(s) = a.spp {
        if s == 0 {
            bail!("--spp must be at least 1");
        }
        limits::SAMPLES_PER_PIXEL
            .check_usize(s)
            .map_err(|e| anyhow::anyhow!("--spp: {e}"))?;
    }
    if let Some(t) = a.threads {
        if t == 0 {
            bail!("--threads must be at least 1");
        }
        limits::THREADS
            .check_usize(t)
            .map_err(|e| anyhow::anyhow!("--threads: {e}"))?;
    }
    if let Some(t) = a.time_limit {
        let max = limits::TIME_LIMIT_SECONDS;
        if !(t.is_finite() && t > 0.0 && t <= max) {
            bail!(
                "--time-limit must be a number of seconds in (0, {max:e}], got {}",
                facette_bsdf::math::fmt_num(t)
            );
        }
    }
    if let Some(e) = a.exposure {
        limits::check_exposure(e).map_err(|m| anyhow::anyhow!("--exposure: {m}"))?;
    }
    Ok(())
}

/// What the process is doing, for the Ctrl-C handler: a second Ctrl-C exits at once while
/// rendering (nothing written), but not while the output is being written — exiting then
/// would leave a temporary file beside the output, or an image written after the message
/// "exiting without writing". The lock makes the check and the exit one step with respect
/// to the start of the write.
static WRITING: Mutex<bool> = Mutex::new(false);

/// Marks the start of the output's write: from now on a Ctrl-C lets the write finish.
fn start_writing() {
    *WRITING.lock().unwrap_or_else(|p| p.into_inner()) = true;
}

/// Ctrl-C sets `cancel` (the render stops after the tiles in flight and writes what it
/// has); a second Ctrl-C exits at once without writing (the previous output stays) unless
/// the write has started, which then completes.
fn install_interrupt_handler(cancel: &Arc<AtomicBool>) {
    let cancel = cancel.clone();
    let res = ctrlc::set_handler(move || {
        let writing = WRITING.lock().unwrap_or_else(|p| p.into_inner());
        if *writing {
            eprintln!("\ninterrupted while writing the output: the write completes first");
            return;
        }
        if cancel.swap(true, Ordering::SeqCst) {
            eprintln!("\ninterrupted twice: exiting without writing");
            // Exits with the lock held, so the write cannot start meanwhile.
            std::process::exit(130);
        }
        eprintln!("\nstopping: finishing the tiles in flight, then writing the image so far (Ctrl-C again to abort)");
    });
    if let Err(e) = res {
        eprintln!("warning: Ctrl-C handler not installed ({e}); Ctrl-C will abort without writing");
    }
}

/// The progress bar over `total` samples, hidden when quiet or not on a terminal.
fn progress_bar(total: u64, quiet: bool) -> ProgressBar {
    let pb = ProgressBar::new(total);
    if quiet || !std::io::stderr().is_terminal() {
        pb.set_draw_target(ProgressDrawTarget::hidden());
    }
    pb.set_style(
        ProgressStyle::with_template(
            "rendering [{bar:40}] {percent:>3}% {msg} elapsed {elapsed} eta {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    pb
}

/// The line printed after a render: sizes, samples, times, and what went missing.
fn summary(
    output: &Path,
    scene: &Scene,
    spp: usize,
    stats: &RenderStats,
    load_secs: f64,
    empty: usize,
) -> String {
    let (w, h) = (scene.film.width, scene.film.height);
    let samples = stats.samples;
    let mean_spp = samples as f64 / (w * h) as f64;
    let mut line = format!(
        "{} ({w}×{h}, {} spp{}): scene loaded in {load_secs:.2} s ({} primitives), rendered in {:.2} s, {:.2} Msamples/s, {} discarded samples (NaN/Inf/negative){}",
        output.display(),
        if stats.interrupted { format!("{mean_spp:.1} of {spp}") } else { spp.to_string() },
        if stats.interrupted { ", interrupted" } else { "" },
        scene.geometry.primitive_count(),
        stats.seconds,
        stats.msamples_per_second(),
        stats.discarded,
        if empty > 0 { format!(", {empty} pixels without samples (black)") } else { String::new() },
    );
    if stats.discarded > 0 {
        line.push_str(&format!(
            " = {:.2e} of all samples",
            stats.discarded as f64 / samples.max(1) as f64
        ));
    }
    line
}

/// `NAME=VALUE` of `-D`.
fn parse_define(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((name, value)) if !name.trim().is_empty() => {
            Ok((name.trim().to_string(), value.to_string()))
        }
        _ => Err(format!("`{s}` is not NAME=VALUE")),
    }
}

/// Fails before rendering when the output could not be written: an unknown extension or a
/// missing directory.
pub fn check_output(path: &Path, partial: bool) -> Result<()> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match (ext.as_deref(), partial) {
        (Some("exr") | Some("png"), false) | (Some("fcpart"), true) => {}
        (_, true) => bail!(
            "-o {}: a part is written to a `.fcpart` file",
            path.display()
        ),
        (Some(e), false) => bail!(
            "-o {}: unsupported image extension `.{e}`; valid: .exr, .png",
            path.display()
        ),
        (None, false) => bail!(
            "-o {}: the output needs an extension, .exr or .png",
            path.display()
        ),
    }
    crate::outputs::check_writable(&[("-o", path)])
}
