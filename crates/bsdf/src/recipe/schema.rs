//! Every material type's keys as data: kind, unit, range, default, choices, and when a key
//! applies. This is what a program builds controls from (`facette explore` generates its
//! sliders and menus from it); the grammar itself is the parsers of [`super::material`], and
//! the tests below hold the two together: every key the grammar accepts is described here,
//! every range here is the one the grammar enforces (checked at both ends), every default
//! here builds the same BSDF as leaving the key out, every choice listed is accepted and an
//! unknown one is refused. docs/materials.md documents the same keys (tested too).

use crate::checks::Bounds;
use std::f64::consts::FRAC_PI_2;

/// An interval of valid values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub lo: f64,
    pub hi: f64,
    pub bounds: Bounds,
}

impl Range {
    /// Every finite number.
    pub const FINITE: Range = Range {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
        bounds: Bounds::Open,
    };

    const fn closed(lo: f64, hi: f64) -> Range {
        Range {
            lo,
            hi,
            bounds: Bounds::Closed,
        }
    }
    const fn open_closed(lo: f64, hi: f64) -> Range {
        Range {
            lo,
            hi,
            bounds: Bounds::OpenClosed,
        }
    }
    const fn closed_open(lo: f64, hi: f64) -> Range {
        Range {
            lo,
            hi,
            bounds: Bounds::ClosedOpen,
        }
    }

    /// Whether the lower (upper) end belongs to the range.
    pub fn lo_closed(&self) -> bool {
        matches!(self.bounds, Bounds::Closed | Bounds::ClosedOpen)
    }
    pub fn hi_closed(&self) -> bool {
        matches!(self.bounds, Bounds::Closed | Bounds::OpenClosed)
    }

    pub fn contains(&self, v: f64) -> bool {
        (if self.lo_closed() {
            v >= self.lo
        } else {
            v > self.lo
        }) && (if self.hi_closed() {
            v <= self.hi
        } else {
            v < self.hi
        })
    }

    /// The range as the docs write it: `[0, 1]`, `(0, 10]`.
    pub fn describe(&self) -> String {
        use crate::math::fmt_num;
        format!(
            "{}{}, {}{}",
            if self.lo_closed() { '[' } else { '(' },
            fmt_num(self.lo),
            fmt_num(self.hi),
            if self.hi_closed() { ']' } else { ')' }
        )
    }
}

/// What a key's value is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamKind {
    /// A number in `range`; `log`: spans decades (a slider moves its logarithm).
    Number {
        range: Range,
        unit: &'static str,
        log: bool,
    },
    /// A whole number in [min, max].
    Integer { min: u64, max: u64 },
    /// A number or an RGB triple `[r, g, b]`, each in `range`.
    Spectrum { range: Range },
    /// One to `max_len` numbers, each in `range` (a number alone stands for all).
    Numbers {
        max_len: usize,
        range: Range,
        unit: &'static str,
    },
    /// One of `values`.
    Choice { values: &'static [&'static str] },
    /// A file path.
    Path,
}

/// A key applies only where another key's value (given, or its default) is among `any_of`;
/// an empty `any_of` asks only that the other key be given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct When {
    pub key: &'static str,
    pub any_of: &'static [&'static str],
}

/// One key of a material type. A key may appear several times in a type with disjoint
/// [`when`](Self::when) conditions where its range, default or choices depend on another
/// key (`alpha` of Phong is in (0, 1], of Beckmann in [0, 10]); the first entry whose
/// conditions hold is the one that applies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Param {
    pub key: &'static str,
    pub kind: ParamKind,
    /// The value the grammar uses when the key is absent, as a TOML literal; `None` where
    /// there is none (a required key, or an alternative to other keys).
    pub default: Option<&'static str>,
    /// Whether a table must give the key (or one of [`excludes`](Self::excludes)).
    pub required: bool,
    /// The value an editor starts a control at: the default, or a typical value.
    pub start: &'static str,
    /// What the key means, as docs/materials.md says it.
    pub doc: &'static str,
    /// All must hold for the key to apply.
    pub when: &'static [When],
    /// Keys that cannot be given together with this one (`alpha` and `alpha_u`).
    pub excludes: &'static [&'static str],
    /// Keys that must be given together with this one (`alpha_v` with `alpha_u`).
    pub needs: &'static [&'static str],
}

impl Param {
    const fn new(
        key: &'static str,
        kind: ParamKind,
        default: &'static str,
        doc: &'static str,
    ) -> Param {
        Param {
            key,
            kind,
            default: Some(default),
            required: false,
            start: default,
            doc,
            when: &[],
            excludes: &[],
            needs: &[],
        }
    }

    /// A key without a default: an editor starts it at `start`.
    const fn without_default(self, start: &'static str) -> Param {
        Param {
            default: None,
            start,
            ..self
        }
    }

    /// A key a table must give (or one of its alternatives), starting at `start`.
    const fn required(self, start: &'static str) -> Param {
        Param {
            required: true,
            ..self.without_default(start)
        }
    }

    const fn when(self, when: &'static [When]) -> Param {
        Param { when, ..self }
    }

    const fn excluding(self, excludes: &'static [&'static str]) -> Param {
        Param { excludes, ..self }
    }

    const fn needing(self, needs: &'static [&'static str]) -> Param {
        Param { needs, ..self }
    }

    /// A number spanning decades (a slider moves its logarithm).
    const fn logarithmic(self) -> Param {
        match self.kind {
            ParamKind::Number { range, unit, .. } => Param {
                kind: ParamKind::Number {
                    range,
                    unit,
                    log: true,
                },
                ..self
            },
            _ => self,
        }
    }

    /// Whether the key applies given `value_of` (a key's value, or its default).
    pub fn applies(&self, value_of: impl Fn(&str) -> Option<String>) -> bool {
        self.when.iter().all(|w| {
            value_of(w.key).is_some_and(|v| w.any_of.is_empty() || w.any_of.contains(&v.as_str()))
        })
    }
}

/// A material type (`type = "…"`) and its keys.
#[derive(Clone, Copy, Debug)]
pub struct MaterialType {
    pub name: &'static str,
    pub summary: &'static str,
    /// The type's keys, by group (the microfacet keys are one group shared by the rough
    /// models).
    pub groups: &'static [&'static [Param]],
    /// A valid table of this type, the starting point of an editor.
    pub example: &'static str,
}

impl MaterialType {
    /// Every entry of every group, in order.
    pub fn params(&self) -> impl Iterator<Item = &'static Param> + '_ {
        self.groups.iter().flat_map(|g| g.iter())
    }

    /// The distinct keys, in order.
    pub fn keys(&self) -> Vec<&'static str> {
        let mut keys: Vec<&'static str> = Vec::new();
        for p in self.params() {
            if !keys.contains(&p.key) {
                keys.push(p.key);
            }
        }
        keys
    }

    /// The entry of `key` that applies given `value_of` (see [`Param::applies`]).
    pub fn applying(
        &self,
        key: &str,
        value_of: impl Fn(&str) -> Option<String> + Copy,
    ) -> Option<&'static Param> {
        self.params().find(|p| p.key == key && p.applies(value_of))
    }
}

