//! Parts of an IL body table for distributed tabulation: part K of N computes the θ_i rows
//! with index ≡ K (mod N) (interleaved, so parts cost about the same: rows near θ_i = 0
//! hold more entries); [`merge_table_parts`] assembles the N parts into exactly the table
//! [`BodyTable::build`] makes (every entry uses the same shared microfacet set wherever it
//! is computed).
//!
//! ## File format (`.fctpart`, version 2, little-endian)
//!
//! A framed file (`crate::storage::framed`: magic `FCTPART1`, u32 format version 2, u64
//! payload length, payload, CRC-32); version 1 files (the same payload, unframed) are
//! still read. The payload:
//!
//! | bytes | content |
//! |---|---|
//! | 4 | u32 length L of the header |
//! | L | UTF-8 TOML header: `model = "il-body-part"`, `ni`, `distribution`, `masking`, `step_deg`, `n_theta`, `n_phi`, `samples` (0 for adaptive entries), `tolerance` (adaptive entries only), `part`, `parts` |
//! | 4 | u32 number of rows R |
//! | R × (8 + E·24) | per row: u32 θ_i index, u32 entry count E, then E × (u32 θ_o index, u32 φ index, f64 value, f64 standard error or error estimate) |

use super::il_table::{compute_rows, tolerance_line, BodyTable, TableError, TableGrid, TableRow};
use crate::error::ParamResult;
use crate::limits;
use crate::microfacet::integral::TableEntries;
use crate::microfacet::specular_lobe::SpecularLobe;
use std::path::Path;

use crate::storage::atomic_file::write_atomically;
use crate::storage::framed::Framed;

const FRAME: Framed = Framed {
    magic: b"FCTPART1",
    version: 2,
    legacy_version: Some(1),
    what: "facette IL table part",
};

/// One part of a table.
#[derive(Clone, Debug, PartialEq)]
pub struct TablePart {
    pub part: u32,
    pub parts: u32,
    grid: TableGrid,
    rows: Vec<TableRow>,
}

