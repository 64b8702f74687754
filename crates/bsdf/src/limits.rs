//! Resource limits: every bound facette puts on what an input may make it allocate or
//! compute, stated once. A size read from a file or a flag is checked here *before* the
//! allocation or the loop it would drive, with checked arithmetic, so a careless or hostile
//! input gets an error naming the quantity, its value and the limit — never an allocation
//! abort, an overflow panic or a run that cannot finish.
//!
//! The limits are far above anything the documented uses need (an 8K film, a 0.25° table,
//! a million-triangle mesh); each says how to get past it when that makes sense. The ones
//! that only guard memory or time can be raised for one run, up to a hard ceiling set by
//! the data types (`facette --limit mesh-elements=2000000000 render …`, or
//! `FACETTE_LIMITS=mesh-elements=2000000000`; see [`set_limit`]); the ones that guard
//! the stack, 32-bit indices or a format's own bound are fixed. This
//! module sits at the bottom of the crate with `error` and `checks`: every crate of the
//! workspace depends on `facette-bsdf`, so the render, lab and CLI limits live here too.

use crate::math::fmt_num;
use std::sync::atomic::{AtomicU64, Ordering};
use thiserror::Error;

/// One resource bound: what is counted, its maximum, and how to get past it.
#[derive(Debug)]
pub struct Limit {
    /// What is counted, as the message names it (`"film pixels (width × height)"`).
    pub what: &'static str,
    /// The name `--limit KEY=N` and `FACETTE_LIMITS` give it (`"film-pixels"`).
    pub key: &'static str,
    /// The largest accepted value unless raised.
    pub default: u64,
    /// The largest value it may be raised to; equal to `default` when the limit is fixed
    /// (it guards the stack, 32-bit indices or a format's own bound, not memory or time).
    pub ceiling: u64,
    /// How to get past the limit, or why it is where it is.
    pub lift: &'static str,
    /// The value in force (`default` unless [`set_limit`] changed it).
    current: AtomicU64,
}

/// A value over its limit (or one whose computation overflowed).
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[error("{what} = {value} exceeds the limit of {max} ({lift})")]
pub struct LimitError {
    pub what: String,
    /// The value, or `"more than 2^64"` when its computation overflowed.
    pub value: String,
    pub max: u64,
    pub lift: String,
}

impl Limit {
    const fn new(
        what: &'static str,
        key: &'static str,
        default: u64,
        ceiling: u64,
        lift: &'static str,
    ) -> Limit {
        Limit {
            what,
            key,
            default,
            ceiling,
            lift,
            current: AtomicU64::new(default),
        }
    }

    /// A limit that cannot be raised.
    const fn fixed(what: &'static str, key: &'static str, max: u64, lift: &'static str) -> Limit {
        Limit::new(what, key, max, max, lift)
    }

    /// The largest accepted value now.
    pub fn max(&self) -> u64 {
        self.current.load(Ordering::Relaxed)
    }

    /// Whether `--limit` can raise it.
    pub fn is_raisable(&self) -> bool {
        self.ceiling > self.default
    }

    /// `value` if it is at most the limit.
    pub fn check(&self, value: u64) -> Result<u64, LimitError> {
        if value <= self.max() {
            Ok(value)
        } else {
            Err(self.error(value.to_string()))
        }
    }

    /// `value` (a `usize`) if it is at most the limit.
    pub fn check_usize(&self, value: usize) -> Result<usize, LimitError> {
        self.check(value as u64).map(|v| v as usize)
    }

    /// The product of `factors`, computed with overflow checks, if it is at most the limit.
    /// An overflowing product is reported as over the limit, not wrapped.
    pub fn check_product(&self, factors: &[u64]) -> Result<u64, LimitError> {
        let mut p: u64 = 1;
        for &f in factors {
            p = p
                .checked_mul(f)
                .ok_or_else(|| self.error(format!("{} (more than 2^64)", product_text(factors))))?;
        }
        if p <= self.max() {
            Ok(p)
        } else {
            Err(self.error(format!("{} = {p}", product_text(factors))))
        }
    }

