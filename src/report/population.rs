//! The final population of a fit and what its spread says: which
//! parameters the image pins down, and which trade off against each other.
//!
//! The population is read from the fit's `checkpoint.json`, which holds
//! unit-cube vectors of the phase being searched (the last one, once the fit
//! has finished). They are mapped to scene units through the bounds of the
//! scene the stage searched (the checkpoint's own `base`, whose free list is
//! that stage's: narrowed for a pipeline's stage 2), never the original
//! scene's.
//!
//! A converged population spreads along the directions the deviation barely
//! changes in. The classic one: light intensity times albedo is what an
//! image of a diffuse surface shows, so intensity and albedo spread along a
//! hyperbola, negatively correlated, while their product stays put.

use crate::fit;
use crate::rundir::{RunDir, CHECKPOINT};
use crate::scene::field::{LightField, MaterialField};
use crate::scene::{Field, ParamSpace, Value};
use std::path::Path;

/// What kind of quantity a column is, for the trade-off table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A light's intensity or colour: scales all the light it sends.
    Light,
    /// A reflectance: colour, diffuse or specular strength, and the colour's
    /// luminance (derived).
    Albedo,
    Other,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    pub name: String,
    pub kind: Kind,
}

/// Individuals of the final population in scene units, failed ones left out.
#[derive(Clone, Debug)]
pub struct Population {
    pub file: String,
    pub phase: u32,
    pub columns: Vec<Column>,
    /// One row per individual, one value per column.
    pub rows: Vec<Vec<f64>>,
    /// Average deviation (%) of each row.
    pub deviation: Vec<f64>,
}

/// Reads the final population of the fit in `dir` from its checkpoint (a
/// finished fit keeps its last phase's search there); the error says why
/// there is none.
pub fn load(dir: &Path) -> Result<Population, String> {
    let run = RunDir::existing(dir).map_err(|e| e.to_string())?;
    if !run.file(CHECKPOINT).is_file() {
        return Err(format!("no {CHECKPOINT}"));
    }
    let c = fit::load_state(&run).map_err(|e| e.to_string())?;
    let p = c
        .population()
        .ok_or_else(|| format!("{CHECKPOINT} holds no population (the search keeps none)"))?;
    Ok(from_fit(&p, CHECKPOINT))
}

/// The population of a fit in scene units, failed individuals left out.
pub fn from_fit(p: &fit::Population, file: &str) -> Population {
    let sub = ParamSpace::from_scene(&p.base).phase(p.phase);
    let mut rows = Vec::new();
    let mut deviation = Vec::new();
    for (u, &f) in p.members.iter().zip(&p.fitness) {
        if !f.is_finite() {
            continue;
        }
        rows.push(row(&sub, u));
        deviation.push(f / 3.0);
    }
    Population {
        file: file.into(),
        phase: p.phase,
        columns: columns(&sub),
        rows,
        deviation,
    }
}

fn kind(field: &Field) -> Kind {
    match field {
        Field::Light(_, LightField::Intensity | LightField::Color) => Kind::Light,
        Field::Material(
            _,
            MaterialField::Color | MaterialField::Diffuse | MaterialField::Specular,
        ) => Kind::Albedo,
        _ => Kind::Other,
    }
}

fn columns(space: &ParamSpace) -> Vec<Column> {
    let mut cols = Vec::new();
    for s in &space.specs {
        let k = kind(&s.field);
        if s.dim() == 1 {
            cols.push(Column {
                name: s.name.clone(),
                kind: k,
            });
            continue;
        }
        let suffixes = if s.field.is_color() {
            ["r", "g", "b"]
        } else {
            ["x", "y", "z"]
        };
        for c in suffixes {
            cols.push(Column {
                name: format!("{}.{c}", s.name),
                kind: k,
            });
        }
        if s.field.is_color() {
            cols.push(Column {
                name: format!("{}.luminance", s.name),
                kind: k,
            });
        }
    }
    cols
}

/// Rec. 709 luminance of a linear RGB colour.
fn luminance([r, g, b]: [f64; 3]) -> f64 {
    0.2126 * r + 0.7152 * g + 0.0722 * b
}

fn row(space: &ParamSpace, u: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for (spec, (_, value)) in space.specs.iter().zip(space.values(u)) {
        match value {
            Value::Scalar(x) => out.push(x),
            Value::Vector(v) => {
                out.extend_from_slice(&v);
                if spec.field.is_color() {
                    out.push(luminance(v));
                }
            }
        }
    }
    out
}

/// A column's spread over the population.
#[derive(Clone, Debug, PartialEq)]
pub struct Spread {
    pub name: String,
    pub mean: f64,
    pub std: f64,
    pub min: f64,
    pub max: f64,
}

impl Spread {
    /// Standard deviation relative to the mean's size (None near zero).
    pub fn relative(&self) -> Option<f64> {
        (self.mean.abs() > 1e-12).then(|| self.std / self.mean.abs())
    }
}

fn mean_std(x: &[f64]) -> (f64, f64) {
    let n = x.len().max(1) as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, var.sqrt())
}

impl Population {
    fn column(&self, i: usize) -> Vec<f64> {
        self.rows.iter().map(|r| r[i]).collect()
    }

    pub fn spreads(&self) -> Vec<Spread> {
        (0..self.columns.len())
            .map(|i| {
                let x = self.column(i);
                let (mean, std) = mean_std(&x);
                Spread {
                    name: self.columns[i].name.clone(),
                    mean,
                    std,
                    min: x.iter().copied().fold(f64::INFINITY, f64::min),
                    max: x.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                }
            })
            .collect()
    }

