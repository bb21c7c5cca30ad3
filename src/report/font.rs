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
/// figure (later calls are ignored). The font is read at once, so that a
/// bad one is refused before a run whose report would need it, not after.
pub fn use_file(source: &'static str, path: PathBuf) -> Result<()> {
    let _ = NAMED.set((source, path));
    ensure()
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
        return register(path).map_err(|why| {
            format!(
                "{source} {}: {why} (the report's figures need a TrueType font)",
                path.display()
            )
        });
    }
    for path in CANDIDATES.iter().map(PathBuf::from) {
        if register(&path).is_ok() {
            return Ok(());
        }
    }
    Err("no TrueType font found for the report's figures: install one (Debian: apt-get install fonts-dejavu-core), pass --font /path/to/font.ttf or set SCENEFIT_FONT".into())
}

/// Registers the font in this file as "sans-serif"; the error says why
/// not (not a regular file of at most `MAX_FONT_BYTES`, not a font).
fn register(path: &std::path::Path) -> std::result::Result<(), String> {
    use crate::input::{read_capped, CappedRead, MAX_FONT_BYTES};
    let bytes = read_capped(path, MAX_FONT_BYTES).map_err(|e| match e {
        CappedRead::Io(e) => e.to_string(),
        CappedRead::Directory => "a directory; expected a font file".into(),
        CappedRead::TooLarge => format!(
            "larger than {} MiB; expected a font file",
            MAX_FONT_BYTES >> 20
        ),
    })?;
    // plotters keeps fonts for the life of the process; one font file,
    // once, is what is leaked.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    register_font("sans-serif", FontStyle::Normal, bytes).map_err(|_| "not a TrueType font".into())
}
