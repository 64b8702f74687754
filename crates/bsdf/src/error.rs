//! Parameter errors: every part validates its parameters when it is built and reports the
//! offending name, its value and the valid range — never a panic.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum ParamError {
    // Values are printed short (1.00000e308, not 309 digits).
    #[error("parameter `{name}` = {} is out of range: expected {expected}", crate::math::fmt_num(*.value))]
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
