//! Parameter errors: every part validates its parameters when it is built and reports the
//! offending name, its value and the valid range — never a panic.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum ParamError {
    #[error("parameter `{name}` = {value} is out of range: expected {expected}")]
    OutOfRange {
        name: String,
        value: f64,
        expected: String,
    },
    #[error("parameter `{name}` must be a finite number, got {value}")]
    NotFinite { name: String, value: f64 },
    #[error("unknown {what} `{given}`; valid values: {valid}")]
    UnknownChoice {
        what: String,
        given: String,
        valid: String,
    },
    #[error("unknown key `{key}` for {context}; valid keys: {valid}")]
    UnknownKey {
        key: String,
        context: String,
        valid: String,
    },
    #[error("missing required key `{key}` for {context}")]
    MissingKey { key: String, context: String },
    #[error("key `{key}`: expected {expected}, got {got}")]
    WrongType {
        key: String,
        expected: String,
        got: String,
    },
    #[error("{0}")]
    Invalid(String),
}

pub type ParamResult<T> = Result<T, ParamError>;

/// Which ends of an interval are included.
#[derive(Clone, Copy, Debug)]
pub enum Bounds {
    /// (lo, hi)
    Open,
    /// [lo, hi]
    Closed,
    /// (lo, hi]
    OpenClosed,
    /// [lo, hi)
    ClosedOpen,
}

/// Checks that `value` is finite and inside the interval; the error names the parameter.
pub fn check_range(name: &str, value: f64, lo: f64, hi: f64, bounds: Bounds) -> ParamResult<f64> {
    if !value.is_finite() {
        return Err(ParamError::NotFinite {
            name: name.into(),
            value,
        });
    }
    let ok = match bounds {
        Bounds::Open => value > lo && value < hi,
        Bounds::Closed => value >= lo && value <= hi,
        Bounds::OpenClosed => value > lo && value <= hi,
        Bounds::ClosedOpen => value >= lo && value < hi,
    };
    if ok {
        return Ok(value);
    }
    // The message is formatted only on failure: materials are rebuilt per shading point
    // when textured.
    let (l, h) = (crate::math::fmt_num(lo), crate::math::fmt_num(hi));
    let expected = match bounds {
        Bounds::Open => format!("{l} < {name} < {h}"),
        Bounds::Closed => format!("{l} <= {name} <= {h}"),
        Bounds::OpenClosed => format!("{l} < {name} <= {h}"),
        Bounds::ClosedOpen => format!("{l} <= {name} < {h}"),
    };
    Err(ParamError::OutOfRange {
        name: name.into(),
        value,
        expected,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn range_errors_name_the_parameter() {
        let e = check_range("alpha", -1.0, 0.0, 10.0, Bounds::OpenClosed).unwrap_err();
        assert_eq!(
            e.to_string(),
            "parameter `alpha` = -1 is out of range: expected 0 < alpha <= 10"
        );
        let e = check_range("ior", f64::NAN, 0.0, 10.0, Bounds::Open).unwrap_err();
        assert!(e.to_string().contains("`ior` must be a finite number"));
        assert_eq!(check_range("x", 0.0, 0.0, 1.0, Bounds::Closed), Ok(0.0));
    }
}