    /// How to get past it, with the flag that raises it when there is one.
    pub fn how_to_lift(&self) -> String {
        let max = self.max();
        if max < self.ceiling {
            format!(
                "{}; or raise it with --limit {}=N, up to {}",
                self.lift, self.key, self.ceiling
            )
        } else {
            self.lift.to_string()
        }
    }

    fn error(&self, value: String) -> LimitError {
        LimitError {
            what: self.what.to_string(),
            value,
            max: self.max(),
            lift: self.how_to_lift(),
        }
    }
}

/// Every limit, in the order docs/validation.md lists them.
pub fn all() -> [&'static Limit; 22] {
    [
        &FILM_PIXELS,
        &FILM_SIDE,
        &SAMPLES_PER_PIXEL,
        &RENDER_SAMPLES,
        &THREADS,
        &TABLE_ENTRIES,
        &PARTS,
        &PLOT_POINTS,
        &SAMPLES,
        &RECIPE_COUNT,
        &GLINT_LOBES,
        &XML_INCLUDES,
        &XML_INCLUDE_DEPTH,
        &XML_DEPTH,
        &XML_ELEMENTS,
        &XML_REF_DEPTH,
        &XML_EXPANDED_BYTES,
        &MESH_ELEMENTS,
        &SCENE_FILE_BYTES,
        &MESH_FILE_BYTES,
        &IMAGE_PIXELS,
        &IMAGE_SAMPLES,
    ]
}

/// Sets a limit for the rest of the process from `KEY=N` (the `--limit` flag and the
/// `FACETTE_LIMITS` variable): an unknown key lists the valid ones; a fixed limit, a value
/// of 0 or one above the ceiling is refused with the reason.
pub fn set_limit(assignment: &str) -> Result<(), String> {
    let (key, value) = assignment
        .split_once('=')
        .ok_or_else(|| format!("`{assignment}`: expected KEY=N, e.g. mesh-elements=1000000000"))?;
    let key = key.trim();
    let raisable = || {
        all()
            .iter()
            .filter(|l| l.is_raisable())
            .map(|l| l.key)
            .collect::<Vec<_>>()
            .join(", ")
    };
    let limit = all().into_iter().find(|l| l.key == key).ok_or_else(|| {
        format!(
            "unknown limit `{key}`; the limits that can be raised: {}",
            raisable()
        )
    })?;
    if !limit.is_raisable() {
        return Err(format!(
            "the limit `{key}` ({}) is fixed at {}: {}; the limits that can be raised: {}",
            limit.what,
            limit.default,
            limit.lift,
            raisable()
        ));
    }
    let n: u64 = value
        .trim()
        .replace('_', "")
        .parse()
        .map_err(|_| format!("--limit {key}={value}: `{value}` is not a whole number"))?;
    if n == 0 || n > limit.ceiling {
        return Err(format!(
            "--limit {key}={n}: outside 1…{} ({} cannot go higher)",
            limit.ceiling, limit.what
        ));
    }
    limit.current.store(n, Ordering::Relaxed);
    Ok(())
}

/// Applies `FACETTE_LIMITS` (comma-separated `KEY=N`), if set; errors name the variable.
pub fn set_limits_from_env() -> Result<(), String> {
    match std::env::var("FACETTE_LIMITS") {
        Ok(v) => v
            .split(',')
            .map(str::trim)
            .filter(|a| !a.is_empty())
            .try_for_each(|a| set_limit(a).map_err(|e| format!("FACETTE_LIMITS: {e}"))),
        Err(std::env::VarError::NotPresent) => Ok(()),
        Err(e) => Err(format!("FACETTE_LIMITS: {e}")),
    }
}

fn product_text(factors: &[u64]) -> String {
    factors
        .iter()
        .map(u64::to_string)
        .collect::<Vec<_>>()
        .join(" × ")
}