/// A table's value of `key` as text (a string without its quotes, other values as TOML
/// writes them), or `None`.
fn table_text(table: &toml::Table, key: &str) -> Option<String> {
    table.get(key).map(|v| match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    })
}

impl MaterialType {
    /// The value of `key` in `table` as text, or the default of the key's first entry that
    /// has one (a string without its quotes): what [`Param::applies`] tests.
    pub fn value_of(&self, table: &toml::Table, key: &str) -> Option<String> {
        table_text(table, key).or_else(|| {
            self.params()
                .filter(|p| p.key == key)
                .find_map(|p| p.default)
                .map(|d| d.trim_matches('"').to_string())
        })
    }

    /// Whether some entry of `key` applies to `table`.
    pub fn key_applies(&self, table: &toml::Table, key: &str) -> bool {
        self.applying(key, |k| self.value_of(table, k)).is_some()
    }

    /// Removes the keys that do not apply to `table` (an `alpha` left over after
    /// `distribution` became `gaussian`) and the choices whose value the entry that now
    /// applies does not offer (`g1 = "exact"` after Beckmann became Phong), until none is
    /// left; `type` stays.
    pub fn retain_applicable(&self, table: &mut toml::Table) {
        loop {
            let stale: Vec<String> = table
                .keys()
                .filter(|k| {
                    let entry = self.applying(k, |q| self.value_of(table, q));
                    let offered = match (entry.map(|e| e.kind), table[k.as_str()].as_str()) {
                        (Some(ParamKind::Choice { values }), Some(v)) => values.contains(&v),
                        _ => true,
                    };
                    k.as_str() != "type" && (entry.is_none() || !offered)
                })
                .cloned()
                .collect();
            if stale.is_empty() {
                return;
            }
            for k in stale {
                table.remove(&k);
            }
        }
    }

    /// Adds each required key that applies and is missing (with none of its alternatives
    /// given), and each key a given key [`needs`](Param::needs), at its
    /// [`start`](Param::start) value.
    pub fn fill_required(&self, table: &mut toml::Table) {
        for p in self.params() {
            if !p.applies(|k| self.value_of(table, k)) {
                continue;
            }
            let given = table.contains_key(p.key);
            // Exclusion goes both ways: a `preset` given stands for the `alpha` it excludes.
            let alternative = p.excludes.iter().any(|k| table.contains_key(*k))
                || self
                    .params()
                    .any(|q| q.excludes.contains(&p.key) && table.contains_key(q.key));
            let needed = self.params().any(|q| {
                q.needs.contains(&p.key)
                    && table.contains_key(q.key)
                    && q.applies(|k| self.value_of(table, k))
            });
            if !given && ((p.required && !alternative) || needed) {
                if let Ok(v) = toml_value(p.start) {
                    table.insert(p.key.to_string(), v);
                }
            }
        }
    }
}

/// A TOML literal as a value.
pub fn toml_value(literal: &str) -> Result<toml::Value, crate::error::ParamError> {
    let t = super::parse_inline_table(&format!("{{v = {literal}}}"))?;
    t.get("v")
        .cloned()
        .ok_or_else(|| crate::error::ParamError::Invalid(format!("not a TOML value: {literal}")))
}

const fn choice(
    key: &'static str,
    values: &'static [&'static str],
    default: &'static str,
    doc: &'static str,
) -> Param {
    Param::new(key, ParamKind::Choice { values }, default, doc)
}

const fn number(
    key: &'static str,
    range: Range,
    unit: &'static str,
    default: &'static str,
    doc: &'static str,
) -> Param {
    Param::new(
        key,
        ParamKind::Number {
            range,
            unit,
            log: false,
        },
        default,
        doc,
    )
}

const fn reflectance(key: &'static str, default: &'static str, doc: &'static str) -> Param {
    Param::new(
        key,
        ParamKind::Spectrum {
            range: Range::closed(0.0, 1.0),
        },
        default,
        doc,
    )
}

const fn integer(
    key: &'static str,
    min: u64,
    max: u64,
    default: &'static str,
    doc: &'static str,
) -> Param {
    Param::new(key, ParamKind::Integer { min, max }, default, doc)
}

const BECKMANN_GGX: When = When {
    key: "distribution",
    any_of: &["beckmann", "ggx"],
};
const BECKMANN: When = When {
    key: "distribution",
    any_of: &["beckmann"],
};
const GAUSSIAN: When = When {
    key: "distribution",
    any_of: &["gaussian"],
};
const PHONG: When = When {
    key: "distribution",
    any_of: &["phong"],
};
const NOT_GAUSSIAN: When = When {
    key: "distribution",
    any_of: &["beckmann", "ggx", "phong"],
};
const SINGLE: When = When {
    key: "scattering",
    any_of: &["single"],
};
const MULTIPLE: When = When {
    key: "scattering",
    any_of: &["multiple"],
};
const EXACT_ON: When = When {
    key: "model",
    any_of: &["exact"],
};
const QUADRATURE: When = When {
    key: "evaluation",
    any_of: &["quadrature"],
};
const GENERATED: When = When {
    key: "generate",
    any_of: crate::models::glint::NormalMapKind::NAMES,
};

/// Widths: α ≤ 10 (`checks::ALPHA_MAX`).
const ALPHA: Range = Range::closed(0.0, crate::checks::ALPHA_MAX);
const ALPHA_ROUGH: Range = Range::open_closed(0.0, crate::checks::ALPHA_MAX);
/// `tolerance` keys (`microfacet::integral::TOLERANCE_RANGE`).
const TOLERANCE: Range = Range::closed(
    crate::microfacet::integral::TOLERANCE_RANGE.0,
    crate::microfacet::integral::TOLERANCE_RANGE.1,
);
/// Metal presets of conductors and glints: `none` and `fresnel::conductor::METALS`.
pub const METAL_CHOICES: &[&str] = &["none", "Au", "Ag", "Cu", "Al", "Cr"];
/// Glass presets of dielectrics (`models::rough_dielectric::MEASURED_GLASSES`).
pub const GLASS_CHOICES: &[&str] = &["ground", "frosted", "etched", "antiglare"];
/// The largest count a recipe accepts by default (`limits::RECIPE_COUNT`).
const COUNT_MAX: u64 = 1 << 24;

const DISTRIBUTION_DOC: &str = "the normal distribution D";

/// `distribution` of the models that take every distribution.
const ANY_DISTRIBUTION: &[Param] = &[choice(
    "distribution",
    crate::recipe::microfacet::DISTRIBUTION_NAMES,
    "\"beckmann\"",
    DISTRIBUTION_DOC,
)];

