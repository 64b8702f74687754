//! Plugins as Mitsuba sees them: an object element (`<bsdf type="diffuse" id="…">`) with
//! its named properties (`<float>`, `<rgb>`, `<transform>`, nested objects, `<ref>`s).
//!
//! The typed getters mark what they read; [`Plugin::finish`] then turns anything unread
//! into an error naming the parameter, its line, and the parameters the plugin supports —
//! Mitsuba's "unreferenced property" check, so nothing in a file is silently ignored.

use super::transform::parse_transform;
use super::values::{parse_numbers, parse_one_or_three};
use super::xml::{Element, Pos};
use crate::scene::SceneError;
use facette_bsdf::limits;
use glam::DMat4;
use std::cell::Cell;
use std::collections::HashMap;
use std::rc::Rc;

/// The object classes (element names) of Mitsuba 3.
pub(crate) const OBJECT_TAGS: &[&str] = &[
    "scene",
    "bsdf",
    "shape",
    "emitter",
    "sensor",
    "film",
    "rfilter",
    "sampler",
    "integrator",
    "texture",
    "medium",
    "phase",
    "volume",
];

/// The value of a property.
#[derive(Debug)]
pub(crate) enum Value {
    Bool(bool),
    Integer(i64),
    Float(f64),
    String(String),
    /// `<rgb>`, or `<spectrum value="v">` (a uniform spectrum).
    Color([f64; 3]),
    /// `<point>`, `<vector>`.
    Vector([f64; 3]),
    Transform(DMat4),
    Object(Rc<Plugin>),
    /// `<ref id="…">`.
    Ref(String),
}

impl Value {
    fn kind(&self) -> &'static str {
        match self {
            Value::Bool(_) => "a <boolean>",
            Value::Integer(_) => "an <integer>",
            Value::Float(_) => "a <float>",
            Value::String(_) => "a <string>",
            Value::Color(_) => "an <rgb>",
            Value::Vector(_) => "a <point>/<vector>",
            Value::Transform(_) => "a <transform>",
            Value::Object(_) => "a nested object",
            Value::Ref(_) => "a <ref>",
        }
    }
}

#[derive(Debug)]
pub(crate) struct Prop {
    /// Empty for unnamed nested objects and references.
    pub name: String,
    pub value: Value,
    pub pos: Pos,
    used: Cell<bool>,
}

/// An object element.
#[derive(Debug)]
pub(crate) struct Plugin {
    /// The element name: `bsdf`, `shape`, …
    pub class: String,
    /// The `type` attribute (`scene` for the scene).
    pub kind: String,
    pub id: Option<String>,
    pub pos: Pos,
    pub props: Vec<Prop>,
}

/// Objects by `id`, for `<ref>`.
#[derive(Default)]
pub(crate) struct Registry {
    by_id: HashMap<String, Rc<Plugin>>,
}

impl Registry {
    /// Registers `p` and every object nested in it; a repeated id is an error.
    pub fn add(&mut self, p: &Rc<Plugin>) -> Result<(), SceneError> {
        if let Some(id) = &p.id {
            if let Some(prev) = self.by_id.get(id) {
                return Err(p.pos.err(format!(
                    "duplicate id \"{id}\" (first used at {})",
                    prev.pos
                )));
            }
            self.by_id.insert(id.clone(), p.clone());
        }
        for prop in &p.props {
            if let Value::Object(o) = &prop.value {
                self.add(o)?;
            }
        }
        Ok(())
    }

    /// Checks that following `<ref>`s from `root` never comes back to an object on the way
    /// (`<bsdf type="twosided" id="a"><ref id="a"/></bsdf>` would make every translation
    /// recurse forever) and that chains of references stay within
    /// [`limits::XML_REF_DEPTH`]. Every object is walked once (a colour mark per id), so
    /// references shared by many objects cost nothing more.
    pub fn check_references(&self, root: &Rc<Plugin>) -> Result<(), SceneError> {
        let mut done: HashMap<*const Plugin, ()> = HashMap::new();
        let mut path: Vec<(*const Plugin, String)> = Vec::new();
        self.walk(root, &mut done, &mut path, 0)
    }

