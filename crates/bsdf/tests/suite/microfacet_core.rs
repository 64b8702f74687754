//! The microfacet-core suite (issue: microfacet core): every distribution at roughness
//! 0.01–1.5 and incidence up to 89°, masking and Fresnel. Fixed seeds; run with
//! `cargo test --profile optimized-tests`.

use facette_bsdf::validation::suites::{
    core_suite, distribution_suite, fresnel_checks, masking_checks, Family, SuiteOptions,
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

#[test]
fn beckmann_family() {
    assert_report(&distribution_suite(
        Family::Beckmann,
        &SuiteOptions::default(),
    ));
}

#[test]
fn ggx_family() {
    assert_report(&distribution_suite(Family::Ggx, &SuiteOptions::default()));
}

#[test]
fn gaussian_family() {
    assert_report(&distribution_suite(
        Family::Gaussian,
        &SuiteOptions::default(),
    ));
}

#[test]
fn phong_family() {
    assert_report(&distribution_suite(Family::Phong, &SuiteOptions::default()));
}

#[test]
fn masking_and_fresnel() {
    let mut r = Report::new();
    r.extend(masking_checks(7));
    r.extend(fresnel_checks());
    assert_report(&r);
}

#[test]
fn a_broken_sampler_is_caught_by_the_suite_machinery() {
    // Sanity of the harness itself: a suite over a single family reports chi-square tests.
    let r = core_suite(
        &SuiteOptions {
            chi2_samples: 20_000,
            seed: 1,
        },
        Some(Family::Ggx),
    );
    assert!(r.chi2_count() >= 7 * 6);
}
