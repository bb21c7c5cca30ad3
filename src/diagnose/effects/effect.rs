//! The `Effect` trait: what each effect in the registry (`ALL`) says about
//! itself — its evidence features, how it extends a scene, its starts and
//! other forms, and what it trades with.

use super::edit::Trades;
use crate::diagnose::features::Features;
use crate::scene::texture::MapKind;
use crate::scene::{FreeParam, Scene};

/// One effect of the library.
pub trait Effect: Sync {
    /// Its name in diagnosis.json.
    fn name(&self) -> &'static str;

    /// Feature maps (one value per pixel each) whose regression explains
    /// the residual a model without the effect leaves; computed from the
    /// render alone.
    fn features(&self, f: &Features) -> Vec<Vec<f64>>;

    /// `scene` with the effect at its neutral value and the free entries
    /// it adds (not yet in the scene's free list); None when it does not
    /// apply (already there, or nothing it could act on).
    fn extend(&self, scene: &Scene) -> Option<(Scene, Vec<FreeParam>)>;

    /// Other starts for its search besides `extended` (whose free list
    /// holds `added`): the parameters a fit without the effect had bent
    /// to absorb it, bent back.
    fn starts(&self, _extended: &Scene, _added: &[FreeParam]) -> Vec<Scene> {
        Vec::new()
    }

    /// Other forms of the effect that none of its numbers moves between,
    /// each built from `extended` (the neutral form): the camera's response
    /// written as linear values besides through the sRGB curve. Each form
    /// is refitted from its own best start and the best refit counts, so a
    /// form that starts further from the target but ends closer is not
    /// lost to the start's comparison.
    fn variants(&self, _extended: &Scene) -> Vec<Scene> {
        Vec::new()
    }

    /// What its own parameters are searched with: the fitted parameters it
    /// trades with, and how far from the start the search spreads.
    fn trades(&self) -> Trades {
        Trades::default()
    }

    /// The kind of texture a closed-form effect solves, one value per
    /// texel (`albedo_map` a colour map, `specular_map` a specular one,
    /// solved in `diagnose/albedo.rs`); None for a searched effect.
    fn map_kind(&self) -> Option<MapKind> {
        None
    }

    /// Every kind of texture the effect's solve may write: its
    /// [`Effect::map_kind`] first, then any it solves beside it
    /// (`specular_map` a shininess map where the highlights' widths vary).
    fn written_kinds(&self) -> Vec<MapKind> {
        self.map_kind().into_iter().collect()
    }

    /// True for an effect solved in closed form rather than searched (a
    /// map: [`Effect::map_kind`]); its `extend` adds no free entries.
    fn closed_form(&self) -> bool {
        self.map_kind().is_some()
    }

    /// True for an effect only a set of photographs can tell apart from
    /// the model (one photograph's light colour is its material's): the
    /// diagnosis of one photograph does not try it.
    fn set_only(&self) -> bool {
        false
    }

    /// True when it can be added to `scene`.
    fn applies(&self, scene: &Scene) -> bool {
        if self.closed_form() {
            return self.extend(scene).is_some();
        }
        self.extend(scene)
            .is_some_and(|(_, added)| !added.is_empty())
    }
}
