//! Value checks that name the scene file and the key they refuse:
//! finite, non-negative, positive, non-zero. Shared by the scene's
//! validation and the shapes' own checks (`shape.rs`).

use crate::error::{Error, Result};
use crate::math::{Vec3, V3};

pub(crate) fn finite3(v: Vec3) -> bool {
    v.iter().all(|x| x.is_finite())
}

pub(crate) fn non_negative3(file: &str, key: &str, v: Vec3) -> Result<()> {
    if !finite3(v) || v.iter().any(|&x| x < 0.0) {
        return Err(Error::invalid(
            file,
            key,
            format!("expected three non-negative numbers, got {v:?}"),
        ));
    }
    Ok(())
}

pub(crate) fn non_negative(file: &str, key: &str, x: f64) -> Result<()> {
    if !x.is_finite() || x < 0.0 {
        return Err(Error::invalid(
            file,
            key,
            format!("expected a non-negative number, got {x}"),
        ));
    }
    Ok(())
}

pub(crate) fn positive(file: &str, key: &str, x: f64) -> Result<()> {
    if !x.is_finite() || x <= 0.0 {
        return Err(Error::invalid(
            file,
            key,
            format!("expected a positive number, got {x}"),
        ));
    }
    Ok(())
}

pub(crate) fn nonzero3(file: &str, key: &str, v: Vec3) -> Result<()> {
    if !finite3(v) || V3::from(v).length() < 1e-12 {
        return Err(Error::invalid(
            file,
            key,
            format!("expected a non-zero vector, got {v:?}"),
        ));
    }
    Ok(())
}
