//! Bit-exact serde encoding of `f64` values for checkpoints.
//!
//! Why not plain JSON numbers: serde_json (without its `float_roundtrip`
//! feature) parses decimals with a fast method that can be off by one ulp,
//! and it writes NaN and infinities as `null`, which cannot be read back.
//! Either would make a resumed run drift from an uninterrupted one. Each
//! `f64` is therefore stored as its IEEE-754 bit pattern, a `u64`, which
//! JSON carries exactly.
//!
//! Use with `#[serde(with = "exact::…")]` on the field's type.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// One `f64`.
pub mod scalar {
    use super::*;

    pub fn serialize<S: Serializer>(value: &f64, s: S) -> Result<S::Ok, S::Error> {
        value.to_bits().serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        u64::deserialize(d).map(f64::from_bits)
    }
}

/// A `Vec<f64>`.
pub mod vector {
    use super::*;

    pub fn serialize<S: Serializer>(values: &[f64], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(values.iter().map(|v| v.to_bits()))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        let bits = Vec::<u64>::deserialize(d)?;
        Ok(bits.into_iter().map(f64::from_bits).collect())
    }
}

/// A `Vec<Vec<f64>>` (a population or an archive).
pub mod matrix {
    use super::*;

    pub fn serialize<S: Serializer>(rows: &[Vec<f64>], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(rows.iter().map(|row| Row(row)))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Vec<f64>>, D::Error> {
        let bits = Vec::<Vec<u64>>::deserialize(d)?;
        Ok(bits
            .into_iter()
            .map(|row| row.into_iter().map(f64::from_bits).collect())
            .collect())
    }

    /// Serialises one row through [`super::vector`] without copying it.
    struct Row<'a>(&'a [f64]);

    impl Serialize for Row<'_> {
        fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
            super::vector::serialize(self.0, s)
        }
    }
}

/// A [`DeConfig`](super::DeConfig), whose F and CR drive the search and so
/// must come back exactly too.
pub mod config {
    use super::*;
    use crate::optimize::{DeConfig, Strategy};

    #[derive(Serialize, Deserialize)]
    struct Exact {
        population: usize,
        #[serde(with = "super::scalar")]
        f: f64,
        #[serde(with = "super::scalar")]
        cr: f64,
        strategy: Strategy,
        seed: u64,
    }

    pub fn serialize<S: Serializer>(c: &DeConfig, s: S) -> Result<S::Ok, S::Error> {
        Exact {
            population: c.population,
            f: c.f,
            cr: c.cr,
            strategy: c.strategy,
            seed: c.seed,
        }
        .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<DeConfig, D::Error> {
        let e = Exact::deserialize(d)?;
        Ok(DeConfig {
            population: e.population,
            f: e.f,
            cr: e.cr,
            strategy: e.strategy,
            seed: e.seed,
        })
    }
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};

    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct Sample {
        #[serde(with = "super::scalar")]
        one: f64,
        #[serde(with = "super::vector")]
        many: Vec<f64>,
        #[serde(with = "super::matrix")]
        rows: Vec<Vec<f64>>,
    }

    #[test]
    fn plain_json_floats_are_not_exact() {
        // Guards the reason this module exists: if serde_json ever parses
        // these exactly (e.g. its `float_roundtrip` feature gets enabled),
        // this fails and the bit encoding could be reconsidered.
        for value in [4.478_604_724_313_871_5e-4_f64, 2.193_245_804_838_001e-14] {
            let text = serde_json::to_string(&value).expect("serialise");
            let back: f64 = serde_json::from_str(&text).expect("deserialise");
            assert_ne!(back.to_bits(), value.to_bits(), "{text}");
        }
        assert_eq!(
            serde_json::to_string(&f64::INFINITY).expect("serialise"),
            "null"
        );
    }

    #[test]
    fn awkward_values_survive_json_bit_for_bit() {
        // Values with 17 significant digits are the ones serde_json's fast
        // parser can round wrongly; infinities and NaN become null in plain JSON.
        let awkward = [
            0.1 + 0.2,
            1.0 / 3.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE / 3.0,
            -0.0,
            4.478_604_724_313_871_5e-4,
            2.193_245_804_838_001e-14,
        ];
        let sample = Sample {
            one: 0.1 + 0.7,
            many: awkward.to_vec(),
            rows: vec![awkward.to_vec(), vec![], awkward[..3].to_vec()],
        };
        let text = serde_json::to_string(&sample).expect("serialise");
        let back: Sample = serde_json::from_str(&text).expect("deserialise");
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(back.one.to_bits(), sample.one.to_bits());
        assert_eq!(bits(&back.many), bits(&sample.many));
        assert_eq!(back.rows.len(), sample.rows.len());
        for (a, b) in back.rows.iter().zip(&sample.rows) {
            assert_eq!(bits(a), bits(b));
        }
    }
}
