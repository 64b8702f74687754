//! The reference-BSDF suite (issue: reference BSDFs): chi-square, consistency, reciprocity,
//! albedo and NaN sweeps for every model over its grid. Fixed seeds; `cargo test --profile optimized-tests`.

use facette_bsdf::validation::suites::{
    is_energy_option, material_suite, material_suite_matching, SuiteOptions,
};
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

// The energy options (multiple scattering, compensation) are checked in
// tests/multiple_scattering.rs.
#[test]
fn conductors() {
    assert_report(&material_suite_matching(
        &opts(),
        |m| m.contains("conductor") && !is_energy_option(m),
        None,
    ));
}

#[test]
fn dielectrics() {
    assert_report(&material_suite_matching(
        &opts(),
        |m| m.contains("dielectric") && !is_energy_option(m),
        None,
    ));
}

#[test]
fn kelemen() {
    assert_report(&material_suite(&opts(), Some("kelemen")));
}

#[test]
fn interfaced_lambertian() {
    assert_report(&material_suite(&opts(), Some("\"il\"")));
}