/// Widths of Beckmann and GGX.
const ALPHA_KEYS: &[Param] = &[
    number(
        "alpha",
        ALPHA,
        "",
        "",
        "isotropic width α; 0 is perfectly smooth",
    )
    .required("0.2")
    .when(&[BECKMANN_GGX])
    .excluding(&["alpha_u", "alpha_v"]),
    number(
        "alpha_u",
        ALPHA_ROUGH,
        "",
        "",
        "width along the tangent (x)",
    )
    .without_default("0.1")
    .when(&[BECKMANN_GGX])
    .excluding(&["alpha"])
    .needing(&["alpha_v"]),
    number(
        "alpha_v",
        ALPHA_ROUGH,
        "",
        "",
        "width along the bitangent (y)",
    )
    .without_default("0.4")
    .when(&[BECKMANN_GGX])
    .excluding(&["alpha"])
    .needing(&["alpha_u"]),
];

/// The width of the Gaussian.
const SIGMA_KEY: &[Param] = &[number(
    "sigma",
    Range::closed_open(0.0, FRAC_PI_2),
    "rad",
    "",
    "width σ of the Gaussian distribution of normal angles; 0 is smooth",
)
.required("0.3")
.when(&[GAUSSIAN])];

/// The Phong exponent, or its α.
const PHONG_KEYS: &[Param] = &[
    number(
        "exponent",
        Range::closed(0.0, 1e7),
        "",
        "",
        "Phong exponent α_p",
    )
    .logarithmic()
    .required("100.0")
    .when(&[PHONG])
    .excluding(&["alpha"]),
    number(
        "alpha",
        Range::open_closed(0.0, 1.0),
        "",
        "",
        "instead of `exponent`: α_p = 2/α² − 2",
    )
    .without_default("0.2")
    .when(&[PHONG])
    .excluding(&["exponent"]),
];

/// How G1 is evaluated.
const G1_KEYS: &[Param] = &[
    choice(
        "g1",
        &["exact", "rational"],
        "\"exact\"",
        "how G1 is evaluated: the erf form, or WMLT07 eq. 27's rational fit",
    )
    .when(&[BECKMANN]),
    choice(
        "g1",
        &["rational", "numeric"],
        "\"rational\"",
        "how G1 is evaluated: WMLT07's rational fit, or the exact Smith Λ tabulated",
    )
    .when(&[PHONG]),
];

const MASKING_DOC: &str = "the masking-shadowing G";

const MULTIPLE_MASKING: Param = choice(
    "masking",
    &["smith-correlated"],
    "\"smith-correlated\"",
    "the masking-shadowing G (the random walk's height-correlated Smith)",
)
.when(&[MULTIPLE]);

/// `masking` of conductors.
const CONDUCTOR_MASKING: &[Param] = &[
    MULTIPLE_MASKING,
    choice(
        "masking",
        crate::microfacet::Masking::NAMES,
        "\"smith\"",
        MASKING_DOC,
    )
    .when(&[NOT_GAUSSIAN]),
    choice("masking", &["v-cavity"], "\"v-cavity\"", MASKING_DOC).when(&[GAUSSIAN]),
];

/// `distribution` and `masking` of dielectrics: Smith forms only (transmission).
const DIELECTRIC_MASKING: &[Param] = &[
    choice(
        "distribution",
        &["beckmann", "ggx", "phong"],
        "\"beckmann\"",
        DISTRIBUTION_DOC,
    ),
    MULTIPLE_MASKING,
    choice(
        "masking",
        &["smith", "smith-correlated"],
        "\"smith\"",
        "the masking-shadowing G (Smith forms: the others have no transmission)",
    ),
];

const SAMPLING: Param = choice(
    "sampling",
    crate::microfacet::specular_lobe::NormalSampling::NAMES,
    "\"visible\"",
    "which normals samplers draw: visible normals, or D|m·n|",
);

const SPECULAR_REFLECTANCE: Param = reflectance(
    "specular_reflectance",
    "1.0",
    "multiplier of the reflection",
);

const CONDUCTOR_FRESNEL: &[Param] = &[
    choice(
        "material",
        METAL_CHOICES,
        "\"none\"",
        "metal preset (Palik's data, RGB); `none` is F = 1",
    )
    .excluding(&["eta", "k"]),
    Param::new(
        "eta",
        ParamKind::Spectrum {
            range: Range::closed(1e-4, 100.0),
        },
        "",
        "real part η of the complex index, per channel (with `k`)",
    )
    .without_default("[0.2, 0.9, 1.1]")
    .excluding(&["material"])
    .needing(&["k"]),
    Param::new(
        "k",
        ParamKind::Spectrum {
            range: Range::closed(0.0, 100.0),
        },
        "",
        "imaginary part k of the complex index, per channel (with `eta`)",
    )
    .without_default("[3.9, 2.4, 1.6]")
    .excluding(&["material"])
    .needing(&["eta"]),
    choice("fresnel", &["exact", "schlick"], "\"exact\"", FRESNEL_DOC).when(&[When {
        key: "material",
        any_of: &["Au", "Ag", "Cu", "Al", "Cr"],
    }]),
    choice("fresnel", &["exact", "schlick"], "\"exact\"", FRESNEL_DOC).when(&[When {
        key: "eta",
        any_of: &[],
    }]),
];

const FRESNEL_DOC: &str =
    "exact Fresnel equations, or Schlick's approximation from F0 (metals only)";

const ENERGY_DOC: &str = "Kulla & Conty's compensation lobe for the energy single scattering loses";

const SCATTERING_DOC: &str =
    "single scattering, or every order by the random walk on the microsurface (HHdD16)";

/// A conductor's `scattering` with the Gaussian: the walk needs a Smith microsurface,
/// which the Gaussian has not (its Λ diverges).
const GAUSSIAN_SCATTERING: &[Param] = &[
    choice("scattering", &["single"], "\"single\"", SCATTERING_DOC).when(&[GAUSSIAN]),
    choice(
        "energy",
        &["uncompensated"],
        "\"uncompensated\"",
        ENERGY_DOC,
    )
    .when(&[GAUSSIAN]),
];

const ENERGY_KEYS: &[Param] = &[
    // The walk draws visible normals: Phong has no such sampler.
    choice("scattering", &["single"], "\"single\"", SCATTERING_DOC).when(&[PHONG]),
    choice(
        "scattering",
        &["single", "multiple"],
        "\"single\"",
        SCATTERING_DOC,
    ),
    choice(
        "energy",
        &["uncompensated", "compensated"],
        "\"uncompensated\"",
        ENERGY_DOC,
    )
    .when(&[SINGLE, BECKMANN_GGX]),
    // The compensation is tabulated for Beckmann and GGX only.
    choice(
        "energy",
        &["uncompensated"],
        "\"uncompensated\"",
        ENERGY_DOC,
    )
    .when(&[SINGLE, PHONG]),
    choice(
        "height_distribution",
        crate::models::multiple_scattering::smith_microsurface::HeightDistribution::NAMES,
        "\"uniform\"",
        "heights of the random walk's microsurface (the BSDF does not depend on it)",
    )
    .when(&[MULTIPLE]),
];