    fn walk(
        &self,
        p: &Rc<Plugin>,
        done: &mut HashMap<*const Plugin, ()>,
        path: &mut Vec<(*const Plugin, String)>,
        refs: usize,
    ) -> Result<(), SceneError> {
        let key = Rc::as_ptr(p);
        if done.contains_key(&key) {
            return Ok(());
        }
        path.push((key, p.id.clone().unwrap_or_else(|| p.describe())));
        for prop in &p.props {
            let (next, refs) = match &prop.value {
                Value::Object(o) => (o.clone(), refs),
                Value::Ref(id) => (self.get(id, &prop.pos)?, refs + 1),
                _ => continue,
            };
            if let Some(at) = path.iter().position(|(k, _)| *k == Rc::as_ptr(&next)) {
                let mut cycle: Vec<&str> = path[at..].iter().map(|(_, n)| n.as_str()).collect();
                cycle.push(path[at].1.as_str());
                return Err(prop.pos.err(format!(
                    "<ref id=\"{}\">: the reference makes a cycle ({}); an object cannot contain itself",
                    next.id.as_deref().unwrap_or(""),
                    cycle.join(" → ")
                )));
            }
            if let Err(e) = limits::XML_REF_DEPTH.check_usize(refs) {
                return Err(prop.pos.err(e.to_string()));
            }
            self.walk(&next, done, path, refs)?;
        }
        path.pop();
        done.insert(key, ());
        Ok(())
    }

    pub fn get(&self, id: &str, at: &Pos) -> Result<Rc<Plugin>, SceneError> {
        self.by_id.get(id).cloned().ok_or_else(|| {
            let mut known: Vec<&str> = self.by_id.keys().map(String::as_str).collect();
            known.sort_unstable();
            at.err(format!(
                "<ref id=\"{id}\">: no object has this id; ids in the scene: {}",
                if known.is_empty() {
                    "none".to_string()
                } else {
                    known.join(", ")
                }
            ))
        })
    }
}

/// A colour-valued parameter: a constant or a texture.
#[derive(Debug, Clone)]
pub(crate) enum ColorParam {
    Value([f64; 3]),
    Texture(Rc<Plugin>),
}

impl Plugin {
    /// Builds a plugin from an object element (after preprocessing).
    pub fn from_element(e: &Element) -> Result<Rc<Plugin>, SceneError> {
        let is_scene = e.tag == "scene";
        if is_scene {
            e.check_attrs(&[], &[])?;
        } else {
            e.check_attrs(&["type", "id", "name"], &["type"])?;
        }
        // `<spectrum type="…">` is a texture plugin.
        let class = if e.tag == "spectrum" {
            "texture".to_string()
        } else {
            e.tag.clone()
        };
        let mut props: Vec<Prop> = Vec::new();
        for c in &e.children {
            let prop = Self::property(c)?;
            if !prop.name.is_empty() {
                if let Some(prev) = props.iter().find(|p| p.name == prop.name) {
                    return Err(c.pos.err(format!(
                        "parameter `{}` of {} is given twice (first at line {})",
                        prop.name,
                        e.describe(),
                        prev.pos.line
                    )));
                }
            }
            props.push(prop);
        }
        Ok(Rc::new(Plugin {
            class,
            kind: if is_scene {
                "scene".into()
            } else {
                e.attr("type").unwrap_or("").to_string()
            },
            id: e.attr("id").map(str::to_string),
            pos: e.pos.clone(),
            props,
        }))
    }

