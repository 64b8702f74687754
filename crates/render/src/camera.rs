//! The perspective camera, with an optional thin lens, in Mitsuba 3's conventions: the
//! camera frame is `look_at(position, target, up)` (local +z toward the target, +y up), and
//! image x grows toward local −x so that the image is not mirrored (Mitsuba's perspective
//! sensor scales x and y by −½ from its normalized device coordinates).

use crate::geometry::{Ray, RayDifferential, Transform, Vec2, Vec3};
use facette_bsdf::lanes::{LVec3, Real};
use facette_bsdf::math::warp::{square_to_disk_concentric, square_to_disk_concentric_lanes};

/// Which image axis `fov` spans (Mitsuba's `fov_axis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FovAxis {
    X,
    Y,
    Diagonal,
    Smaller,
    Larger,
}

impl FovAxis {
    pub const NAMES: &'static [&'static str] = &["x", "y", "diagonal", "smaller", "larger"];

    pub fn parse(s: &str) -> Option<FovAxis> {
        Some(match s {
            "x" => FovAxis::X,
            "y" => FovAxis::Y,
            "diagonal" => FovAxis::Diagonal,
            "smaller" => FovAxis::Smaller,
            "larger" => FovAxis::Larger,
            _ => return None,
        })
    }
}

#[derive(Clone, Debug)]
pub struct Camera {
    to_world: Transform,
    /// The camera's position and its local axes in world space (the rigid part of
    /// `to_world`, kept apart so that a primary ray costs one 3×3 product per direction).
    origin: Vec3,
    axes: glam::DMat3,
    /// tan of half the field of view along x and y.
    tan_x: f64,
    tan_y: f64,
    lens_radius: f64,
    focus_distance: f64,
    width: usize,
    height: usize,
}

