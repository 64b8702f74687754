//! The precomputed glint surface of one normal map: the map, its lobes (one per texel), the
//! slope hierarchy and the moment pyramid. Built once per material and shared (behind an
//! `Arc`) by every per-shading-point [`super::glint_bsdf::GlintBsdf`].

use super::hierarchy::SlopeHierarchy;
use super::lobe_blocks::LobeBlocks;
use super::microsurface::{build_lobes, check_roughness_floor};
use super::mip_levels::MomentPyramid;
use super::normal_map::NormalMap;
use crate::error::ParamResult;
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct GlintSurface {
    pub(crate) map: NormalMap,
    pub(crate) lobes: LobeBlocks,
    pub(crate) hierarchy: SlopeHierarchy,
    pub(crate) pyramid: MomentPyramid,
    roughness_floor: f64,
    /// Where the map came from (`scratched 512² seed 1`, a file name).
    label: String,
    build_seconds: f64,
}

/// Memory held by a surface, in bytes.
#[derive(Clone, Copy, Debug)]
pub struct MemoryReport {
    pub texels: usize,
    pub normal_map: usize,
    pub lobes: usize,
    pub hierarchy: usize,
    pub mip_levels: usize,
}

impl MemoryReport {
    pub fn total(&self) -> usize {
        self.normal_map + self.lobes + self.hierarchy + self.mip_levels
    }

    /// One line per part, in MiB and bytes per texel.
    pub fn lines(&self) -> Vec<String> {
        let mib = |b: usize| b as f64 / (1024.0 * 1024.0);
        let per = |b: usize| b as f64 / self.texels as f64;
        [
            ("normal map (2 × f32 slopes)", self.normal_map),
            ("lobes (6 × f32, by block)", self.lobes),
            ("slope hierarchy", self.hierarchy),
            ("moment mip levels", self.mip_levels),
            ("total", self.total()),
        ]
        .iter()
        .map(|(n, b)| format!("{n}: {:.2} MiB ({:.2} bytes/texel)", mib(*b), per(*b)))
        .collect()
    }
}

impl GlintSurface {
    /// Builds lobes, hierarchy and pyramid for `map` with roughness floor σ_ε.
    pub fn build(
        map: NormalMap,
        roughness_floor: f64,
        label: impl Into<String>,
    ) -> ParamResult<Self> {
        check_roughness_floor(roughness_floor)?;
        let t0 = Instant::now();
        let (w, h) = (map.width(), map.height());
        let lobes = build_lobes(&map, roughness_floor);
        let hierarchy = SlopeHierarchy::build(&lobes, w, h);
        let pyramid = MomentPyramid::build(&lobes, w, h);
        let lobes = LobeBlocks::new(&lobes, w, h);
        Ok(GlintSurface {
            map,
            lobes,
            hierarchy,
            pyramid,
            roughness_floor,
            label: label.into(),
            build_seconds: t0.elapsed().as_secs_f64(),
        })
    }

    pub fn width(&self) -> usize {
        self.map.width()
    }

    pub fn height(&self) -> usize {
        self.map.height()
    }

    pub fn map(&self) -> &NormalMap {
        &self.map
    }

    /// The lobes, by leaf block (texel (x, y) with [`LobeBlocks::get`]).
    pub fn lobes(&self) -> &LobeBlocks {
        &self.lobes
    }

    pub fn roughness_floor(&self) -> f64 {
        self.roughness_floor
    }

    pub fn label(&self) -> &str {
        &self.label
    }

    /// Wall time of [`GlintSurface::build`] (lobes, hierarchy and pyramid).
    pub fn build_seconds(&self) -> f64 {
        self.build_seconds
    }

    pub fn memory(&self) -> MemoryReport {
        MemoryReport {
            texels: self.map.texels(),
            normal_map: self.map.texels() * 8,
            lobes: self.lobes.size_bytes(),
            hierarchy: self.hierarchy.size_bytes(),
            mip_levels: self.pyramid.size_bytes(),
        }
    }
}
