//! The linear algebra of one Levenberg–Marquardt step on per-value
//! residuals: the reweighted normal equations from a forward-difference
//! Jacobian, the damped solve, and the adaptive difference steps.
//!
//! The fit reports an L1 deviation, so the step minimises it by
//! iteratively reweighted least squares: each value's squared residual is
//! weighted by `1 / max(|r_i|, WEIGHT_FLOOR)`, which makes `Σ w_i r_i²`
//! equal `Σ |r_i|` at the current point (values within a level of zero
//! count as quadratic there, so the weights stay bounded). Only the small
//! `P×P` products are kept, never the Jacobian itself, so a search state
//! stays small enough to checkpoint whatever the image size.

use serde::{Deserialize, Serialize};

use super::exact;

/// Residuals below this (in 8-bit levels) get the same weight: below one
/// level a value is within its quantisation and cannot say more.
const WEIGHT_FLOOR: f64 = 1.0;

/// The smallest residual scale reported: the standard deviation of 8-bit
/// rounding (1/√12 level). A perfect fit of quantised images still leaves
/// that much uncertainty.
const SCALE_FLOOR: f64 = 0.288_675_134_594_812_9;

/// √(π/2): the asymptotic standard error of a least-absolute-deviations
/// fit is `1/(2 f(0))` times that of the normal equations, which for
/// Gaussian residuals of deviation σ is σ√(π/2).
const LAD_FACTOR: f64 = 1.253_314_137_315_500_3;

/// 1/Φ⁻¹(3/4): turns a median absolute deviation into a standard deviation
/// for Gaussian residuals.
const MAD_TO_SIGMA: f64 = 1.482_602_218_505_602;

/// Mean change (in levels, over the values that changed) a difference step
/// aims for. Below the band a column is mostly rounding noise; above it
/// the step is no longer small and the column stops being a derivative.
const CHANGE_LOW: f64 = 3.0;
const CHANGE_HIGH: f64 = 24.0;
/// Bounds of a difference step in unit coordinates.
pub const STEP_MIN: f64 = 1e-4;
pub const STEP_MAX: f64 = 0.1;

/// The reweighted normal equations at one point, plus what the
/// identifiability estimate needs there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Normal {
    /// `Jᵀ W J`.
    #[serde(with = "exact::matrix")]
    pub a: Vec<Vec<f64>>,
    /// `Jᵀ W r`.
    #[serde(with = "exact::vector")]
    pub g: Vec<f64>,
    /// `Jᵀ J` (unweighted), for the covariance.
    #[serde(with = "exact::matrix")]
    pub jtj: Vec<Vec<f64>>,
    /// Robust standard deviation of one residual, in levels.
    #[serde(with = "exact::scalar")]
    pub scale: f64,
    /// `rᵀ W r`: the L1 sum the weights make the quadratic model equal at
    /// the point, for the gain a step predicts.
    #[serde(with = "exact::scalar", default)]
    pub wrr: f64,
}

/// One Jacobian column from a forward difference: the perturbed point's
/// residuals and the signed step that produced them. `None` residuals (a
/// failed render) give a zero column.
pub struct Column<'a> {
    pub residuals: Option<&'a [f32]>,
    pub step: f64,
}

/// One Jacobian column from the quadratic through the point (residuals
/// `r`) and two neighbours along the coordinate, `a` at signed offset
/// `first` and `b` at `second`: a central difference when they lie on
/// either side, a one-sided second-order difference when both lie on one
/// side (at a face of the cube). Returned as the residuals a forward
/// difference of `first` would have seen, for [`Column`]. Why: a forward
/// difference is off by half the second derivative times the step, and on
/// 8-bit images the step must be large enough to change values by whole
/// levels; there that term is what turns the Jacobian into a secant that
/// sees only one wall of a narrow valley. A quadratic's slope is off by a
/// third-order term only.
pub fn second_order(r: &[f32], a: &[f32], first: f64, b: &[f32], second: f64) -> Vec<f32> {
    let (s, t) = (first, second);
    // d = r + s·J, J the slope at 0 of the quadratic through the nodes
    // 0, s and t.
    let ca = t / (t - s);
    let cb = -s * s / (t * (t - s));
    let cr = -(s + t) / t;
    r.iter()
        .zip(a)
        .zip(b)
        .map(|((&r, &a), &b)| {
            let (r, a, b) = (f64::from(r), f64::from(a), f64::from(b));
            (r + ca * a + cb * b + cr * r) as f32
        })
        .collect()
}

