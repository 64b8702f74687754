//! BSDF plugins as facette material tables (the keys of docs/materials.md).
//!
//! | Mitsuba | facette |
//! |---|---|
//! | `diffuse` (`reflectance` 0.5) | `lambert` |
//! | `conductor`, `roughconductor` (`distribution` beckmann/ggx, `alpha` 0.1 or `alpha_u` + `alpha_v`, `material` preset or `eta` + `k`, `specular_reflectance`, `sample_visible`) | `conductor` (`alpha = 0` when smooth; `sample_visible = false` → `sampling = "distribution"`; Beckmann with `g1 = "rational"`, Mitsuba's masking) |
//! | `dielectric`, `roughdielectric` (`int_ior` bk7, `ext_ior` air, numbers or media names; `specular_reflectance`, `specular_transmittance`; microfacet keys as above) | `dielectric` (`ior`, `ext_ior`) |
//! | `plastic`, `roughplastic` (`diffuse_reflectance` 0.5, `int_ior` polypropylene, `ext_ior` air, `nonlinear`; rough: `distribution`, `alpha`) | `il` — a Lambertian substrate under a dielectric interface, the same physical set-up, with `ni = int_ior / ext_ior` (see below for `nonlinear`) |
//! | `twosided` (one BSDF, or the same one twice) | the wrapped BSDF (facette's reflective materials are two-sided) |
//! | `lambert`, `oren-nayar`, `kelemen`, `il`, … (every facette material type that is not a Mitsuba name), or `facette-<type>` for any of them | that material, parameters named as in TOML |
//!
//! **`nonlinear`.** Mitsuba's plastic divides the substrate albedo by 1 − r_i when
//! `nonlinear` is false (its default) and by 1 − K_d r_i when true; the second is the
//! physics of IL18 (internal reflections between substrate and interface, [IL18 eq. 9]).
//! With `nonlinear = false`, facette gives the IL substrate the albedo K such that
//! K / (1 − K r_i) = K_d / (1 − r_i), which reproduces Mitsuba's body term exactly
//! (K ≤ 1 whenever K_d ≤ 1); r_i is facette's exact internal diffuse reflectance.

use super::ior::ior_param;
use super::plugin::{ColorParam, Plugin};
use super::texture::{color_value, constant_color, rgb_value, texture_table};
use super::translator::Translator;
use crate::scene::SceneError;
use facette_bsdf::fresnel::internal_diffuse_reflectance;
use facette_bsdf::recipe::MATERIAL_TYPES;
use std::rc::Rc;

/// The Mitsuba BSDF plugins facette reads.
pub(crate) const MITSUBA_BSDFS: &[&str] = &[
    "diffuse",
    "conductor",
    "roughconductor",
    "dielectric",
    "roughdielectric",
    "plastic",
    "roughplastic",
    "twosided",
];

/// facette's metal presets (names as Mitsuba spells them).
const PRESETS: &[&str] = &["Au", "Ag", "Cu", "Al", "Cr", "none"];

/// Mitsuba's defaults: bk7 inside, air outside; polypropylene for plastics.
const BK7: f64 = 1.5046;
const AIR: f64 = 1.000277;
const POLYPROPYLENE: f64 = 1.49;

/// The material name of a BSDF plugin, translating it on first use.
pub(crate) fn material(cx: &mut Translator, bsdf: &Rc<Plugin>) -> Result<String, SceneError> {
    if let Some(name) = cx.material_name(bsdf) {
        return Ok(name);
    }
    let table = bsdf_table(cx, bsdf)?;
    Ok(cx.add_material(bsdf, table))
}

