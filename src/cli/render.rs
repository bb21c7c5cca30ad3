//! `scenefit render SCENE -o OUT.png [--renderer R] [--set P=V]... [--width W --height H]`

use crate::api;
use crate::error::{Error, Result};
use crate::raster::io as image_io;
use crate::scene::Override;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The scene file (JSON).
    scene: PathBuf,
    /// Where to write the image (.png or .bmp).
    #[arg(short, long)]
    output: PathBuf,
    /// phong, povray, blender, mitsuba, cmd:TEMPLATE or worker:COMMAND.
    #[arg(long, default_value = "phong")]
    renderer: String,
    /// Override a field: PARAM=JSON, e.g. lights.key.position=[1,2,3].
    #[arg(long = "set", value_name = "PARAM=JSON")]
    set: Vec<Override>,
    /// Image width (overrides the scene's).
    #[arg(long, allow_hyphen_values = true, value_parser = super::numbers::pixels)]
    width: Option<u32>,
    /// Image height (overrides the scene's).
    #[arg(long, allow_hyphen_values = true, value_parser = super::numbers::pixels)]
    height: Option<u32>,
    /// Sampler seed for sampling renderers.
    #[arg(long, default_value_t = 0, value_parser = super::numbers::seed, allow_hyphen_values = true)]
    seed: u64,
    #[command(flatten)]
    render_options: super::renderer_args::RendererArgs,
}

pub fn run(a: RenderArgs) -> Result<()> {
    // Where the image goes is checked before any rendering.
    if a.output.is_dir() {
        return Err(Error::Usage(format!(
            "-o {}: is a directory; expected an image file name ending in .png or .bmp",
            a.output.display()
        )));
    }
    image_io::output_format(&a.output).map_err(|_| {
        Error::Usage(format!(
            "-o {}: expected a file name ending in .png or .bmp",
            a.output.display()
        ))
    })?;
    let mut set = a.set.clone();
    for (key, v) in [("image.width", a.width), ("image.height", a.height)] {
        if let Some(v) = v {
            set.push(Override {
                path: key.into(),
                value: v.into(),
            });
        }
    }
    let scene = api::load_scene(&a.scene, &set)?;
    let renderer = api::renderer(&a.renderer, &a.render_options.options()?)?;
    let img = api::render(
        &scene,
        &a.scene.display().to_string(),
        renderer.as_ref(),
        a.seed,
    )?;
    image_io::write_image(&img, &a.output)
}
