//! Rendering a scene: square tiles in parallel (rayon), in passes of samples so that an
//! interruption (Ctrl-C, a time limit) leaves every pixel with a valid mean. Each camera
//! sample's random numbers are a pure function of (seed, pixel, sample index) — the
//! [`sampler`](crate::sampler)'s stream — so the image depends on the seed and the sampler
//! only, not on the thread count, the tiling or the passes, and any subset of samples can be
//! rendered separately and merged exactly.

use crate::film::Film;
use crate::geometry::{Ray, RayDifferential, Vec2};
use crate::integrator::{radiance, Strategy};
use crate::kernel::{packet, Kernel};
use crate::pixel_footprint::PixelRay;
use crate::sampler::{PixelSampler, SampleStream, SamplerKind};
use crate::scene::Scene;
use facette_bsdf::Spectrum;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// How to render.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Samples per pixel (the scene's when `None`).
    pub spp: Option<usize>,
    pub seed: u64,
    /// Worker threads (all cores when `None`).
    pub threads: Option<usize>,
    /// Stop after this many seconds (the image so far is kept).
    pub time_limit: Option<f64>,
    /// Render only sample indices `s` with `s % parts.1 == parts.0` (a share of the samples
    /// for distributed rendering).
    pub part: Option<(usize, usize)>,
    pub strategy: Strategy,
    /// The pixel sampler (the scene's when `None`).
    pub sampler: Option<SamplerKind>,
    /// The render kernel (the scene's when `None`).
    pub kernel: Option<Kernel>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            spp: None,
            seed: 0,
            threads: None,
            time_limit: None,
            part: None,
            strategy: Strategy::Mis,
            sampler: None,
            kernel: None,
        }
    }
}

/// Statistics of a render.
#[derive(Clone, Debug)]
pub struct RenderStats {
    pub samples: u64,
    pub seconds: f64,
    pub discarded: u64,
    pub interrupted: bool,
}

impl RenderStats {
    pub fn msamples_per_second(&self) -> f64 {
        self.samples as f64 / self.seconds.max(1e-9) / 1e6
    }
}

const TILE: usize = 32;

/// Samples per pass: 1, 1, 2, 4, … doubling up to a sixteenth of the total, so that a
/// first image comes fast and the time limit is checked often, while long renders keep few
/// passes. Depends on the sample count only (the image must not depend on timing).
fn pass_sizes(n: usize) -> Vec<usize> {
    let cap = n.div_ceil(16).max(1);
    let mut sizes = Vec::new();
    let (mut left, mut next) = (n, 1usize);
    while left > 0 {
        let s = next.min(cap).min(left);
        sizes.push(s);
        left -= s;
        if sizes.len() > 1 {
            next *= 2;
        }
    }
    sizes
}

/// One pixel's samples of one pass.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PixelSums {
    sum: [f64; 3],
    sq: [f64; 3],
    n: u32,
    bad: u32,
}

impl PixelSums {
    /// The radiance sums per channel.
    #[cfg(test)]
    pub(crate) fn sums(&self) -> [f64; 3] {
        self.sum
    }

    /// The samples added.
    #[cfg(test)]
    pub(crate) fn count(&self) -> u32 {
        self.n
    }

    /// Adds one camera sample's radiance; a non-finite or negative one is counted and
    /// left out.
    #[inline]
    pub(crate) fn add(&mut self, l: Spectrum) {
        if l.is_finite() && !l.has_negative() {
            self.add_valid(l);
        } else {
            self.add_invalid();
        }
    }

    /// Adds one camera sample's radiance, known to be finite and not negative.
    #[inline(always)]
    pub(crate) fn add_valid(&mut self, l: Spectrum) {
        self.n += 1;
        for c in 0..3 {
            self.sum[c] += l[c];
            self.sq[c] += l[c] * l[c];
        }
    }

    /// Counts one camera sample whose radiance is non-finite or negative.
    #[inline(always)]
    pub(crate) fn add_invalid(&mut self) {
        self.n += 1;
        self.bad += 1;
    }
}

/// How camera rays are made for one render.
#[derive(Clone, Copy)]
pub(crate) struct CameraSampling {
    /// Whether some material reads texture or glint footprints (only then are ray
    /// differentials computed).
    pub footprints: bool,
    /// The differentials' scale for the pixel's sample count.
    pub diff_scale: f64,
    /// Whether some material shades a camera ray's hit with the pixel's footprint (then
    /// each camera sample carries its pixel's centre ray, [`PixelRay`]).
    pub pixel_footprints: bool,
}

