//! A material as the app sends it — a TOML inline table, the syntax of `--material` and of
//! scene files — parsed and built by the grammar ([`facette_bsdf::recipe`]), so the app
//! shows the grammar's own error messages; or `measured:ID`, a MERL file the app uploaded
//! (or `--merl` loaded), shown through [`MeasuredBsdf`]. Built materials are kept in a
//! small cache keyed by their canonical text: moving the light does not rebuild a Kelemen
//! albedo table or a glint map.

use facette_bsdf::recipe::schema::{canonical_type, material_type};
use facette_bsdf::recipe::{build_material_with_reader, parse_inline_table};
use facette_bsdf::Bsdf;
use facette_lab::measured_bsdf::MeasuredBsdf;
use facette_lab::merl::MerlBrdf;
use facette_render::image::ImageNormalMapReader;
use std::sync::{Arc, Mutex, OnceLock};

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
        parts.push(format!("{} = {}", toml_key(k), table[k.as_str()]));
    }
    format!("{{{}}}", parts.join(", "))
}

/// A key as TOML writes it: bare when it can be, quoted otherwise (so that no key, however
/// spelt, ends the table it is written in).
fn toml_key(k: &str) -> String {
    let bare = !k.is_empty()
        && k.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-');
    if bare {
        return k.to_string();
    }
    // A basic string on one line (toml's own writer may choose a multi-line string, which
    // is no key).
    let mut out = String::from("\"");
    for c in k.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Parses `text` with the type's alias (`diffuse`, `interfaced-lambertian`) replaced by
/// its name, the one the schema and the app know.
fn parse(text: &str) -> Result<toml::Table, String> {
    let mut table = parse_inline_table(text).map_err(|e| e.to_string())?;
    let ty = table
        .get("type")
        .and_then(|t| t.as_str())
        .map(str::to_string);
    if let Some(name) = ty.as_deref().and_then(canonical_type) {
        if Some(name) != ty.as_deref() {
            table.insert("type".into(), toml::Value::String(name.into()));
        }
    }
    Ok(table)
}

/// Parses and builds `text`; the error is the grammar's message.
pub fn build(text: &str) -> Result<Material, String> {
    let table = parse(text)?;
    let bsdf = build_material_with_reader(&table, std::path::Path::new("."), &ImageNormalMapReader)
        .map_err(|e| e.to_string())?;
    Ok(Material {
        text: canonical_text(&table),
        table,
        bsdf,
    })
}

/// How the app names a measured file as a material: `measured:ID`.
pub const MEASURED_PREFIX: &str = "measured:";

/// A measured file held in memory.
#[derive(Clone)]
pub struct MeasuredFile {
    pub id: u64,
    pub name: String,
    pub merl: Arc<MerlBrdf>,
    pub valid_bins: usize,
}

impl MeasuredFile {
    /// Its material text, `measured:ID`.
    pub fn text(&self) -> String {
        format!("{MEASURED_PREFIX}{}", self.id)
    }
}

/// A build, shared by every request that asks for the same material while it runs.
type SharedBuild = Arc<OnceLock<Result<Material, String>>>;

/// The last few materials built (or being built), by canonical text, and the measured files
/// loaded.
#[derive(Default)]
pub struct MaterialCache {
    entries: Mutex<Vec<(String, SharedBuild)>>,
    measured: Mutex<(u64, Vec<MeasuredFile>)>,
}

impl MaterialCache {
    /// Materials kept. A glint material holds its map's lobes and hierarchy (about 40
    /// bytes a texel: 640 MiB at 4096²), so the cache stays small.
    const SIZE: usize = 8;
    /// Measured files kept (35 MB each); loading another drops the oldest.
    pub const MEASURED_FILES: usize = 4;

    /// Keeps a measured file; its id names it in later requests.
    pub fn add_measured(&self, name: &str, merl: MerlBrdf) -> MeasuredFile {
        let mut m = self.measured.lock().unwrap_or_else(|p| p.into_inner());
        m.0 += 1;
        let file = MeasuredFile {
            id: m.0,
            name: name.to_string(),
            valid_bins: merl.valid_bins(),
            merl: Arc::new(merl),
        };
        m.1.push(file.clone());
        if m.1.len() > Self::MEASURED_FILES {
            m.1.remove(0);
        }
        file
    }

    /// The measured file `id`.
    pub fn measured(&self, id: u64) -> Result<MeasuredFile, String> {
        let m = self.measured.lock().unwrap_or_else(|p| p.into_inner());
        m.1.iter().find(|f| f.id == id).cloned().ok_or_else(|| {
            format!(
                "no measured file {id} (the server keeps the last {} loaded; load it again)",
                Self::MEASURED_FILES
            )
        })
    }

    /// The material of `text`, built once.
    pub fn get(&self, text: &str) -> Result<Material, String> {
        if let Some(id) = text.trim().strip_prefix(MEASURED_PREFIX) {
            let id: u64 = id
                .trim()
                .parse()
                .map_err(|_| format!("`{text}`: expected {MEASURED_PREFIX}ID"))?;
            let f = self.measured(id)?;
            return Ok(Material {
                text: f.text(),
                table: toml::Table::new(),
                bsdf: Arc::new(MeasuredBsdf::two_sided(f.merl.clone(), f.name.clone())),
            });
        }
        let key = canonical_text(&parse(text)?);
        // The slice, hemisphere and albedo requests of one change ask at once: the first
        // builds, the others wait for its result.
        let cell = {
            let mut entries = self.lock();
            match entries.iter().position(|(k, _)| *k == key) {
                Some(i) => {
                    let e = entries.remove(i);
                    entries.insert(0, e);
                }
                None => {
                    entries.insert(0, (key.clone(), SharedBuild::default()));
                    entries.truncate(Self::SIZE);
                }
            }
            entries[0].1.clone()
        };
        cell.get_or_init(|| build(&key)).clone()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<(String, SharedBuild)>> {
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
    fn keys_that_are_not_bare_are_quoted() {
        let t = parse_inline_table(r#"{type = "lambert", "a}\n[x]\n#" = 1}"#).unwrap();
        let text = canonical_text(&t);
        assert_eq!(parse_inline_table(&text).unwrap(), t, "{text}");
        assert!(build(&text).err().unwrap().contains("unknown key"));
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
            .get(r#"{ reflectance = 0.3, type = "diffuse" }"#)
            .unwrap();
        assert!(
            Arc::ptr_eq(&a.bsdf, &b.bsdf),
            "an alias is the same material"
        );
        assert_eq!(b.text, r#"{type = "lambert", reflectance = 0.3}"#);
    }

    #[test]
    fn measured_files_are_materials_by_id() {
        let cache = MaterialCache::default();
        let f = cache.add_measured(
            "grey.binary",
            MerlBrdf::from_fn(|_, _, _| Some(facette_bsdf::Spectrum::splat(0.1))),
        );
        let m = cache.get(&f.text()).unwrap();
        assert!(m.bsdf.describe().contains("grey.binary"));
        assert!(cache
            .get("measured:99")
            .err()
            .unwrap()
            .contains("no measured file 99"));
        assert!(cache
            .get("measured:x")
            .err()
            .unwrap()
            .contains("expected measured:ID"));
    }
}
