//! Mitsuba XML files read (with `roxmltree`) into an owned element tree in which every
//! element remembers its file and line, so that every later error can name them — also
//! after `<include>`d files have been spliced into the main one.

use crate::scene::SceneError;
use facette_bsdf::limits;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// Where an element starts: file and 1-based line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Pos {
    pub file: Rc<PathBuf>,
    pub line: usize,
}

impl Pos {
    /// An error at this place.
    pub fn err(&self, message: impl Into<String>) -> SceneError {
        SceneError {
            file: self.file.as_ref().clone(),
            line: Some(self.line),
            message: message.into(),
        }
    }
}

impl std::fmt::Display for Pos {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.file.display(), self.line)
    }
}

/// An XML element: tag, attributes in document order, child elements.
#[derive(Clone, Debug)]
pub(crate) struct Element {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub pos: Pos,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    pub fn set_attr(&mut self, name: &str, value: String) {
        match self.attrs.iter_mut().find(|(k, _)| k == name) {
            Some(a) => a.1 = value,
            None => self.attrs.push((name.to_string(), value)),
        }
    }

    pub fn remove_attr(&mut self, name: &str) {
        self.attrs.retain(|(k, _)| k != name);
    }

    /// Checks that the attributes are among `allowed` and that `required` are present
    /// (Mitsuba rejects both unexpected and missing attributes).
    pub fn check_attrs(&self, allowed: &[&str], required: &[&str]) -> Result<(), SceneError> {
        for (k, _) in &self.attrs {
            if !allowed.contains(&k.as_str()) {
                return Err(self.pos.err(format!(
                    "unexpected attribute `{k}` in <{}>; valid attributes: {}",
                    self.tag,
                    allowed.join(", ")
                )));
            }
        }
        for r in required {
            if self.attr(r).is_none() {
                return Err(self
                    .pos
                    .err(format!("<{}> needs the attribute `{r}`", self.tag)));
            }
        }
        Ok(())
    }

    /// The element as it reads in messages: `<bsdf type="diffuse">`.
    pub fn describe(&self) -> String {
        match self.attr("type") {
            Some(t) => format!("<{} type=\"{t}\">", self.tag),
            None => format!("<{}>", self.tag),
        }
    }
}

/// Reads and parses an XML file; returns its root element and its text (for hashing).
/// A missing file or malformed XML is an error naming the file (and the line).
pub(crate) fn read_xml_file(path: &Path) -> Result<(Element, String), SceneError> {
    let text = crate::scene::source::read_scene_text(path)?;
    let root = parse_xml(&text, path)?;
    Ok((root, text))
}

/// Parses XML text; `path` names it in positions and errors.
pub(crate) fn parse_xml(text: &str, path: &Path) -> Result<Element, SceneError> {
    let file = Rc::new(path.to_path_buf());
    let doc = roxmltree::Document::parse(text).map_err(|e| SceneError {
        file: path.to_path_buf(),
        line: Some(e.pos().row as usize),
        message: format!("malformed XML: {e}"),
    })?;
    convert(&doc, doc.root_element(), &file, 1)
}

/// Converts `node` at nesting `depth` (the root is 1). The depth is bounded so that every
/// later pass over the tree (preprocessing, plugins, translation, drop) recurses a bounded
/// number of levels: 20,000 nested elements are an error, not a stack overflow.
fn convert(
    doc: &roxmltree::Document,
    node: roxmltree::Node,
    file: &Rc<PathBuf>,
    depth: usize,
) -> Result<Element, SceneError> {
    let pos = Pos {
        file: file.clone(),
        line: doc.text_pos_at(node.range().start).row as usize,
    };
    if let Err(e) = limits::XML_DEPTH.check_usize(depth) {
        return Err(pos.err(format!("<{}>: {e}", node.tag_name().name())));
    }
    let mut children = Vec::new();
    for child in node.children() {
        if child.is_element() {
            children.push(convert(doc, child, file, depth + 1)?);
        } else if child.is_text() {
            let text = child.text().unwrap_or("");
            if !text.trim().is_empty() {
                let lead = text.len() - text.trim_start().len();
                let line = doc.text_pos_at(child.range().start + lead).row as usize;
                return Err(Pos {
                    file: file.clone(),
                    line,
                }
                .err(format!(
                    "unexpected text `{}` inside <{}>: Mitsuba scenes hold values in attributes",
                    text.trim(),
                    node.tag_name().name()
                )));
            }
        }
        // Comments and processing instructions carry nothing.
    }
    Ok(Element {
        tag: node.tag_name().name().to_string(),
        attrs: node
            .attributes()
            .map(|a| (a.name().to_string(), a.value().to_string()))
            .collect(),
        children,
        pos,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_keep_their_lines_and_attributes() {
        let text = "<?xml version=\"1.0\"?>\n<scene version=\"3.0.0\">\n  <!-- c -->\n  <bsdf type=\"diffuse\" id=\"a\">\n    <rgb name=\"reflectance\" value=\"0.5\"/>\n  </bsdf>\n</scene>\n";
        let root = parse_xml(text, Path::new("s.xml")).unwrap();
        assert_eq!(root.tag, "scene");
        assert_eq!(root.pos.line, 2);
        assert_eq!(root.attr("version"), Some("3.0.0"));
        let bsdf = &root.children[0];
        assert_eq!((bsdf.tag.as_str(), bsdf.pos.line), ("bsdf", 4));
        assert_eq!(bsdf.describe(), "<bsdf type=\"diffuse\">");
        assert_eq!(bsdf.children[0].pos.line, 5);
    }

    #[test]
    fn malformed_xml_and_stray_text_name_the_line() {
        let e = parse_xml("<scene>\n<bsdf>\n</scene>\n", Path::new("bad.xml")).unwrap_err();
        assert_eq!(e.line, Some(3), "{e}");
        assert!(e.to_string().starts_with("bad.xml:3: malformed XML"), "{e}");
        let e = parse_xml("<scene>\n  oops\n</scene>", Path::new("t.xml")).unwrap_err();
        assert!(
            e.to_string().contains("t.xml:2: unexpected text `oops`"),
            "{e}"
        );
    }
}
