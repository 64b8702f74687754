//! Materials: the named `[materials]` of the scene, and the material of each object (a
//! name, an inline table, or black for a pure emitter).

use super::context::Ctx;
use crate::materials::SceneMaterial;
use crate::scene::description::{MaterialRef, ObjectDesc};
use crate::scene::SceneError;
use std::collections::BTreeMap;
use toml::Spanned;

/// The scene's materials, in the order shapes index them.
pub(super) struct MaterialTable {
    pub list: Vec<SceneMaterial>,
    by_name: BTreeMap<String, u32>,
}

impl MaterialTable {
    /// The named materials of the description's `[materials]`.
    pub fn create(
        ctx: &Ctx,
        desc: &BTreeMap<String, Spanned<toml::Table>>,
    ) -> Result<MaterialTable, SceneError> {
        let mut list = Vec::new();
        let mut by_name = BTreeMap::new();
        for (name, table) in desc {
            let m = SceneMaterial::parse(name, table.get_ref(), &ctx.base_dir)
                .map_err(|e| ctx.err(Some(table.span()), format!("material `{name}`: {e}")))?;
            by_name.insert(name.clone(), list.len() as u32);
            list.push(m);
        }
        Ok(MaterialTable { list, by_name })
    }

    /// The material index of object `k` (0-based) described by `o`; `what` names the
    /// object in messages, `e` makes an error at the object. Errors in the material
    /// itself point at the `material` line.
    pub fn for_object(
        &mut self,
        ctx: &Ctx,
        k: usize,
        what: &str,
        o: &ObjectDesc,
        e: &dyn Fn(String) -> SceneError,
    ) -> Result<u32, SceneError> {
        let Some(m) = &o.material else {
            if o.emission.is_none() {
                return Err(e(
                    "needs a `material` (a name from [materials] or an inline table)".into(),
                ));
            }
            // Pure emitters are black.
            let black = SceneMaterial::parse(
                "black",
                &toml::from_str("type = \"lambert\"\nreflectance = 0").expect("valid"),
                &ctx.base_dir,
            )
            .map_err(e)?;
            return Ok(self.push(black));
        };
        let em = |msg: String| ctx.err(Some(m.span()), format!("{what}: {msg}"));
        match m.get_ref() {
            MaterialRef::Name(n) => self.by_name.get(n).copied().ok_or_else(|| {
                em(format!(
                    "unknown material `{n}`; defined: {}",
                    if self.by_name.is_empty() {
                        "none".to_string()
                    } else {
                        self.by_name.keys().cloned().collect::<Vec<_>>().join(", ")
                    }
                ))
            }),
            MaterialRef::Inline(t) => {
                let inline = SceneMaterial::parse(&format!("object {}", k + 1), t, &ctx.base_dir)
                    .map_err(em)?;
                Ok(self.push(inline))
            }
        }
    }

    fn push(&mut self, m: SceneMaterial) -> u32 {
        self.list.push(m);
        (self.list.len() - 1) as u32
    }
}
