//! The reference-BSDF suite (issue: reference BSDFs): chi-square, consistency, reciprocity,
//! albedo and NaN sweeps for every model over its grid. Fixed seeds; `cargo test --release`.

use facette_bsdf::validation::suites::{material_suite, SuiteOptions};
use facette_bsdf::validation::Report;

fn assert_report(r: &Report) {
    for l in r.lines() {
        println!("{l}");
    }
    println!("{}", r.summary_line());
    assert!(r.all_passed(), "failures:\n{}", r.failures().join("\n"));
    assert!(r.passed() > 0);
}

fn opts() -> SuiteOptions {
    SuiteOptions {
        chi2_samples: 400_000,
        seed: 7,
    }
}

#[test]
fn lambert_and_oren_nayar() {
    let mut r = material_suite(&opts(), Some("lambert"));
    r.extend(material_suite(&opts(), Some("oren-nayar")).checks);
    assert_report(&r);
}

#[test]
fn conductors() {
    assert_report(&material_suite(&opts(), Some("conductor")));
}

#[test]
fn dielectrics() {
    assert_report(&material_suite(&opts(), Some("dielectric")));
}

#[test]
fn kelemen() {
    assert_report(&material_suite(&opts(), Some("kelemen")));
}

#[test]
fn interfaced_lambertian() {
    assert_report(&material_suite(&opts(), Some("\"il\"")));
}