impl TablePart {
    /// Computes part `part` of `parts` (see the module documentation); the arguments are
    /// those of [`BodyTable::build`].
    pub fn build(
        lobe: &SpecularLobe,
        ni: f64,
        step_deg: f64,
        samples: usize,
        part: u32,
        parts: u32,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> ParamResult<TablePart> {
        Self::build_with(
            lobe,
            ni,
            step_deg,
            TableEntries::Samples(samples),
            part,
            parts,
            progress,
        )
    }

    /// [`TablePart::build`] with sampled or adaptive entries (see [`BodyTable::build_with`]).
    pub fn build_with(
        lobe: &SpecularLobe,
        ni: f64,
        step_deg: f64,
        entries: TableEntries,
        part: u32,
        parts: u32,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> ParamResult<TablePart> {
        if parts == 0 || part >= parts {
            return Err(crate::error::ParamError::Invalid(format!(
                "part {part}/{parts}: need 0 ≤ K < N"
            )));
        }
        let keep = move |t: usize| t % parts as usize == part as usize;
        let (grid, rows) = compute_rows(lobe, ni, step_deg, entries, &keep, progress)?;
        Ok(TablePart {
            part,
            parts,
            grid,
            rows,
        })
    }

    /// Number of θ_i rows this part holds.
    pub fn row_count(&self) -> usize {
        self.rows.len()
    }

    fn header(&self) -> String {
        let g = &self.grid;
        format!(
            "model = \"il-body-part\"\nni = {}\ndistribution = \"{}\"\nmasking = \"{}\"\nstep_deg = {}\nn_theta = {}\nn_phi = {}\nsamples = {}\n{}part = {}\nparts = {}\n",
            g.ni, g.distribution, g.masking, g.step_deg, g.n_theta, g.n_phi, g.samples, tolerance_line(g.tolerance), self.part, self.parts
        )
    }

    pub fn to_bytes(&self) -> Vec<u8> {
        let header = self.header();
        let mut out = Vec::new();
        out.extend_from_slice(&(header.len() as u32).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        out.extend_from_slice(&(self.rows.len() as u32).to_le_bytes());
        for r in &self.rows {
            out.extend_from_slice(&(r.theta_i as u32).to_le_bytes());
            out.extend_from_slice(&(r.entries.len() as u32).to_le_bytes());
            for &(to, ph, v, se) in &r.entries {
                out.extend_from_slice(&(to as u32).to_le_bytes());
                out.extend_from_slice(&(ph as u32).to_le_bytes());
                out.extend_from_slice(&v.to_le_bytes());
                out.extend_from_slice(&se.to_le_bytes());
            }
        }
        FRAME.frame(&out)
    }

    /// Parses a part; `path` names it in errors.
    pub fn from_bytes(bytes: &[u8], path: &str) -> Result<TablePart, TableError> {
        let bad = |reason: String| TableError::Invalid {
            path: path.to_string(),
            reason,
        };
        let body = FRAME
            .unframe(bytes)
            .map_err(|e| bad(e.to_string()))?
            .payload;
        let mut at = 0;
        let mut take = |n: usize| -> Result<&[u8], TableError> {
            let s = body
                .get(at..at + n)
                .ok_or_else(|| bad("truncated contents".into()))?;
            at += n;
            Ok(s)
        };
        let u32_ = |s: &[u8]| u32::from_le_bytes(s.try_into().expect("4 bytes"));
        let hlen = u32_(take(4)?) as usize;
        let header =
            std::str::from_utf8(take(hlen)?).map_err(|_| bad("the header is not UTF-8".into()))?;
        let h: toml::Table =
            toml::from_str(header).map_err(|e| bad(format!("bad header: {}", e.message())))?;
        let num = |k: &str| -> Result<f64, TableError> {
            match h.get(k) {
                Some(toml::Value::Float(f)) => Ok(*f),
                Some(toml::Value::Integer(i)) => Ok(*i as f64),
                _ => Err(bad(format!("header lacks `{k}`"))),
            }
        };
        let text = |k: &str| -> Result<String, TableError> {
            h.get(k)
                .and_then(|v| v.as_str())
                .map(str::to_string)
                .ok_or_else(|| bad(format!("header lacks `{k}`")))
        };
        if text("model")? != "il-body-part" {
            return Err(bad("not an IL body table part".into()));
        }
        // Counts are whole numbers in the header; a float or a negative number is refused
        // rather than truncated.
        let count = |k: &str| -> Result<u64, TableError> {
            match h.get(k) {
                Some(toml::Value::Integer(i)) if *i >= 0 => Ok(*i as u64),
                _ => Err(bad(format!("header: `{k}` must be a whole number ≥ 0"))),
            }
        };
        let grid = TableGrid {
            ni: num("ni")?,
            distribution: text("distribution")?,
            masking: text("masking")?,
            step_deg: num("step_deg")?,
            n_theta: count("n_theta")? as usize,
            n_phi: count("n_phi")? as usize,
            samples: count("samples")? as usize,
            tolerance: match h.get("tolerance") {
                None => None,
                Some(toml::Value::Float(t)) => Some(*t),
                Some(_) => return Err(bad("header: `tolerance` must be a number".into())),
            },
        };
        grid.validate().map_err(|m| bad(format!("header: {m}")))?;
        let (part, parts) = (count("part")?, count("parts")?);
        if parts == 0 || part >= parts {
            return Err(bad(format!(
                "header: part {part} of {parts}: need 0 ≤ part < parts"
            )));
        }
        limits::PARTS
            .check(parts)
            .map_err(|e| bad(format!("header: {e}")))?;
        let (part, parts) = (part as u32, parts as u32);
        let n_rows = u32_(take(4)?) as usize;
        let mut rows = Vec::with_capacity(n_rows.min(grid.n_theta));
        for _ in 0..n_rows {
            let theta_i = u32_(take(4)?) as usize;
            let n = u32_(take(4)?) as usize;
            if theta_i >= grid.n_theta || n > (grid.n_theta - theta_i) * grid.n_phi {
                return Err(bad(format!("row {theta_i} is outside the grid")));
            }
            let mut entries = Vec::with_capacity(n);
            for _ in 0..n {
                let to = u32_(take(4)?) as usize;
                let ph = u32_(take(4)?) as usize;
                let v = f64::from_le_bytes(take(8)?.try_into().expect("8 bytes"));
                let se = f64::from_le_bytes(take(8)?.try_into().expect("8 bytes"));
                // The table's own loader refuses negative values: a part that holds one
                // would merge into a table that cannot be read back (found by the fuzzer).
                let valid = |x: f64| x.is_finite() && x >= 0.0;
                if to >= grid.n_theta || ph >= grid.n_phi || !valid(v) || !valid(se) {
                    return Err(bad(format!(
                        "row {theta_i}: an entry is outside the grid, negative or not finite"
                    )));
                }
                entries.push((to, ph, v, se));
            }
            rows.push(TableRow { theta_i, entries });
        }
        if at != body.len() {
            return Err(bad("trailing bytes after the rows".into()));
        }
        Ok(TablePart {
            part,
            parts,
            grid,
            rows,
        })
    }

    pub fn load(path: &Path) -> Result<TablePart, TableError> {
        let p = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| TableError::Io {
            path: p.clone(),
            source: e,
        })?;
        Self::from_bytes(&bytes, &p)
    }

    /// Writes the part atomically (temporary file, then rename).
    pub fn save(&self, path: &Path) -> Result<(), TableError> {
        let bytes = self.to_bytes();
        // Never write a file the loader would refuse.
        Self::from_bytes(&bytes, &path.display().to_string())?;
        write_atomically(path, &bytes).map_err(|e| TableError::Io {
            path: path.display().to_string(),
            source: e,
        })
    }
}

/// Assembles the parts 0…N−1 of one table (any order) into the table; parts of different
/// tables, duplicates and missing parts are errors.
pub fn merge_table_parts(parts: &[TablePart]) -> Result<BodyTable, String> {
    let first = parts.first().ok_or("no parts given")?;
    let n = first.parts;
    // `n` was checked against `limits::PARTS` when the part was loaded.
    let mut seen = vec![None::<usize>; n as usize];
    for (k, p) in parts.iter().enumerate() {
        if p.parts != n {
            return Err(format!(
                "parts come from different jobs: {} parts in the first, {} in part {}",
                n, p.parts, p.part
            ));
        }
        if p.grid != first.grid {
            return Err(format!(
                "part {}/{n} is of another table ({}; the first part is {})",
                p.part,
                p.header().replace('\n', " "),
                first.header().replace('\n', " ")
            ));
        }
        if seen[p.part as usize].replace(k).is_some() {
            return Err(format!("part {}/{n} is given twice", p.part));
        }
    }
    let missing: Vec<String> = (0..n as usize)
        .filter(|&k| seen[k].is_none())
        .map(|k| k.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(format!("missing part(s) {} of {n}", missing.join(", ")));
    }
    let mut rows: Vec<TableRow> = parts.iter().flat_map(|p| p.rows.iter().cloned()).collect();
    rows.sort_by_key(|r| r.theta_i);
    if rows.len() != first.grid.n_theta || rows.iter().enumerate().any(|(k, r)| r.theta_i != k) {
        return Err("the parts do not hold every θ_i row exactly once".into());
    }
    Ok(BodyTable::assemble(first.grid.clone(), rows))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::microfacet::beckmann::Beckmann;
    use crate::microfacet::masking::Masking;
    use crate::microfacet::specular_lobe::NormalSampling;
    use crate::microfacet::Ndf;

    fn lobe() -> SpecularLobe {
        SpecularLobe::new(
            Ndf::Beckmann(Beckmann::new(0.4, 0.4).unwrap()),
            Masking::SmithSeparable,
            NormalSampling::Visible,
        )
        .unwrap()
    }

    #[test]
    fn parts_merge_into_exactly_the_full_table() {
        let l = lobe();
        let full = BodyTable::build(&l, 1.5, 10.0, 64, &|_, _| {}).unwrap();
        let parts: Vec<TablePart> = (0..3)
            .rev()
            .map(|k| {
                let p = TablePart::build(&l, 1.5, 10.0, 64, k, 3, &|_, _| {}).unwrap();
                // Through the file format.
                TablePart::from_bytes(&p.to_bytes(), "part").unwrap()
            })
            .collect();
        let merged = merge_table_parts(&parts).unwrap();
        assert_eq!(merged.to_bytes(), full.to_bytes());
        // Errors: missing, duplicate, foreign parts; corruption.
        assert!(merge_table_parts(&parts[..2])
            .unwrap_err()
            .contains("missing part(s)"));
        let dup = vec![parts[0].clone(), parts[0].clone(), parts[1].clone()];
        assert!(merge_table_parts(&dup).unwrap_err().contains("given twice"));
        let other = TablePart::build(&l, 1.3, 10.0, 64, 1, 3, &|_, _| {}).unwrap();
        let mixed = vec![parts[0].clone(), other, parts[2].clone()];
        assert!(merge_table_parts(&mixed)
            .unwrap_err()
            .contains("another table"));
        let mut bytes = parts[0].to_bytes();
        bytes[40] ^= 1;
        assert!(TablePart::from_bytes(&bytes, "x")
            .unwrap_err()
            .to_string()
            .contains("checksum"));
        assert!(TablePart::from_bytes(&bytes[..30], "x").is_err());
    }
}
