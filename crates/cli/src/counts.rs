//! Counts given on the command line (`--samples`, `--points`, …) are parsed with their
//! range, so that 0 or 10^18 is a clear usage error naming the option before anything is
//! allocated or looped over; the upper bounds come from `facette_bsdf::limits`.

use facette_bsdf::limits;

/// A whole number in `MIN..=MAX`, for clap's `value_parser`.
pub fn count<const MIN: u64, const MAX: u64>(s: &str) -> Result<usize, String> {
    let v: u64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a whole number"))?;
    if v < MIN || v > MAX {
        return Err(format!("{v} is outside {MIN}…{MAX}"));
    }
    usize::try_from(v).map_err(|_| format!("{v} does not fit this machine's usize"))
}

/// Monte Carlo samples (`--samples` of albedo, eval, validate, plot).
pub const SAMPLES: u64 = limits::SAMPLES_MAX;
/// Microfacets of a quadrature (`--samples` of tabulate and il-approx, `--il-samples`).
pub const QUADRATURE: u64 = 1 << 24;
/// Points of a plotted curve.
pub const POINTS: u64 = limits::PLOT_POINTS_MAX;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_outside_their_range_are_refused() {
        assert_eq!(count::<1, 10>("3"), Ok(3));
        assert!(count::<1, 10>("0").unwrap_err().contains("outside 1…10"));
        assert!(count::<1, 10>("18446744073709551616")
            .unwrap_err()
            .contains("not a whole number"));
        assert!(count::<2, POINTS>("1000000000").is_err());
    }
}