impl Camera {
    /// `fov_deg` in (0, 180) along `axis`; a lens radius > 0 enables depth of field focused
    /// at `focus_distance` along the view axis.
    pub fn new(
        to_world: Transform,
        fov_deg: f64,
        axis: FovAxis,
        width: usize,
        height: usize,
        lens_radius: f64,
        focus_distance: f64,
    ) -> Camera {
        let (w, h) = (width as f64, height as f64);
        let t = (0.5 * fov_deg.to_radians()).tan();
        let axis = match axis {
            FovAxis::Smaller => {
                if w <= h {
                    FovAxis::X
                } else {
                    FovAxis::Y
                }
            }
            FovAxis::Larger => {
                if w >= h {
                    FovAxis::X
                } else {
                    FovAxis::Y
                }
            }
            a => a,
        };
        let (tan_x, tan_y) = match axis {
            FovAxis::X => (t, t * h / w),
            FovAxis::Y => (t * w / h, t),
            _ => {
                let d = (w * w + h * h).sqrt();
                (t * w / d, t * h / d)
            }
        };
        let m = to_world.matrix();
        Camera {
            origin: to_world.point(Vec3::ZERO),
            axes: glam::DMat3::from_cols(
                m.x_axis.truncate(),
                m.y_axis.truncate(),
                m.z_axis.truncate(),
            ),
            to_world,
            tan_x,
            tan_y,
            lens_radius,
            focus_distance,
            width,
            height,
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// Local (camera-space) direction through the continuous film position (x, y) in
    /// pixels, y down.
    #[inline]
    fn local_dir(&self, x: f64, y: f64) -> Vec3 {
        let sx = 1.0 - 2.0 * x / self.width as f64;
        let sy = 1.0 - 2.0 * y / self.height as f64;
        Vec3::new(sx * self.tan_x, sy * self.tan_y, 1.0)
    }

    /// Whether rays read their lens sample (a thin lens); a pinhole camera ignores it.
    #[inline]
    pub fn has_lens(&self) -> bool {
        self.lens_radius > 0.0
    }

    /// The world origin of the rays through lens sample `u_lens`, and the world direction
    /// from it through the local pinhole direction `dl`: every ray through a lens point
    /// meets its pinhole ray on the focal plane. A pinhole camera uses its origin.
    #[inline]
    fn through_lens(&self, u_lens: Vec2) -> (Vec3, impl Fn(Vec3) -> Vec3 + '_) {
        let lens = (self.lens_radius > 0.0).then(|| {
            let l = square_to_disk_concentric(u_lens) * self.lens_radius;
            Vec3::new(l.x, l.y, 0.0)
        });
        let origin = lens.map_or(self.origin, |o| self.to_world.point(o));
        let dir = move |dl: Vec3| match lens {
            Some(o) => (self.axes * (dl * (self.focus_distance / dl.z) - o)).normalize(),
            None => (self.axes * dl).normalize(),
        };
        (origin, dir)
    }

    /// The primary ray through film position (x, y), without differentials (for scenes
    /// whose materials read no texture footprint); the same ray as
    /// [`generate_ray`](Self::generate_ray)'s.
    pub fn generate_primary_ray(&self, x: f64, y: f64, u_lens: Vec2) -> Ray {
        let (o, d) = self.primary_rays(x, y, (u_lens.x, u_lens.y));
        Ray {
            origin: o.into(),
            dir: d.into(),
            t_max: f64::INFINITY,
        }
    }

    /// [`generate_primary_ray`](Self::generate_primary_ray) over lanes of film positions
    /// and lens samples — its one source, with glam's order of operations — as (origins,
    /// unit directions; normalized twice, as the ray constructor did).
    #[inline(always)]
    pub fn primary_rays<R: Real>(&self, x: R, y: R, u_lens: (R, R)) -> (LVec3<R>, LVec3<R>) {
        let one = R::one();
        let sx = one - R::splat(2.0) * x / R::splat(self.width as f64);
        let sy = one - R::splat(2.0) * y / R::splat(self.height as f64);
        let dl = LVec3::new(sx * R::splat(self.tan_x), sy * R::splat(self.tan_y), one);
        // A function, not a closure: closures are compiled for the baseline CPU, out of
        // the render kernel's AVX2 code.
        #[inline(always)]
        fn to_axes<R: Real>(m: &glam::DMat3, v: LVec3<R>) -> LVec3<R> {
            let (x, y, z) = (m.x_axis, m.y_axis, m.z_axis);
            LVec3::new(
                R::splat(x.x) * v.x + R::splat(y.x) * v.y + R::splat(z.x) * v.z,
                R::splat(x.y) * v.x + R::splat(y.y) * v.y + R::splat(z.y) * v.z,
                R::splat(x.z) * v.x + R::splat(y.z) * v.y + R::splat(z.z) * v.z,
            )
        }
        if self.lens_radius > 0.0 {
            let (lx, ly) = square_to_disk_concentric_lanes(u_lens.0, u_lens.1);
            let r = R::splat(self.lens_radius);
            let lens = LVec3::new(lx * r, ly * r, R::zero());
            let origin = self.to_world.point_lanes(lens);
            let focus = dl.scale(R::splat(self.focus_distance) / dl.z);
            (
                origin,
                to_axes(&self.axes, focus - lens).normalize().normalize(),
            )
        } else {
            (
                LVec3::splat(self.origin),
                to_axes(&self.axes, dl).normalize().normalize(),
            )
        }
    }

    /// The primary ray through film position (x, y) and its differentials toward
    /// (x + 1, y) and (x, y + 1); `u_lens` samples the aperture.
    pub fn generate_ray(&self, x: f64, y: f64, u_lens: Vec2) -> (Ray, RayDifferential) {
        let dl = self.local_dir(x, y);
        // One film pixel in local direction space.
        let step_x = Vec3::new(-2.0 * self.tan_x / self.width as f64, 0.0, 0.0);
        let step_y = Vec3::new(0.0, -2.0 * self.tan_y / self.height as f64, 0.0);
        let (o, dir) = self.through_lens(u_lens);
        let ray = Ray::infinite(o, dir(dl));
        let rd = RayDifferential {
            rx_origin: o,
            rx_dir: dir(dl + step_x),
            ry_origin: o,
            ry_dir: dir(dl + step_y),
        };
        (ray, rd)
    }

    /// Film position of a world direction from the pinhole (for tests): `None` behind the
    /// camera.
    pub fn project(&self, d_world: Vec3) -> Option<(f64, f64)> {
        let l = self.to_world.inverse_vector(d_world);
        if l.z <= 0.0 {
            return None;
        }
        let (sx, sy) = (l.x / l.z / self.tan_x, l.y / l.z / self.tan_y);
        Some((
            0.5 * (1.0 - sx) * self.width as f64,
            0.5 * (1.0 - sy) * self.height as f64,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_looks_at_the_target_and_the_image_is_not_mirrored() {
        let t = Transform::look_at(Vec3::new(0.0, 0.0, -5.0), Vec3::ZERO, Vec3::Y).unwrap();
        let cam = Camera::new(t, 40.0, FovAxis::X, 200, 100, 0.0, 1.0);
        let (r, _) = cam.generate_ray(100.0, 50.0, Vec2::ZERO);
        assert!((r.dir - Vec3::Z).length() < 1e-12);
        // Looking along +z with +y up, world +x is on the left of the image (Mitsuba).
        let (x, y) = cam.project(Vec3::new(1.0, 0.0, 5.0).normalize()).unwrap();
        assert!(x < 100.0 && (y - 50.0).abs() < 1e-9, "{x} {y}");
        // Up is up: +y projects to the upper half (smaller row index).
        let (_, y) = cam.project(Vec3::new(0.0, 1.0, 5.0).normalize()).unwrap();
        assert!(y < 50.0);
        // fov along x: the left edge is at 20°.
        let (r, _) = cam.generate_ray(0.0, 50.0, Vec2::ZERO);
        assert!((r.dir.angle_between(Vec3::Z).to_degrees() - 20.0).abs() < 1e-9);
    }
}