/// Builds the normal equations at a point with residuals `r` from its
/// perturbed neighbours, one per coordinate, in coordinate order.
///
/// Sums run in value order in one thread, so the result does not depend on
/// how the executor scheduled the renders.
pub fn normal_equations(r: &[f32], columns: &[Column]) -> Normal {
    let p = columns.len();
    let mut a = vec![vec![0.0; p]; p];
    let mut jtj = vec![vec![0.0; p]; p];
    let mut g = vec![0.0; p];
    let mut wrr = 0.0;
    let usable: Vec<bool> = columns
        .iter()
        .map(|c| c.residuals.is_some_and(|d| d.len() == r.len()) && c.step != 0.0)
        .collect();
    let mut row = vec![0.0; p];
    // The residuals of the values some coordinate moves: only those enter
    // the covariance, so only their spread is the noise that matters (a
    // black background, exact in target and render, would halve a scale
    // taken over every value).
    let mut moved: Vec<f32> = Vec::new();
    for (i, &ri) in r.iter().enumerate() {
        let ri = f64::from(ri);
        for (j, column) in columns.iter().enumerate() {
            row[j] = match (usable[j], column.residuals) {
                (true, Some(d)) => (f64::from(d[i]) - ri) / column.step,
                _ => 0.0,
            };
        }
        if row.iter().any(|&x| x != 0.0) {
            moved.push(ri as f32);
        }
        let w = 1.0 / ri.abs().max(WEIGHT_FLOOR);
        wrr += w * ri * ri;
        for j in 0..p {
            if row[j] == 0.0 {
                continue;
            }
            g[j] += w * row[j] * ri;
            for k in 0..=j {
                a[j][k] += w * row[j] * row[k];
                jtj[j][k] += row[j] * row[k];
            }
        }
    }
    for j in 0..p {
        for k in 0..j {
            a[k][j] = a[j][k];
            jtj[k][j] = jtj[j][k];
        }
    }
    Normal {
        a,
        g,
        jtj,
        scale: residual_scale(if moved.is_empty() { r } else { &moved }),
        wrr,
    }
}

/// The period of coordinate `j` in unit coordinates (0: not periodic;
/// an empty `periods` has none).
fn period(periods: &[f64], j: usize) -> f64 {
    periods.get(j).copied().filter(|p| *p > 0.0).unwrap_or(0.0)
}

/// `x` with each periodic coordinate moved by whole periods to the
/// representative nearest the cube's centre. A periodic coordinate (a
/// hue, searched over an interval that overlaps itself) has several
/// points in the cube with the same image; the central one is farthest
/// from the faces, so a local step is not stopped at a face of the
/// overlap while the circle goes on.
pub fn wrap(x: &[f64], periods: &[f64]) -> Vec<f64> {
    x.iter()
        .enumerate()
        .map(|(j, &v)| match period(periods, j) {
            p if p > 0.0 => (v - p * ((v - 0.5) / p).round()).clamp(0.0, 1.0),
            _ => v,
        })
        .collect()
}

/// The step from `x` to `y`, each periodic coordinate's the shortest way
/// round its circle.
pub fn offset(x: &[f64], y: &[f64], periods: &[f64]) -> Vec<f64> {
    x.iter()
        .zip(y)
        .enumerate()
        .map(|(j, (a, b))| match (b - a, period(periods, j)) {
            (d, p) if p > 0.0 => d - p * (d / p).round(),
            (d, _) => d,
        })
        .collect()
}

/// The relative decrease of the reweighted sum the model predicts for the
/// step from `x` to `trial`: `(−gᵀδ − ½ δᵀAδ) / rᵀWr` (0 when unknown).
pub fn predicted_gain(normal: &Normal, x: &[f64], trial: &[f64], periods: &[f64]) -> f64 {
    let d = offset(x, trial, periods);
    let mut gain = 0.0;
    for (j, &dj) in d.iter().enumerate() {
        let ad: f64 = normal.a[j].iter().zip(&d).map(|(a, dk)| a * dk).sum();
        gain -= normal.g[j] * dj + 0.5 * dj * ad;
    }
    if normal.wrr > 0.0 {
        gain / normal.wrr
    } else {
        0.0
    }
}

