//! Parsing of `--material` (a TOML inline table) shared by the subcommands.

use anyhow::{Context, Result};
use facette_bsdf::spec::{build_material, parse_inline_table};
use facette_bsdf::Bsdf;
use std::sync::Arc;

pub fn parse_material(text: &str) -> Result<Arc<dyn Bsdf>> {
    let table = parse_inline_table(text).context("--material")?;
    build_material(&table).context("--material")
}
