//! What Mitsuba does to the XML before it looks at plugins, in document order:
//! - `<scene version="x.y.z">`: required; files older than 2.0.0 are upgraded in memory
//!   as Mitsuba 3 does (camelCase parameter names to snake_case, `lookAt` to `lookat`,
//!   a diffuse BSDF's `diffuse_reflectance` to `reflectance`, texture `uoffset`/`voffset`/
//!   `uscale`/`vscale` to a `to_uv` transform);
//! - `<default name value>` defines `$name` unless the command line (`-D name=value`) or an
//!   earlier default already did;
//! - every attribute value has `$name` replaced (longest names first, as Mitsuba does); a
//!   `$` left over is an undefined parameter;
//! - `<include filename>` splices the children of the included file's `<scene>` (or its
//!   single root object) in place, with the same parameters.
//!
//! The result is one element tree with every element still knowing its file and line.

use super::xml::{read_xml_file, Element, Pos};
use crate::scene::SceneError;
use facette_bsdf::limits;
use std::path::{Path, PathBuf};

/// A scene parameter: `-D` or `<default>`.
struct Param {
    name: String,
    value: String,
    from_command_line: bool,
    used: bool,
}

/// The main file's tree after preprocessing, with every file read (for hashing) and
/// warnings.
pub(crate) struct Preprocessed {
    pub root: Element,
    /// Text of every file read, main file first.
    pub texts: Vec<String>,
    pub warnings: Vec<String>,
}

struct State {
    params: Vec<Param>,
    texts: Vec<String>,
    warnings: Vec<String>,
    main_dir: PathBuf,
    /// Files being included (cycle detection).
    stack: Vec<PathBuf>,
    /// Files included so far, all levels together: an include fan-out (4 per file, 12
    /// levels) would otherwise read 16 million files.
    includes: usize,
    /// Elements kept so far, all files together (the total-work limit).
    elements: usize,
    /// Bytes of attribute values after substitution, all together: parameters that expand
    /// to parameters grow exponentially.
    expanded_bytes: usize,
}

/// Reads `path` and preprocesses it with the command-line `defines`.
pub(crate) fn preprocess(
    path: &Path,
    defines: &[(String, String)],
) -> Result<Preprocessed, SceneError> {
    let (mut root, text) = read_xml_file(path)?;
    let mut params: Vec<Param> = Vec::new();
    for (name, value) in defines {
        if name.is_empty() || name.contains('$') {
            return Err(SceneError {
                file: path.to_path_buf(),
                line: None,
                message: format!("-D: `{name}` is not a parameter name"),
            });
        }
        match params.iter_mut().find(|p| &p.name == name) {
            Some(p) => p.value = value.clone(),
            None => params.push(Param {
                name: name.clone(),
                value: value.clone(),
                from_command_line: true,
                used: false,
            }),
        }
    }
    let mut st = State {
        params,
        texts: vec![text],
        warnings: Vec::new(),
        main_dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        stack: vec![canonical(path)],
        includes: 0,
        elements: 0,
        expanded_bytes: 0,
    };
    if root.tag != "scene" {
        return Err(root.pos.err(format!(
            "the root element must be <scene version=\"3.0.0\">, not <{}>",
            root.tag
        )));
    }
    upgrade_file(&mut root, true)?;
    st.substitute(&mut root)?;
    root.check_attrs(&["version"], &[])?;
    let children = std::mem::take(&mut root.children);
    root.children = st.expand(children, 0)?;
    for p in &st.params {
        if p.from_command_line && !p.used {
            st.warnings.push(format!(
                "-D {}={}: the scene has no `${}`",
                p.name, p.value, p.name
            ));
        }
    }
    Ok(Preprocessed {
        root,
        texts: st.texts,
        warnings: st.warnings,
    })
}

fn canonical(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf())
}

/// Reads the `version` of a file's `<scene>` root (removing it) and upgrades old files.
/// The main file must have one; an included file may omit it.
fn upgrade_file(root: &mut Element, required: bool) -> Result<(), SceneError> {
    let Some(v) = root.attr("version") else {
        if !required {
            return Ok(());
        }
        return Err(root
            .pos
            .err("<scene> needs a `version` attribute (Mitsuba 3 files say version=\"3.0.0\")"));
    };
    let version = parse_version(v).ok_or_else(|| {
        root.pos.err(format!(
            "could not parse the version `{v}`: expected three numbers, like 3.0.0"
        ))
    })?;
    if version.0 > 3 {
        return Err(root.pos.err(format!(
            "version `{v}` is newer than the Mitsuba 3 format facette reads (versions up to 3.x.y; older files are upgraded)"
        )));
    }
    root.remove_attr("version");
    if version < (2, 0, 0) {
        upgrade_pre_2(root);
    }
    Ok(())
}

