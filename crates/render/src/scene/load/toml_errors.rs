//! serde's messages for a scene that does not fit the description types name Rust types
//! (`expected usize`, `expected struct FilmDesc`, `untagged enum ColorDesc`). They are
//! rewritten here into the scene format's words: the key as written, the expected shape
//! (a whole number, a number, a table, a colour …) and what was found.

use std::ops::Range;

/// The message for a TOML deserialization error `message` at `span` of `source`.
pub(super) fn rewrite(message: &str, source: &str, span: Option<Range<usize>>) -> String {
    let key = span.and_then(|s| key_at(source, s.start));
    let prefix = key.map(|k| format!("`{k}`: ")).unwrap_or_default();
    let m = message.trim();
    if let Some(rest) = m.strip_prefix("invalid type: ") {
        if let Some((got, expected)) = rest.split_once(", expected ") {
            return format!("{prefix}expected {}, got {}", shape(expected), got);
        }
    }
    if let Some(rest) = m.strip_prefix("invalid value: ") {
        if let Some((got, expected)) = rest.split_once(", expected ") {
            return format!("{prefix}expected {}, got {}", shape(expected), got);
        }
    }
    if let Some(rest) = m.strip_prefix("invalid length ") {
        if let Some((got, expected)) = rest.split_once(", expected ") {
            return format!("{prefix}expected {expected}, got {got} values");
        }
    }
    if let Some(name) = m.strip_prefix("data did not match any variant of untagged enum ") {
        return format!("{prefix}expected {}", shape(&format!("enum {name}")));
    }
    if let Some(rest) = m.strip_prefix("unknown field ") {
        if let Some((field, valid)) = rest.split_once(", expected ") {
            let valid = valid.trim_start_matches("one of ");
            return format!("unknown key {field}; valid keys: {valid}");
        }
        return format!("unknown key {rest}");
    }
    if let Some(field) = m.strip_prefix("missing field ") {
        return format!("missing key {field}");
    }
    format!("{prefix}{}", shape_words(m))
}

/// The key of the `key = value` line holding byte `at` (or of the array of tables that
/// starts there), as written.
fn key_at(source: &str, at: usize) -> Option<String> {
    let at = at.min(source.len());
    let start = source[..at].rfind('\n').map_or(0, |i| i + 1);
    let end = source[at..].find('\n').map_or(source.len(), |i| at + i);
    let line = &source[start..end];
    let upto = &source[start..at];
    if let Some(eq) = upto.rfind('=') {
        // The last key before the value (inline tables: `{ a = 1, b = "x" }`).
        let k = upto[..eq].trim_end();
        let k = k
            .rsplit(|c: char| c == '{' || c == ',' || c.is_whitespace())
            .next()
            .unwrap_or(k);
        return (!k.is_empty()).then(|| k.trim_matches('"').to_string());
    }
    let t = line.trim();
    if t.starts_with('[') {
        return Some(t.trim_matches(|c| c == '[' || c == ']').trim().to_string());
    }
    None
}

/// An expected shape in the scene format's words.
fn shape(expected: &str) -> String {
    let e = expected.trim();
    match e {
        "usize" | "u8" | "u16" | "u32" | "u64" => return "a whole number ≥ 0".into(),
        "isize" | "i8" | "i16" | "i32" | "i64" => return "a whole number".into(),
        "f32" | "f64" => return "a number".into(),
        "a sequence" => return "an array".into(),
        "a map" => return "a table".into(),
        _ => {}
    }
    if let Some(name) = e.strip_prefix("enum ") {
        return match name {
            "ColorDesc" => "a colour: a number (grey) or [r, g, b]".into(),
            "MaterialRef" => {
                "a material: the name of an entry of [materials], or an inline table".into()
            }
            _ => "one of the documented values".into(),
        };
    }
    if e.starts_with("struct ") {
        return "a table".into();
    }
    shape_words(e)
}

/// Any Rust type name left in a message, in words.
fn shape_words(m: &str) -> String {
    let mut out = m.to_string();
    for (from, to) in [
        ("expected usize", "expected a whole number ≥ 0"),
        ("expected u32", "expected a whole number ≥ 0"),
        ("expected u64", "expected a whole number ≥ 0"),
        ("expected f64", "expected a number"),
        ("a sequence", "an array"),
    ] {
        out = out.replace(from, to);
    }
    // `struct FooDesc` → `a table`.
    while let Some(i) = out.find("struct ") {
        let end = out[i + 7..]
            .find(|c: char| !c.is_alphanumeric() && c != '_')
            .map_or(out.len(), |j| i + 7 + j);
        out.replace_range(i..end, "a table");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(source: &str, needle: &str) -> Option<Range<usize>> {
        let i = source.find(needle).unwrap();
        Some(i..i + needle.len())
    }

    #[test]
    fn type_errors_name_the_key_and_the_shape_in_the_format_words() {
        let src = "[film]\nwidth = \"a\"\n";
        let m = rewrite(
            "invalid type: string \"a\", expected usize",
            src,
            at(src, "\"a\""),
        );
        assert_eq!(m, "`width`: expected a whole number ≥ 0, got string \"a\"");
        let src = "[[lights]]\ntype = \"constant\"\nradiance = \"red\"\n";
        let m = rewrite(
            "data did not match any variant of untagged enum ColorDesc",
            src,
            at(src, "\"red\""),
        );
        assert_eq!(
            m,
            "`radiance`: expected a colour: a number (grey) or [r, g, b]"
        );
        let src = "film = 3\n";
        let m = rewrite(
            "invalid type: integer `3`, expected struct FilmDesc",
            src,
            at(src, "3"),
        );
        assert_eq!(m, "`film`: expected a table, got integer `3`");
        for m in [
            rewrite("unknown field `x`, expected one of `a`, `b`", "", None),
            rewrite("missing field `position`", "", None),
        ] {
            assert!(!m.contains("field") && m.contains("key"), "{m}");
        }
    }
}