impl CameraSampling {
    /// The camera ray of pixel (x, y) from the stream's first dimensions: the filter
    /// offset (2), then the lens position (2); its differentials and its pixel's centre ray
    /// where materials read them.
    #[inline]
    pub(crate) fn ray(
        &self,
        scene: &Scene,
        stream: &mut SampleStream,
        x: usize,
        y: usize,
    ) -> (Ray, Option<RayDifferential>, Option<PixelRay>) {
        let off = scene.film.filter.sample(stream.get_2d());
        let (fx, fy) = (x as f64 + 0.5 + off.x, y as f64 + 0.5 + off.y);
        let lens = stream.get_2d_where(scene.camera.has_lens());
        let lens = Vec2::new(lens.x, lens.y);
        if self.footprints {
            let (ray, rd) = scene.camera.generate_ray(fx, fy, lens);
            let pixel = self
                .pixel_footprints
                .then(|| PixelRay::new(&scene.camera, x as u32, y as u32, lens));
            (ray, Some(rd.scaled(&ray, self.diff_scale)), pixel)
        } else {
            (scene.camera.generate_primary_ray(fx, fy, lens), None, None)
        }
    }
}

/// Renders `scene`. `cancel` stops the render between tiles; `progress(done, total)` is
/// called with sample counts as tiles finish.
pub fn render(
    scene: &Scene,
    opts: &RenderOptions,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Film, RenderStats), String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| format!("cannot start the thread pool: {e}"))?;
    pool.install(|| render_in_pool(scene, opts, cancel, progress))
}