    /// One child element as a property.
    fn property(c: &Element) -> Result<Prop, SceneError> {
        let name = c.attr("name").unwrap_or("").to_string();
        fn scalar(c: &Element) -> Result<&str, SceneError> {
            c.check_attrs(&["name", "value"], &["name", "value"])?;
            Ok(c.attr("value").unwrap_or(""))
        }
        let bad = |what: &str, v: &str, x: String| {
            c.pos
                .err(format!("<{}> `{name}`: {what} \"{v}\": {x}", c.tag))
        };
        let value = match c.tag.as_str() {
            "boolean" => {
                let v = scalar(c)?;
                match v.to_ascii_lowercase().as_str() {
                    "true" => Value::Bool(true),
                    "false" => Value::Bool(false),
                    _ => {
                        return Err(c.pos.err(format!(
                            "<boolean> `{name}`: \"{v}\" must be true or false"
                        )))
                    }
                }
            }
            "integer" => {
                let v = scalar(c)?;
                Value::Integer(v.trim().parse::<i64>().map_err(|_| {
                    c.pos
                        .err(format!("<integer> `{name}`: \"{v}\" is not an integer"))
                })?)
            }
            "float" => {
                let v = scalar(c)?;
                Value::Float(v.trim().parse::<f64>().map_err(|_| {
                    c.pos
                        .err(format!("<float> `{name}`: \"{v}\" is not a number"))
                })?)
            }
            "string" => Value::String(scalar(c)?.to_string()),
            "rgb" => {
                let v = scalar(c)?;
                Value::Color(
                    parse_one_or_three(v).map_err(|x| bad("could not read the colour", v, x))?,
                )
            }
            "spectrum" if c.attr("type").is_some() => Value::Object(Plugin::from_element(c)?),
            "spectrum" => {
                c.check_attrs(&["name", "value", "filename"], &["name"])?;
                let v = c.attr("value").unwrap_or("");
                let n = parse_numbers(v);
                match (c.attr("filename"), n) {
                    (None, Ok(n)) if n.len() == 1 => Value::Color([n[0]; 3]),
                    _ => {
                        return Err(c.pos.err(format!(
                            "<spectrum> `{name}`: facette renders in RGB; only a constant spectrum (value=\"0.5\") is supported — give an <rgb> instead"
                        )))
                    }
                }
            }
            "point" | "vector" => {
                c.check_attrs(&["name", "value", "x", "y", "z"], &["name"])?;
                let v = match c.attr("value") {
                    Some(v) => {
                        if ["x", "y", "z"].iter().any(|k| c.attr(k).is_some()) {
                            return Err(c.pos.err(format!(
                                "<{}> `{name}`: give `value` or `x`/`y`/`z`, not both",
                                c.tag
                            )));
                        }
                        parse_one_or_three(v).map_err(|x| bad("could not read", v, x))?
                    }
                    None => {
                        let mut out = [0.0; 3];
                        for (i, k) in ["x", "y", "z"].iter().enumerate() {
                            if let Some(v) = c.attr(k) {
                                out[i] = v.trim().parse::<f64>().map_err(|_| {
                                    c.pos.err(format!(
                                        "<{}> `{name}`: `{k}` = \"{v}\" is not a number",
                                        c.tag
                                    ))
                                })?;
                            }
                        }
                        out
                    }
                };
                Value::Vector(v)
            }
            "transform" => {
                c.check_attrs(&["name"], &["name"])?;
                Value::Transform(parse_transform(c)?)
            }
            "ref" => {
                c.check_attrs(&["id", "name"], &["id"])?;
                Value::Ref(c.attr("id").unwrap_or("").to_string())
            }
            tag if OBJECT_TAGS.contains(&tag) && tag != "scene" => {
                Value::Object(Plugin::from_element(c)?)
            }
            other => {
                return Err(c.pos.err(format!(
                    "unexpected element <{other}>; valid here: boolean, integer, float, string, rgb, spectrum, point, vector, transform, ref, include, default, and objects ({})",
                    OBJECT_TAGS[1..].join(", ")
                )))
            }
        };
        Ok(Prop {
            name,
            value,
            pos: c.pos.clone(),
            used: Cell::new(false),
        })
    }

    /// `<bsdf type="diffuse">`, for messages.
    pub fn describe(&self) -> String {
        if self.class == "scene" {
            "<scene>".into()
        } else {
            format!("<{} type=\"{}\">", self.class, self.kind)
        }
    }

    /// An error at this plugin's element.
    pub fn err(&self, message: impl AsRef<str>) -> SceneError {
        self.pos
            .err(format!("{}: {}", self.describe(), message.as_ref()))
    }

    /// The named property, marked as read.
    pub fn get(&self, name: &str) -> Option<&Prop> {
        let p = self.props.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    fn type_error(&self, p: &Prop, expected: &str) -> SceneError {
        p.pos.err(format!(
            "{}: `{}` must be {expected}, not {}",
            self.describe(),
            p.name,
            p.value.kind()
        ))
    }

    /// A number (`<float>` or `<integer>`).
    pub fn float(&self, name: &str) -> Result<Option<f64>, SceneError> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        match p.value {
            Value::Float(v) => Ok(Some(v)),
            Value::Integer(v) => Ok(Some(v as f64)),
            _ => Err(self.type_error(p, "a <float>")),
        }
    }

