//! A layer over another renderer: something done to every scene before
//! the backend draws it, or to every image after (near lights lowered to
//! point lights, the camera's image-space effects, the registry's refusal
//! of what a backend cannot draw). The layered renderer keeps the inner
//! one's name and default jobs; a layer says only what it changes.

use super::{Image, RenderResult, RenderSession, Renderer};
use crate::error::Result;
use crate::scene::{ParamSpace, Scene};
use std::borrow::Cow;

/// The base scene and varying parameters the inner renderer prepares for.
pub type Prepared<'a> = Result<(Cow<'a, Scene>, Cow<'a, ParamSpace>)>;

/// What a layer changes.
pub trait Layer: Clone + Send + Sync + 'static {
    /// The base scene and varying parameters the inner renderer sees, or
    /// why the scene is refused before any renderer starts.
    fn prepare<'a>(&self, base: &'a Scene, varying: &'a ParamSpace) -> Prepared<'a> {
        Ok((Cow::Borrowed(base), Cow::Borrowed(varying)))
    }

    /// The scenes the inner session draws instead of `scenes`; None: those.
    fn before(&self, _scenes: &[Scene]) -> Option<Vec<Scene>> {
        None
    }

    /// What happens to the image of `scene` once drawn.
    fn after(&self, _scene: &Scene, _image: &mut Image) {}
}

/// A renderer drawn through a layer.
pub struct Layered<L> {
    pub inner: Box<dyn Renderer>,
    pub layer: L,
}

impl<L: Layer> Layered<L> {
    pub fn new(layer: L, inner: Box<dyn Renderer>) -> Layered<L> {
        Layered { inner, layer }
    }
}

impl<L: Layer> Renderer for Layered<L> {
    fn name(&self) -> String {
        self.inner.name()
    }

    fn default_jobs(&self) -> usize {
        self.inner.default_jobs()
    }

    fn session(
        &self,
        base: &Scene,
        varying: &ParamSpace,
        jobs: usize,
    ) -> Result<Box<dyn RenderSession>> {
        let (base, varying) = self.layer.prepare(base, varying)?;
        Ok(Box::new(LayeredSession {
            inner: self.inner.session(&base, &varying, jobs)?,
            layer: self.layer.clone(),
        }))
    }
}

/// A session drawn through a layer.
struct LayeredSession<L> {
    inner: Box<dyn RenderSession>,
    layer: L,
}

impl<L: Layer> RenderSession for LayeredSession<L> {
    fn describe(&self) -> String {
        self.inner.describe()
    }

    fn render_batch(&mut self, scenes: &[Scene], seed: u64) -> Vec<RenderResult> {
        let drawn = self.layer.before(scenes);
        let mut out = self
            .inner
            .render_batch(drawn.as_deref().unwrap_or(scenes), seed);
        for (res, scene) in out.iter_mut().zip(scenes) {
            if let Ok(image) = res {
                self.layer.after(scene, image);
            }
        }
        out
    }
}
