//! The film and integrator settings of a scene: sizes, samples, filter, sampler, depths.

use super::context::Ctx;
use crate::film::Filter;
use crate::kernel::Kernel;
use crate::sampler::SamplerKind;
use crate::scene::description::{FilmDesc, IntegratorDesc};
use crate::scene::{FilmSettings, IntegratorSettings, SceneError};
use facette_bsdf::limits;
use toml::Spanned;

/// The film of the description (defaults where there is no `[film]`), validated.
pub(super) fn create_film(
    ctx: &Ctx,
    desc: Option<Spanned<FilmDesc>>,
) -> Result<FilmSettings, SceneError> {
    let film_span = desc.as_ref().map(|f| f.span());
    let f = desc.map(|f| f.into_inner()).unwrap_or_default();
    if f.width == 0 || f.height == 0 {
        return Err(ctx.err(
            film_span.clone(),
            format!(
                "film size {}×{}: width and height must be at least 1",
                f.width, f.height
            ),
        ));
    }
    // Checked before anything is allocated: a 65536² film would need 220 GB.
    let size = limits::FILM_SIDE
        .check_usize(f.width.max(f.height))
        .and_then(|_| limits::FILM_PIXELS.check_product(&[f.width as u64, f.height as u64]));
    if let Err(x) = size {
        return Err(ctx.err(film_span.clone(), format!("film size: {x}")));
    }
    if f.spp == 0 {
        return Err(ctx.err(film_span.clone(), "`spp` must be at least 1"));
    }
    if let Err(x) = limits::SAMPLES_PER_PIXEL.check_usize(f.spp) {
        return Err(ctx.err(film_span.clone(), format!("`spp`: {x}")));
    }
    limits::check_exposure(f.exposure)
        .map_err(|m| ctx.err(film_span.clone(), format!("`exposure`: {m}")))?;
    let filter = match f.filter.as_str() {
        "box" => Filter::Box,
        "gaussian" => {
            if !(f.filter_stddev > 0.0
                && f.filter_stddev.is_finite()
                && f.filter_radius > 0.0
                && f.filter_radius.is_finite())
            {
                return Err(ctx.err(
                    film_span.clone(),
                    "`filter_stddev` and `filter_radius` must be positive",
                ));
            }
            Filter::gaussian(f.filter_stddev, f.filter_radius)
        }
        other => {
            return Err(ctx.err(
                film_span,
                format!(
                    "unknown filter `{other}`; valid: {}",
                    Filter::NAMES.join(", ")
                ),
            ));
        }
    };
    let Some(sampler) = SamplerKind::parse(&f.sampler) else {
        return Err(ctx.err(
            film_span,
            format!(
                "unknown sampler `{}`; valid: {}",
                f.sampler,
                SamplerKind::NAMES.join(", ")
            ),
        ));
    };
    Ok(FilmSettings {
        width: f.width,
        height: f.height,
        spp: f.spp,
        filter,
        exposure: f.exposure,
        sampler,
    })
}

/// The integrator of the description (defaults where there is no `[integrator]`).
pub(super) fn create_integrator(
    ctx: &Ctx,
    desc: Option<Spanned<IntegratorDesc>>,
) -> Result<IntegratorSettings, SceneError> {
    let integ_span = desc.as_ref().map(|i| i.span());
    let i = desc.map(|i| i.into_inner()).unwrap_or_default();
    if i.max_depth == 0 || i.max_depth > 1024 {
        return Err(ctx.err(integ_span, "`max_depth` must be in 1…1024"));
    }
    let kernel = match i.kernel.as_deref() {
        None => Kernel::default(),
        Some(name) => Kernel::parse(name).ok_or_else(|| {
            ctx.err(
                integ_span,
                format!(
                    "unknown kernel `{name}`; valid kernels: {}",
                    Kernel::NAMES.join(", ")
                ),
            )
        })?,
    };
    Ok(IntegratorSettings {
        max_depth: i.max_depth,
        rr_depth: i.rr_depth,
        kernel,
    })
}
