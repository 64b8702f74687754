//! Resource limits: every bound facette puts on what an input may make it allocate or
//! compute, stated once. A size read from a file or a flag is checked here *before* the
//! allocation or the loop it would drive, with checked arithmetic, so a careless or hostile
//! input gets an error naming the quantity, its value and the limit — never an allocation
//! abort, an overflow panic or a run that cannot finish.
//!
//! The limits are far above anything the documented uses need (an 8K film, a 0.25° table,
//! a million-triangle mesh); each says how to get past it when that makes sense. This
//! module sits at the bottom of the crate with `error` and `checks`: every crate of the
//! workspace depends on `facette-bsdf`, so the render, lab and CLI limits live here too.

use crate::math::fmt_num;
use thiserror::Error;

/// One resource bound: what is counted, its maximum, and how to get past it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limit {
    /// What is counted, as the message names it (`"film pixels (width × height)"`).
    pub what: &'static str,
    /// The largest accepted value.
    pub max: u64,
    /// How to get past the limit, or why it is where it is.
    pub lift: &'static str,
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
    /// `value` if it is at most the limit.
    pub fn check(&self, value: u64) -> Result<u64, LimitError> {
        if value <= self.max {
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
        if p <= self.max {
            Ok(p)
        } else {
            Err(self.error(format!("{} = {p}", product_text(factors))))
        }
    }

    fn error(&self, value: String) -> LimitError {
        LimitError {
            what: self.what.to_string(),
            value,
            max: self.max,
            lift: self.lift.to_string(),
        }
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
pub const FILM_PIXELS: Limit = Limit {
    what: "film pixels (width × height)",
    max: 1 << 25,
    lift: "8K UHD fits; render a larger image as tiles with a cropped camera",
};

/// Film width or height on its own.
pub const FILM_SIDE: Limit = Limit {
    what: "film width or height",
    max: 65536,
    lift: "the film's pixel count is limited separately",
};

/// Samples per pixel. Sample indices are 32-bit in the sampler and part files.
pub const SAMPLES_PER_PIXEL: Limit = Limit {
    what: "samples per pixel",
    max: 1 << 24,
    lift: "16.7 million samples per pixel; for more, render parts with --part K/N and merge them",
};

/// Camera samples of a whole render, pixels × spp: 2^40 (10^12) samples take more than a
/// day at 10 Msamples/s, so a larger product is a mistake (an 8K film at 32768 spp fits).
pub const RENDER_SAMPLES: Limit = Limit {
    what: "camera samples (width × height × spp)",
    max: 1 << 40,
    lift: "more than a day of rendering; lower spp or the film size",
};

/// Worker threads.
pub const THREADS: Limit = Limit {
    what: "worker threads",
    max: 4096,
    lift: "more threads than cores only adds overhead",
};

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

/// Entries of an IL body table, n_θ × n_θ × n_φ (8 bytes each: 800 MB). A 0.25° grid
/// (94 million entries) fits.
pub const TABLE_ENTRIES: Limit = Limit {
    what: "table entries (n_theta × n_theta × n_phi)",
    max: 100_000_000,
    lift: "a 0.25° grid fits; use a coarser --step",
};

/// Parts of a distributed render or table.
pub const PARTS: Limit = Limit {
    what: "parts of a distributed job",
    max: 1 << 20,
    lift: "a part count written by facette is far below this; the file is likely corrupt",
};

/// Points of a plotted curve or pixels of a plotted map side.
pub const PLOT_POINTS: Limit = Limit {
    what: "plot points",
    max: 1_000_000,
    lift: "a chart cannot show more points than that",
};

/// Monte Carlo or quadrature samples asked for on the command line.
pub const SAMPLES: Limit = Limit {
    what: "samples",
    max: 1 << 32,
    lift: "4.3 billion samples; run several seeds and average",
};

/// A count in a material table that sizes a table or a loop (`samples`, `table_samples`,
/// `resolution`, `masking_lobes`).
pub const RECIPE_COUNT: Limit = Limit {
    what: "a material's count",
    max: 1 << 24,
    lift: "16.7 million; the defaults are far below",
};

/// Files `<include>`d by a Mitsuba scene, all levels together.
pub const XML_INCLUDES: Limit = Limit {
    what: "<include>d files",
    max: 256,
    lift: "a scene that needs more includes can concatenate them",
};

/// `<include>` nesting (Mitsuba's own limit).
pub const XML_INCLUDE_DEPTH: Limit = Limit {
    what: "<include> nesting depth",
    max: 15,
    lift: "Mitsuba 3 has the same limit",
};

/// Element nesting in an XML file (Mitsuba scenes nest a handful of levels).
pub const XML_DEPTH: Limit = Limit {
    what: "XML element nesting depth",
    max: 64,
    lift: "Mitsuba scenes nest a handful of levels",
};

/// XML elements of a scene after includes are spliced in.
pub const XML_ELEMENTS: Limit = Limit {
    what: "XML elements (after includes)",
    max: 1_000_000,
    lift: "store geometry in mesh files, not in the XML",
};

/// `<ref>` chains (an object referring to an object referring to …).
pub const XML_REF_DEPTH: Limit = Limit {
    what: "<ref> chain length",
    max: 64,
    lift: "objects refer to each other a few levels deep at most",
};

/// Bytes of one attribute after `$parameter` substitution, and of all of them together.
pub const XML_EXPANDED_BYTES: Limit = Limit {
    what: "bytes of attributes after $parameter substitution",
    max: 16 << 20,
    lift: "parameters that expand to parameters grow exponentially",
};

/// Vertices or faces of one mesh (indices are 32-bit).
pub const MESH_ELEMENTS: Limit = Limit {
    what: "mesh elements (vertices or faces)",
    max: 1 << 28,
    lift: "split the mesh into several objects",
};

/// Scene files (TOML or XML) read into memory.
pub const SCENE_FILE_BYTES: Limit = Limit {
    what: "scene file bytes",
    max: 256 << 20,
    lift: "store geometry in mesh files, not in the scene",
};

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
        assert!((MAX_RADIANCE * SAMPLES_PER_PIXEL.max as f64).is_finite());
    }
}