/// A robust standard deviation of the residuals (scaled MAD), times the
/// least-absolute-deviations factor, floored at the rounding deviation.
fn residual_scale(r: &[f32]) -> f64 {
    if r.is_empty() {
        return SCALE_FLOOR;
    }
    let mut magnitudes: Vec<f32> = r.iter().map(|v| v.abs()).collect();
    let middle = magnitudes.len() / 2;
    let (_, median, _) = magnitudes.select_nth_unstable_by(middle, f32::total_cmp);
    (LAD_FACTOR * MAD_TO_SIGMA * f64::from(*median)).max(SCALE_FLOOR)
}

/// The Levenberg–Marquardt step `δ` solving
/// `(A + λ (diag A + ε)) δ = −g` over the coordinates not `fixed` (a fixed
/// coordinate's step is the value given, and its coupling to the others
/// moves to the right-hand side). `ε`, a tiny fraction of the largest
/// diagonal entry, keeps a coordinate the image ignores from making the
/// system singular. `None` when the system cannot be solved (non-finite
/// input).
pub fn damped_step(normal: &Normal, lambda: f64, fixed: &[Option<f64>]) -> Option<Vec<f64>> {
    let index: Vec<usize> = (0..normal.g.len())
        .filter(|&j| fixed[j].is_none())
        .collect();
    let largest = index.iter().map(|&j| normal.a[j][j]).fold(0.0, f64::max);
    let epsilon = (largest * 1e-9).max(1e-12);
    let matrix: Vec<Vec<f64>> = index
        .iter()
        .map(|&j| {
            index
                .iter()
                .map(|&k| {
                    let damping = if j == k {
                        lambda * (normal.a[j][j] + epsilon)
                    } else {
                        0.0
                    };
                    normal.a[j][k] + damping
                })
                .collect()
        })
        .collect();
    let rhs: Vec<f64> = index
        .iter()
        .map(|&j| {
            let coupled: f64 = (0..fixed.len())
                .filter_map(|k| fixed[k].map(|d| normal.a[j][k] * d))
                .sum();
            -normal.g[j] - coupled
        })
        .collect();
    let solved = cholesky_solve(&matrix, &rhs)?;
    let mut step: Vec<f64> = fixed.iter().map(|f| f.unwrap_or(0.0)).collect();
    for (&j, v) in index.iter().zip(solved) {
        step[j] = v;
    }
    Some(step)
}

