//! The font the figures' text is drawn with. plotters draws text through
//! ab_glyph from a font registered by name; a font file is read once from
//! the system (DejaVu Sans on Debian, package fonts-dejavu-core) or from
//! the file the caller names (the command line's `--font` or
//! `SCENEFIT_FONT`, read in `cli::env`), rather than linking fontconfig or
//! shipping a font in the binary.

use crate::error::{Error, Result};
use plotters::style::{register_font, FontStyle};
use std::path::PathBuf;
use std::sync::OnceLock;

/// The font the caller named, and where it was named (for errors).
static NAMED: OnceLock<(&'static str, PathBuf)> = OnceLock::new();

/// Uses this font file for the figures, ahead of the system's fonts;
/// `source` says where it was named (`--font`). Call before the first
/// figure (later calls are ignored).
pub fn use_file(source: &'static str, path: PathBuf) {
    let _ = NAMED.set((source, path));
}

/// Where to look, in order, when the caller named no font.
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
    // A named font that cannot be read is an error rather than silently
    // replaced by a system font.
    if let Some((source, path)) = NAMED.get() {
        return register(path).ok_or_else(|| {
            format!(
                "{source} {}: not a readable TrueType font; the report's figures need one",
                path.display()
            )
        });
    }
    for path in CANDIDATES.iter().map(PathBuf::from) {
        if register(&path).is_some() {
            return Ok(());
        }
    }
    Err("no TrueType font found for the report's figures: install one (Debian: apt-get install fonts-dejavu-core), pass --font /path/to/font.ttf or set SCENEFIT_FONT".into())
}

/// Registers the font in this file as "sans-serif"; `None` if it cannot be
/// read or is not a font.
fn register(path: &std::path::Path) -> Option<()> {
    let bytes = std::fs::read(path).ok()?;
    // plotters keeps fonts for the life of the process; one font file,
    // once, is what is leaked.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    register_font("sans-serif", FontStyle::Normal, bytes).ok()
}