fn parse_version(v: &str) -> Option<(u32, u32, u32)> {
    let parts: Vec<&str> = v
        .split(|c: char| c == '.' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .collect();
    if parts.len() != 3 {
        return None;
    }
    Some((
        parts[0].parse().ok()?,
        parts[1].parse().ok()?,
        parts[2].parse().ok()?,
    ))
}

/// Mitsuba 3's in-memory upgrade of files older than 2.0.0.
fn upgrade_pre_2(root: &mut Element) {
    fn walk(e: &mut Element, parent_is_diffuse: bool) {
        if e.tag == "lookAt" {
            e.tag = "lookat".into();
        }
        if e.tag != "default" {
            if let Some(name) = e.attr("name") {
                let mut upgraded = snake_case(name);
                if parent_is_diffuse && upgraded == "diffuse_reflectance" {
                    upgraded = "reflectance".into();
                }
                e.set_attr("name", upgraded);
            }
        }
        if let Some(id) = e.attr("id") {
            if id.starts_with('_') {
                let id = format!("ID{id}__UPGR");
                e.set_attr("id", id);
            }
        }
        uv_transform_upgrade(e);
        let diffuse = e.tag == "bsdf" && e.attr("type") == Some("diffuse");
        for c in &mut e.children {
            walk(c, diffuse);
        }
    }
    walk(root, false);
}

/// `uoffset`, `voffset`, `uscale`, `vscale` floats become `<transform name="to_uv">` with a
/// translation followed by a scale.
fn uv_transform_upgrade(e: &mut Element) {
    let names = ["uoffset", "voffset", "uscale", "vscale"];
    let is_uv =
        |c: &Element| c.tag == "float" && c.attr("name").is_some_and(|n| names.contains(&n));
    if !e.children.iter().any(is_uv) {
        return;
    }
    let mut offset = ["0".to_string(), "0".to_string()];
    let mut scale = ["1".to_string(), "1".to_string()];
    let mut pos = e.pos.clone();
    for c in e.children.iter().filter(|c| is_uv(c)) {
        pos = c.pos.clone();
        let v = c.attr("value").unwrap_or("").to_string();
        match c.attr("name").unwrap_or("") {
            "uoffset" => offset[0] = v,
            "voffset" => offset[1] = v,
            "uscale" => scale[0] = v,
            _ => scale[1] = v,
        }
    }
    e.children.retain(|c| !is_uv(c));
    let op = |tag: &str, v: &[String; 2]| Element {
        tag: tag.into(),
        attrs: vec![("x".into(), v[0].clone()), ("y".into(), v[1].clone())],
        children: Vec::new(),
        pos: pos.clone(),
    };
    e.children.push(Element {
        tag: "transform".into(),
        attrs: vec![("name".into(), "to_uv".into())],
        children: vec![op("translate", &offset), op("scale", &scale)],
        pos: pos.clone(),
    });
}

/// Mitsuba's camelCase → snake_case: `maxDepth` → `max_depth`, `intIOR` → `int_ior`.
fn snake_case(name: &str) -> String {
    let mut c: Vec<char> = name.chars().collect();
    let mut i = 0;
    while i + 1 < c.len() {
        if c[i].is_ascii_lowercase() && c[i + 1].is_ascii_uppercase() {
            c.insert(i + 1, '_');
            i += 2;
            while i < c.len() && c[i].is_ascii_uppercase() {
                c[i] = c[i].to_ascii_lowercase();
                i += 1;
            }
        } else {
            i += 1;
        }
    }
    c.into_iter().collect()
}

impl State {
    /// Replaces `$name` in every attribute of `e` (not its children).
    fn substitute(&mut self, e: &mut Element) -> Result<(), SceneError> {
        // Longest names first, so that `$spp` does not eat the start of `$spp_max`.
        let mut order: Vec<usize> = (0..self.params.len()).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(self.params[i].name.len()));
        for (_, value) in e.attrs.iter_mut() {
            if !value.contains('$') {
                continue;
            }
            let mut v = value.clone();
            for &i in &order {
                let key = format!("${}", self.params[i].name);
                let uses = v.matches(&key).count();
                if uses > 0 {
                    // The size of the result is checked before it is built.
                    let grown = uses
                        .checked_mul(self.params[i].value.len())
                        .and_then(|g| g.checked_add(v.len()))
                        .unwrap_or(usize::MAX);
                    limits::XML_EXPANDED_BYTES
                        .check_usize(grown.saturating_add(self.expanded_bytes))
                        .map_err(|x| {
                            e.pos.err(format!(
                                "expanding ${} in \"{}…\": {x}",
                                self.params[i].name,
                                value.chars().take(40).collect::<String>()
                            ))
                        })?;
                    v = v.replace(&key, &self.params[i].value);
                    self.params[i].used = true;
                }
            }
            self.expanded_bytes += v.len();
            if let Some(at) = v.find('$') {
                let name: String = v[at + 1..]
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                return Err(e.pos.err(format!(
                    "undefined parameter `${name}` in \"{value}\": define it with <default name=\"{name}\" value=\"…\"/> or -D {name}=…"
                )));
            }
            *value = v;
        }
        Ok(())
    }

    /// Preprocesses a list of sibling elements in document order.
    fn expand(&mut self, elements: Vec<Element>, depth: usize) -> Result<Vec<Element>, SceneError> {
        let mut out = Vec::with_capacity(elements.len());
        for mut e in elements {
            self.elements += 1;
            limits::XML_ELEMENTS
                .check_usize(self.elements)
                .map_err(|x| e.pos.err(x.to_string()))?;
            self.substitute(&mut e)?;
            match e.tag.as_str() {
                "default" => {
                    e.check_attrs(&["name", "value"], &["name", "value"])?;
                    let name = e.attr("name").unwrap_or("").to_string();
                    if name.is_empty() {
                        return Err(e.pos.err("<default>: the name must not be empty"));
                    }
                    if !self.params.iter().any(|p| p.name == name) {
                        self.params.push(Param {
                            name,
                            value: e.attr("value").unwrap_or("").to_string(),
                            from_command_line: false,
                            used: false,
                        });
                    }
                }
                "include" => {
                    e.check_attrs(&["filename"], &["filename"])?;
                    out.extend(self.include(&e, depth)?);
                }
                _ => {
                    let children = std::mem::take(&mut e.children);
                    e.children = self.expand(children, depth)?;
                    out.push(e);
                }
            }
        }
        Ok(out)
    }

    /// The elements an `<include>` stands for.
    fn include(&mut self, e: &Element, depth: usize) -> Result<Vec<Element>, SceneError> {
        if depth + 1 > limits::XML_INCLUDE_DEPTH.max() as usize {
            return Err(e.pos.err(format!(
                "<include> nested deeper than {} files",
                limits::XML_INCLUDE_DEPTH.max()
            )));
        }
        self.includes += 1;
        limits::XML_INCLUDES
            .check_usize(self.includes)
            .map_err(|x| e.pos.err(format!("<include>: {x}")))?;
        let name = e.attr("filename").unwrap_or("");
        let path = resolve(name, &e.pos, &self.main_dir).ok_or_else(|| {
            e.pos.err(format!(
                "included file \"{name}\" not found (looked next to {} and in {})",
                e.pos.file.display(),
                self.main_dir.display()
            ))
        })?;
        let key = canonical(&path);
        if self.stack.contains(&key) {
            return Err(e.pos.err(format!(
                "<include filename=\"{name}\">: {} includes itself",
                path.display()
            )));
        }
        let (mut root, text) = read_xml_file(&path)
            .map_err(|x| e.pos.err(format!("in the file included here: {x}")))?;
        self.texts.push(text);
        self.stack.push(key);
        let result = if root.tag == "scene" {
            upgrade_file(&mut root, false)?;
            self.substitute(&mut root)?;
            root.check_attrs(&[], &[])?;
            self.expand(root.children, depth + 1)
        } else {
            self.expand(vec![root], depth + 1)
        };
        self.stack.pop();
        result
    }
}

