//! The backends, as one list (`ALL`) like the diagnosis's effects: each
//! entry names a backend, says in a line what it is, builds it from the
//! caller's options and says what in a scene it cannot draw (`supports`).
//! Choosing a backend by name, listing the names and refusing a scene
//! before any renderer starts all go through this list; plug-ins
//! (`cmd:`, `worker:`) are entries whose name is a prefix.

pub use super::backend::{Backend, Refusal};
use super::camera_effects::CameraEffects;
use super::layer::{Layer, Layered, Prepared};
use super::near_lights::NearLights;
use super::{phong, RenderOptions, Renderer};
use crate::error::{Error, Result};
use crate::scene::{ParamSpace, Scene};
use std::borrow::Cow;

/// The built-in tracer: draws every field (it is the model) but the
/// texture maps it does not draw yet (`maps.rs`).
const PHONG: Backend = Backend {
    name: "phong",
    arg: None,
    about: "the built-in Whitted-style tracer (the model every other backend is matched to)",
    build: |_, _| Box::new(phong::Phong),
    supports: |s| super::maps::refusals(s, "phong", super::maps::PHONG),
};

/// Every backend, in the order help and errors list them.
pub static ALL: &[Backend] = &[
    PHONG,
    super::povray::BACKEND,
    super::blender::BACKEND,
    super::mitsuba::BACKEND,
    super::command::ONE_SHOT,
    super::command::WORKER,
];

/// The entry `spec` names, and what follows its prefix (empty for a plain
/// name). An unknown name is a usage error listing the known ones.
pub fn find(spec: &str) -> Result<(&'static Backend, &str)> {
    for b in ALL {
        match b.arg {
            None if spec == b.name => return Ok((b, "")),
            Some(_) if spec.starts_with(b.name) => return Ok((b, &spec[b.name.len()..])),
            _ => {}
        }
    }
    let names: Vec<String> = ALL.iter().map(Backend::usage).collect();
    let (last, rest) = names.split_last().expect("ALL is not empty");
    Err(Error::Usage(format!(
        "--renderer {spec}: unknown renderer; expected {} or {last}",
        rest.join(", ")
    )))
}

/// The backend named by `spec`, refusing, before its session starts, any
/// scene with a field it cannot draw.
pub fn build(spec: &str, opts: &RenderOptions) -> Result<Box<dyn Renderer>> {
    let (entry, rest) = find(spec)?;
    let inner = (entry.build)(rest, opts.clone());
    let name = inner.name();
    Ok(Box::new(Layered::new(Checked { entry, name }, inner)))
}

/// A backend's `supports` check, as a layer over it.
#[derive(Clone)]
struct Checked {
    entry: &'static Backend,
    name: String,
}

impl Layer for Checked {
    fn prepare<'a>(&self, base: &'a Scene, varying: &'a ParamSpace) -> Prepared<'a> {
        let refused = (self.entry.supports)(base);
        if let Some(first) = refused.first() {
            // one line: the first field in full, the others by name
            let more: Vec<&str> = refused[1..].iter().map(|r| r.field.as_str()).collect();
            let also = if more.is_empty() {
                String::new()
            } else {
                format!(" (also refused: {})", more.join(", "))
            };
            return Err(Error::Usage(format!(
                "{}: {}: {}{also}",
                self.name, first.field, first.why
            )));
        }
        Ok((Cow::Borrowed(base), Cow::Borrowed(varying)))
    }
}

/// The backend named by `spec` (see the module doc), followed by the
/// camera's image-space effects (`camera_effects.rs`), with the defaults.
pub fn from_spec(spec: &str) -> Result<Box<dyn Renderer>> {
    from_spec_with(spec, &RenderOptions::default())
}

/// `from_spec` with the caller's options over the defaults.
pub fn from_spec_with(spec: &str, opts: &RenderOptions) -> Result<Box<dyn Renderer>> {
    let drawn = Layered::new(NearLights, build(spec, opts)?);
    Ok(Box::new(Layered::new(CameraEffects, Box::new(drawn))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_resolve_to_their_entry_and_unknown_names_list_every_entry() {
        for b in ALL {
            let spec = format!("{}{}", b.name, if b.arg.is_some() { "prog" } else { "" });
            let (found, rest) = find(&spec).unwrap();
            assert_eq!(found.name, b.name);
            assert_eq!(rest, if b.arg.is_some() { "prog" } else { "" });
        }
        let e = find("povrey").err().unwrap().to_string();
        for b in ALL {
            assert!(e.contains(&b.usage()), "{e}");
        }
        assert!(e.contains("--renderer povrey"), "{e}");
    }

    #[test]
    fn a_refused_field_stops_the_session_naming_every_refused_field() {
        let mut scene = crate::scene::test_scene::ball(r#""color": [0.5, 0.5, 0.5]"#, "");
        scene.objects[0].material.diffuse_f90 = Some(0.4);
        scene.objects[0].material.fresnel = Some(0.1);
        let r = build("povray", &RenderOptions::default()).unwrap();
        let e = r
            .session(&scene, &ParamSpace::default(), 1)
            .err()
            .unwrap()
            .to_string();
        assert!(e.starts_with("povray: objects."), "{e}");
        assert!(
            e.contains("material.fresnel") && e.contains("material.diffuse_f90"),
            "{e}"
        );
        assert!(build("phong", &RenderOptions::default())
            .unwrap()
            .session(&scene, &ParamSpace::default(), 1)
            .is_ok());
    }
}
