//! The environment variables scenefit reads, all of them here at the
//! command line's edge: each fills an option its flag left unset, so a flag
//! wins over its variable and the library below sees typed options only
//! (`RenderOptions`, the report's font). Documented in docs/usage.md.

use crate::error::{Error, Result};
use crate::render::RenderOptions;
use std::path::PathBuf;

/// Seconds one render may take (`--render-timeout`).
pub const RENDER_TIMEOUT: &str = "SCENEFIT_RENDER_TIMEOUT";
/// Renders a persistent worker serves before its restart (`--worker-max-renders`).
pub const MAX_RENDERS: &str = "SCENEFIT_WORKER_MAX_RENDERS";
/// The Python that runs the Mitsuba worker (`--python`).
pub const PYTHON: &str = "SCENEFIT_PYTHON";
/// The report figures' font (`--font`).
pub const FONT: &str = "SCENEFIT_FONT";

/// A variable's value, unset when empty or blank.
fn var(key: &str) -> Option<String> {
    std::env::var(key).ok().filter(|s| !s.trim().is_empty())
}

/// `opts` with what its flags left unset taken from the environment.
pub fn render_options(opts: RenderOptions) -> Result<RenderOptions> {
    fill(opts, var)
}

/// [`render_options`] over any source of variables. A variable its flag
/// overrides is not read, so an unusable value there is no error.
fn fill(mut o: RenderOptions, var: impl Fn(&str) -> Option<String>) -> Result<RenderOptions> {
    if o.render_timeout.is_none() {
        if let Some(s) = var(RENDER_TIMEOUT) {
            let t = crate::exec::parse_seconds(&s).ok_or_else(|| {
                Error::Usage(format!(
                    "{RENDER_TIMEOUT}={s}: expected a number of seconds > 0, e.g. 120"
                ))
            })?;
            o.render_timeout = Some(t);
        }
    }
    if o.worker_max_renders.is_none() {
        if let Some(s) = var(MAX_RENDERS) {
            let n = s.trim().parse::<usize>().ok().filter(|n| *n > 0);
            o.worker_max_renders = Some(n.ok_or_else(|| {
                Error::Usage(format!(
                    "{MAX_RENDERS}={s}: expected a whole number of renders >= 1, e.g. 200"
                ))
            })?);
        }
    }
    if o.python.is_none() {
        o.python = var(PYTHON).map(PathBuf::from);
    }
    Ok(o)
}

/// The report figures' font: the one `flag` names, else the one
/// `SCENEFIT_FONT` names (None: a system font), with what named it.
pub fn font(flag: Option<PathBuf>) -> Option<(&'static str, PathBuf)> {
    match flag {
        Some(p) => Some(("--font", p)),
        None => std::env::var_os(FONT).map(|p| (FONT, PathBuf::from(p))),
    }
}

/// Draws the report's figures with the font [`font`] finds.
pub fn use_font(flag: Option<PathBuf>) -> Result<()> {
    match font(flag) {
        Some((source, path)) => crate::report::font::use_file(source, path),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn vars(pairs: &'static [(&'static str, &'static str)]) -> impl Fn(&str) -> Option<String> {
        move |k| {
            pairs
                .iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn variables_fill_what_the_flags_left_unset() {
        let env = vars(&[
            (RENDER_TIMEOUT, "2.5"),
            (MAX_RENDERS, "7"),
            (PYTHON, "/opt/py"),
        ]);
        let o = fill(RenderOptions::default(), &env).unwrap();
        assert_eq!(o.render_timeout, Some(Duration::from_millis(2500)));
        assert_eq!(o.worker_max_renders, Some(7));
        assert_eq!(o.python, Some(PathBuf::from("/opt/py")));
        let flags = RenderOptions {
            render_timeout: Some(Duration::from_secs(9)),
            worker_max_renders: Some(3),
            python: Some("/usr/bin/python3".into()),
            ..Default::default()
        };
        assert_eq!(fill(flags.clone(), &env).unwrap(), flags);
    }

    #[test]
    fn an_unusable_variable_is_an_error_naming_it_unless_its_flag_is_given() {
        let env = vars(&[(RENDER_TIMEOUT, "soon"), (MAX_RENDERS, "0")]);
        let e = fill(RenderOptions::default(), &env)
            .unwrap_err()
            .to_string();
        assert!(e.contains("SCENEFIT_RENDER_TIMEOUT=soon"), "{e}");
        let timeout = RenderOptions {
            render_timeout: Some(Duration::from_secs(1)),
            ..Default::default()
        };
        let e = fill(timeout, &env).unwrap_err().to_string();
        assert!(e.contains("SCENEFIT_WORKER_MAX_RENDERS=0"), "{e}");
    }
}