/// A file named in the scene: absolute, or relative to the directory of the file that
/// names it, then to the main scene file's directory (Mitsuba's file resolver holds the
/// latter). `None` when neither exists. The path returned is absolute: the scene builder
/// resolves relative file names against the scene's directory once more, which would
/// double a relative directory (`scenes/x/scenes/x/mesh.obj` for a scene given as
/// `scenes/x/scene.xml`).
pub(crate) fn resolve(name: &str, from: &Pos, main_dir: &Path) -> Option<PathBuf> {
    let p = Path::new(name);
    let found = if p.is_absolute() {
        p.exists().then(|| p.to_path_buf())
    } else {
        let here = from
            .file
            .parent()
            .map(|d| d.join(p))
            .unwrap_or_else(|| p.to_path_buf());
        if here.exists() {
            Some(here)
        } else {
            let main = main_dir.join(p);
            main.exists().then_some(main)
        }
    }?;
    Some(std::path::absolute(&found).unwrap_or(found))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camel_case_names_are_upgraded_like_mitsuba() {
        assert_eq!(snake_case("maxDepth"), "max_depth");
        assert_eq!(snake_case("intIOR"), "int_ior");
        assert_eq!(snake_case("sampleCount"), "sample_count");
        assert_eq!(snake_case("specularReflectance"), "specular_reflectance");
        assert_eq!(snake_case("fov"), "fov");
        assert_eq!(snake_case("to_world"), "to_world");
    }

    #[test]
    fn versions_need_three_numbers() {
        assert_eq!(parse_version("3.0.0"), Some((3, 0, 0)));
        assert_eq!(parse_version("0.6.0"), Some((0, 6, 0)));
        assert_eq!(parse_version("3.0"), None);
        assert_eq!(parse_version("a.b.c"), None);
    }
}