/// Film pixels, width × height. The film keeps 52 bytes per pixel (sums, squared sums,
/// count), so this is 1.7 GB; 8K UHD (7680 × 4320) fits.
pub static FILM_PIXELS: Limit = Limit::new(
    "film pixels (width × height)",
    "film-pixels",
    1 << 25,
    1 << 31,
    "8K UHD fits; render a larger image as tiles with a cropped camera",
);

/// Film width or height on its own.
pub static FILM_SIDE: Limit = Limit::fixed(
    "film width or height",
    "film-side",
    65536,
    "the film's pixel count is limited separately",
);

/// Samples per pixel. Sample indices are 32-bit in the sampler and part files.
pub static SAMPLES_PER_PIXEL: Limit = Limit::fixed(
    "samples per pixel",
    "spp",
    1 << 24,
    "16.7 million samples per pixel; for more, render parts with --part K/N and merge them",
);

/// Camera samples of a whole render, pixels × spp: 2^40 (10^12) samples take more than a
/// day at 10 Msamples/s, so a larger product is a mistake (an 8K film at 32768 spp fits).
pub static RENDER_SAMPLES: Limit = Limit::new(
    "camera samples (width × height × spp)",
    "render-samples",
    1 << 40,
    1 << 56,
    "more than a day of rendering; lower spp or the film size",
);

/// Worker threads.
pub static THREADS: Limit = Limit::fixed(
    "worker threads",
    "threads",
    4096,
    "more threads than cores only adds overhead",
);

/// A time limit in seconds (a `Duration` holds up to 2^64 s; this is about 31 years).
pub const TIME_LIMIT_SECONDS: f64 = 1e9;

/// Exposure in stops, either sign: 2^64 times the largest radiance input
/// ([`MAX_RADIANCE`]) stays inside f32, the image's pixel type.
pub const MAX_EXPOSURE_STOPS: f64 = 64.0;

/// An exposure in stops: finite and within ±[`MAX_EXPOSURE_STOPS`], so that no pixel of a
/// scene within the radiance limit becomes infinite (2^2000 is +Inf).
pub fn check_exposure(stops: f64) -> Result<f64, String> {
    let max = MAX_EXPOSURE_STOPS;
    if stops.is_finite() && stops.abs() <= max {
        Ok(stops)
    } else {
        Err(format!(
            "{} stops is outside -{max}…{max} (beyond it the image's pixels overflow or vanish)",
            fmt_num(stops)
        ))
    }
}

/// A radiance-like input (emission, intensity, irradiance, scale): finite, ≥ 0 and at most
/// [`MAX_RADIANCE`], so that film sums stay finite.
pub fn check_radiance(value: f64) -> Result<f64, String> {
    if value.is_finite() && (0.0..=MAX_RADIANCE).contains(&value) {
        Ok(value)
    } else {
        Err(format!(
            "{} is outside 0…{MAX_RADIANCE:e} (larger values overflow the film's sums; scale the exposure instead)",
            fmt_num(value)
        ))
    }
}

/// The largest radiance-like input (emission, light intensity, environment scale, …):
/// with at most [`SAMPLES_PER_PIXEL`] samples a pixel's f64 sums cannot overflow, and an
/// exposure of up to ±[`MAX_EXPOSURE_STOPS`] keeps pixels finite in f32.
pub const MAX_RADIANCE: f64 = 1e15;

/// The largest world-space coordinate of any object's bounds. Beyond it areas (2e30² is
/// fine, 1e300² is not) and the BVH's f32 boxes (largest finite value 3.4e38) overflow,
/// and a light's sampling density silently becomes 0: a rectangle scaled by 1e300 rendered
/// 0.007 where its emission is 1. 1e30 m is far beyond the observable universe (4.4e26 m).
pub const MAX_COORDINATE: f64 = 1e30;