const LAMBERT: &[Param] = &[reflectance("reflectance", "0.5", "albedo R")];

const OREN_NAYAR: &[Param] = &[
    reflectance("reflectance", "0.5", "facet albedo K_d"),
    number(
        "sigma",
        Range::closed_open(0.0, FRAC_PI_2),
        "rad",
        "",
        "roughness σ; 0 gives `lambert`",
    )
    .required("0.3"),
    choice(
        "model",
        &["exact", "qualitative", "l1"],
        "\"exact\"",
        "the exact integral, or Oren–Nayar's qualitative or L1 forms",
    ),
    choice(
        "evaluation",
        crate::models::oren_nayar::IntegralEvaluation::NAMES,
        "\"quadrature\"",
        "deterministic quadrature, or one stochastic microfacet per call",
    )
    .when(&[EXACT_ON]),
    number(
        "tolerance",
        TOLERANCE,
        "",
        "",
        "relative tolerance of the adaptive quadrature (without it and `samples`: 256 microfacets)",
    )
    .logarithmic()
    .without_default("1e-6")
    .when(&[EXACT_ON, QUADRATURE])
    .excluding(&["samples"]),
    integer(
        "samples",
        8,
        COUNT_MAX,
        "256",
        "a fixed set of N microfacets per evaluation",
    )
    .when(&[EXACT_ON, QUADRATURE])
    .excluding(&["tolerance"]),
];

/// `g1` with `scattering = "multiple"`: the walk's free paths are defined by the exact Λ.
const WALK_G1: &[Param] = &[choice(
    "g1",
    &["exact"],
    "\"exact\"",
    "the random walk needs the exact Beckmann Λ (HHdD16 §4)",
)
.when(&[BECKMANN, MULTIPLE])];

/// `sampling` with `scattering = "multiple"`: the random walk draws visible normals.
const WALK_SAMPLING: Param = choice(
    "sampling",
    &["visible"],
    "\"visible\"",
    "the random walk samples visible normals (HHdD16)",
)
.when(&[MULTIPLE]);

const CONDUCTOR: &[Param] = &[WALK_SAMPLING, SAMPLING, SPECULAR_REFLECTANCE];

const DIELECTRIC: &[Param] = &[
    WALK_SAMPLING,
    choice(
        "sampling",
        &["visible", "distribution", "widened"],
        "\"visible\"",
        "which normals samplers draw: visible normals, D|m·n|, or WMLT07 §5.3's widened Beckmann",
    )
    .when(&[BECKMANN]),
    SAMPLING,
    number(
        "ior",
        Range::open_closed(0.0, 100.0),
        "",
        "1.5",
        "index of refraction of the inside",
    )
    .excluding(&["preset"]),
    number(
        "ext_ior",
        Range::open_closed(0.0, 100.0),
        "",
        "1.0",
        "index of refraction of the outside",
    ),
    Param::new(
        "preset",
        ParamKind::Choice {
            values: GLASS_CHOICES,
        },
        "",
        "WMLT07 Fig. 12's measured glasses (fixes roughness and ior = 1.51)",
    )
    .without_default("\"ground\"")
    .when(&[BECKMANN_GGX])
    .excluding(&["alpha", "alpha_u", "alpha_v", "exponent", "ior", "g1"]),
    SPECULAR_REFLECTANCE,
    reflectance(
        "specular_transmittance",
        "1.0",
        "multiplier of the transmission",
    ),
];

const KELEMEN: &[Param] = &[
    choice(
        "distribution",
        crate::microfacet::half_vector_density::HalfVectorDensity::NAMES,
        "\"ward\"",
        "half-vector density [KSK01 eqs. 4–5]",
    ),
    number(
        "alpha",
        ALPHA_ROUGH,
        "",
        "",
        "RMS slope m (below 1e-4 taken as 1e-4)",
    )
    .required("0.2")
    .when(&[When {
        key: "distribution",
        any_of: &["ward", "beckmann"],
    }]),
    number(
        "exponent",
        Range::closed(0.0, 1e7),
        "",
        "",
        "Phong exponent n",
    )
    .logarithmic()
    .required("100.0")
    .when(&[PHONG]),
    number(
        "ior",
        Range::open_closed(1.0, 100.0),
        "",
        "1.5",
        "index of the Fresnel term",
    ),
    reflectance("kd", "0.5", "matte colour k"),
    number(
        "table_tolerance",
        TOLERANCE,
        "",
        "1e-4",
        "relative tolerance of each entry of the specular-albedo table",
    )
    .logarithmic()
    .excluding(&["table_samples"]),
    integer(
        "table_samples",
        64,
        COUNT_MAX,
        "",
        "instead of `table_tolerance`: randomized-QMC samples per table entry",
    )
    .without_default("1024")
    .excluding(&["table_tolerance"]),
];

const IL_BODY: &[Param] = &[
    reflectance("kd", "0.5", "substrate albedo K_d"),
    number(
        "ni",
        Range::closed(1.0, 10.0),
        "",
        "1.5",
        "relative index n_i of the interface",
    ),
];

const IL: &[Param] = &[
    choice(
        "masking",
        crate::microfacet::Masking::NAMES,
        "\"smith\"",
        MASKING_DOC,
    )
    .when(&[NOT_GAUSSIAN, SINGLE]),
    choice(
        "masking",
        &["v-cavity"],
        "\"v-cavity\"",
        "the masking-shadowing G (V-cavities: the only one of the Gaussian)",
    )
    .when(&[GAUSSIAN]),
    choice(
        "masking",
        &["v-cavity"],
        "\"v-cavity\"",
        "the masking-shadowing G (V-cavities: the inter-reflections are traced in them)",
    )
    .when(&[When {
        key: "scattering",
        any_of: &["double", "multiple"],
    }]),
    SAMPLING,
    choice(
        "evaluation",
        crate::models::il::interfaced_lambertian::BodyEvaluation::NAMES,
        "\"stochastic\"",
        "how the body integral is computed",
    ),
    number(
        "tolerance",
        TOLERANCE,
        "",
        "",
        "relative tolerance of the adaptive quadratures: the body's (1e-6 when absent) and the multiple scattering's (1e-4)",
    )
    .logarithmic()
    .without_default("1e-4")
    .when(&[QUADRATURE])
    .excluding(&["samples"]),
    number(
        "tolerance",
        TOLERANCE,
        "",
        "",
        "relative tolerance of the multiple scattering's quadrature (1e-4 when absent)",
    )
    .logarithmic()
    .without_default("1e-4")
    .when(&[When {
        key: "multiple_evaluation",
        any_of: &["quadrature"],
    }]),
    integer(
        "samples",
        8,
        COUNT_MAX,
        "",
        "instead of `tolerance`: a fixed set of N microfacets per evaluation",
    )
    .without_default("256")
    .when(&[QUADRATURE])
    .excluding(&["tolerance"]),
    Param::new(
        "table",
        ParamKind::Path,
        "",
        "a body table written by `facette tabulate`",
    )
    .required("\"\"")
    .when(&[When {
        key: "evaluation",
        any_of: &["table"],
    }]),
    choice(
        "scattering",
        crate::models::il::interfaced_lambertian::Scattering::NAMES,
        "\"single\"",
        "inter-reflections between microfacets: IL₁, IL₂ or IL_∞",
    ),
    choice(
        "multiple_evaluation",
        &["stochastic", "quadrature"],
        "\"stochastic\"",
        "how `eval` computes the V-cavity inter-reflections",
    )
    .when(&[When {
        key: "scattering",
        any_of: &["double", "multiple"],
    }]),
];

