//! Partial renders for distributed rendering: part K of N renders the sample indices
//! s ≡ K (mod N) of every pixel (each sample's random numbers are a pure function of the
//! seed, the sampler, the pixel and s, so parts are disjoint and independent of where they
//! run)
//! and is saved as a `.fcpart` file holding the exact per-pixel f64 sums, squared sums and
//! sample counts. [`merge_parts`] adds the N parts in part order, so the merged film is
//! bit for bit the film of [`render_in_parts`] — the same N parts rendered in one process.
//!
//! File format (`docs/file-formats.md`), little-endian:
//!
//! | bytes | content |
//! |---|---|
//! A framed file (`facette_bsdf::storage::framed`: magic `FCRPART1`, u32 format version 3,
//! u64 payload length, payload, CRC-32). Version 2 parts (the same payload, unframed) are
//! still read; version 1 parts predate the samplers and are refused. The payload:
//!
//! | bytes | content |
//! |---|---|
//! | 8 | scene hash (FNV-1a of the scene source) |
//! | 8 | seed |
//! | 4 + 4 | part K, part count N |
//! | 4 | samples per pixel of the whole render |
//! | 4 | sampler: 0 `sobol`, 1 `independent`, 2 `stratified` |
//! | 4 + 4 | width, height |
//! | 8 | exposure (f64, stops) |
//! | 8 | discarded samples |
//! | w·h·(3·8 + 3·8 + 4) | per pixel, row-major from the top: sums R, G, B (f64), squared sums R, G, B (f64), sample count (u32) |

use crate::film::Film;
use crate::render::{render, RenderOptions, RenderStats};
use crate::sampler::SamplerKind;
use crate::scene::Scene;
use facette_bsdf::storage::atomic_file::write_atomically;
use facette_bsdf::storage::framed::Framed;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

const FRAME: Framed = Framed {
    magic: b"FCRPART1",
    version: 3,
    legacy_version: Some(2),
    what: "facette partial render",
};
/// Bytes of the payload before the pixels.
const HEADER: usize = 8 + 8 + 4 + 4 + 4 + 4 + 4 + 4 + 8 + 8;
const PIXEL: usize = 6 * 8 + 4;

/// Errors of partial files.
#[derive(Debug, thiserror::Error)]
pub enum PartError {
    #[error("{}: {reason}", path.display())]
    Invalid { path: PathBuf, reason: String },
    #[error("{}: {reason}", path.display())]
    Io { path: PathBuf, reason: String },
    #[error("cannot merge: {0}")]
    Mismatch(String),
}

/// One part of a render.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialFilm {
    pub scene_hash: u64,
    pub seed: u64,
    pub part: u32,
    pub parts: u32,
    pub spp: u32,
    pub sampler: SamplerKind,
    pub exposure: f64,
    pub film: Film,
}