    pub fn integer(&self, name: &str) -> Result<Option<i64>, SceneError> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        match p.value {
            Value::Integer(v) => Ok(Some(v)),
            _ => Err(self.type_error(p, "an <integer>")),
        }
    }

    pub fn boolean(&self, name: &str) -> Result<Option<bool>, SceneError> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        match p.value {
            Value::Bool(v) => Ok(Some(v)),
            _ => Err(self.type_error(p, "a <boolean>")),
        }
    }

    pub fn string(&self, name: &str) -> Result<Option<String>, SceneError> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        match &p.value {
            Value::String(v) => Ok(Some(v.clone())),
            _ => Err(self.type_error(p, "a <string>")),
        }
    }

    /// A `<point>` or `<vector>`.
    pub fn vector(&self, name: &str) -> Result<Option<[f64; 3]>, SceneError> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        match p.value {
            Value::Vector(v) => Ok(Some(v)),
            _ => Err(self.type_error(p, "a <point> or <vector>")),
        }
    }

    pub fn transform(&self, name: &str) -> Result<Option<DMat4>, SceneError> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        match p.value {
            Value::Transform(m) => Ok(Some(m)),
            _ => Err(self.type_error(p, "a <transform>")),
        }
    }

    /// A colour: `<rgb>`, a number, a constant `<spectrum>`, or a texture (nested or by
    /// `<ref>`).
    pub fn color(&self, name: &str, reg: &Registry) -> Result<Option<ColorParam>, SceneError> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        let texture = |o: Rc<Plugin>| {
            if o.class == "texture" {
                Ok(Some(ColorParam::Texture(o)))
            } else {
                Err(p.pos.err(format!(
                    "{}: `{name}` must be a colour or a <texture>, not {}",
                    self.describe(),
                    o.describe()
                )))
            }
        };
        match &p.value {
            Value::Color(c) => Ok(Some(ColorParam::Value(*c))),
            Value::Float(v) => Ok(Some(ColorParam::Value([*v; 3]))),
            Value::Integer(v) => Ok(Some(ColorParam::Value([*v as f64; 3]))),
            Value::Object(o) => texture(o.clone()),
            Value::Ref(id) => texture(reg.get(id, &p.pos)?),
            _ => Err(self.type_error(p, "an <rgb>, a <float> or a <texture>")),
        }
    }

    /// The nested objects (and references) of a class, in document order, marked as read.
    pub fn objects(&self, class: &str, reg: &Registry) -> Result<Vec<Rc<Plugin>>, SceneError> {
        let mut out = Vec::new();
        for p in &self.props {
            let o = match &p.value {
                Value::Object(o) => o.clone(),
                Value::Ref(id) => reg.get(id, &p.pos)?,
                _ => continue,
            };
            if o.class == class {
                p.used.set(true);
                out.push(o);
            }
        }
        Ok(out)
    }

    /// At most one nested object of a class.
    pub fn object(&self, class: &str, reg: &Registry) -> Result<Option<Rc<Plugin>>, SceneError> {
        let mut v = self.objects(class, reg)?;
        if v.len() > 1 {
            return Err(v[1].err(format!(
                "{} takes one <{class}>, this is a second one",
                self.describe()
            )));
        }
        Ok(v.pop())
    }

    /// Every property that was not read is an error: an unknown parameter (with the list
    /// of `supported` ones), a parameter that does not apply here, or an unexpected nested
    /// object.
    pub fn finish(&self, supported: &[&str], reg: &Registry) -> Result<(), SceneError> {
        for p in &self.props {
            if p.used.get() {
                continue;
            }
            let list = if supported.is_empty() {
                "none".to_string()
            } else {
                supported.join(", ")
            };
            let nested = match &p.value {
                Value::Object(o) => Some(o.clone()),
                Value::Ref(id) => Some(reg.get(id, &p.pos)?),
                _ => None,
            };
            return Err(match nested {
                Some(o) => p.pos.err(format!(
                    "{} cannot hold {}{}; its parameters: {list}",
                    self.describe(),
                    o.describe(),
                    if p.name.is_empty() {
                        String::new()
                    } else {
                        format!(" as `{}`", p.name)
                    }
                )),
                None if supported.contains(&p.name.as_str()) => p.pos.err(format!(
                    "{}: `{}` does not apply together with the other parameters given",
                    self.describe(),
                    p.name
                )),
                None => p.pos.err(format!(
                    "{}: unknown parameter `{}`; supported: {list}",
                    self.describe(),
                    p.name
                )),
            });
        }
        Ok(())
    }
}
