//! The precomputed glint surface of one normal map: the map, its lobes (one per seed of the
//! seed lattice: one per texel at the paper's h = 1), the slope hierarchy and the moment
//! pyramid, all over the seed lattice. Built once per material and shared (behind an
//! `Arc`) by every per-shading-point [`super::glint_bsdf::GlintBsdf`].

use super::footprint::{Footprint, FootprintQuery};
use super::hierarchy::SlopeHierarchy;
use super::lobe_blocks::LobeBlocks;
use super::microsurface::{build_lattice_lobes, check_roughness_floor};
use super::mip_levels::MomentPyramid;
use super::normal_map::NormalMap;
use crate::error::{ParamError, ParamResult};
use crate::limits::GLINT_LOBES;
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct GlintSurface {
    pub(crate) map: NormalMap,
    pub(crate) lobes: LobeBlocks,
    pub(crate) hierarchy: SlopeHierarchy,
    pub(crate) pyramid: MomentPyramid,
    /// Seeds per texel side n = 1/h  [CCM19 §3.1, §5.1.1].
    seed_subdivision: usize,
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
    /// Builds lobes, hierarchy and pyramid for `map` with roughness floor σ_ε, one seed per
    /// texel (h = 1, the paper's).
    pub fn build(
        map: NormalMap,
        roughness_floor: f64,
        label: impl Into<String>,
    ) -> ParamResult<Self> {
        Self::build_with_seeds(map, roughness_floor, 1, label)
    }

    /// The same with n = `seed_subdivision` = 1/h seeds per texel side (1 … 4: see
    /// [`super::microsurface::check_seed_subdivision`]).
    pub fn build_with_seeds(
        map: NormalMap,
        roughness_floor: f64,
        seed_subdivision: usize,
        label: impl Into<String>,
    ) -> ParamResult<Self> {
        check_roughness_floor(roughness_floor)?;
        super::microsurface::check_seed_subdivision(seed_subdivision)?;
        GLINT_LOBES
            .check_product(&[
                map.width() as u64,
                map.height() as u64,
                (seed_subdivision * seed_subdivision) as u64,
            ])
            .map_err(|e| {
                ParamError::Invalid(format!("seed_subdivision {seed_subdivision}: {e}"))
            })?;
        let t0 = Instant::now();
        let (w, h) = (
            map.width() * seed_subdivision,
            map.height() * seed_subdivision,
        );
        let lobes = build_lattice_lobes(&map, roughness_floor, seed_subdivision);
        let hierarchy = SlopeHierarchy::build(&lobes, w, h);
        let pyramid = MomentPyramid::build(&lobes, w, h);
        let lobes = LobeBlocks::new(&lobes, w, h);
        Ok(GlintSurface {
            map,
            lobes,
            hierarchy,
            pyramid,
            seed_subdivision,
            roughness_floor,
            label: label.into(),
            build_seconds: t0.elapsed().as_secs_f64(),
        })
    }

    /// The map's width in texels.
    pub fn width(&self) -> usize {
        self.map.width()
    }

    /// The map's height in texels.
    pub fn height(&self) -> usize {
        self.map.height()
    }

    /// Seeds per texel side, n = 1/h (n² lobes a texel).
    pub fn seed_subdivision(&self) -> usize {
        self.seed_subdivision
    }

    /// The seed lattice's size (seeds along x and y): the map's size times 1/h. Lobes,
    /// hierarchy, pyramid and [`FootprintQuery`] are indexed on this lattice.
    pub fn lattice_size(&self) -> (usize, usize) {
        (
            self.map.width() * self.seed_subdivision,
            self.map.height() * self.seed_subdivision,
        )
    }

    /// The query of a footprint given in texels: centre and covariance scaled to lattice
    /// units (one lattice unit is h texels).
    pub fn query(&self, footprint: Footprint) -> FootprintQuery {
        let s = self.seed_subdivision as f64;
        let fp = footprint.sanitized();
        let lattice = Footprint {
            center: fp.center * s,
            cov: fp.cov.map(|c| c * s * s),
        };
        let (w, h) = self.lattice_size();
        FootprintQuery::new(lattice, w, h)
    }

    pub fn map(&self) -> &NormalMap {
        &self.map
    }

    /// The lobes, by leaf block (seed (x, y) of the lattice with [`LobeBlocks::get`]).
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