/// Solves `M x = b` for a symmetric positive definite `M` by Cholesky.
/// `None` if `M` is not positive definite or anything is non-finite.
pub fn cholesky_solve(m: &[Vec<f64>], b: &[f64]) -> Option<Vec<f64>> {
    let l = cholesky(m)?;
    let n = b.len();
    let mut y = vec![0.0; n];
    for i in 0..n {
        let sum: f64 = (0..i).map(|k| l[i][k] * y[k]).sum();
        y[i] = (b[i] - sum) / l[i][i];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let sum: f64 = (i + 1..n).map(|k| l[k][i] * x[k]).sum();
        x[i] = (y[i] - sum) / l[i][i];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The lower Cholesky factor of `m`, or `None` when it is not positive
/// definite.
fn cholesky(m: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let n = m.len();
    let mut l = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..=i {
            let sum: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
            if i == j {
                let d = m[i][i] - sum;
                if !(d > 0.0 && d.is_finite()) {
                    return None;
                }
                l[i][i] = d.sqrt();
            } else {
                l[i][j] = (m[i][j] - sum) / l[j][j];
            }
        }
    }
    Some(l)
}

/// The next difference step for one coordinate, from the change the last
/// one produced: the mean absolute change over the values that changed at
/// all. Too small (rounding noise dominates) → four times larger; too
/// large (no longer a derivative) → halved; kept within
/// [`STEP_MIN`, `STEP_MAX`].
pub fn adapt_step(step: f64, center: &[f32], perturbed: Option<&[f32]>) -> f64 {
    let mut change = Change::default();
    change.add(center, perturbed);
    change.next_step(step)
}

/// Whether a coordinate's difference step is as the step rule wants it
/// (its mean change at least the band's low end, or the step at
/// [`STEP_MAX`]): only then does a column's noise say something about
/// the image rather than about a step still too short.
pub fn resolved(step: f64, center: &[f32], perturbed: Option<&[f32]>) -> bool {
    let mut change = Change::default();
    change.add(center, perturbed);
    !change.failed && (step >= STEP_MAX || change.mean() >= CHANGE_LOW)
}

/// What one coordinate's difference changed, summed over one or more
/// residual vectors (a set's coordinate changes several photographs), for
/// [`Change::next_step`].
#[derive(Clone, Copy, Debug, Default)]
pub struct Change {
    total: f64,
    changed: usize,
    failed: bool,
}

impl Change {
    /// Adds one photograph's residuals at the point and at its perturbed
    /// neighbour (None or a wrong length: the render failed).
    pub fn add(&mut self, center: &[f32], perturbed: Option<&[f32]>) {
        let Some(perturbed) = perturbed.filter(|p| p.len() == center.len()) else {
            self.failed = true;
            return;
        };
        for (&a, &b) in center.iter().zip(perturbed) {
            let d = f64::from(b - a).abs();
            if d > 0.0 {
                self.total += d;
                self.changed += 1;
            }
        }
    }

    /// The mean absolute change over the values that changed.
    fn mean(&self) -> f64 {
        if self.changed == 0 {
            0.0
        } else {
            self.total / self.changed as f64
        }
    }

    /// The next step after `step` (see [`adapt_step`]).
    pub fn next_step(&self, step: f64) -> f64 {
        if self.failed {
            // A failed render near a point: try closer next time.
            return (step * 0.5).clamp(STEP_MIN, STEP_MAX);
        }
        let mean = self.mean();
        let next = if mean < CHANGE_LOW {
            step * 4.0
        } else if mean > CHANGE_HIGH {
            step * 0.5
        } else {
            step
        };
        next.clamp(STEP_MIN, STEP_MAX)
    }
}

/// The damped step's end point from `x` in the unit cube, by an active
/// set: a coordinate whose step would leave the cube is pinned at the face
/// it crosses and the others are solved again with it held there, until
/// no new coordinate is pinned. Clamping each coordinate alone instead
/// bends the step off the direction the model chose; on a ridge, where
/// the step is long and the coordinates trade, that lands the trial far
/// from the model's minimum on the face. A periodic coordinate is never
/// pinned: its step goes round the circle ([`wrap`]). None when it does
/// not move or the system cannot be solved.
pub fn bounded_trial(normal: &Normal, lambda: f64, x: &[f64], periods: &[f64]) -> Option<Vec<f64>> {
    let mut fixed: Vec<Option<f64>> = vec![None; x.len()];
    let mut step = damped_step(normal, lambda, &fixed)?;
    // Each pass pins at least one more coordinate, so this ends.
    loop {
        let mut pinned = false;
        for j in 0..x.len() {
            let inside = (0.0..=1.0).contains(&(x[j] + step[j])) || period(periods, j) > 0.0;
            if fixed[j].is_none() && !inside {
                let face = if x[j] + step[j] < 0.0 { 0.0 } else { 1.0 };
                fixed[j] = Some(face - x[j]);
                pinned = true;
            }
        }
        if !pinned || fixed.iter().all(Option::is_some) {
            break;
        }
        step = damped_step(normal, lambda, &fixed)?;
    }
    let moved: Vec<f64> = x.iter().zip(&step).map(|(&x, &s)| x + s).collect();
    let trial: Vec<f64> = wrap(&moved, periods)
        .into_iter()
        .map(|v| v.clamp(0.0, 1.0))
        .collect();
    (trial != x).then_some(trial)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_counts_only_values_a_coordinate_moves() {
        // Four values the coordinate moves, with residuals of 4 levels,
        // and four it does not (a black background, exact in both).
        let r = [4.0, -4.0, 4.0, -4.0, 0.0, 0.0, 0.0, 0.0];
        let d = [5.0, -3.0, 5.0, -3.0, 0.0, 0.0, 0.0, 0.0];
        let n = normal_equations(
            &r,
            &[Column {
                residuals: Some(&d),
                step: 0.1,
            }],
        );
        assert!(
            (n.scale - LAD_FACTOR * MAD_TO_SIGMA * 4.0).abs() < 1e-9,
            "{}",
            n.scale
        );
    }

    #[test]
    fn cholesky_solves_a_known_system() {
        let m = vec![vec![4.0, 2.0], vec![2.0, 3.0]];
        let x = cholesky_solve(&m, &[2.0, 5.0]).expect("positive definite");
        assert!(
            (x[0] + 0.5).abs() < 1e-12 && (x[1] - 2.0).abs() < 1e-12,
            "{x:?}"
        );
        assert!(cholesky_solve(&[vec![0.0]], &[1.0]).is_none());
    }

    #[test]
    fn one_step_solves_a_linear_problem_with_small_damping() {
        // r(x) = 3 x0 - 6 and 2 x1 + 4 at x = 0: the step is (2, -2).
        let r = [-6.0f32, 4.0];
        let c0 = [-3.0f32, 4.0]; // x0 moved by 1
        let c1 = [-6.0f32, 6.0]; // x1 moved by 1
        let normal = normal_equations(
            &r,
            &[
                Column {
                    residuals: Some(&c0),
                    step: 1.0,
                },
                Column {
                    residuals: Some(&c1),
                    step: 1.0,
                },
            ],
        );
        let step = damped_step(&normal, 1e-12, &[None, None]).expect("solvable");
        assert!((step[0] - 2.0).abs() < 1e-6 && (step[1] + 2.0).abs() < 1e-6);
        let only_first = damped_step(&normal, 1e-12, &[None, Some(0.0)]).expect("solvable");
        assert_eq!(only_first[1], 0.0);
    }

    #[test]
    fn second_order_columns_are_exact_on_a_quadratic() {
        // r(u) = 3 + 2u + 5u² at u = 0.5: slope 7; a forward difference of
        // 0.1 would see 7.5.
        let f = |u: f64| [(3.0 + 2.0 * u + 5.0 * u * u) as f32];
        let slope = |d: &[f32], s: f64| (f64::from(d[0]) - f64::from(f(0.5)[0])) / s;
        let central = second_order(&f(0.5), &f(0.6), 0.1, &f(0.4), -0.1);
        assert!((slope(&central, 0.1) - 7.0).abs() < 1e-4, "{central:?}");
        let one_sided = second_order(&f(0.5), &f(0.4), -0.1, &f(0.3), -0.2);
        assert!(
            (slope(&one_sided, -0.1) - 7.0).abs() < 1e-4,
            "{one_sided:?}"
        );
    }

    #[test]
    fn a_periodic_coordinate_steps_round_its_circle() {
        // r(x) = x0 + 0.3 at x0 = 0.1: the step to -0.3 leaves the cube;
        // with period 2/3 it lands at -0.3 + 2/3 instead of the face.
        let r = [0.3f32];
        let moved = [1.3f32];
        let column = Column {
            residuals: Some(&moved),
            step: 1.0,
        };
        let normal = normal_equations(&r, &[column]);
        let x = [0.1];
        let pinned = bounded_trial(&normal, 1e-12, &x, &[]).expect("moves");
        assert_eq!(pinned, vec![0.0]);
        let period = 2.0 / 3.0;
        let round = bounded_trial(&normal, 1e-12, &x, &[period]).expect("moves");
        assert!((round[0] - (period - 0.2)).abs() < 1e-6, "{round:?}");
        let d = offset(&x, &round, &[period]);
        assert!((d[0] + 0.3).abs() < 1e-6, "{d:?}");
        let straight = predicted_gain(&normal, &x, &[-0.2], &[]);
        assert!((predicted_gain(&normal, &x, &round, &[period]) - straight).abs() < 1e-6);
        assert_eq!(
            wrap(&[0.05, 0.05], &[period, 0.0]),
            vec![0.05 + period, 0.05]
        );
    }

    #[test]
    fn steps_grow_when_nothing_changes_and_shrink_when_too_much_does() {
        let center = [10.0f32; 4];
        assert_eq!(adapt_step(0.01, &center, Some(&center)), 0.04);
        assert_eq!(adapt_step(0.01, &center, Some(&[110.0; 4])), 0.005);
        assert_eq!(adapt_step(0.01, &center, Some(&[18.0; 4])), 0.01);
        assert_eq!(adapt_step(0.01, &center, None), 0.005);
    }
}