/// Renders part `part` of `parts` of the scene's samples (`opts.part` is set here; a time
/// limit is refused: a part must hold all its samples for the merge to be exact).
pub fn render_part(
    scene: &Scene,
    opts: &RenderOptions,
    part: u32,
    parts: u32,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(PartialFilm, RenderStats), String> {
    if parts == 0 || part >= parts {
        return Err(format!("part {part}/{parts}: need 0 ≤ K < N"));
    }
    if opts.time_limit.is_some() {
        return Err(
            "a part cannot have a time limit: its samples must all be rendered for an exact merge"
                .into(),
        );
    }
    let spp = opts.spp.unwrap_or(scene.film.spp);
    let sampler = opts.sampler.unwrap_or(scene.film.sampler);
    let o = RenderOptions {
        spp: Some(spp),
        sampler: Some(sampler),
        part: Some((part as usize, parts as usize)),
        ..opts.clone()
    };
    let (film, stats) = render(scene, &o, cancel, progress)?;
    if stats.interrupted {
        return Err("interrupted: the part is incomplete and was not kept".into());
    }
    Ok((
        PartialFilm {
            scene_hash: scene.source_hash,
            seed: opts.seed,
            part,
            parts,
            spp: spp as u32,
            sampler,
            exposure: scene.film.exposure,
            film,
        },
        stats,
    ))
}

/// Renders all `parts` parts in this process and merges them: the reference that a
/// distributed render of the same parts reproduces bit for bit.
pub fn render_in_parts(scene: &Scene, opts: &RenderOptions, parts: u32) -> Result<Film, String> {
    let cancel = AtomicBool::new(false);
    let films: Vec<PartialFilm> = (0..parts)
        .map(|k| render_part(scene, opts, k, parts, &cancel, &|_, _| {}).map(|r| r.0))
        .collect::<Result<_, _>>()?;
    merge_parts(&films).map_err(|e| e.to_string())
}

/// Adds the parts of one render, in part order. Every part 0…N−1 must be present exactly
/// once, and all must come from the same scene, seed, sample count and image size.
pub fn merge_parts(parts: &[PartialFilm]) -> Result<Film, PartError> {
    let first = parts
        .first()
        .ok_or_else(|| PartError::Mismatch("no parts given".into()))?;
    let n = first.parts;
    let mut seen = vec![None::<usize>; n as usize];
    for (i, p) in parts.iter().enumerate() {
        let what = |field: &str, a: String, b: String| {
            PartError::Mismatch(format!(
                "parts come from different renders: {field} is {a} in the first part and {b} in part {}/{}",
                p.part, p.parts
            ))
        };
        if p.parts != n {
            return Err(what("the part count", n.to_string(), p.parts.to_string()));
        }
        if p.scene_hash != first.scene_hash {
            return Err(what(
                "the scene",
                format!("{:016x}", first.scene_hash),
                format!("{:016x}", p.scene_hash),
            ));
        }
        if p.seed != first.seed {
            return Err(what("the seed", first.seed.to_string(), p.seed.to_string()));
        }
        if p.spp != first.spp {
            return Err(what("spp", first.spp.to_string(), p.spp.to_string()));
        }
        if p.sampler != first.sampler {
            return Err(what(
                "the sampler",
                first.sampler.name().to_string(),
                p.sampler.name().to_string(),
            ));
        }
        if (p.film.width, p.film.height) != (first.film.width, first.film.height) {
            return Err(what(
                "the image size",
                format!("{}×{}", first.film.width, first.film.height),
                format!("{}×{}", p.film.width, p.film.height),
            ));
        }
        match seen[p.part as usize] {
            Some(_) => {
                return Err(PartError::Mismatch(format!(
                    "part {}/{n} is given twice",
                    p.part
                )))
            }
            None => seen[p.part as usize] = Some(i),
        }
    }
    let missing: Vec<String> = seen
        .iter()
        .enumerate()
        .filter(|(_, s)| s.is_none())
        .map(|(k, _)| k.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(PartError::Mismatch(format!(
            "missing part(s) {} of {n}",
            missing.join(", ")
        )));
    }
    let mut film = Film::new(first.film.width, first.film.height);
    for slot in seen.into_iter().flatten() {
        let f = &parts[slot].film;
        for i in 0..film.sums.len() {
            for c in 0..3 {
                film.sums[i][c] += f.sums[i][c];
                film.sq_sums[i][c] += f.sq_sums[i][c];
            }
            // Corrupt (but CRC-valid) parts must not overflow the sums or the counts.
            let count = film.counts[i].checked_add(f.counts[i]);
            if count.is_none_or(|c| c > first.spp)
                || !film.sums[i]
                    .iter()
                    .chain(&film.sq_sums[i])
                    .all(|v| v.is_finite())
            {
                return Err(PartError::Mismatch(format!(
                    "pixel {i}: the parts' sums or sample counts exceed what {} spp can give (corrupt parts?)",
                    first.spp
                )));
            }
            film.counts[i] = count.unwrap_or(0);
        }
        film.discarded = film.discarded.saturating_add(f.discarded);
    }
    Ok(film)
}

/// The sampler's code in a part file: its index in [`SamplerKind::NAMES`].
fn sampler_id(kind: SamplerKind) -> u32 {
    SamplerKind::NAMES
        .iter()
        .position(|n| *n == kind.name())
        .unwrap_or(0) as u32
}

impl PartialFilm {
    pub fn to_bytes(&self) -> Vec<u8> {
        let f = &self.film;
        let mut out = Vec::with_capacity(HEADER + f.sums.len() * PIXEL);
        out.extend_from_slice(&self.scene_hash.to_le_bytes());
        out.extend_from_slice(&self.seed.to_le_bytes());
        out.extend_from_slice(&self.part.to_le_bytes());
        out.extend_from_slice(&self.parts.to_le_bytes());
        out.extend_from_slice(&self.spp.to_le_bytes());
        out.extend_from_slice(&sampler_id(self.sampler).to_le_bytes());
        out.extend_from_slice(&(f.width as u32).to_le_bytes());
        out.extend_from_slice(&(f.height as u32).to_le_bytes());
        out.extend_from_slice(&self.exposure.to_le_bytes());
        out.extend_from_slice(&f.discarded.to_le_bytes());
        for i in 0..f.sums.len() {
            for c in 0..3 {
                out.extend_from_slice(&f.sums[i][c].to_le_bytes());
            }
            for c in 0..3 {
                out.extend_from_slice(&f.sq_sums[i][c].to_le_bytes());
            }
            out.extend_from_slice(&f.counts[i].to_le_bytes());
        }
        FRAME.frame(&out)
    }

    /// Parses a part; `path` names it in errors.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<PartialFilm, PartError> {
        let bad = |reason: &str| PartError::Invalid {
            path: path.to_path_buf(),
            reason: reason.to_string(),
        };
        let body = FRAME
            .unframe(bytes)
            .map_err(|e| bad(&e.to_string()))?
            .payload;
        if body.len() < HEADER {
            return Err(bad("truncated header"));
        }
        let mut at = 0;
        let mut take = |n: usize| {
            let s = &body[at..at + n];
            at += n;
            s
        };
        let u32_ = |s: &[u8]| u32::from_le_bytes(s.try_into().expect("4 bytes"));
        let u64_ = |s: &[u8]| u64::from_le_bytes(s.try_into().expect("8 bytes"));
        let scene_hash = u64_(take(8));
        let seed = u64_(take(8));
        let part = u32_(take(4));
        let parts = u32_(take(4));
        let spp = u32_(take(4));
        let sampler_code = u32_(take(4));
        let Some(sampler) = SamplerKind::NAMES
            .get(sampler_code as usize)
            .and_then(|n| SamplerKind::parse(n))
        else {
            return Err(bad(&format!("unknown sampler code {sampler_code}")));
        };
        let width = u32_(take(4)) as usize;
        let height = u32_(take(4)) as usize;
        let exposure = f64::from_bits(u64_(take(8)));
        let discarded = u64_(take(8));
        if parts == 0 || part >= parts {
            return Err(bad(&format!("invalid part {part}/{parts}")));
        }
        // Every header field is checked before it sizes or scales anything: the part count
        // sizes the merge, spp bounds the counts, the exposure scales the image.
        facette_bsdf::limits::PARTS
            .check(parts as u64)
            .map_err(|e| bad(&e.to_string()))?;
        if spp == 0
            || facette_bsdf::limits::SAMPLES_PER_PIXEL
                .check(spp as u64)
                .is_err()
        {
            return Err(bad(&format!("invalid spp {spp}")));
        }
        facette_bsdf::limits::check_exposure(exposure)
            .map_err(|m| bad(&format!("exposure: {m}")))?;
        let pixels = facette_bsdf::limits::FILM_PIXELS
            .check_product(&[width as u64, height as u64])
            .ok()
            .map(|p| p as usize)
            .filter(|&p| p > 0 && width <= 65536 && height <= 65536);
        let Some(pixels) = pixels else {
            return Err(bad(&format!("invalid image size {width}×{height}")));
        };
        if body.len() != HEADER + pixels * PIXEL {
            return Err(bad(&format!(
                "{} bytes of pixel data, expected {} for {width}×{height}",
                body.len().saturating_sub(HEADER),
                pixels * PIXEL
            )));
        }
        let mut film = Film::new(width, height);
        film.discarded = discarded;
        for i in 0..pixels {
            for c in 0..3 {
                film.sums[i][c] = f64::from_bits(u64_(take(8)));
            }
            for c in 0..3 {
                film.sq_sums[i][c] = f64::from_bits(u64_(take(8)));
            }
            film.counts[i] = u32_(take(4));
            if film.counts[i] > spp {
                return Err(bad(&format!(
                    "pixel {i} counts {} samples, more than the render's {spp} spp",
                    film.counts[i]
                )));
            }
            if !film.sums[i]
                .iter()
                .chain(&film.sq_sums[i])
                .all(|v| v.is_finite() && *v >= 0.0)
            {
                return Err(bad(&format!(
                    "pixel {i} holds a negative or non-finite sum"
                )));
            }
        }
        Ok(PartialFilm {
            scene_hash,
            seed,
            part,
            parts,
            spp,
            sampler,
            exposure,
            film,
        })
    }

    pub fn load(path: &Path) -> Result<PartialFilm, PartError> {
        let bytes = std::fs::read(path).map_err(|e| PartError::Io {
            path: path.to_path_buf(),
            reason: format!("cannot read: {e}"),
        })?;
        Self::from_bytes(&bytes, path)
    }

    /// Writes the part atomically (a temporary file renamed into place).
    pub fn save(&self, path: &Path) -> Result<(), PartError> {
        let io = |reason: String| PartError::Io {
            path: path.to_path_buf(),
            reason,
        };
        write_atomically(path, &self.to_bytes()).map_err(|e| io(e.to_string()))
    }
}
