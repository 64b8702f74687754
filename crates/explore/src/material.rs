//! A material as the app sends it — a TOML inline table, the syntax of `--material` and of
//! scene files — parsed and built by the grammar ([`facette_bsdf::recipe`]), so the app
//! shows the grammar's own error messages. Built materials are kept in a small cache keyed
//! by their canonical text: moving the light does not rebuild a Kelemen albedo table or a
//! glint map.

use facette_bsdf::recipe::schema::material_type;
use facette_bsdf::recipe::{build_material_with_reader, parse_inline_table};
use facette_bsdf::Bsdf;
use facette_render::image::ImageNormalMapReader;
use std::sync::{Arc, Mutex};

/// A parsed and built material.
#[derive(Clone)]
pub struct Material {
    /// The table written back with `type` first and the other keys in the schema's order.
    pub text: String,
    /// The table itself.
    pub table: toml::Table,
    pub bsdf: Arc<dyn Bsdf>,
}

/// The canonical inline-table text of `table`: `type` first, then the keys in the order of
/// the type's schema (unknown keys last, alphabetically: the grammar refuses them anyway).
pub fn canonical_text(table: &toml::Table) -> String {
    let ty = table.get("type").and_then(|t| t.as_str());
    let order: Vec<&str> = ty
        .and_then(material_type)
        .map(|t| t.keys())
        .unwrap_or_default();
    let mut keys: Vec<&String> = table.keys().filter(|k| k.as_str() != "type").collect();
    keys.sort_by_key(|k| {
        (
            order.iter().position(|o| o == k).unwrap_or(usize::MAX),
            k.to_string(),
        )
    });
    let mut parts = Vec::new();
    if let Some(t) = table.get("type") {
        parts.push(format!("type = {t}"));
    }
    for k in keys {
        parts.push(format!("{k} = {}", table[k.as_str()]));
    }
    format!("{{{}}}", parts.join(", "))
}

/// Parses and builds `text`; the error is the grammar's message.
pub fn build(text: &str) -> Result<Material, String> {
    let table = parse_inline_table(text).map_err(|e| e.to_string())?;
    let bsdf = build_material_with_reader(&table, std::path::Path::new("."), &ImageNormalMapReader)
        .map_err(|e| e.to_string())?;
    Ok(Material {
        text: canonical_text(&table),
        table,
        bsdf,
    })
}

/// The last few materials built, by canonical text.
#[derive(Default)]
pub struct MaterialCache {
    entries: Mutex<Vec<Material>>,
}

impl MaterialCache {
    const SIZE: usize = 16;

    /// The material of `text`, built once.
    pub fn get(&self, text: &str) -> Result<Material, String> {
        let key = parse_inline_table(text)
            .map(|t| canonical_text(&t))
            .map_err(|e| e.to_string())?;
        if let Some(m) = self.lock().iter().find(|m| m.text == key) {
            return Ok(m.clone());
        }
        let m = build(text)?;
        let mut entries = self.lock();
        entries.retain(|e| e.text != m.text);
        entries.insert(0, m.clone());
        entries.truncate(Self::SIZE);
        Ok(m)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<Material>> {
        // A panic while holding the lock leaves a list of whole entries: keep using it.
        self.entries.lock().unwrap_or_else(|p| p.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn canonical_text_orders_keys_by_the_schema() {
        let t = parse_inline_table(
            r#"{material = "Au", alpha = 0.2, type = "conductor", distribution = "ggx"}"#,
        )
        .unwrap();
        assert_eq!(
            canonical_text(&t),
            r#"{type = "conductor", distribution = "ggx", alpha = 0.2, material = "Au"}"#
        );
    }

    #[test]
    fn errors_are_the_grammars_and_the_cache_builds_once() {
        let e = build(r#"{type = "conductor", alpha = -1}"#).err().unwrap();
        assert!(e.contains("`alpha` = -1 is out of range"), "{e}");
        let cache = MaterialCache::default();
        let a = cache
            .get(r#"{type = "lambert", reflectance = 0.3}"#)
            .unwrap();
        let b = cache
            .get(r#"{ reflectance = 0.3, type = "lambert" }"#)
            .unwrap();
        assert!(Arc::ptr_eq(&a.bsdf, &b.bsdf));
    }
}