/// Entries of an IL body table, n_θ × n_θ × n_φ (8 bytes each: 800 MB). A 0.25° grid
/// (94 million entries) fits.
pub static TABLE_ENTRIES: Limit = Limit::new(
    "table entries (n_theta × n_theta × n_phi)",
    "table-entries",
    100_000_000,
    1 << 33,
    "a 0.25° grid fits; use a coarser --step",
);

/// Parts of a distributed render or table.
pub static PARTS: Limit = Limit::fixed(
    "parts of a distributed job",
    "parts",
    1 << 20,
    "a part count written by facette is far below this; the file is likely corrupt",
);

/// [`PLOT_POINTS`]'s bound as a constant (command-line parsers take it as a const
/// parameter; the limit is fixed, so the two cannot differ).
pub const PLOT_POINTS_MAX: u64 = 1_000_000;
/// [`SAMPLES`]'s bound as a constant, for the same reason.
pub const SAMPLES_MAX: u64 = 1 << 32;

/// Points of a plotted curve or pixels of a plotted map side.
pub static PLOT_POINTS: Limit = Limit::fixed(
    "plot points",
    "plot-points",
    PLOT_POINTS_MAX,
    "a chart cannot show more points than that",
);

/// Monte Carlo or quadrature samples asked for on the command line.
pub static SAMPLES: Limit = Limit::fixed(
    "samples",
    "samples",
    SAMPLES_MAX,
    "4.3 billion samples; run several seeds and average",
);

/// A count in a material table that sizes a table or a loop (`samples`, `table_samples`,
/// `resolution`, `masking_lobes`).
pub static RECIPE_COUNT: Limit = Limit::new(
    "a material's count",
    "material-count",
    1 << 24,
    1 << 28,
    "16.7 million; the defaults are far below",
);

/// Lobes of a glint surface: map texels × `seed_subdivision`² (40 bytes each with the
/// hierarchy and mip levels).
pub static GLINT_LOBES: Limit = Limit::new(
    "glint lobes (map texels × seed_subdivision²)",
    "glint-lobes",
    1 << 24,
    1 << 28,
    "40 bytes a lobe, 640 MiB at the default; use a smaller seed_subdivision or map",
);

/// Files `<include>`d by a Mitsuba scene, all levels together.
pub static XML_INCLUDES: Limit = Limit::new(
    "<include>d files",
    "xml-includes",
    256,
    1 << 16,
    "a scene that needs more includes can concatenate them",
);

/// `<include>` nesting (Mitsuba's own limit).
pub static XML_INCLUDE_DEPTH: Limit = Limit::fixed(
    "<include> nesting depth",
    "xml-include-depth",
    15,
    "Mitsuba 3 has the same limit",
);

/// Element nesting in an XML file (Mitsuba scenes nest a handful of levels).
pub static XML_DEPTH: Limit = Limit::fixed(
    "XML element nesting depth",
    "xml-depth",
    64,
    "Mitsuba scenes nest a handful of levels",
);

/// XML elements of a scene after includes are spliced in.
pub static XML_ELEMENTS: Limit = Limit::new(
    "XML elements (after includes)",
    "xml-elements",
    1_000_000,
    1 << 28,
    "store geometry in mesh files, not in the XML",
);

/// `<ref>` chains (an object referring to an object referring to …).
pub static XML_REF_DEPTH: Limit = Limit::fixed(
    "<ref> chain length",
    "xml-ref-depth",
    64,
    "objects refer to each other a few levels deep at most",
);

/// Bytes of one attribute after `$parameter` substitution, and of all of them together.
pub static XML_EXPANDED_BYTES: Limit = Limit::new(
    "bytes of attributes after $parameter substitution",
    "xml-expanded-bytes",
    16 << 20,
    1 << 32,
    "parameters that expand to parameters grow exponentially",
);

/// Vertices or faces of one mesh (indices are 32-bit).
pub static MESH_ELEMENTS: Limit = Limit::new(
    "mesh elements (vertices or faces)",
    "mesh-elements",
    1 << 28,
    u32::MAX as u64,
    "split the mesh into several objects",
);

