//! The validation harness: the same checks run by the test suite and by `facette validate`.
//!
//! Every check yields a [`Check`] with the measured figure. Chi-square checks carry their
//! p-value and are judged together at the end of a [`Report`] with a significance of 1 %
//! corrected for the number of chi-square tests (Šidák), so adding tests does not inflate
//! the false-failure rate. Seeds are fixed: a report is reproducible bit for bit.

pub mod bsdf_checks;
pub mod chi2;
pub mod distribution_checks;
pub mod estimator_chi2;
pub mod measurements;
pub mod sphere_map;
pub mod suites;

pub use chi2::{chi2_test, chi2_test_region, corrected_significance, Chi2Config, Chi2Outcome};
pub use sphere_map::SphereMap;

/// How a check is judged.
#[derive(Clone, Debug)]
pub enum Verdict {
    Pass,
    Fail,
    /// A chi-square p-value, judged against the report's corrected significance; the flag
    /// records structural failures (samples where pdf = 0, invalid directions).
    Chi2 {
        p_value: f64,
        structural_ok: bool,
    },
    /// A measurement reported without a pass/fail criterion.
    Info,
}

impl Verdict {
    pub fn from_bool(ok: bool) -> Self {
        if ok {
            Verdict::Pass
        } else {
            Verdict::Fail
        }
    }
}

/// One line of a report.
#[derive(Clone, Debug)]
pub struct Check {
    pub subject: String,
    pub name: String,
    pub figure: String,
    pub verdict: Verdict,
}

impl Check {
    pub fn new(
        subject: impl Into<String>,
        name: impl Into<String>,
        figure: impl Into<String>,
        verdict: Verdict,
    ) -> Self {
        Check {
            subject: subject.into(),
            name: name.into(),
            figure: figure.into(),
            verdict,
        }
    }

    pub fn chi2(subject: impl Into<String>, name: impl Into<String>, out: &Chi2Outcome) -> Self {
        Check::new(
            subject,
            name,
            out.summary(),
            Verdict::Chi2 {
                p_value: out.p_value,
                structural_ok: out.zero_pdf_hits == 0 && out.invalid == 0,
            },
        )
    }
}

/// A list of checks judged together.
#[derive(Clone, Debug)]
pub struct Report {
    pub checks: Vec<Check>,
    /// Overall significance for the chi-square family (default 1 %).
    pub alpha: f64,
}

impl Default for Report {
    fn default() -> Self {
        Report {
            checks: Vec::new(),
            alpha: 0.01,
        }
    }
}

impl Report {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn push(&mut self, c: Check) {
        self.checks.push(c);
    }

    pub fn extend(&mut self, cs: impl IntoIterator<Item = Check>) {
        self.checks.extend(cs);
    }

    pub fn chi2_count(&self) -> usize {
        self.checks
            .iter()
            .filter(|c| matches!(c.verdict, Verdict::Chi2 { .. }))
            .count()
    }

    /// Per-test significance after the Šidák correction.
    pub fn significance(&self) -> f64 {
        corrected_significance(self.alpha, self.chi2_count())
    }

    /// `Some(true/false)` for judged checks, `None` for measurements.
    pub fn judge(&self, c: &Check) -> Option<bool> {
        match c.verdict {
            Verdict::Pass => Some(true),
            Verdict::Fail => Some(false),
            Verdict::Chi2 {
                p_value,
                structural_ok,
            } => Some(structural_ok && p_value > self.significance()),
            Verdict::Info => None,
        }
    }

    pub fn passed(&self) -> usize {
        self.checks
            .iter()
            .filter(|c| self.judge(c) == Some(true))
            .count()
    }

    pub fn failed(&self) -> usize {
        self.checks
            .iter()
            .filter(|c| self.judge(c) == Some(false))
            .count()
    }

    pub fn all_passed(&self) -> bool {
        self.failed() == 0
    }

    /// One formatted line per check.
    pub fn lines(&self) -> Vec<String> {
        self.checks
            .iter()
            .map(|c| {
                let tag = match self.judge(c) {
                    Some(true) => "PASS",
                    Some(false) => "FAIL",
                    None => "INFO",
                };
                format!("[{tag}] {}: {}: {}", c.subject, c.name, c.figure)
            })
            .collect()
    }

    /// The closing line, `N passed, M failed`.
    pub fn summary_line(&self) -> String {
        format!(
            "{} passed, {} failed ({} chi-square tests at per-test significance {:.2e})",
            self.passed(),
            self.failed(),
            self.chi2_count(),
            self.significance()
        )
    }

    /// The failing lines (for test assertions).
    pub fn failures(&self) -> Vec<String> {
        self.lines()
            .into_iter()
            .filter(|l| l.starts_with("[FAIL]"))
            .collect()
    }
}

/// Relative error |a − b| / |b| (absolute when b = 0).
pub fn rel_err(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        a.abs()
    } else {
        ((a - b) / b).abs()
    }
}
