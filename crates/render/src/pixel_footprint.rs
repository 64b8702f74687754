//! The footprint of a whole pixel at a camera ray's first hit, for materials whose BSDF is
//! the reflection of a surface patch (glints, CCM19, `footprint = "pixel"`).
//!
//! A glint BSDF is the P-BRDF of the part of the normal map its footprint covers. With the
//! footprint of each sample's own ray differential (scaled by 1/√spp, the default), a pixel
//! averages the map filtered twice — by each footprint, then by the spread of the samples —
//! and converges as the footprints shrink. Here every sample of a pixel shades the same
//! patch: the footprint of the pixel's centre ray, as wide as the reconstruction filter
//! (the Gaussian of the unscaled differentials whose standard deviation is the filter's,
//! [`Filter::stddev`](crate::film::Filter::stddev)), so the glints are converged at a few
//! samples per pixel. Neither footprint converges to the brute-force reference: one lobe
//! per texel is the limit (measured in docs/glints.md).
//!
//! **The frame of the centre.** The map's slopes are relative to the geometric normal of
//! the point where they lie; a patch's lobes are combined with one frame. The sample's own
//! frame is off by the surface's turn between the sample and the patch's centre (on the
//! test sphere 0.0066 in slope per pixel, beside σ_ε = 0.01: the highlight moves with it;
//! the scratched sphere's RMSE against the reference was 0.52 in the sample's frame, 0.45
//! in the centre's).
//! In the centre's frame each lobe is off by the turn between the centre and its own
//! position, which averages to zero over the patch (what remains is a spread of the turn's
//! variance over the footprint, second order). So the BSDF is built at the centre ray's hit
//! and the vertex shades in that hit's shading frame; positions, light connections and
//! the geometric side stay the sample's own.
//!
//! Where the centre ray does not hit the sample's shape, or hits its other side (silhouettes
//! of the shape), the sample keeps its own ray footprint.

use crate::camera::Camera;
use crate::geometry::{HitDetail, Ray, RayDifferential, SurfaceHit, Vec2};
use crate::scene::Scene;
use facette_bsdf::math::Frame;
use facette_bsdf::recipe::material::glint::PIXEL_FOOTPRINT_SIGMA;

/// The camera ray through a pixel's centre (with the sample's lens position) and its
/// unscaled differentials: one pixel step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelRay {
    pub ray: Ray,
    pub rd: RayDifferential,
}

impl PixelRay {
    /// The centre ray of pixel (x, y) for the lens position `u_lens`.
    pub fn new(camera: &Camera, x: u32, y: u32, u_lens: Vec2) -> PixelRay {
        let (ray, rd) = camera.generate_ray(x as f64 + 0.5, y as f64 + 0.5, u_lens);
        PixelRay { ray, rd }
    }
}

/// What a vertex shades with in place of its own hit's details.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelShading {
    /// The centre hit's texture coordinates.
    pub uv: Vec2,
    /// `[du/dx, dv/dx, du/dy, dv/dy]` of the centre hit, scaled so that the footprint's
    /// standard deviation is the reconstruction filter's.
    pub derivs: [f64; 4],
    /// The centre hit's shading frame.
    pub frame: Frame,
}

/// The pixel's footprint for a camera ray's hit `hit` (travelling along `dir`): the centre
/// ray's hit on the same shape and side, or `None` (module notes).
pub fn pixel_shading(
    scene: &Scene,
    hit: &SurfaceHit,
    dir: crate::geometry::Vec3,
    pixel: &PixelRay,
) -> Option<PixelShading> {
    let mut centre = scene
        .geometry
        .intersect_with(&pixel.ray, HitDetail::Shading)?;
    let same_side = (centre.ng.dot(pixel.ray.dir) < 0.0) == (hit.ng.dot(dir) < 0.0);
    if centre.shape != hit.shape || !same_side {
        return None;
    }
    scene.geometry.complete_hit(&mut centre);
    let scale = scene.film.filter.stddev() / PIXEL_FOOTPRINT_SIGMA;
    // Finite: `uv_derivatives` clamps them, and the filter's width is finite.
    let derivs = centre.uv_derivatives(&pixel.rd).map(|d| d * scale);
    Some(PixelShading {
        uv: centre.uv,
        derivs,
        frame: centre.shading_frame(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene_str;
    use std::path::Path;

    fn scene(filter: &str) -> Scene {
        let src = format!(
            r#"
            [camera]
            position = [0, 0, 4]
            target = [0, 0, 0]
            fov = 35
            [film]
            width = 64
            height = 64
            filter = "{filter}"
            [[objects]]
            shape = "sphere"
            radius = 1
            material = {{ type = "glint", generate = "bumpy", resolution = 64, footprint = "pixel" }}
            [[lights]]
            type = "point"
            position = [3, 3, 4]
            intensity = 10
            "#
        );
        load_scene_str(&src, Path::new("t.toml")).unwrap()
    }

    #[test]
    fn a_sample_shades_with_its_pixel_centre_and_the_filter_width() {
        let s = scene("box");
        let lens = Vec2::new(0.5, 0.5);
        let (x, y) = (40u32, 25u32);
        let pixel = PixelRay::new(&s.camera, x, y, lens);
        // A sample a third of a pixel off the centre.
        let (ray, _) = s
            .camera
            .generate_ray(x as f64 + 0.83, y as f64 + 0.21, lens);
        let hit = s.geometry.intersect_with(&ray, HitDetail::Shading).unwrap();
        let c = pixel_shading(&s, &hit, ray.dir, &pixel).unwrap();
        let mut centre = s
            .geometry
            .intersect_with(&pixel.ray, HitDetail::Shading)
            .unwrap();
        s.geometry.complete_hit(&mut centre);
        assert_eq!(c.uv, centre.uv);
        assert_eq!(c.frame, centre.shading_frame());
        // Not the sample's own frame: the sphere turns between the two points.
        assert!((c.frame.n - hit.ns).length() > 1e-4);
        // The box filter's standard deviation 1/√12 against the footprint's 0.5 steps.
        let d = centre.uv_derivatives(&pixel.rd);
        let k = (1.0f64 / 12.0).sqrt() / PIXEL_FOOTPRINT_SIGMA;
        for (got, d) in c.derivs.iter().zip(d) {
            assert!((got - k * d).abs() <= 1e-15 * d.abs().max(1.0));
        }
    }

    #[test]
    fn off_the_shape_the_sample_keeps_its_own_footprint() {
        // Pixel (x, 32)'s centre misses the sphere where its sample still hits it: the
        // silhouette, found by walking out along the middle row.
        let s = scene("gaussian");
        let lens = Vec2::new(0.5, 0.5);
        let mut checked = 0;
        for x in 32..64u32 {
            let pixel = PixelRay::new(&s.camera, x, 32, lens);
            if s.geometry
                .intersect_with(&pixel.ray, HitDetail::Shading)
                .is_some()
            {
                continue;
            }
            let (ray, _) = s.camera.generate_ray(x as f64 + 0.02, 32.5, lens);
            if let Some(hit) = s.geometry.intersect_with(&ray, HitDetail::Shading) {
                assert!(pixel_shading(&s, &hit, ray.dir, &pixel).is_none());
                checked += 1;
            }
        }
        assert!(checked > 0, "no silhouette pixel found");
    }
}
