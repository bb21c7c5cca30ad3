//! What a backend is to the registry (`registry.rs`): its name, a line
//! about it, how it is built and what in a scene it refuses. A leaf the
//! backends and the registry both use, so that neither imports the other
//! for it.

use super::{RenderOptions, Renderer};
use crate::scene::Scene;

/// A scene field a backend cannot draw, and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// The field's path in the scene, e.g. `objects.ball.material.fresnel`.
    pub field: String,
    /// Why, and what to use instead.
    pub why: String,
}

impl Refusal {
    pub fn new(field: impl Into<String>, why: impl Into<String>) -> Refusal {
        Refusal {
            field: field.into(),
            why: why.into(),
        }
    }
}

/// One backend.
pub struct Backend {
    /// The name on the command line; for a plug-in, the prefix before its
    /// command (`cmd:`).
    pub name: &'static str,
    /// For a plug-in, what follows the prefix (`TEMPLATE`); None for a
    /// plain name.
    pub arg: Option<&'static str>,
    /// One line: what draws the image.
    pub about: &'static str,
    /// The backend, given what follows the prefix (empty for a plain name).
    pub build: fn(&str, RenderOptions) -> Box<dyn Renderer>,
    /// Every field of the scene it cannot draw, and why; empty if it draws
    /// all of it.
    pub supports: fn(&Scene) -> Vec<Refusal>,
}

impl Backend {
    /// How the name is written in help and errors: `phong`, `cmd:TEMPLATE`.
    pub fn usage(&self) -> String {
        format!("{}{}", self.name, self.arg.unwrap_or(""))
    }
}
