//! Table and table-part files whose header lies (issue 17): every header field is checked
//! when loaded — a NaN or zero step, a grid that does not match its step, a NaN index, an
//! absurd part count — and a table is never saved unless its own loader accepts it.

use facette_bsdf::microfacet::specular_lobe::{NormalSampling, SpecularLobe};
use facette_bsdf::microfacet::{Beckmann, Masking, Ndf};
use facette_bsdf::models::il::il_table::BodyTable;
use facette_bsdf::models::il::il_table_part::{merge_table_parts, TablePart};
use facette_bsdf::storage::framed::Framed;

const TABLE: Framed = Framed {
    magic: b"FCTBODY1",
    version: 2,
    legacy_version: Some(1),
    what: "facette IL body table",
};
const PART: Framed = Framed {
    magic: b"FCTPART1",
    version: 2,
    legacy_version: Some(1),
    what: "facette IL table part",
};

fn lobe() -> SpecularLobe {
    SpecularLobe::new(
        Ndf::Beckmann(Beckmann::new(0.4, 0.4).unwrap()),
        Masking::SmithSeparable,
        NormalSampling::Visible,
    )
    .unwrap()
}

/// The file `bytes` (framed by `frame`) with its TOML header line `key = …` replaced by
/// `line`, reframed with a valid checksum (a corrupt file that the CRC cannot catch).
fn with_header_line(frame: &Framed, bytes: &[u8], key: &str, line: &str) -> Vec<u8> {
    let payload = frame.unframe(bytes).unwrap().payload;
    let hlen = u32::from_le_bytes(payload[..4].try_into().unwrap()) as usize;
    let header = std::str::from_utf8(&payload[4..4 + hlen]).unwrap();
    let edited: String = header
        .lines()
        .map(|l| {
            if l.starts_with(&format!("{key} =")) {
                format!("{line}\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let mut out = (edited.len() as u32).to_le_bytes().to_vec();
    out.extend_from_slice(edited.as_bytes());
    out.extend_from_slice(&payload[4 + hlen..]);
    frame.frame(&out)
}

#[test]
fn table_headers_are_validated_field_by_field() {
    let t = BodyTable::build(&lobe(), 1.3, 30.0, 16, &|_, _| {}).unwrap();
    let bytes = t.to_bytes();
    assert!(BodyTable::from_bytes(&bytes, "t.fctab").is_ok());
    for (key, line, expect) in [
        ("step_deg", "step_deg = 0", "step"),
        ("step_deg", "step_deg = nan", "step"),
        ("step_deg", "step_deg = 15", "does not match step_deg"),
        ("ni", "ni = nan", "`ni`"),
        ("ni", "ni = 0.5", "`ni`"),
        ("n_theta", "n_theta = 3.5", "n_theta"),
        ("samples", "samples = -3", "samples"),
        ("max_stderr", "max_stderr = inf", "max_stderr"),
    ] {
        let bad = with_header_line(&TABLE, &bytes, key, line);
        let e = BodyTable::from_bytes(&bad, "t.fctab")
            .expect_err(line)
            .to_string();
        assert!(e.contains("t.fctab") && e.contains(expect), "{line}: {e}");
    }
}

#[test]
fn part_headers_are_validated_and_merge_never_sizes_from_a_corrupt_count() {
    let parts: Vec<TablePart> = (0..2)
        .map(|k| TablePart::build(&lobe(), 1.3, 30.0, 16, k, 2, &|_, _| {}).unwrap())
        .collect();
    let bytes = parts[0].to_bytes();
    assert!(TablePart::from_bytes(&bytes, "p.fctpart").is_ok());
    for (key, line, expect) in [
        ("parts", "parts = 4000000000", "parts of a distributed job"),
        ("parts", "parts = 0", "part 0 of 0"),
        ("step_deg", "step_deg = nan", "step"),
        ("n_phi", "n_phi = 100000", "does not match"),
    ] {
        let bad = with_header_line(&PART, &bytes, key, line);
        let e = TablePart::from_bytes(&bad, "p.fctpart")
            .expect_err(line)
            .to_string();
        assert!(e.contains(expect), "{line}: {e}");
    }
    // A negative entry (finite, CRC-valid) is refused by the part loader: merged, it would
    // make a table its own loader refuses (found by the fuzzer, fctpart seed 23 case 690).
    let mut payload = PART.unframe(&bytes).unwrap().payload.to_vec();
    let hlen = u32::from_le_bytes(payload[..4].try_into().unwrap()) as usize;
    let first_value = 4 + hlen + 4 + 8 + 8;
    payload[first_value..first_value + 8].copy_from_slice(&(-0.5f64).to_le_bytes());
    let e = TablePart::from_bytes(&PART.frame(&payload), "p.fctpart")
        .unwrap_err()
        .to_string();
    assert!(e.contains("negative"), "{e}");
    // Merged, the parts make a table its loader accepts.
    let table = merge_table_parts(&parts).unwrap();
    assert!(BodyTable::from_bytes(&table.to_bytes(), "m.fctab").is_ok());
}
