//! The glint view: the patch NDF D_P of a glint material's footprint [CCM19 eq. 9] over the
//! projected disk of half vectors (the lab's [`patch_ndf_map`], each cell averaged over
//! supersample² points), with its integral ∫ D_P cos θ_h dω_h (≈ 1: a check the view
//! prints).

use crate::frame::Frame;
use facette_bsdf::recipe::{parse_inline_table, MaterialRecipe};
use facette_bsdf::Vec2;
use facette_lab::plot::ndf_map::patch_ndf_map;
use facette_render::image::ImageNormalMapReader;
use serde::Deserialize;

#[derive(Clone, Debug, Deserialize)]
pub struct PatchNdfRequest {
    pub material: String,
    /// Cells per side of the disk.
    pub n: usize,
    #[serde(default = "two")]
    pub supersample: usize,
}

fn two() -> usize {
    2
}

impl PatchNdfRequest {
    pub fn check(&self) -> Result<(), String> {
        if !(8..=crate::views::MAX_GRID).contains(&self.n) {
            return Err(format!(
                "`n` = {} is out of range: expected 8 <= n <= {}",
                self.n,
                crate::views::MAX_GRID
            ));
        }
        if !(1..=4).contains(&self.supersample) {
            return Err(format!(
                "`supersample` = {} is out of range: expected 1 <= supersample <= 4",
                self.supersample
            ));
        }
        Ok(())
    }
}

/// The map: array `d` (n², row-major from y = −1, NaN outside the disk); fields `n`,
/// `integral`, `max`, `footprint`. An error for a material that is not a glint.
pub fn patch_ndf(q: &PatchNdfRequest) -> Result<Frame, String> {
    let table = parse_inline_table(&q.material).map_err(|e| e.to_string())?;
    let recipe = MaterialRecipe::parse_with_reader(
        &table,
        std::path::Path::new("."),
        Some(&ImageNormalMapReader),
    )
    .map_err(|e| e.to_string())?;
    let MaterialRecipe::Glint(g) = recipe else {
        return Err("the patch NDF view shows `type = \"glint\"` materials".into());
    };
    let bsdf = g.bsdf_at(Vec2::from(g.footprint_center), [0.0; 4]);
    let map = patch_ndf_map(&bsdf, "", q.n, q.supersample);
    Ok(Frame::default()
        .field("n", q.n)
        .field("integral", map.integral)
        .field("max", map.max)
        .field("footprint_center", g.footprint_center.to_vec())
        .field("footprint_size", g.footprint_size.to_vec())
        .array(
            "d",
            map.map
                .values
                .iter()
                .map(|v| v.unwrap_or(f64::NAN))
                .collect(),
        ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_integrates_to_one_and_other_types_are_refused() {
        let q = PatchNdfRequest {
            material:
                r#"{type = "glint", generate = "bumpy", resolution = 64, footprint_size = 6.0}"#
                    .into(),
            n: 64,
            supersample: 2,
        };
        let f = patch_ndf(&q).unwrap();
        let integral = f.fields["integral"].as_f64().unwrap();
        assert!((integral - 1.0).abs() < 0.05, "{integral}");
        assert_eq!(f.get("d").unwrap().len(), 64 * 64);
        let e = patch_ndf(&PatchNdfRequest {
            material: r#"{type = "lambert"}"#.into(),
            ..q
        })
        .unwrap_err();
        assert!(e.contains("glint"), "{e}");
    }
}