fn render_in_pool(
    scene: &Scene,
    opts: &RenderOptions,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Film, RenderStats), String> {
    let (w, h) = (scene.film.width, scene.film.height);
    let spp = opts.spp.unwrap_or(scene.film.spp);
    if spp == 0 {
        return Err("spp must be at least 1".into());
    }
    // Sizes are checked before anything is allocated or counted (limits.rs).
    facette_bsdf::limits::SAMPLES_PER_PIXEL
        .check_usize(spp)
        .and_then(|_| {
            facette_bsdf::limits::RENDER_SAMPLES.check_product(&[w as u64, h as u64, spp as u64])
        })
        .map_err(|e| e.to_string())?;
    let (part, parts) = opts.part.unwrap_or((0, 1));
    if parts == 0 || part >= parts {
        return Err(format!(
            "part {part}/{parts}: the part index must be below the part count"
        ));
    }
    // The sample indices this render takes.
    let indices: Vec<u32> = (0..spp as u32)
        .filter(|s| *s as usize % parts == part)
        .collect();
    let total = (indices.len() * w * h) as u64;
    let passes = pass_sizes(indices.len());
    let tiles: Vec<(usize, usize)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx, ty)))
        .collect();
    let mut film = Film::new(w, h);
    let start = Instant::now();
    let deadline = opts.time_limit.map(|s| {
        start + Duration::from_secs_f64(s.clamp(0.0, facette_bsdf::limits::TIME_LIMIT_SECONDS))
    });
    let done = AtomicU64::new(0);
    let stop = AtomicBool::new(false);
    // Whether to stop now. The time limit never cuts the first pass, so that every pixel
    // gets samples; Ctrl-C does.
    let should_stop = |pass: usize| {
        if cancel.load(Ordering::Relaxed) || stop.load(Ordering::Relaxed) {
            return true;
        }
        if let (Some(d), true) = (deadline, pass > 0) {
            if Instant::now() >= d {
                stop.store(true, Ordering::Relaxed);
                return true;
            }
        }
        false
    };
    let cameras = CameraSampling {
        diff_scale: 1.0 / (spp as f64).sqrt().max(1.0),
        // Ray differentials only serve texture and glint footprints.
        footprints: scene.materials.iter().any(|m| m.reads_surface_details()),
        pixel_footprints: scene.materials.iter().any(|m| m.reads_pixel_footprint()),
    };
    let kernel = opts
        .kernel
        .unwrap_or(scene.integrator.kernel)
        .resolve(&scene.geometry);
    let sampler = PixelSampler::new(
        opts.sampler.unwrap_or(scene.film.sampler),
        opts.seed,
        w,
        h,
        spp,
    );
    // Each tile's sums, gathered over all passes and added to the film once at the end:
    // merged after every pass (18 passes at 64 spp), the film's 14 MB at 512² were read and
    // written each time, 3.9 % of a one-thread render of a conductor sphere.
    let mut tile_sums: Vec<Vec<PixelSums>> = vec![Vec::new(); tiles.len()];
    let mut first = 0;
    for (pass, size) in passes.into_iter().enumerate() {
        let chunk = &indices[first..first + size];
        first += size;
        if should_stop(pass) {
            break;
        }
        tiles
            .par_iter()
            .zip(tile_sums.par_iter_mut())
            .for_each(|(&(tx, ty), out)| {
                let x0 = tx * TILE;
                let y0 = ty * TILE;
                let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
                match kernel {
                    // `resolve` never gives `Auto`.
                    Kernel::Scalar | Kernel::Auto => {
                        out.resize((x1 - x0) * (y1 - y0), PixelSums::default());
                        for y in y0..y1 {
                            // Checked per row: a pass of many samples is stopped promptly;
                            // the rows left out keep the samples of the earlier passes.
                            if should_stop(pass) {
                                break;
                            }
                            for x in x0..x1 {
                                let p = &mut out[(y - y0) * (x1 - x0) + x - x0];
                                for &s in chunk {
                                    let mut stream = sampler.stream(x, y, s as u64);
                                    let (ray, rd, pixel) = cameras.ray(scene, &mut stream, x, y);
                                    p.add(radiance(
                                        scene,
                                        ray,
                                        rd,
                                        pixel,
                                        &mut stream,
                                        opts.strategy,
                                    ));
                                }
                            }
                            let row = ((x1 - x0) * chunk.len()) as u64;
                            let d = done.fetch_add(row, Ordering::Relaxed) + row;
                            progress(d, total);
                        }
                    }
                    Kernel::Packet => {
                        // The same stop rule: asked before each row is started.
                        let stop = || should_stop(pass);
                        let job = packet::TileJob {
                            scene,
                            sampler: &sampler,
                            cameras,
                            strategy: opts.strategy,
                            xs: x0..x1,
                            ys: y0..y1,
                            chunk,
                            stop: &stop,
                        };
                        let rows = packet::render_tile(&job, out);
                        let n = (rows * (x1 - x0) * chunk.len()) as u64;
                        let d = done.fetch_add(n, Ordering::Relaxed) + n;
                        progress(d, total);
                    }
                }
            });
    }
    // The tiles' sums go to the film a band of TILE rows at a time, the bands in parallel
    // (`tiles` is in order: band by band, each band's tiles left to right).
    let (band, tiles_a_band) = (TILE * w, w.div_ceil(TILE));
    film.discarded += film
        .sums
        .par_chunks_mut(band)
        .zip(film.sq_sums.par_chunks_mut(band))
        .zip(film.counts.par_chunks_mut(band))
        .zip(tiles.par_chunks(tiles_a_band))
        .zip(tile_sums.par_chunks(tiles_a_band))
        .map(|((((sums, sq_sums), counts), band_tiles), band_sums)| {
            let mut bad = 0;
            for (&(tx, _), px) in band_tiles.iter().zip(band_sums) {
                let x0 = tx * TILE;
                let tile_width = (x0 + TILE).min(w) - x0;
                // A tile of no pass (stopped before the first) has no entries.
                for (r, row) in px.chunks(tile_width).enumerate() {
                    let start = r * w + x0;
                    for (i, p) in (start..start + tile_width).zip(row) {
                        for c in 0..3 {
                            sums[i][c] += p.sum[c];
                            sq_sums[i][c] += p.sq[c];
                        }
                        counts[i] += p.n;
                        bad += p.bad as u64;
                    }
                }
            }
            bad
        })
        .sum::<u64>();
    let stats = RenderStats {
        samples: film.total_samples(),
        seconds: start.elapsed().as_secs_f64(),
        discarded: film.discarded,
        interrupted: cancel.load(Ordering::Relaxed) || stop.load(Ordering::Relaxed),
    };
    Ok((film, stats))
}

#[cfg(test)]
mod tests {
    use super::pass_sizes;

    #[test]
    fn passes_start_small_double_and_cover_every_sample() {
        assert_eq!(pass_sizes(1), vec![1]);
        assert_eq!(pass_sizes(8), vec![1; 8]);
        assert_eq!(pass_sizes(64), [vec![1, 1, 2, 4], vec![4; 14]].concat());
        for n in [0, 1, 7, 100, 4096, 1_000_000] {
            let p = pass_sizes(n);
            assert_eq!(p.iter().sum::<usize>(), n);
            assert!(p.len() <= 16 + 2 + (n.max(1) as f64).log2() as usize);
        }
    }
}
