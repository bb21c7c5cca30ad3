//! The scene format (`scenefit-scene/1`, docs/scene-format.md): typed structs,
//! loading with validation, numeric fields addressed by name, and the
//! parameter space that maps the `free` list to a search vector and back.

pub mod albedo_map;
mod checks;
pub mod color;
pub mod field;
pub mod limits;
pub mod load;
pub mod memory;
pub mod mesh;
pub mod nuisance;
pub mod params;
pub mod pinhole;
pub mod shape;
#[cfg(test)]
pub(crate) mod test_scene;
pub mod texture;
pub mod transform;
pub mod types;
pub mod validate;
pub mod written;

pub use field::{Field, Value};
pub use load::{load, load_with, parse, Override};
pub use nuisance::Nuisance;
pub use params::{ParamSpace, ParamSpec};
pub use types::*;
