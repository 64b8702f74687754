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

// IL's grid is the dearest (Monte Carlo and quadrature bodies, multiple-scattering orders):
// split in four so the test threads share it rather than one thread waiting on it alone.
fn il_suite(select: impl Fn(&str) -> bool) {
    assert_report(&material_suite_matching(
        &opts(),
        |m| m.contains("\"il\"") && select(m),
        None,
    ));
}

fn il_flat(m: &str) -> bool {
    m.contains("alpha = 0}")
}

fn il_quadrature(m: &str) -> bool {
    m.contains("evaluation = \"quadrature\"")
}

fn il_orders(m: &str) -> bool {
    m.contains("scattering = ")
}

fn il_stochastic(m: &str) -> bool {
    !il_flat(m) && !il_quadrature(m) && !il_orders(m)
}

#[test]
fn interfaced_lambertian_flat() {
    il_suite(il_flat);
}

#[test]
fn interfaced_lambertian_rough_quadrature() {
    il_suite(il_quadrature);
}

#[test]
fn interfaced_lambertian_multiple_scattering_orders() {
    il_suite(il_orders);
}

#[test]
fn interfaced_lambertian_rough_stochastic() {
    il_suite(il_stochastic);
}

#[test]
fn the_four_interfaced_lambertian_tests_cover_its_grid_once() {
    use facette_bsdf::validation::suites::material_grid;
    let il: Vec<&str> = material_grid()
        .into_iter()
        .filter(|m| m.contains("\"il\""))
        .collect();
    let parts: [fn(&str) -> bool; 4] = [il_flat, il_quadrature, il_orders, il_stochastic];
    for m in &il {
        let n = parts.iter().filter(|p| p(m)).count();
        assert_eq!(n, 1, "{m} is in {n} of the four IL tests");
    }
    for (k, p) in parts.iter().enumerate() {
        assert!(il.iter().any(|m| p(m)), "IL part {k} selects nothing");
    }
}
