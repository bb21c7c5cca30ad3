//! The value parsers of every numeric option. Each option that uses one
//! also allows hyphen values (`allow_hyphen_values`), so that `--workers -1`
//! reaches the parser and clap's message names the option, the value and
//! what was expected, instead of "unexpected argument '-1'".

/// Renderer workers at most (`--workers`): more could never start (a
/// batch uses one per candidate) and a pool's slots are allocated up front.
pub const MAX_WORKERS: usize = 65536;

/// A count (`--population`, `--rounds`): a whole number of at least 1.
pub(crate) fn positive_count(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err("expected a positive whole number (1, 2, ...)".into()),
    }
}

/// A count that may be 0 (`--stagnation`, `--restart-generations`).
pub(crate) fn whole(s: &str) -> Result<usize, String> {
    s.trim()
        .parse::<usize>()
        .map_err(|_| "expected a whole number (0, 1, 2, ...)".into())
}

/// `--workers`: 1 to [`MAX_WORKERS`].
pub(crate) fn workers(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=MAX_WORKERS).contains(&n) => Ok(n),
        _ => Err(format!("expected a whole number from 1 to {MAX_WORKERS}")),
    }
}

/// `diagnose --map-size`: 1 to the largest side of a solved map.
pub(crate) fn map_size(s: &str) -> Result<u32, String> {
    let max = crate::diagnose::MAX_MAP_SIDE;
    match s.trim().parse::<u32>() {
        Ok(n) if (1..=max).contains(&n) => Ok(n),
        _ => Err(format!(
            "expected a whole number from 1 to {max} (texels a side)"
        )),
    }
}

/// A seed: a whole number from 0 to 2^64 - 1.
pub(crate) fn seed(s: &str) -> Result<u64, String> {
    s.trim()
        .parse::<u64>()
        .map_err(|_| format!("expected a whole number from 0 to {}", u64::MAX))
}

/// A finite number (`--f`, `--stage2-window`); its range is checked
/// where the value is used.
pub(crate) fn number(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err("expected a finite number, e.g. 0.5".into()),
    }
}

/// A fraction from 0 up to, not including, 1 (`diagnose --min-gain`).
pub(crate) fn fraction(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if (0.0..1.0).contains(&x) => Ok(x),
        _ => Err("expected a fraction from 0 up to 1, e.g. 0.05".into()),
    }
}

/// `positive_count` for pixel sizes: 1 to the scene format's limit.
pub(crate) fn pixels(s: &str) -> Result<u32, String> {
    let max = crate::scene::limits::MAX_IMAGE_SIDE;
    match s.trim().parse::<u32>() {
        Ok(n) if (1..=max).contains(&n) => Ok(n),
        _ => Err(format!("expected a whole number of pixels from 1 to {max}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_and_malformed_values_are_refused() {
        for s in ["-1", "abc", "1.5", ""] {
            assert!(positive_count(s).is_err(), "{s}");
            assert!(whole(s).is_err(), "{s}");
            assert!(workers(s).is_err(), "{s}");
            assert!(seed(s).is_err(), "{s}");
        }
        assert!(positive_count("0").is_err());
        assert_eq!(whole("0"), Ok(0));
        assert_eq!(seed("0"), Ok(0));
        assert_eq!(positive_count(" 7 "), Ok(7));
    }

    #[test]
    fn workers_are_bounded() {
        assert_eq!(workers("8"), Ok(8));
        assert!(workers(&MAX_WORKERS.to_string()).is_ok());
        assert!(workers(&(MAX_WORKERS + 1).to_string()).is_err());
        assert!(workers("1000000000").is_err());
    }

    #[test]
    fn numbers_are_finite() {
        assert_eq!(number("-0.5"), Ok(-0.5));
        for s in ["nan", "inf", "-inf", "x"] {
            assert!(number(s).is_err(), "{s}");
        }
    }

    #[test]
    fn fractions_are_below_one() {
        assert_eq!(fraction("0"), Ok(0.0));
        assert_eq!(fraction("0.05"), Ok(0.05));
        for s in ["1", "-0.01", "nan", "x"] {
            assert!(fraction(s).is_err(), "{s}");
        }
    }
}
