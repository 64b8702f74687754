//! Numbers in attribute values: Mitsuba separates the components of a vector, colour or
//! matrix by commas and/or whitespace.

use crate::geometry::Vec3;

/// Every number of a comma- or whitespace-separated list.
pub(crate) fn parse_numbers(s: &str) -> Result<Vec<f64>, String> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| {
            t.parse::<f64>()
                .map_err(|_| format!("`{t}` is not a number (in \"{s}\")"))
        })
        .collect()
}

/// Exactly three numbers.
pub(crate) fn parse_vec3(s: &str) -> Result<Vec3, String> {
    match parse_numbers(s)?.as_slice() {
        [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
        v => Err(format!(
            "expected three numbers, got {} in \"{s}\"",
            v.len()
        )),
    }
}

/// One or three numbers (one is repeated), as `<rgb value>` takes.
pub(crate) fn parse_one_or_three(s: &str) -> Result<[f64; 3], String> {
    match parse_numbers(s)?.as_slice() {
        [x] => Ok([*x; 3]),
        [x, y, z] => Ok([*x, *y, *z]),
        v => Err(format!(
            "expected one or three numbers, got {} in \"{s}\"",
            v.len()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commas_and_spaces_separate_numbers() {
        assert_eq!(parse_numbers("1, 2 3,4").unwrap(), vec![1.0, 2.0, 3.0, 4.0]);
        assert_eq!(parse_one_or_three("0.5").unwrap(), [0.5; 3]);
        assert_eq!(parse_vec3(" 1,2,3 ").unwrap(), Vec3::new(1.0, 2.0, 3.0));
        assert!(parse_vec3("1 2").unwrap_err().contains("three numbers"));
        assert!(parse_numbers("1 x")
            .unwrap_err()
            .contains("`x` is not a number"));
    }
}
