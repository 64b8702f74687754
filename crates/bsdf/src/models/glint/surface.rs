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

/// The most seeds (lobes) a surface may hold: a 4096² lattice, 640 MiB of lobes, hierarchy
/// and mip levels at 40 bytes a seed.
pub const MAX_SEEDS: usize = 4096 * 4096;
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct GlintSurface {
    pub(crate) map: NormalMap,
    pub(crate) lobes: LobeBlocks,
    pub(crate) hierarchy: SlopeHierarchy,
    pub(crate) pyramid: MomentPyramid,
    /// Seeds per texel along each axis, 1/h  [CCM19 §5.1.1].
    seeds_per_texel: usize,
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

    /// The same with `seeds_per_texel` = n = 1/h seeds per texel side (1 … 4: see
    /// [`super::microsurface::check_seed_subdivision`]).
    pub fn build_with_seeds(
        map: NormalMap,
        roughness_floor: f64,
        seeds_per_texel: usize,
        label: impl Into<String>,
    ) -> ParamResult<Self> {
        check_roughness_floor(roughness_floor)?;
        super::microsurface::check_seed_subdivision(seeds_per_texel)?;
        let seeds = map.texels() * seeds_per_texel * seeds_per_texel;
        if seeds > MAX_SEEDS {
            return Err(ParamError::Invalid(format!(
                "seed_subdivision {seeds_per_texel} on a {}×{} map makes {seeds} lobes \
                 ({:.1} GiB); at most {MAX_SEEDS} (a 4096² lattice): use a smaller subdivision \
                 or a smaller map",
                map.width(),
                map.height(),
                seeds as f64 * 40.0 / (1u64 << 30) as f64,
            )));
        }
        let t0 = Instant::now();
        let (w, h) = (
            map.width() * seeds_per_texel,
            map.height() * seeds_per_texel,
        );
        let lobes = build_lattice_lobes(&map, roughness_floor, seeds_per_texel);
        let hierarchy = SlopeHierarchy::build(&lobes, w, h);
        let pyramid = MomentPyramid::build(&lobes, w, h);
        let lobes = LobeBlocks::new(&lobes, w, h);
        Ok(GlintSurface {
            map,
            lobes,
            hierarchy,
            pyramid,
            seeds_per_texel,
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

    /// Seeds per texel along each axis (1/h).
    pub fn seeds_per_texel(&self) -> usize {
        self.seeds_per_texel
    }

    /// The seed lattice's size (seeds along x and y): the map's size times 1/h. Lobes,
    /// hierarchy, pyramid and [`FootprintQuery`] are indexed on this lattice.
    pub fn lattice_size(&self) -> (usize, usize) {
        (
            self.map.width() * self.seeds_per_texel,
            self.map.height() * self.seeds_per_texel,
        )
    }

    /// The query of a footprint given in texels: centre and covariance scaled to lattice
    /// units (one lattice unit is h texels).
    pub fn query(&self, footprint: Footprint) -> FootprintQuery {
        let s = self.seeds_per_texel as f64;
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
