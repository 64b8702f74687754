//! Named indices of refraction that Mitsuba's dielectric parameters (`int_ior`,
//! `ext_ior`) accept instead of a number: Mitsuba's table, values at about 589 nm
//! from Hecht, *Optics* (4th ed.).

use super::plugin::{Plugin, Value};
use crate::scene::SceneError;

/// (name, index), in Mitsuba's order.
pub(crate) const NAMED_IORS: &[(&str, f64)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// The index a name stands for (case-insensitive).
pub(crate) fn lookup_ior(name: &str) -> Option<f64> {
    let lower = name.trim().to_ascii_lowercase();
    NAMED_IORS
        .iter()
        .find(|(n, _)| *n == lower)
        .map(|(_, v)| *v)
}

/// An index-of-refraction parameter: a number or a name from [`NAMED_IORS`]; `default`
/// when absent.
pub(crate) fn ior_param(p: &Plugin, name: &str, default: f64) -> Result<f64, SceneError> {
    let Some(prop) = p.get(name) else {
        return Ok(default);
    };
    let v = match &prop.value {
        Value::Float(v) => *v,
        Value::Integer(v) => *v as f64,
        Value::String(s) => lookup_ior(s).ok_or_else(|| {
            prop.pos.err(format!(
                "{}: `{name}` = \"{s}\" is not a known medium; give a number or one of: {}",
                p.describe(),
                NAMED_IORS
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?,
        _ => {
            return Err(prop.pos.err(format!(
                "{}: `{name}` must be a <float> or a <string> naming a medium",
                p.describe()
            )))
        }
    };
    if !(v > 0.0 && v.is_finite()) {
        return Err(prop.pos.err(format!(
            "{}: `{name}` = {v} must be a finite index > 0",
            p.describe()
        )));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_media_match_mitsubas_table() {
        assert_eq!(lookup_ior("BK7"), Some(1.5046));
        assert_eq!(lookup_ior("water"), Some(1.333));
        assert_eq!(lookup_ior("air"), Some(1.000277));
        assert_eq!(lookup_ior("Acrylic Glass"), Some(1.49));
        assert_eq!(lookup_ior("unobtainium"), None);
    }
}
