//! How well the image pins each fitted coordinate: standard errors and
//! correlations from the Jacobian at the fit, `cov ≈ s² (JᵀJ)⁻¹` with `s`
//! a robust scale of the residuals (see `lm.rs`).
//!
//! Everything is in unit-cube coordinates; the caller maps standard errors
//! to parameter units (multiply by each parameter's range). A coordinate
//! the image does not constrain at all has an infinite standard error and
//! correlations of 0 (it is not correlated with anything, just unknown).

use serde::{Deserialize, Serialize};

use super::lm::{cholesky_solve, Normal};

/// Standard errors and correlation matrix of a fit, in unit coordinates.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Identifiability {
    /// One standard error per coordinate (+inf when unconstrained).
    pub std_error: Vec<f64>,
    /// Correlation of every pair; 1 on the diagonal.
    pub correlation: Vec<Vec<f64>>,
}

impl Identifiability {
    /// From the normal equations at the fitted point. Coordinates whose
    /// Jacobian column is zero are left out of the inverse and reported as
    /// unconstrained; `None` if the rest is singular.
    pub(super) fn from_normal(normal: &Normal) -> Option<Identifiability> {
        let p = normal.jtj.len();
        let largest = (0..p).map(|j| normal.jtj[j][j]).fold(0.0, f64::max);
        let seen: Vec<usize> = (0..p)
            .filter(|&j| normal.jtj[j][j] > largest * 1e-14 && normal.jtj[j][j] > 0.0)
            .collect();
        let reduced: Vec<Vec<f64>> = seen
            .iter()
            .map(|&j| seen.iter().map(|&k| normal.jtj[j][k]).collect())
            .collect();
        // The inverse, column by column.
        let mut inverse = vec![vec![0.0; seen.len()]; seen.len()];
        for c in 0..seen.len() {
            let mut unit = vec![0.0; seen.len()];
            unit[c] = 1.0;
            let column = cholesky_solve(&reduced, &unit)?;
            for (r, v) in column.into_iter().enumerate() {
                inverse[r][c] = v;
            }
        }
        let s2 = normal.scale * normal.scale;
        let mut std_error = vec![f64::INFINITY; p];
        let mut correlation = vec![vec![0.0; p]; p];
        for (a, &j) in seen.iter().enumerate() {
            std_error[j] = (s2 * inverse[a][a]).sqrt();
            for (b, &k) in seen.iter().enumerate() {
                correlation[j][k] = inverse[a][b] / (inverse[a][a] * inverse[b][b]).sqrt();
            }
        }
        for (j, row) in correlation.iter_mut().enumerate() {
            row[j] = 1.0;
        }
        Some(Identifiability {
            std_error,
            correlation,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diagonal_system_gives_independent_errors() {
        let normal = Normal {
            a: vec![vec![4.0, 0.0, 0.0], vec![0.0, 1.0, 0.0], vec![0.0; 3]],
            g: vec![0.0; 3],
            jtj: vec![vec![4.0, 0.0, 0.0], vec![0.0, 1.0, 0.0], vec![0.0; 3]],
            scale: 2.0,
            wrr: 0.0,
        };
        let id = Identifiability::from_normal(&normal).expect("solvable");
        assert!((id.std_error[0] - 1.0).abs() < 1e-12);
        assert!((id.std_error[1] - 2.0).abs() < 1e-12);
        assert!(id.std_error[2].is_infinite());
        assert_eq!(id.correlation[0][1], 0.0);
        assert_eq!(id.correlation[2][2], 1.0);
    }

    #[test]
    fn correlated_columns_are_reported() {
        let normal = Normal {
            a: vec![vec![2.0, 1.0], vec![1.0, 2.0]],
            g: vec![0.0; 2],
            jtj: vec![vec![2.0, 1.0], vec![1.0, 2.0]],
            scale: 1.0,
            wrr: 0.0,
        };
        let id = Identifiability::from_normal(&normal).expect("solvable");
        // (JᵀJ)⁻¹ = [[2, -1], [-1, 2]] / 3: correlation -1/2.
        assert!((id.correlation[0][1] + 0.5).abs() < 1e-12);
        assert!((id.std_error[0] - (2.0f64 / 3.0).sqrt()).abs() < 1e-12);
    }
}