    /// Every light column against every albedo column.
    pub fn trade_offs(&self) -> Vec<TradeOff> {
        let mut out = Vec::new();
        for (i, a) in self.columns.iter().enumerate() {
            for (j, b) in self.columns.iter().enumerate() {
                if a.kind != Kind::Light || b.kind != Kind::Albedo {
                    continue;
                }
                let (x, y) = (self.column(i), self.column(j));
                let product: Vec<f64> = x.iter().zip(&y).map(|(p, q)| p * q).collect();
                out.push(TradeOff {
                    light: a.name.clone(),
                    albedo: b.name.clone(),
                    correlation: correlation(&x, &y),
                    relative_spread: [relative(&x), relative(&y), relative(&product)],
                });
            }
        }
        out
    }

    /// Pairs of columns with |correlation| at or above `threshold`, strongest
    /// first, leaving out a colour's luminance against its own components.
    pub fn strong_pairs(&self, threshold: f64) -> Vec<(String, String, f64)> {
        let mut out = Vec::new();
        for i in 0..self.columns.len() {
            for j in i + 1..self.columns.len() {
                let (a, b) = (&self.columns[i].name, &self.columns[j].name);
                if same_colour(a, b) {
                    continue;
                }
                if let Some(r) = correlation(&self.column(i), &self.column(j)) {
                    if r.abs() >= threshold {
                        out.push((a.clone(), b.clone(), r));
                    }
                }
            }
        }
        out.sort_by(|x, y| y.2.abs().total_cmp(&x.2.abs()));
        out
    }

    /// The values of two columns, for a scatter plot.
    pub fn pairs(&self, a: &str, b: &str) -> Option<Vec<(f64, f64, f64)>> {
        let i = self.columns.iter().position(|c| c.name == a)?;
        let j = self.columns.iter().position(|c| c.name == b)?;
        Some(
            self.rows
                .iter()
                .zip(&self.deviation)
                .map(|(r, d)| (r[i], r[j], *d))
                .collect(),
        )
    }
}

fn same_colour(a: &str, b: &str) -> bool {
    let stem = |s: &str| s.rsplit_once('.').map(|(p, _)| p.to_string());
    let colourish = |s: &str| s.ends_with(".luminance");
    (colourish(a) || colourish(b)) && stem(a) == stem(b)
}

fn relative(x: &[f64]) -> Option<f64> {
    let (mean, std) = mean_std(x);
    (mean.abs() > 1e-12).then(|| std / mean.abs())
}

/// A light parameter against an albedo parameter over the population.
#[derive(Clone, Debug, PartialEq)]
pub struct TradeOff {
    pub light: String,
    pub albedo: String,
    pub correlation: Option<f64>,
    /// Relative spread (std / |mean|) of the light, the albedo and their
    /// product: a product much tighter than its factors is what the image
    /// determines, the factors separately it does not.
    pub relative_spread: [Option<f64>; 3],
}

/// Pearson's correlation; None with fewer than 3 values or no variance.
pub fn correlation(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len().min(y.len());
    if n < 3 {
        return None;
    }
    let (mx, sx) = mean_std(&x[..n]);
    let (my, sy) = mean_std(&y[..n]);
    if sx <= 1e-15 * mx.abs().max(1.0) || sy <= 1e-15 * my.abs().max(1.0) {
        return None;
    }
    let cov = x[..n]
        .iter()
        .zip(&y[..n])
        .map(|(a, b)| (a - mx) * (b - my))
        .sum::<f64>()
        / n as f64;
    Some((cov / (sx * sy)).clamp(-1.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn correlation_of_known_series() {
        let x = [1.0, 2.0, 3.0, 4.0];
        assert!((correlation(&x, &[2.0, 4.0, 6.0, 8.0]).unwrap() - 1.0).abs() < 1e-12);
        assert!((correlation(&x, &[8.0, 6.0, 4.0, 2.0]).unwrap() + 1.0).abs() < 1e-12);
        assert_eq!(correlation(&x, &[1.0, 1.0, 1.0, 1.0]), None);
        assert_eq!(correlation(&x[..2], &x[..2]), None);
    }

    #[test]
    fn intensity_times_albedo_is_what_a_valley_keeps() {
        // Points on I * rho = 2: the factors spread, the product does not.
        let rows: Vec<Vec<f64>> = (0..20)
            .map(|i| {
                let rho = 0.3 + 0.02 * i as f64;
                vec![2.0 / rho, rho]
            })
            .collect();
        let p = Population {
            file: "t".into(),
            phase: 1,
            columns: vec![
                Column {
                    name: "lights.key.intensity".into(),
                    kind: Kind::Light,
                },
                Column {
                    name: "objects.ball.material.diffuse".into(),
                    kind: Kind::Albedo,
                },
            ],
            deviation: vec![1.0; rows.len()],
            rows,
        };
        let t = p.trade_offs();
        assert_eq!(t.len(), 1);
        assert!(t[0].correlation.unwrap() < -0.95);
        let [l, a, prod] = t[0].relative_spread;
        assert!(prod.unwrap() < 1e-12 && l.unwrap() > 0.1 && a.unwrap() > 0.1);
        assert_eq!(p.strong_pairs(0.9).len(), 1);
    }
}
