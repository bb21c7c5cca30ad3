//! `scenefit export SCENE.json --to blender|mitsuba -o OUT`: a scene in
//! another tool's format (docs/interchange.md). Each target's logic lives
//! in src/interchange/; this file only dispatches on `--to`.

use crate::error::{Error, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// The scene file (JSON).
    scene: PathBuf,
    /// The format to write: blender (a .blend) or mitsuba (XML).
    #[arg(long, value_name = "FORMAT")]
    to: String,
    /// The file to write (never replaced: it must not exist).
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(a: ExportArgs) -> Result<()> {
    match a.to.as_str() {
        "blender" => crate::interchange::blend_export::export(&a.scene, &a.output)?,
        other => {
            return Err(Error::Usage(format!(
                "--to {other}: not built yet; expected blender"
            )))
        }
    }
    println!("{} written", a.output.display());
    Ok(())
}
