//! The camera: its frame (look-at, or a translated Mitsuba sensor's own), field of view,
//! and thin-lens aperture.

use super::context::Ctx;
use super::values::finite3;
use crate::camera::{Camera, FovAxis};
use crate::geometry::Transform;
use crate::scene::description::CameraDesc;
use crate::scene::{FilmSettings, SceneError};
use toml::Spanned;

/// The camera of the description, for an image of the size of `film`.
pub(super) fn create_camera(
    ctx: &Ctx,
    desc: Spanned<CameraDesc>,
    film: &FilmSettings,
) -> Result<Camera, SceneError> {
    let cam_span = desc.span();
    let c = desc.into_inner();
    let position = finite3(ctx, &cam_span, "position", c.position)?;
    let target = finite3(ctx, &cam_span, "target", c.target)?;
    let up = finite3(ctx, &cam_span, "up", c.up)?;
    if !(c.fov > 0.0 && c.fov < 180.0) {
        return Err(ctx.err(
            Some(cam_span),
            format!("camera `fov` = {} must be in (0, 180) degrees", c.fov),
        ));
    }
    let axis = match &c.fov_axis {
        None => FovAxis::X,
        Some(s) => FovAxis::parse(s).ok_or_else(|| {
            ctx.err(
                Some(cam_span.clone()),
                format!(
                    "unknown fov_axis `{s}`; valid: {}",
                    FovAxis::NAMES.join(", ")
                ),
            )
        })?,
    };
    // A translated Mitsuba sensor brings its own frame (which may mirror the image).
    let to_world = match c.to_world {
        Some(t) => t,
        None => Transform::look_at(position, target, up)
            .map_err(|e| ctx.err(Some(cam_span.clone()), format!("camera: {e}")))?,
    };
    if !(c.aperture_radius >= 0.0 && c.aperture_radius.is_finite()) {
        return Err(ctx.err(Some(cam_span), "`aperture_radius` must be ≥ 0"));
    }
    let focus = c.focus_distance.unwrap_or((target - position).length());
    if !(focus > 0.0 && focus.is_finite()) {
        return Err(ctx.err(Some(cam_span), "`focus_distance` must be > 0"));
    }
    Ok(Camera::new(
        to_world,
        c.fov,
        axis,
        film.width,
        film.height,
        c.aperture_radius,
        focus,
    ))
}
