//! Classic benchmark functions, taking unit-cube coordinates, for checking
//! the optimiser against known answers.
//!
//! Each maps `u` in `[0,1]^dim` linearly onto its usual domain and has a
//! known global minimum of 0:
//! - sphere `Σ x²` on `[-5.12, 5.12]`, minimum at `x = 0` (u = 0.5);
//! - Rosenbrock `Σ 100 (x_{k+1} - x_k²)² + (1 - x_k)²` on `[-5, 10]`,
//!   minimum at `x = 1` (u = 0.4), in a long curved valley;
//! - Rastrigin `10 n + Σ x² - 10 cos(2π x)` on `[-5.12, 5.12]`, minimum at
//!   `x = 0` (u = 0.5), among about 11^n local minima.

use std::f64::consts::PI;

/// Maps a unit coordinate onto `[low, high]`.
fn scale(u: f64, (low, high): (f64, f64)) -> f64 {
    low + u * (high - low)
}

/// The sphere function; cheap and unimodal, a check of basic convergence.
pub fn sphere(u: &[f64]) -> f64 {
    let domain = TestFunction::Sphere.domain();
    u.iter().map(|&u| scale(u, domain).powi(2)).sum()
}

/// The Rosenbrock function; checks progress along a narrow curved valley.
pub fn rosenbrock(u: &[f64]) -> f64 {
    let domain = TestFunction::Rosenbrock.domain();
    let x: Vec<f64> = u.iter().map(|&u| scale(u, domain)).collect();
    x.windows(2)
        .map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (1.0 - w[0]).powi(2))
        .sum()
}

/// The Rastrigin function; checks escape from many regular local minima.
pub fn rastrigin(u: &[f64]) -> f64 {
    let domain = TestFunction::Rastrigin.domain();
    u.iter()
        .map(|&u| {
            let x = scale(u, domain);
            x * x - 10.0 * (2.0 * PI * x).cos() + 10.0
        })
        .sum()
}

/// The benchmark functions, with their domains and known minima.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TestFunction {
    Sphere,
    Rosenbrock,
    Rastrigin,
}

impl TestFunction {
    pub const ALL: [TestFunction; 3] = [
        TestFunction::Sphere,
        TestFunction::Rosenbrock,
        TestFunction::Rastrigin,
    ];

    pub fn name(self) -> &'static str {
        match self {
            TestFunction::Sphere => "sphere",
            TestFunction::Rosenbrock => "rosenbrock",
            TestFunction::Rastrigin => "rastrigin",
        }
    }

    /// Value at unit-cube coordinates `u`.
    pub fn eval(self, u: &[f64]) -> f64 {
        match self {
            TestFunction::Sphere => sphere(u),
            TestFunction::Rosenbrock => rosenbrock(u),
            TestFunction::Rastrigin => rastrigin(u),
        }
    }

    /// The real interval each unit coordinate is mapped onto.
    pub fn domain(self) -> (f64, f64) {
        match self {
            TestFunction::Sphere | TestFunction::Rastrigin => (-5.12, 5.12),
            TestFunction::Rosenbrock => (-5.0, 10.0),
        }
    }

    /// The global minimum value.
    pub fn minimum(self) -> f64 {
        0.0
    }

    /// Where the global minimum is, in unit coordinates.
    pub fn argmin(self, dim: usize) -> Vec<f64> {
        let (low, high) = self.domain();
        let x = match self {
            TestFunction::Sphere | TestFunction::Rastrigin => 0.0,
            TestFunction::Rosenbrock => 1.0,
        };
        vec![(x - low) / (high - low); dim]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_is_at_argmin() {
        for function in TestFunction::ALL {
            let at = function.argmin(6);
            assert!(function.eval(&at).abs() < 1e-12, "{}", function.name());
            let mut off = at.clone();
            off[2] += 0.01;
            assert!(function.eval(&off) > 1e-3, "{}", function.name());
        }
    }

    #[test]
    fn known_values() {
        // u = 0 maps to the domain's low corner.
        assert!((sphere(&[0.0, 0.0]) - 2.0 * 5.12 * 5.12).abs() < 1e-12);
        // x = (-5, -5): 100 (−5 − 25)² + 36 = 90036.
        assert!((rosenbrock(&[0.0, 0.0]) - 90_036.0).abs() < 1e-9);
        // x = 1 is a local minimum of Rastrigin's cosine term: 1 − 10 + 10.
        let u = (1.0 + 5.12) / 10.24;
        assert!((rastrigin(&[u]) - 1.0).abs() < 1e-9);
    }
}
