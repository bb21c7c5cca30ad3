//! Value parsers the commands share (clap's `value_parser`), so that each
//! option of a kind refuses a bad value with the same message.

/// A clap value parser for counts (`--population`, `--width`): a whole
/// number of at least 1. Options using it also allow hyphen values, so
/// that `--population -5` reaches it and the message names the option.
pub(crate) fn positive_count(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err("expected a positive whole number (1, 2, ...)".into()),
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
