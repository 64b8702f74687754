//! Typed access to a table of parameters that remembers which keys were read, so that
//! leftovers are reported as unknown with the list of valid keys.

use crate::error::{ParamError, ParamResult};
use crate::math::spectrum::Spectrum;
use std::cell::RefCell;
use std::collections::BTreeSet;

pub struct Params<'a> {
    table: &'a toml::Table,
    context: String,
    used: RefCell<BTreeSet<String>>,
}

fn type_name(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => format!("the string \"{s}\""),
        toml::Value::Integer(i) => format!("the integer {i}"),
        toml::Value::Float(f) => format!("the number {f}"),
        toml::Value::Boolean(b) => format!("the boolean {b}"),
        toml::Value::Array(_) => "an array".into(),
        toml::Value::Table(_) => "a table".into(),
        toml::Value::Datetime(_) => "a date".into(),
    }
}

impl<'a> Params<'a> {
    /// `context` names the thing being built in error messages (`material "dielectric"`).
    pub fn new(table: &'a toml::Table, context: impl Into<String>) -> Self {
        Params {
            table,
            context: context.into(),
            used: RefCell::new(BTreeSet::new()),
        }
    }

    pub fn context(&self) -> &str {
        &self.context
    }

    pub fn has(&self, key: &str) -> bool {
        self.table.contains_key(key)
    }

    fn take(&self, key: &str) -> Option<&'a toml::Value> {
        let v = self.table.get(key);
        if v.is_some() {
            self.used.borrow_mut().insert(key.to_string());
        }
        v
    }

    fn wrong(&self, key: &str, expected: &str, got: &toml::Value) -> ParamError {
        ParamError::WrongType {
            key: key.into(),
            expected: expected.into(),
            got: type_name(got),
        }
    }

    /// A number (integers accepted).
    pub fn f64(&self, key: &str) -> ParamResult<Option<f64>> {
        match self.take(key) {
            None => Ok(None),
            Some(toml::Value::Float(f)) => Ok(Some(*f)),
            Some(toml::Value::Integer(i)) => Ok(Some(*i as f64)),
            Some(v) => Err(self.wrong(key, "a number", v)),
        }
    }

    pub fn f64_or(&self, key: &str, default: f64) -> ParamResult<f64> {
        Ok(self.f64(key)?.unwrap_or(default))
    }

    pub fn required_f64(&self, key: &str) -> ParamResult<f64> {
        self.f64(key)?.ok_or_else(|| ParamError::MissingKey {
            key: key.into(),
            context: self.context.clone(),
        })
    }

    /// A non-negative integer.
    pub fn usize(&self, key: &str) -> ParamResult<Option<usize>> {
        match self.take(key) {
            None => Ok(None),
            Some(toml::Value::Integer(i)) if *i >= 0 => Ok(Some(*i as usize)),
            Some(v) => Err(self.wrong(key, "a non-negative integer", v)),
        }
    }

    /// A count that sizes a table or a loop (`samples`, `table_samples`, `resolution`):
    /// a non-negative integer within [`crate::limits::RECIPE_COUNT`], checked before it
    /// is used (10^12 samples would never finish).
    pub fn count(&self, key: &str) -> ParamResult<Option<usize>> {
        let v = self.usize(key)?;
        if let Some(n) = v {
            let max = crate::limits::RECIPE_COUNT.max();
            if n as u64 > max {
                return Err(ParamError::OutOfRange {
                    name: key.into(),
                    value: n as f64,
                    expected: format!(
                        "{key} <= {max} ({})",
                        crate::limits::RECIPE_COUNT.how_to_lift()
                    ),
                });
            }
        }
        Ok(v)
    }

    pub fn bool(&self, key: &str) -> ParamResult<Option<bool>> {
        match self.take(key) {
            None => Ok(None),
            Some(toml::Value::Boolean(b)) => Ok(Some(*b)),
            Some(v) => Err(self.wrong(key, "true or false", v)),
        }
    }

    pub fn str(&self, key: &str) -> ParamResult<Option<&'a str>> {
        match self.take(key) {
            None => Ok(None),
            Some(toml::Value::String(s)) => Ok(Some(s.as_str())),
            Some(v) => Err(self.wrong(key, "a string", v)),
        }
    }

    /// A reflectance or index per channel: a number, or an array of three numbers.
    pub fn spectrum(&self, key: &str) -> ParamResult<Option<Spectrum>> {
        match self.take(key) {
            None => Ok(None),
            Some(toml::Value::Float(f)) => Ok(Some(Spectrum::splat(*f))),
            Some(toml::Value::Integer(i)) => Ok(Some(Spectrum::splat(*i as f64))),
            Some(toml::Value::Array(a)) if a.len() == 3 => {
                let mut s = Spectrum::ZERO;
                for (k, v) in a.iter().enumerate() {
                    s[k] = match v {
                        toml::Value::Float(f) => *f,
                        toml::Value::Integer(i) => *i as f64,
                        other => return Err(self.wrong(key, "three numbers [r, g, b]", other)),
                    };
                }
                Ok(Some(s))
            }
            Some(v) => Err(self.wrong(key, "a number or an RGB triple [r, g, b]", v)),
        }
    }

    /// One number or an array of numbers (integers accepted).
    pub fn numbers(&self, key: &str) -> ParamResult<Option<Vec<f64>>> {
        let num = |v: &toml::Value| match v {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        };
        match self.take(key) {
            None => Ok(None),
            Some(toml::Value::Array(a)) => a
                .iter()
                .map(|v| num(v).ok_or_else(|| self.wrong(key, "numbers", v)))
                .collect::<ParamResult<Vec<f64>>>()
                .map(Some),
            Some(v) => num(v)
                .map(|x| Some(vec![x]))
                .ok_or_else(|| self.wrong(key, "a number or an array of numbers", v)),
        }
    }

    /// Errors on any key not read so far, listing `valid`.
    /// Fails on the first key of the table that is not in `valid` (before any is read).
    pub fn check_known(&self, valid: &[&str]) -> ParamResult<()> {
        match self.table.keys().find(|k| !valid.contains(&k.as_str())) {
            Some(key) => Err(ParamError::UnknownKey {
                key: key.clone(),
                context: self.context.clone(),
                valid: valid.join(", "),
            }),
            None => Ok(()),
        }
    }

    pub fn finish(&self, valid: &[&str]) -> ParamResult<()> {
        let used = self.used.borrow();
        for key in self.table.keys() {
            if !used.contains(key) {
                return Err(ParamError::UnknownKey {
                    key: key.clone(),
                    context: self.context.clone(),
                    valid: valid.join(", "),
                });
            }
        }
        Ok(())
    }
}

/// The error of a key whose value is not one of `valid`.
pub fn choice(what: &str, given: &str, valid: &[&str]) -> ParamError {
    ParamError::UnknownChoice {
        what: what.into(),
        given: given.into(),
        valid: valid.join(", "),
    }
}
