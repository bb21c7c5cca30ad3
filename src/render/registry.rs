//! The backends by name: `from_spec` turns `phong`, `povray`, `blender`,
//! `mitsuba`, `cmd:TEMPLATE` or `worker:COMMAND` into a renderer, with the
//! rewrites and image-space effects every backend gets around it.

use super::{blender, camera_effects, command, mitsuba, near_lights, phong, povray};
use super::{RenderOptions, Renderer};
use crate::error::{Error, Result};

/// The backend named by `spec` (see the module doc), followed by the
/// camera's image-space effects (`camera_effects.rs`), with the defaults
/// and the environment's settings.
pub fn from_spec(spec: &str) -> Result<Box<dyn Renderer>> {
    from_spec_with(spec, &RenderOptions::default())
}

/// `from_spec` with `opts` over the environment and the defaults.
pub fn from_spec_with(spec: &str, opts: &RenderOptions) -> Result<Box<dyn Renderer>> {
    let drawn = near_lights::WithNearLights(backend(spec, opts)?);
    Ok(Box::new(camera_effects::WithCameraEffects(Box::new(drawn))))
}

/// The bare backend named by `spec`.
fn backend(spec: &str, opts: &RenderOptions) -> Result<Box<dyn Renderer>> {
    let o = opts.clone();
    match spec {
        "phong" => Ok(Box::new(phong::Phong)),
        "povray" => Ok(Box::new(povray::PovRay(o))),
        "blender" => Ok(Box::new(blender::Blender(o))),
        "mitsuba" => Ok(Box::new(mitsuba::Mitsuba(o))),
        s if s.starts_with("cmd:") => Ok(Box::new(command::Command::one_shot(&s["cmd:".len()..], o))),
        s if s.starts_with("worker:") => Ok(Box::new(command::Command::worker(&s["worker:".len()..], o))),
        other => Err(Error::Usage(format!(
            "--renderer {other}: unknown renderer; expected phong, povray, blender, mitsuba, cmd:TEMPLATE or worker:COMMAND"
        ))),
    }
}
