//! scenefit: recover the optical parameters of a scene from a photograph by
//! rendering in the loop. Data flows one way:
//! scene -> parameter vector -> renderer -> image -> metric -> optimizer.

pub mod api;
pub mod cli;
pub mod diagnose;
pub mod error;
pub mod exec;
pub mod fit;
pub mod fsio;
pub mod input;
pub mod interchange;
pub mod math;
pub mod metric;
pub mod optimize;
pub mod pipeline;
pub mod raster;
pub mod render;
pub mod report;
pub mod rundir;
pub mod scene;
