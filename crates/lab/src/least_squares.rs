//! Nonlinear least squares through the `levenberg-marquardt` crate (MINPACK's algorithm on
//! nalgebra), with a forward-difference Jacobian so that callers only write residuals.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};

/// Outcome of a fit.
#[derive(Clone, Debug)]
pub struct FitOutcome {
    pub params: Vec<f64>,
    /// ½ Σ r² at the solution.
    pub objective: f64,
    pub evaluations: usize,
    pub converged: bool,
}

struct Problem<'a, F: Fn(&[f64]) -> Vec<f64>> {
    p: DVector<f64>,
    f: &'a F,
    m: usize,
}

impl<F: Fn(&[f64]) -> Vec<f64>> LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_, F> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.p.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.p.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let r = (self.f)(self.p.as_slice());
        (r.len() == self.m && r.iter().all(|v| v.is_finite())).then(|| DVector::from_vec(r))
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let n = self.p.len();
        let base = (self.f)(self.p.as_slice());
        let mut j = DMatrix::zeros(self.m, n);
        for c in 0..n {
            let mut q = self.p.clone();
            let h = 1e-6 * (1.0 + q[c].abs());
            q[c] += h;
            let r = (self.f)(q.as_slice());
            if r.len() != self.m {
                return None;
            }
            for row in 0..self.m {
                j[(row, c)] = (r[row] - base[row]) / h;
            }
        }
        j.iter().all(|v| v.is_finite()).then_some(j)
    }
}

/// Minimizes ½ Σ r(p)² from `initial`.
pub fn minimize(initial: &[f64], residuals: impl Fn(&[f64]) -> Vec<f64>) -> FitOutcome {
    let m = residuals(initial).len();
    let problem = Problem {
        p: DVector::from_column_slice(initial),
        f: &residuals,
        m,
    };
    let (solved, report) = LevenbergMarquardt::new().minimize(problem);
    FitOutcome {
        params: solved.p.as_slice().to_vec(),
        objective: report.objective_function,
        evaluations: report.number_of_evaluations,
        converged: report.termination.was_successful(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_an_exponential_decay() {
        let xs: Vec<f64> = (0..40).map(|k| k as f64 * 0.1).collect();
        let ys: Vec<f64> = xs.iter().map(|x| 2.5 * (-1.3 * x).exp() + 0.2).collect();
        let out = minimize(&[1.0, -0.5, 0.0], |p| {
            xs.iter()
                .zip(&ys)
                .map(|(x, y)| p[0] * (p[1] * x).exp() + p[2] - y)
                .collect()
        });
        assert!(out.converged);
        assert!(
            (out.params[0] - 2.5).abs() < 1e-6 && (out.params[1] + 1.3).abs() < 1e-6,
            "{out:?}"
        );
    }
}
