//! Materials and distributions written as TOML tables — the syntax shared by the command
//! line (`--material '{type = "dielectric", alpha = 0.3}'`) and the scene files. Every key
//! is validated; unknown keys and values are errors that list the valid ones.
//!
//! - [`params`]: typed access to a table that reports unknown keys;
//! - [`microfacet`]: the microfacet keys shared by every rough model;
//! - [`material`]: [`MaterialRecipe`], one file per family of models.
//!
//! This is the top layer of the crate's models: it imports models, never the reverse.

pub mod material;
pub mod microfacet;
pub mod params;
pub mod schema;

pub use material::glint::{DecodedImage, GlintRecipe, NormalMapReader};
pub use material::{
    build_material, build_material_in, build_material_with_reader, MaterialRecipe, MATERIAL_TYPES,
};
pub use params::Params;

use crate::error::ParamError;

/// Parses `{key = value, …}` (a TOML inline table) into a table.
pub fn parse_inline_table(text: &str) -> Result<toml::Table, ParamError> {
    let src = format!("value = {}", text.trim());
    let mut t: toml::Table = toml::from_str(&src).map_err(|e| {
        ParamError::Invalid(format!(
            "not a TOML inline table ({{key = value, ...}}): {}",
            e.message()
        ))
    })?;
    let value = t.remove("value");
    // Text after the table (`{…}\n[[lights]]…`) parses as more of the document: refuse it
    // rather than drop it silently.
    if let Some(extra) = t.keys().next() {
        return Err(ParamError::Invalid(format!(
            "not a TOML inline table ({{key = value, ...}}): text after the table defines `{extra}`"
        )));
    }
    match value {
        Some(toml::Value::Table(tab)) => Ok(tab),
        Some(other) => Err(ParamError::Invalid(format!(
            "expected a TOML inline table {{key = value, ...}}, got a {}",
            other.type_str()
        ))),
        None => Err(ParamError::Invalid("empty table".into())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inline_tables_parse_and_errors_are_readable() {
        let t = parse_inline_table(r#"{type = "lambert", reflectance = [0.1, 0.2, 0.3]}"#).unwrap();
        assert_eq!(t["type"].as_str(), Some("lambert"));
        let e = parse_inline_table("{type = }").unwrap_err().to_string();
        assert!(e.contains("not a TOML inline table"), "{e}");
        let e = parse_inline_table("3").unwrap_err().to_string();
        assert!(e.contains("got a integer"), "{e}");
        let e = parse_inline_table("{type = \"lambert\"}\n[[lights]]\ntype = \"point\"")
            .unwrap_err()
            .to_string();
        assert!(e.contains("text after the table defines `lights`"), "{e}");
    }
}