/// The facette material table of a BSDF plugin.
fn bsdf_table(cx: &mut Translator, p: &Rc<Plugin>) -> Result<toml::Table, SceneError> {
    let mut t = toml::Table::new();
    let kind = p.kind.as_str();
    match kind {
        "diffuse" => {
            t.insert("type".into(), "lambert".into());
            if let Some(r) = color_value(cx, p, "reflectance")? {
                t.insert("reflectance".into(), r);
            }
            p.finish(&["reflectance"], &cx.reg)?;
        }
        "conductor" | "roughconductor" => conductor(cx, p, kind == "roughconductor", &mut t)?,
        "dielectric" | "roughdielectric" => dielectric(cx, p, kind == "roughdielectric", &mut t)?,
        "plastic" | "roughplastic" => plastic(cx, p, kind == "roughplastic", &mut t)?,
        "twosided" => {
            let inner = p.objects("bsdf", &cx.reg)?;
            p.finish(&[], &cx.reg)?;
            let b = match inner.as_slice() {
                [b] => b.clone(),
                [a, b] if Rc::ptr_eq(a, b) => a.clone(),
                [_, b] => {
                    return Err(b.err(
                        "a twosided BSDF with different front and back BSDFs is not supported: facette materials are the same on both sides",
                    ))
                }
                _ => return Err(p.err("needs one nested <bsdf> (or a <ref> to one)")),
            };
            if b.kind.contains("dielectric") {
                return Err(b.err(
                    "twosided cannot wrap a transmissive BSDF (Mitsuba refuses it too); dielectrics already work from both sides",
                ));
            }
            t = bsdf_table(cx, &b)?;
        }
        _ => {
            let native = kind.strip_prefix("facette-").unwrap_or(kind);
            let reserved = !kind.starts_with("facette-") && MITSUBA_NAMES_TAKEN.contains(&kind);
            if MATERIAL_TYPES.contains(&native) && !reserved {
                native_material(cx, p, native, &mut t)?;
            } else {
                return Err(p.err(format!(
                    "unsupported BSDF `{kind}`; supported: {}; facette's own materials: {} (or facette-<type> for any of them)",
                    MITSUBA_BSDFS.join(", "),
                    MATERIAL_TYPES
                        .iter()
                        .filter(|m| !MITSUBA_NAMES_TAKEN.contains(m))
                        .cloned()
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
        }
    }
    Ok(t)
}

/// facette material types whose names Mitsuba's plugins already use (reach them as
/// `facette-conductor`, `facette-dielectric`).
const MITSUBA_NAMES_TAKEN: &[&str] = &["conductor", "dielectric"];

/// A facette material written as a plugin: every property becomes the key of the same
/// name (textures included); the material's own validation reports unknown keys.
fn native_material(
    cx: &mut Translator,
    p: &Plugin,
    kind: &str,
    t: &mut toml::Table,
) -> Result<(), SceneError> {
    use super::plugin::Value;
    t.insert("type".into(), kind.into());
    for prop in &p.props {
        if prop.name.is_empty() {
            continue;
        }
        let v = match &prop.value {
            Value::Bool(b) => toml::Value::Boolean(*b),
            Value::Integer(i) => toml::Value::Integer(*i),
            Value::Float(f) => toml::Value::Float(*f),
            Value::String(s) => toml::Value::String(s.clone()),
            Value::Color(c) | Value::Vector(c) => rgb_value(*c),
            Value::Object(_) | Value::Ref(_) => match p.color(&prop.name, &cx.reg)? {
                Some(ColorParam::Texture(tex)) => toml::Value::Table(texture_table(cx, &tex)?),
                _ => unreachable!("objects are textures or an error"),
            },
            Value::Transform(_) => {
                return Err(prop.pos.err(format!(
                    "{}: `{}`: facette materials take no transforms",
                    p.describe(),
                    prop.name
                )))
            }
        };
        p.get(&prop.name);
        t.insert(prop.name.clone(), v);
    }
    p.finish(&[], &cx.reg)
}

/// `distribution`, `alpha` or `alpha_u` + `alpha_v` (textures allowed), `sample_visible`.
/// The parameters [`microfacet`] reads (rough conductors and dielectrics).
const MICROFACET_KEYS: [&str; 5] = [
    "distribution",
    "alpha",
    "alpha_u",
    "alpha_v",
    "sample_visible",
];

fn microfacet(
    cx: &mut Translator,
    p: &Plugin,
    anisotropic: bool,
    t: &mut toml::Table,
) -> Result<(), SceneError> {
    let distribution = p.string("distribution")?.unwrap_or("beckmann".into());
    if !["beckmann", "ggx"].contains(&distribution.as_str()) {
        return Err(p.err(format!(
            "unknown distribution `{distribution}`; valid: beckmann, ggx"
        )));
    }
    // Mitsuba's Beckmann masking is WMLT07's rational G1 (eq. 27, its `smith_g1`): the
    // scene's model is that one, not facette's exact default.
    if distribution == "beckmann" {
        t.insert("g1".into(), "rational".into());
    }
    t.insert("distribution".into(), distribution.into());
    let alpha = roughness(cx, p, "alpha")?;
    let (au, av) = if anisotropic {
        (roughness(cx, p, "alpha_u")?, roughness(cx, p, "alpha_v")?)
    } else {
        (None, None)
    };
    match (alpha, au, av) {
        (Some(a), None, None) => {
            t.insert("alpha".into(), a);
        }
        (None, Some(u), Some(v)) => {
            t.insert("alpha_u".into(), u);
            t.insert("alpha_v".into(), v);
        }
        (None, None, None) => {
            t.insert("alpha".into(), toml::Value::Float(0.1));
        }
        (Some(_), _, _) => return Err(p.err("give `alpha` or `alpha_u` and `alpha_v`, not both")),
        _ => return Err(p.err("`alpha_u` and `alpha_v` go together")),
    }
    if !p.boolean("sample_visible")?.unwrap_or(true) {
        t.insert("sampling".into(), "distribution".into());
    }
    Ok(())
}

/// A roughness: a number or a texture (its channel average); a coloured constant is
/// refused.
fn roughness(
    cx: &mut Translator,
    p: &Plugin,
    name: &str,
) -> Result<Option<toml::Value>, SceneError> {
    let v = color_value(cx, p, name)?;
    if let Some(toml::Value::Array(_)) = v {
        return Err(p.err(format!("`{name}` must be one number, not a colour")));
    }
    Ok(v)
}

fn conductor(
    cx: &mut Translator,
    p: &Plugin,
    rough: bool,
    t: &mut toml::Table,
) -> Result<(), SceneError> {
    t.insert("type".into(), "conductor".into());
    if rough {
        microfacet(cx, p, true, t)?;
    } else {
        t.insert("alpha".into(), toml::Value::Float(0.0));
    }
    let what = "facette's complex index is constant over the surface";
    let preset = p.string("material")?;
    let eta = constant_color(cx, p, "eta", what)?;
    let k = constant_color(cx, p, "k", what)?;
    match (preset, eta.is_some() || k.is_some()) {
        (Some(_), true) => {
            return Err(p.err("give `material` or `eta` and `k`, not both"));
        }
        (Some(m), false) => {
            if !PRESETS.contains(&m.as_str()) {
                return Err(p.err(format!(
                    "the conductor preset `{m}` is not built into facette (built in: {}); give its index as <rgb name=\"eta\"> and <rgb name=\"k\">",
                    PRESETS.join(", ")
                )));
            }
            t.insert("material".into(), m.into());
        }
        (None, false) => {
            t.insert("material".into(), "none".into());
        }
        (None, true) => {
            // Mitsuba's defaults, η = 0 and k = 1, make F = 1: facette's `none`.
            let eta = eta.unwrap_or([0.0; 3]);
            let k = k.unwrap_or([1.0; 3]);
            if eta == [0.0; 3] && k == [1.0; 3] {
                t.insert("material".into(), "none".into());
            } else {
                t.insert("eta".into(), rgb_value(eta));
                t.insert("k".into(), rgb_value(k));
            }
        }
    }
    if let Some(s) = color_value(cx, p, "specular_reflectance")? {
        t.insert("specular_reflectance".into(), s);
    }
    let mut keys = vec!["material", "eta", "k", "specular_reflectance"];
    if rough {
        keys.extend(MICROFACET_KEYS);
    }
    p.finish(&keys, &cx.reg)
}

fn dielectric(
    cx: &mut Translator,
    p: &Plugin,
    rough: bool,
    t: &mut toml::Table,
) -> Result<(), SceneError> {
    t.insert("type".into(), "dielectric".into());
    if rough {
        microfacet(cx, p, true, t)?;
    } else {
        t.insert("alpha".into(), toml::Value::Float(0.0));
    }
    t.insert(
        "ior".into(),
        toml::Value::Float(ior_param(p, "int_ior", BK7)?),
    );
    t.insert(
        "ext_ior".into(),
        toml::Value::Float(ior_param(p, "ext_ior", AIR)?),
    );
    for key in ["specular_reflectance", "specular_transmittance"] {
        if let Some(s) = color_value(cx, p, key)? {
            t.insert(key.into(), s);
        }
    }
    let mut keys = vec![
        "int_ior",
        "ext_ior",
        "specular_reflectance",
        "specular_transmittance",
    ];
    if rough {
        keys.extend(MICROFACET_KEYS);
    }
    p.finish(&keys, &cx.reg)
}

fn plastic(
    cx: &mut Translator,
    p: &Plugin,
    rough: bool,
    t: &mut toml::Table,
) -> Result<(), SceneError> {
    t.insert("type".into(), "il".into());
    let int_ior = ior_param(p, "int_ior", POLYPROPYLENE)?;
    let ext_ior = ior_param(p, "ext_ior", AIR)?;
    let ni = int_ior / ext_ior;
    t.insert("ni".into(), toml::Value::Float(ni));
    if rough {
        microfacet(cx, p, false, t)?;
    } else {
        t.insert("alpha".into(), toml::Value::Float(0.0));
    }
    if let Some(s) = constant_color(cx, p, "specular_reflectance", "no specular tint")? {
        if s != [1.0; 3] {
            return Err(p.err(
                "`specular_reflectance` other than 1 is not supported: the interfaced-Lambertian model has no specular tint",
            ));
        }
    }
    let nonlinear = p.boolean("nonlinear")?.unwrap_or(false);
    let kd = p.color("diffuse_reflectance", &cx.reg)?;
    let kd_value = match kd {
        None => Some(linear_albedo([0.5; 3], ni, nonlinear)),
        Some(ColorParam::Value(c)) => Some(linear_albedo(c, ni, nonlinear)),
        Some(ColorParam::Texture(tex)) => {
            if !nonlinear {
                cx.warn(
                    &p.pos,
                    format!("{} with a textured diffuse_reflectance and nonlinear=false: the texture is taken as the substrate albedo (as with nonlinear=true); see docs/scene-format.md, section Mitsuba scenes", p.describe()),
                );
            }
            t.insert("kd".into(), toml::Value::Table(texture_table(cx, &tex)?));
            None
        }
    };
    if let Some(kd) = kd_value {
        t.insert("kd".into(), rgb_value(kd));
    }
    let mut keys = vec![
        "diffuse_reflectance",
        "specular_reflectance",
        "int_ior",
        "ext_ior",
        "nonlinear",
    ];
    if rough {
        keys.extend(["distribution", "alpha", "sample_visible"]);
    }
    p.finish(&keys, &cx.reg)
}

/// The IL substrate albedo for a Mitsuba plastic's `diffuse_reflectance` `kd`: itself when
/// `nonlinear`, otherwise K with K / (1 − K r_i) = kd / (1 − r_i) (module docs).
fn linear_albedo(kd: [f64; 3], ni: f64, nonlinear: bool) -> [f64; 3] {
    if nonlinear {
        return kd;
    }
    let ri = internal_diffuse_reflectance(ni);
    kd.map(|k| {
        let a = k / (1.0 - ri);
        a / (1.0 + a * ri)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_plastic_albedo_reproduces_mitsubas_body_term() {
        let ni = 1.49 / 1.000277;
        let ri = internal_diffuse_reflectance(ni);
        for kd in [0.0, 0.2, 0.5, 0.9, 1.0] {
            let k = linear_albedo([kd; 3], ni, false)[0];
            assert!((0.0..=1.0 + 1e-12).contains(&k));
            assert!((k / (1.0 - k * ri) - kd / (1.0 - ri)).abs() < 1e-12, "{kd}");
        }
        assert_eq!(linear_albedo([0.3; 3], ni, true), [0.3; 3]);
    }
}
