//! The material schema as JSON for the app: every type, and every key with its kind,
//! range, unit, default, start value, conditions and alternatives.

use facette_bsdf::recipe::schema::{Param, ParamKind, Range, MATERIAL_SCHEMA};
use serde_json::{json, Value};

fn range(r: &Range) -> Value {
    // JSON has no infinities: an open infinite end is `null`.
    let end = |x: f64| if x.is_finite() { json!(x) } else { Value::Null };
    json!({
        "lo": end(r.lo),
        "hi": end(r.hi),
        "lo_closed": r.lo_closed(),
        "hi_closed": r.hi_closed(),
        "text": r.describe(),
    })
}

fn kind(k: &ParamKind) -> Value {
    match k {
        ParamKind::Number {
            range: r,
            unit,
            log,
        } => {
            json!({"kind": "number", "range": range(r), "unit": unit, "log": log})
        }
        ParamKind::Integer { min, max } => json!({"kind": "integer", "min": min, "max": max}),
        ParamKind::Spectrum { range: r } => json!({"kind": "spectrum", "range": range(r)}),
        ParamKind::Numbers {
            max_len,
            range: r,
            unit,
        } => json!({"kind": "numbers", "max_len": max_len, "range": range(r), "unit": unit}),
        ParamKind::Choice { values } => json!({"kind": "choice", "values": values}),
        ParamKind::Path => json!({"kind": "path"}),
    }
}

fn param(p: &Param) -> Value {
    let mut v = kind(&p.kind);
    let o = v.as_object_mut().expect("kind is an object");
    o.insert("key".into(), json!(p.key));
    o.insert("default".into(), json!(p.default));
    o.insert("required".into(), json!(p.required));
    o.insert("start".into(), json!(p.start));
    o.insert("doc".into(), json!(p.doc));
    o.insert(
        "when".into(),
        Value::Array(
            p.when
                .iter()
                .map(|w| json!({"key": w.key, "any_of": w.any_of}))
                .collect(),
        ),
    );
    o.insert("excludes".into(), json!(p.excludes));
    o.insert("needs".into(), json!(p.needs));
    v
}

/// `{"types": [{"name", "summary", "example", "params": […]}…]}`.
pub fn schema_json() -> Value {
    json!({
        "types": MATERIAL_SCHEMA.iter().map(|t| json!({
            "name": t.name,
            "summary": t.summary,
            "example": t.example,
            "params": t.params().map(param).collect::<Vec<_>>(),
        })).collect::<Vec<_>>()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_type_and_key_is_there() {
        let s = schema_json();
        let types = s["types"].as_array().unwrap();
        assert_eq!(types.len(), MATERIAL_SCHEMA.len());
        let conductor = types.iter().find(|t| t["name"] == "conductor").unwrap();
        let alpha = conductor["params"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["key"] == "alpha")
            .unwrap();
        assert_eq!(alpha["kind"], "number");
        assert_eq!(alpha["range"]["hi"], 10.0);
        assert_eq!(alpha["required"], true);
        assert_eq!(alpha["excludes"][0], "alpha_u");
    }
}