const GLINT: &[Param] = &[
    Param::new(
        "generate",
        ParamKind::Choice {
            values: crate::models::glint::NormalMapKind::NAMES,
        },
        "",
        "a procedural normal map",
    )
    .required("\"scratched\"")
    .excluding(&["normal_map", "normal_encoding"]),
    integer(
        "resolution",
        1,
        4096,
        "512",
        "texels per side of the generated map",
    )
    .when(&[GENERATED]),
    integer("seed", 0, i64::MAX as u64, "1", "seed of the generated map").when(&[GENERATED]),
    Param::new(
        "normal_map",
        ParamKind::Path,
        "",
        "tangent-space normal map file (PNG, EXR, HDR)",
    )
    .without_default("\"\"")
    .excluding(&["generate", "resolution", "seed"]),
    Param::new(
        "normal_encoding",
        ParamKind::Choice {
            values: crate::models::glint::NormalEncoding::NAMES,
        },
        "",
        "unsigned (n = 2c − 1, PNG's default) or signed (n = c, EXR's)",
    )
    .without_default("\"unsigned\"")
    .excluding(&["generate"])
    .needing(&["normal_map"]),
    Param::new(
        "uv_scale",
        ParamKind::Numbers {
            max_len: 2,
            range: Range::open_closed(0.0, 1e6),
            unit: "",
        },
        "1.0",
        "map repetitions per unit of uv: number or [u, v]",
    ),
    number(
        "roughness_floor",
        Range::open_closed(0.0, 1.0),
        "",
        "0.01",
        "σ_ε, slope standard deviation added to every lobe",
    )
    .logarithmic(),
    integer(
        "seed_subdivision",
        1,
        crate::models::glint::microsurface::MAX_SEED_SUBDIVISION as u64,
        "2",
        "n, lobes' seeds per texel side (n² lobes a texel, spacing 1/n texels): 1 is the paper's; more is nearer the map where it changes within a texel; 1 by default for maps above 2048²",
    ),
    choice(
        "masking",
        crate::models::glint::MaskingMode::NAMES,
        "\"exact\"",
        "exact patch masking (CCM19 eqs. 10–17), or the approximation of §4.2.2 taken per mip block (at most 16 filtered lobes)",
    ),
    integer(
        "masking_lobes",
        0,
        COUNT_MAX,
        "1024",
        "budget of the exact masking sum (0: unlimited)",
    ),
    choice(
        "mis_pdf",
        crate::models::glint::MisPdf::NAMES,
        "\"exact\"",
        "density a sample reports to MIS: the sampler's (one P-NDF query), or the footprint's filtered lobe (no query; noisier under wide lights)",
    ),
    choice(
        "evaluation",
        &["patch", "reference"],
        "\"patch\"",
        "the footprint's P-BRDF, or the brute-force reference",
    ),
    choice(
        "footprint",
        &["ray", "pixel"],
        "\"ray\"",
        "at a camera ray's hit: the sample's own ray footprint, or the whole pixel's (in the frame of the pixel's centre)",
    ),
    Param::new(
        "footprint_center",
        ParamKind::Numbers {
            max_len: 2,
            range: Range::FINITE,
            unit: "uv",
        },
        "[0.5, 0.5]",
        "footprint centre where no hit gives one",
    ),
    Param::new(
        "footprint_size",
        ParamKind::Numbers {
            max_len: 3,
            range: Range::closed(0.0, 1e9),
            unit: "texels",
        },
        "2.0",
        "footprint standard deviation(s) σ, [σ_u, σ_v] or [σ_u, σ_v, ρ] where no ray differential gives one",
    ),
];

/// Every material type, in the order of [`MATERIAL_TYPES`](super::MATERIAL_TYPES).
pub const MATERIAL_SCHEMA: &[MaterialType] = &[
    MaterialType {
        name: "lambert",
        summary: "ideal diffuse reflection, f = R/π",
        groups: &[LAMBERT],
        example: "{type = \"lambert\", reflectance = 0.5}",
    },
    MaterialType {
        name: "oren-nayar",
        summary: "rough diffuse V-cavities (Oren–Nayar)",
        groups: &[OREN_NAYAR],
        example: "{type = \"oren-nayar\", reflectance = 0.5, sigma = 0.3}",
    },
    MaterialType {
        name: "conductor",
        summary: "rough conductor: Cook–Torrance with a conductor Fresnel [WMLT07 eq. 20]",
        groups: &[
            ANY_DISTRIBUTION,
            ALPHA_KEYS,
            SIGMA_KEY,
            PHONG_KEYS,
            WALK_G1,
            G1_KEYS,
            CONDUCTOR_MASKING,
            CONDUCTOR,
            CONDUCTOR_FRESNEL,
            GAUSSIAN_SCATTERING,
            ENERGY_KEYS,
        ],
        example: "{type = \"conductor\", distribution = \"ggx\", alpha = 0.2, material = \"Au\"}",
    },
    MaterialType {
        name: "dielectric",
        summary: "rough dielectric interface, reflection and refraction [WMLT07 eqs. 20–21]",
        groups: &[
            DIELECTRIC_MASKING,
            ALPHA_KEYS,
            PHONG_KEYS,
            WALK_G1,
            G1_KEYS,
            DIELECTRIC,
            ENERGY_KEYS,
        ],
        example: "{type = \"dielectric\", distribution = \"ggx\", alpha = 0.2, ior = 1.5}",
    },
    MaterialType {
        name: "kelemen",
        summary: "Kelemen & Szirmay-Kalos's coupled specular-matte BRDF [KSK01]",
        groups: &[KELEMEN],
        example: "{type = \"kelemen\", distribution = \"ward\", alpha = 0.2, kd = 0.5}",
    },
    MaterialType {
        name: "il",
        summary: "interfaced Lambertian microfacets [IL18, TSBRM]",
        groups: &[
            IL_BODY,
            ANY_DISTRIBUTION,
            ALPHA_KEYS,
            SIGMA_KEY,
            PHONG_KEYS,
            G1_KEYS,
            IL,
        ],
        example: "{type = \"il\", kd = 0.5, ni = 1.5, distribution = \"beckmann\", alpha = 0.3, evaluation = \"quadrature\", tolerance = 1e-4}",
    },
    MaterialType {
        name: "glint",
        summary: "glints from a high-definition normal map [CCM19]",
        groups: &[GLINT, CONDUCTOR_FRESNEL, &[SPECULAR_REFLECTANCE]],
        example: "{type = \"glint\", generate = \"scratched\", resolution = 256, footprint_size = 4.0}",
    },
];

