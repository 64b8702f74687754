//! The state shared by the plugin translations: the id registry, the location table that
//! the description's spans index, the materials made so far, and the warnings.

use super::plugin::{Plugin, Registry};
use super::preprocess::resolve;
use super::xml::Pos;
use crate::scene::source::Location;
use crate::scene::SceneError;
use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use toml::Spanned;

pub(crate) struct Translator {
    pub reg: Registry,
    /// Directory of the main scene file.
    pub main_dir: PathBuf,
    /// What span `i..i + 1` of the description means.
    pub locations: Vec<Location>,
    pub warnings: Vec<String>,
    /// The description's `[materials]`.
    pub materials: BTreeMap<String, Spanned<toml::Table>>,
    /// Material name of each BSDF already translated (a BSDF referenced by several shapes
    /// is one material).
    material_names: HashMap<*const Plugin, String>,
}

impl Translator {
    pub fn new(reg: Registry, main_dir: PathBuf) -> Translator {
        Translator {
            reg,
            main_dir,
            locations: Vec::new(),
            warnings: Vec::new(),
            materials: BTreeMap::new(),
            material_names: HashMap::new(),
        }
    }

    /// A span of the description standing for `pos`.
    pub fn span(&mut self, pos: &Pos) -> Range<usize> {
        let i = self.locations.len();
        self.locations.push(Location {
            file: pos.file.as_ref().clone(),
            line: pos.line,
        });
        i..i + 1
    }

    /// Records a warning, once per message (the first place it applies is named).
    pub fn warn(&mut self, pos: &Pos, message: impl Into<String>) {
        let message = message.into();
        if !self.warnings.iter().any(|w| w.ends_with(&message)) {
            self.warnings.push(format!("{pos}: {message}"));
        }
    }

    /// The file named by the string parameter `name` of `p`, resolved like Mitsuba does
    /// (next to the file that names it, then next to the main scene file); a missing file
    /// is an error at the parameter's line.
    pub fn file(&self, p: &Plugin, name: &str) -> Result<Option<PathBuf>, SceneError> {
        let Some(value) = p.string(name)? else {
            return Ok(None);
        };
        let at = p.get(name).map(|q| q.pos.clone()).unwrap_or(p.pos.clone());
        match resolve(&value, &at, &self.main_dir) {
            Some(path) => Ok(Some(path)),
            None => Err(at.err(format!(
                "{}: `{name}` = \"{value}\": file not found (looked next to {}{})",
                p.describe(),
                at.file.display(),
                if at.file.parent() == Some(self.main_dir.as_path()) {
                    String::new()
                } else {
                    format!(" and in {}", self.main_dir.display())
                }
            ))),
        }
    }

    /// The material name already given to `bsdf`, if any.
    pub fn material_name(&self, bsdf: &Rc<Plugin>) -> Option<String> {
        self.material_names.get(&Rc::as_ptr(bsdf)).cloned()
    }

    /// Adds a material made from `bsdf`; returns its name (its id, or a name saying where
    /// it was written).
    pub fn add_material(&mut self, bsdf: &Rc<Plugin>, table: toml::Table) -> String {
        let base = match &bsdf.id {
            Some(id) => id.clone(),
            None => format!(
                "{} at {}:{}",
                bsdf.kind,
                file_name(&bsdf.pos.file),
                bsdf.pos.line
            ),
        };
        let mut name = base.clone();
        let mut k = 2;
        while self.materials.contains_key(&name) {
            name = format!("{base} ({k})");
            k += 1;
        }
        let span = self.span(&bsdf.pos);
        self.materials
            .insert(name.clone(), Spanned::new(span, table));
        self.material_names.insert(Rc::as_ptr(bsdf), name.clone());
        name
    }
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}
