//! `scenefit import FILE -o scene.json [--free GLOB...]`: another tool's
//! scene read into a scenefit scene (docs/interchange.md), dispatched by the
//! file's extension; each format's logic lives in src/interchange/.

use crate::error::{Error, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ImportArgs {
    /// The scene to read: a .blend file.
    file: PathBuf,
    /// The scene file to write (JSON); meshes and unpacked images go beside it.
    #[arg(short, long)]
    output: PathBuf,
    /// Make the fields this glob matches free, at their default bounds
    /// (`scenefit free`); repeatable.
    #[arg(long = "free", value_name = "GLOB")]
    free: Vec<String>,
}

pub fn run(a: ImportArgs) -> Result<()> {
    let ext = a.file.extension().and_then(|e| e.to_str()).unwrap_or("");
    let warnings = match ext.to_ascii_lowercase().as_str() {
        "blend" => crate::interchange::blend_import::import(&a.file, &a.output, &a.free)?,
        _ => {
            return Err(Error::Usage(format!(
                "{}: not built yet for this extension; expected a .blend file",
                a.file.display()
            )))
        }
    };
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    println!("{} written", a.output.display());
    Ok(())
}
