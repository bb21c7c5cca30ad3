//! Finding renderer programs on PATH, with an error that says how to
//! install what is missing (a user's problem: exit code 2).

use crate::error::{Error, Result};
use std::path::PathBuf;

/// How to install what scripts/install-renderers.sh installs.
pub const INSTALL_SCRIPT: &str = "scripts/install-renderers.sh";

/// The full path of `program` (a name looked up on PATH, or a path).
/// `install` says how to get it, e.g. "install it with `apt-get install povray`".
pub fn find(program: &str, install: &str) -> Result<PathBuf> {
    which::which(program).map_err(|_| {
        let place = if program.contains('/') {
            "not found or not executable"
        } else {
            "not found on PATH"
        };
        Error::Usage(format!("{program} {place}; {install}"))
    })
}

/// The install advice for a Debian package that the install script also installs.
pub fn apt_hint(package: &str) -> String {
    format!("install it with `apt-get install {package}` or run {INSTALL_SCRIPT}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_program_is_a_usage_error() {
        let e = find("scenefit-no-such-renderer", &apt_hint("nothing")).unwrap_err();
        assert!(e.is_user_error());
        let msg = e.to_string();
        assert!(
            msg.contains("scenefit-no-such-renderer not found on PATH"),
            "{msg}"
        );
        assert!(msg.contains("apt-get install nothing"), "{msg}");
        assert!(find("sh", "").is_ok());
    }
}
