//! The font the figures' text is drawn with. plotters draws text through
//! ab_glyph from a font registered by name; a font file is read once from
//! the system (DejaVu Sans on Debian, package fonts-dejavu-core) or from
//! `SCENEFIT_FONT`, rather than linking fontconfig or shipping a font in
//! the binary.

use crate::error::{Error, Result};
use plotters::style::{register_font, FontStyle};
use std::sync::OnceLock;

/// Where to look, in order, after `SCENEFIT_FONT`.
const CANDIDATES: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/noto/NotoSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "/Library/Fonts/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// Registers a font as "sans-serif" once per process; the error says how
/// to get one.
pub fn ensure() -> Result<()> {
    static DONE: OnceLock<std::result::Result<(), String>> = OnceLock::new();
    DONE.get_or_init(load).clone().map_err(Error::Usage)
}

fn load() -> std::result::Result<(), String> {
    let from_env = std::env::var_os("SCENEFIT_FONT").map(std::path::PathBuf::from);
    let paths = from_env
        .iter()
        .cloned()
        .chain(CANDIDATES.iter().map(std::path::PathBuf::from));
    for path in paths {
        let Ok(bytes) = std::fs::read(&path) else {
            continue;
        };
        // plotters keeps fonts for the life of the process; one font file,
        // once, is what is leaked.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        if register_font("sans-serif", FontStyle::Normal, bytes).is_ok() {
            return Ok(());
        }
    }
    Err(match from_env {
        Some(p) => format!(
            "SCENEFIT_FONT={}: not a readable TrueType font; the report's figures need one",
            p.display()
        ),
        None => "no TrueType font found for the report's figures: install one (Debian: apt-get install fonts-dejavu-core) or set SCENEFIT_FONT=/path/to/font.ttf".into(),
    })
}