/// The schema of a material type.
pub fn material_type(name: &str) -> Option<&'static MaterialType> {
    MATERIAL_SCHEMA.iter().find(|t| t.name == name)
}

/// Other names the grammar takes for a type: (alias, type).
pub const TYPE_ALIASES: &[(&str, &str)] =
    &[("diffuse", "lambert"), ("interfaced-lambertian", "il")];

/// The type a `type` value names (itself, or the type of an alias); `None` if unknown.
pub fn canonical_type(name: &str) -> Option<&'static str> {
    material_type(name).map(|t| t.name).or_else(|| {
        TYPE_ALIASES
            .iter()
            .find(|(a, _)| *a == name)
            .map(|(_, t)| *t)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::ParamError;
    use crate::recipe::{parse_inline_table, MaterialRecipe, MATERIAL_TYPES};

    fn parse(t: &toml::Table) -> Result<MaterialRecipe, ParamError> {
        MaterialRecipe::parse(t, std::path::Path::new("."))
    }

    /// The example of `ty`, small where the example is costly to build (a glint map).
    fn example(ty: &MaterialType) -> toml::Table {
        let mut t = parse_inline_table(ty.example).unwrap();
        if ty.name == "glint" {
            t.insert("resolution".into(), toml::Value::Integer(16));
        }
        t
    }

    /// The example with `p`'s conditions made true, its alternatives removed, what no
    /// longer applies removed and what became required filled in.
    fn context(ty: &MaterialType, p: &Param) -> toml::Table {
        context_with(ty, p, None)
    }

    /// [`context`] with `p.key = value` when given (set before what becomes required is
    /// filled in, so that its own needs are).
    fn context_with(ty: &MaterialType, p: &Param, value: Option<toml::Value>) -> toml::Table {
        let mut t = example(ty);
        for w in p.when {
            let v = ty.value_of(&t, w.key);
            if w.any_of.is_empty() && v.is_none() {
                // "Given": the key's own start value, and what it needs.
                let q = ty.params().find(|q| q.key == w.key).unwrap();
                for k in q.excludes {
                    t.remove(*k);
                }
                t.insert(w.key.into(), toml_value(q.start).unwrap());
            } else if !w.any_of.is_empty() && !w.any_of.contains(&v.unwrap_or_default().as_str()) {
                t.insert(w.key.into(), toml::Value::String(w.any_of[0].into()));
            }
        }
        for k in p.excludes {
            t.remove(*k);
        }
        t.remove(p.key);
        if let Some(v) = value {
            t.insert(p.key.into(), v);
        }
        ty.retain_applicable(&mut t);
        ty.fill_required(&mut t);
        t
    }

    /// A recipe as text, without what differs between two builds of the same recipe (a
    /// glint map's build time).
    fn fingerprint(r: &MaterialRecipe) -> String {
        let s = format!("{r:?}");
        match s.find("build_seconds: ") {
            Some(i) => {
                let end = s[i..].find([',', ' ', '}']).map_or(s.len(), |e| i + e);
                let end = s[end..].find([',', '}']).map_or(s.len(), |e| end + e);
                format!("{}{}", &s[..i], &s[end..])
            }
            None => s,
        }
    }

    /// Whether `message` names `key` as a word (not merely contains its letters: every
    /// message contains a `k`).
    fn names(message: &str, key: &str) -> bool {
        let word = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
        message.match_indices(key).any(|(i, _)| {
            !word(message[..i].chars().next_back())
                && !word(message[i + key.len()..].chars().next())
        })
    }

    fn with(t: &toml::Table, key: &str, v: toml::Value) -> toml::Table {
        let mut t = t.clone();
        t.insert(key.into(), v);
        t
    }

    /// (type or `*`, key, the value its entry's first condition asks or ``, why): in-range
    /// values at an end of the range that another constraint refuses, so only the middle
    /// of the range is tried inside it.
    const CROSS_CONSTRAINED: &[(&str, &str, &str, &str)] = &[
        ("dielectric", "ior", "", "1e-3 <= ior / ext_ior <= 1e3"),
        ("dielectric", "ext_ior", "", "1e-3 <= ior / ext_ior <= 1e3"),
        (
            "*",
            "alpha",
            "phong",
            "exponent = 2/α² − 2 <= 1e7, so α >= 4.5e-4",
        ),
    ];

    fn cross_constrained(ty: &MaterialType, p: &Param) -> bool {
        let cond = p.when.first().map_or("", |w| w.any_of[0]);
        CROSS_CONSTRAINED
            .iter()
            .any(|c| (c.0 == ty.name || c.0 == "*") && c.1 == p.key && c.2 == cond)
    }

    /// (type, key) the grammar knows and the schema leaves out, because no value of the
    /// type's other keys lets it apply: dielectrics share the microfacet keys, but the
    /// Gaussian (the one distribution with `sigma`) has no transmission.
    const KEYS_NOT_DESCRIBED: &[(&str, &str)] = &[("dielectric", "sigma")];

    #[test]
    fn every_type_is_described_with_the_keys_the_grammar_takes() {
        let names: Vec<_> = MATERIAL_SCHEMA.iter().map(|t| t.name).collect();
        assert_eq!(names, MATERIAL_TYPES);
        for ty in MATERIAL_SCHEMA {
            let t = example(ty);
            parse(&t).unwrap_or_else(|e| panic!("{}: example does not parse: {e}", ty.name));
            let err = parse(&with(&t, "zzz", toml::Value::Integer(1))).unwrap_err();
            let ParamError::UnknownKey { valid, .. } = err else {
                panic!("{}: {err}", ty.name)
            };
            let mut grammar: Vec<&str> = valid
                .split(", ")
                .filter(|k| *k != "type" && !KEYS_NOT_DESCRIBED.contains(&(ty.name, *k)))
                .collect();
            let mut schema = ty.keys();
            grammar.sort_unstable();
            schema.sort_unstable();
            assert_eq!(schema, grammar, "{}", ty.name);
        }
    }

    #[test]
    fn entries_are_consistent() {
        for ty in MATERIAL_SCHEMA {
            let keys = ty.keys();
            for p in ty.params() {
                let at = format!("{}.{}", ty.name, p.key);
                for w in p.when {
                    assert!(keys.contains(&w.key), "{at}: condition on {}", w.key);
                    let choices: Vec<&str> = ty
                        .params()
                        .filter(|q| q.key == w.key)
                        .flat_map(|q| match q.kind {
                            ParamKind::Choice { values } => values.to_vec(),
                            _ => vec![],
                        })
                        .collect();
                    for v in w.any_of {
                        assert!(choices.contains(v), "{at}: condition value {v}");
                    }
                }
                for k in p.excludes {
                    assert!(keys.contains(k), "{at}: excludes {k}");
                }
                let literals = p.default.into_iter().chain([p.start]);
                for lit in literals {
                    let v = toml_value(lit).unwrap_or_else(|e| panic!("{at}: {lit}: {e}"));
                    match (p.kind, &v) {
                        (ParamKind::Choice { values }, toml::Value::String(s)) => {
                            assert!(values.contains(&s.as_str()), "{at}: {s}")
                        }
                        (ParamKind::Number { range, .. }, toml::Value::Float(x))
                        | (ParamKind::Spectrum { range }, toml::Value::Float(x))
                        | (ParamKind::Numbers { range, .. }, toml::Value::Float(x)) => {
                            assert!(range.contains(*x), "{at}: {x}")
                        }
                        (ParamKind::Integer { min, max }, toml::Value::Integer(n)) => {
                            assert!((min as i64..=max as i64).contains(n), "{at}: {n}")
                        }
                        (ParamKind::Path, toml::Value::String(_))
                        | (ParamKind::Spectrum { .. }, toml::Value::Array(_))
                        | (ParamKind::Numbers { .. }, toml::Value::Array(_)) => {}
                        (k, v) => panic!("{at}: {v} is not a {k:?}"),
                    }
                }
            }
        }
    }

    #[test]
    fn ranges_are_the_ones_the_grammar_enforces() {
        let mut probes = 0;
        for ty in MATERIAL_SCHEMA {
            for p in ty.params() {
                let at = format!("{}.{}", ty.name, p.key);
                let ctx = context(ty, p);
                // Entries of one key must not shadow each other: where this one's
                // conditions hold, the entry that applies says the same.
                let applying = ty.applying(p.key, |k| ty.value_of(&ctx, k)).unwrap();
                assert!(
                    (applying.kind, applying.default) == (p.kind, p.default),
                    "{at}: another entry applies where this one's conditions hold"
                );
                let (inside, outside): (Vec<toml::Value>, Vec<toml::Value>) = match p.kind {
                    ParamKind::Number { range, .. }
                    | ParamKind::Spectrum { range }
                    | ParamKind::Numbers { range, .. } => {
                        let tiny = |x: f64| (x.abs() * 1e-9).max(1e-12);
                        let lo_in = if range.lo_closed() {
                            range.lo
                        } else {
                            range.lo + tiny(range.lo)
                        };
                        let hi_in = if range.hi_closed() {
                            range.hi
                        } else {
                            range.hi - tiny(range.hi)
                        };
                        // An open infinite end: the largest finite numbers are inside.
                        let lo_in = if lo_in.is_nan() { -f64::MAX } else { lo_in };
                        let hi_in = if hi_in.is_nan() { f64::MAX } else { hi_in };
                        let lo_out = if range.lo_closed() {
                            range.lo - tiny(range.lo)
                        } else {
                            range.lo
                        };
                        let hi_out = if range.hi_closed() {
                            range.hi + tiny(range.hi)
                        } else {
                            range.hi
                        };
                        let mid = if range == Range::FINITE {
                            0.0
                        } else if range.lo > 0.0 && range.hi / range.lo > 1e3 {
                            (range.lo * range.hi).sqrt()
                        } else {
                            0.5 * (range.lo + range.hi)
                        };
                        let ends = !cross_constrained(ty, p);
                        let inside: Vec<f64> = if ends {
                            vec![lo_in, mid, hi_in]
                        } else {
                            vec![mid]
                        };
                        (
                            inside.into_iter().map(toml::Value::Float).collect(),
                            [lo_out, hi_out, f64::NAN]
                                .into_iter()
                                .map(toml::Value::Float)
                                .collect(),
                        )
                    }
                    ParamKind::Integer { min, max } => {
                        let mut out = vec![toml::Value::Float(0.5 + min as f64)];
                        if min > 0 {
                            out.push(toml::Value::Integer(min as i64 - 1));
                        }
                        if max < i64::MAX as u64 {
                            out.push(toml::Value::Integer(max as i64 + 1));
                        }
                        (vec![toml::Value::Integer(min as i64)], out)
                    }
                    _ => continue,
                };
                for v in inside {
                    let ctx = context_with(ty, p, Some(v.clone()));
                    parse(&ctx).unwrap_or_else(|e| panic!("{at} = {v} in {ctx}: refused: {e}"));
                    probes += 1;
                }
                for v in outside {
                    let ctx = context_with(ty, p, Some(v.clone()));
                    let e = parse(&ctx)
                        .err()
                        .unwrap_or_else(|| panic!("{at} = {v} in {ctx}: accepted"));
                    assert!(names(&e.to_string(), p.key), "{at} = {v}: {e}");
                    probes += 1;
                }
            }
        }
        assert!(probes > 150, "{probes}");
    }

    #[test]
    fn choices_are_accepted_and_others_refused() {
        for ty in MATERIAL_SCHEMA {
            for p in ty.params() {
                let ParamKind::Choice { values } = p.kind else {
                    continue;
                };
                let at = format!("{}.{}", ty.name, p.key);
                for v in values {
                    // A body table needs a file written by `facette tabulate`.
                    if (ty.name, p.key, *v) == ("il", "evaluation", "table") {
                        continue;
                    }
                    let t = context_with(ty, p, Some(toml::Value::String(v.to_string())));
                    // Files (a normal map) are the readers' tests.
                    if ty
                        .params()
                        .any(|q| q.kind == ParamKind::Path && t.contains_key(q.key))
                    {
                        continue;
                    }
                    parse(&t).unwrap_or_else(|e| panic!("{at} = {v} in {t}: refused: {e}"));
                }
                let e = parse(&with(
                    &context(ty, p),
                    p.key,
                    toml::Value::String("zzz".into()),
                ))
                .unwrap_err()
                .to_string();
                assert!(e.contains("zzz"), "{at}: {e}");
            }
        }
    }

    /// (type, key, why): defaults that hold for what the key chooses but not for
    /// everything: the grammar reads the key's absence as more than its default.
    const DEFAULT_EXCEPTIONS: &[(&str, &str, &str)] = &[(
        "oren-nayar",
        "evaluation",
        "with none of evaluation, tolerance, samples: 256 microfacets; `evaluation = \"quadrature\"` alone: adaptive to 1e-6",
    )];

    #[test]
    fn defaults_build_what_leaving_the_key_out_builds() {
        for ty in MATERIAL_SCHEMA {
            for p in ty.params() {
                let Some(d) = p.default else { continue };
                if DEFAULT_EXCEPTIONS
                    .iter()
                    .any(|x| (x.0, x.1) == (ty.name, p.key))
                {
                    continue;
                }
                let at = format!("{}.{}", ty.name, p.key);
                let ctx = context(ty, p);
                let absent = parse(&ctx).unwrap_or_else(|e| panic!("{at} absent in {ctx}: {e}"));
                let given = parse(&with(&ctx, p.key, toml_value(d).unwrap()))
                    .unwrap_or_else(|e| panic!("{at} = {d}: {e}"));
                let (a, g) = (fingerprint(&absent), fingerprint(&given));
                if a != g {
                    let i = a.bytes().zip(g.bytes()).take_while(|(x, y)| x == y).count();
                    let near = |s: &str| s[i.saturating_sub(80)..(i + 80).min(s.len())].to_string();
                    panic!(
                        "{at} = {d} builds another recipe: …{}… vs …{}…",
                        near(&a),
                        near(&g)
                    );
                }
            }
        }
    }

    #[test]
    fn required_keys_are_required() {
        for ty in MATERIAL_SCHEMA {
            for p in ty.params().filter(|p| p.required) {
                let at = format!("{}.{}", ty.name, p.key);
                let mut ctx = context(ty, p);
                ctx.remove(p.key);
                let e = parse(&ctx)
                    .err()
                    .unwrap_or_else(|| panic!("{at}: {ctx} accepted"));
                assert!(names(&e.to_string(), p.key), "{at}: {e}");
            }
        }
    }

    #[test]
    fn aliases_name_the_same_types() {
        for (alias, name) in TYPE_ALIASES {
            assert_eq!(canonical_type(alias), Some(*name));
            let ty = material_type(name).unwrap();
            let t = example(ty);
            let aliased = with(&t, "type", toml::Value::String(alias.to_string()));
            assert_eq!(
                fingerprint(&parse(&t).unwrap()),
                fingerprint(&parse(&aliased).unwrap())
            );
        }
        assert_eq!(canonical_type("plastic"), None);
    }

    #[test]
    fn a_choice_the_new_entry_does_not_offer_is_dropped() {
        let ty = material_type("conductor").unwrap();
        let mut t = parse_inline_table(
            r#"{type = "conductor", distribution = "phong", alpha = 0.2, g1 = "exact", masking = "smith"}"#,
        )
        .unwrap();
        ty.retain_applicable(&mut t);
        assert!(!t.contains_key("g1"), "{t}");
        assert!(t.contains_key("masking"));
        t.insert(
            "distribution".into(),
            toml::Value::String("gaussian".into()),
        );
        ty.retain_applicable(&mut t);
        ty.fill_required(&mut t);
        assert!(!t.contains_key("masking") && t.contains_key("sigma"), "{t}");
        parse(&t).unwrap();
    }

    /// Combinations the schema does not yet describe (the grammar refuses them with its own
    /// message, which the explorer shows): IL's closed-form body is fitted for one domain
    /// (Beckmann, Smith or V-cavity masking, a range of n_i; docs/materials.md, `il`).
    const COMBINATIONS_NOT_DESCRIBED: &[(&str, &str, &str)] = &[("il", "evaluation", "approx")];

    /// Every choice's value together with every other key that then applies (a choice at
    /// each of its values, anything else at its start value): the combinations an editor
    /// offers are ones the grammar takes.
    #[test]
    fn what_applies_together_parses_together() {
        let mut tried = 0;
        for ty in MATERIAL_SCHEMA {
            for p in ty.params() {
                let ParamKind::Choice { values } = p.kind else {
                    continue;
                };
                for v in values {
                    if (ty.name, p.key, *v) == ("il", "evaluation", "table") {
                        continue;
                    }
                    let base = context_with(ty, p, Some(toml::Value::String(v.to_string())));
                    let undescribed = |t: &toml::Table| {
                        COMBINATIONS_NOT_DESCRIBED.iter().any(|(n, k, w)| {
                            *n == ty.name && t.get(*k).and_then(|x| x.as_str()) == Some(*w)
                        })
                    };
                    for q in ty.params() {
                        // Exclusion goes both ways (`preset` excludes `alpha`).
                        let excluded = ty
                            .params()
                            .any(|r| r.excludes.contains(&q.key) && base.contains_key(r.key));
                        if base.contains_key(q.key)
                            || excluded
                            || q.kind == ParamKind::Path
                            || !q.applies(|k| ty.value_of(&base, k))
                            || ty.applying(q.key, |k| ty.value_of(&base, k)) != Some(q)
                        {
                            continue;
                        }
                        // A choice at each of its values, anything else at its start.
                        let starts: Vec<toml::Value> = match q.kind {
                            ParamKind::Choice { values } => values
                                .iter()
                                .filter(|w| (ty.name, q.key, **w) != ("il", "evaluation", "table"))
                                .map(|w| toml::Value::String(w.to_string()))
                                .collect(),
                            _ => vec![toml_value(q.start).unwrap()],
                        };
                        for start in starts {
                            let mut t = base.clone();
                            for k in q.excludes {
                                t.remove(*k);
                            }
                            t.insert(q.key.into(), start.clone());
                            ty.retain_applicable(&mut t);
                            ty.fill_required(&mut t);
                            if !t.contains_key(q.key)
                                || undescribed(&t)
                                || ty
                                    .params()
                                    .any(|r| r.kind == ParamKind::Path && t.contains_key(r.key))
                            {
                                continue;
                            }
                            parse(&t).unwrap_or_else(|e| {
                                panic!(
                                    "{}: {} = {v} with {} = {start}: {e}\n{t}",
                                    ty.name, p.key, q.key
                                )
                            });
                            tried += 1;
                        }
                    }
                }
            }
        }
        assert!(tried > 200, "{tried}");
    }

    #[test]
    fn docs_describe_every_key() {
        let docs = include_str!("../../../../docs/materials.md");
        for ty in MATERIAL_SCHEMA {
            let head = format!("### `{}`", ty.name);
            let start = docs
                .find(&head)
                .unwrap_or_else(|| panic!("no section {head}"));
            let rest = &docs[start + head.len()..];
            let section = &rest[..rest.find("\n### ").unwrap_or(rest.len())];
            for k in ty.keys() {
                let shared = [ANY_DISTRIBUTION, ALPHA_KEYS, SIGMA_KEY, PHONG_KEYS, G1_KEYS]
                    .iter()
                    .flat_map(|g| g.iter())
                    .any(|p| p.key == k)
                    && section.contains("microfacet keys");
                // A section shared by several types names them in its heading.
                let common = docs.split("\n### ").any(|sec| {
                    let heading = sec.lines().next().unwrap_or("");
                    (heading.contains(&format!("{})", ty.name))
                        || heading.contains(&format!("({},", ty.name)))
                        && sec.contains(&format!("`{k}`"))
                });
                assert!(
                    shared || common || section.contains(&format!("`{k}`")),
                    "docs/materials.md, {head}: `{k}` missing"
                );
            }
        }
    }
}
