//! The integrator plugin as facette's path-tracer settings.
//!
//! | Mitsuba | facette |
//! |---|---|
//! | `path` (`max_depth` −1 = unlimited, `rr_depth` 5, `hide_emitters` false) | `max_depth` (the same convention: the camera ray is segment 1; −1 becomes 1024, facette's largest, far beyond where Russian roulette ends paths), `rr_depth` |
//! | no integrator | `path` with Mitsuba's defaults |

use super::plugin::Plugin;
use super::translator::Translator;
use crate::scene::description::IntegratorDesc;
use crate::scene::SceneError;

/// facette's longest path, standing for Mitsuba's "unlimited".
pub(crate) const UNLIMITED_DEPTH: u32 = 1024;

/// Mitsuba's `path` defaults.
pub(crate) fn default_integrator() -> IntegratorDesc {
    IntegratorDesc {
        max_depth: UNLIMITED_DEPTH,
        rr_depth: 5,
        kernel: None,
    }
}

pub(crate) fn integrator(cx: &Translator, p: &Plugin) -> Result<IntegratorDesc, SceneError> {
    if p.kind != "path" {
        return Err(p.err(format!(
            "unsupported integrator `{}`; supported: path (facette's MIS path tracer)",
            p.kind
        )));
    }
    let mut d = default_integrator();
    match p.integer("max_depth")? {
        None | Some(-1) => {}
        Some(v) if (1..=UNLIMITED_DEPTH as i64).contains(&v) => d.max_depth = v as u32,
        Some(v) => {
            return Err(p.err(format!(
                "`max_depth` = {v} must be −1 (unlimited) or in 1…{UNLIMITED_DEPTH}"
            )))
        }
    }
    match p.integer("rr_depth")? {
        None => {}
        Some(v) if (0..=u32::MAX as i64).contains(&v) => d.rr_depth = v as u32,
        Some(v) => return Err(p.err(format!("`rr_depth` = {v} must be ≥ 0"))),
    }
    if p.boolean("hide_emitters")? == Some(true) {
        return Err(p.err(
            "`hide_emitters` = true is not supported: facette's camera rays always see emitters",
        ));
    }
    p.finish(&["max_depth", "rr_depth", "hide_emitters"], &cx.reg)?;
    Ok(d)
}