/// Scene files (TOML or XML) read into memory.
pub static SCENE_FILE_BYTES: Limit = Limit::new(
    "scene file bytes",
    "scene-file-bytes",
    256 << 20,
    1 << 34,
    "store geometry in mesh files, not in the scene",
);

/// Bytes of a mesh file (OBJ) read into memory at once.
pub static MESH_FILE_BYTES: Limit = Limit::new(
    "mesh file bytes",
    "mesh-file-bytes",
    1 << 32,
    1 << 40,
    "4 GiB; split the mesh into several files",
);

/// Pixels of one image layer read (EXR, PNG, HDR; 2^28 is 16k × 16k).
pub static IMAGE_PIXELS: Limit = Limit::new(
    "image pixels (width × height)",
    "image-pixels",
    1 << 28,
    1 << 31,
    "16k × 16k; downsample the image",
);

/// Samples (pixels × channels, all layers) of one image file read: 4 GiB as f32.
pub static IMAGE_SAMPLES: Limit = Limit::new(
    "image samples (pixels × channels, all layers)",
    "image-samples",
    1 << 30,
    1 << 33,
    "4 GiB of f32; remove unused layers or channels",
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_are_checked_and_overflow_is_an_error() {
        assert_eq!(FILM_PIXELS.check_product(&[640, 480]), Ok(307_200));
        let e = FILM_PIXELS.check_product(&[65536, 65536]).unwrap_err();
        assert!(e.to_string().contains("65536 × 65536 = 4294967296"), "{e}");
        assert!(e.to_string().contains("limit of 33554432"), "{e}");
        let e = RENDER_SAMPLES
            .check_product(&[1000, 1000, u64::MAX])
            .unwrap_err();
        assert!(e.to_string().contains("more than 2^64"), "{e}");
    }

    #[test]
    fn radiance_and_exposure_bounds_keep_pixels_finite() {
        // The largest pixel mean times the largest exposure must fit an f32.
        let pixel = MAX_RADIANCE * MAX_EXPOSURE_STOPS.exp2();
        assert!(pixel < f32::MAX as f64);
        // And a pixel's f64 sum of the largest sample count cannot overflow.
        assert!((MAX_RADIANCE * SAMPLES_PER_PIXEL.max() as f64).is_finite());
    }

    #[test]
    fn limits_are_raised_by_key_up_to_their_ceiling_and_fixed_ones_stay() {
        // Only this test changes limits, and only XML_INCLUDES, which no other lib test
        // of this crate reads.
        let keys: Vec<&str> = all().iter().map(|l| l.key).collect();
        let mut unique = keys.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), keys.len(), "duplicate keys: {keys:?}");
        assert!(all().iter().all(|l| l.ceiling >= l.default));

        let e = XML_INCLUDES.check(257).unwrap_err().to_string();
        assert!(e.contains("--limit xml-includes=N, up to 65536"), "{e}");
        set_limit("xml-includes=1000").unwrap();
        assert_eq!(XML_INCLUDES.check(1000), Ok(1000));
        assert!(XML_INCLUDES.check(1001).is_err());
        set_limit(&format!("xml-includes={}", XML_INCLUDES.default)).unwrap();

        let e = set_limit("xml-depth=1000").unwrap_err();
        assert!(e.contains("is fixed at 64"), "{e}");
        assert!(e.contains("mesh-elements"), "lists the raisable ones: {e}");
        let e = set_limit("mesh-element=5").unwrap_err();
        assert!(e.starts_with("unknown limit `mesh-element`"), "{e}");
        assert!(set_limit("xml-includes=0")
            .unwrap_err()
            .contains("outside 1…65536"));
        assert!(set_limit("xml-includes=65537").is_err());
        assert!(set_limit("xml-includes")
            .unwrap_err()
            .contains("expected KEY=N"));
        assert!(set_limit("xml-includes=1e3")
            .unwrap_err()
            .contains("not a whole number"));
        assert_eq!(XML_INCLUDES.max(), XML_INCLUDES.default);
    }
}
