//! How a fit runs (`FitConfig`) and what each generation tells the
//! observers (`GenerationReport`): what the fit, its executor, its
//! observers and a set fit share.

use crate::metric::Deviation;
use crate::optimize::DeConfig;
use crate::raster::Image;
use crate::rundir::Mode;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// How a fit runs.
#[derive(Clone, Debug)]
pub struct FitConfig {
    pub de: DeConfig,
    /// Generations over all phases (the paper: 500).
    pub generations: usize,
    /// Generations per phase; default: `generations` split evenly.
    pub phase_generations: Option<Vec<usize>>,
    /// Stop once the average deviation (%) is at or below this.
    pub target_deviation: Option<f64>,
    /// Stop a phase after this many generations without improvement.
    pub stagnation: Option<usize>,
    /// Renders at once.
    pub jobs: usize,
    /// What to do with what is already in the run directory.
    pub mode: Mode,
    /// Start the search around the scene's own values (unit-cube radius)
    /// instead of uniformly over the bounds.
    pub start_radius: Option<f64>,
    /// Snapshots (best_gNNNN.bmp, progress.txt lines) every this many generations.
    pub snapshot_every: usize,
    /// Set from outside (Ctrl-C) to stop after the current generation.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// Input files besides the target (a mask) that the run must not
    /// overwrite, with the option that named each.
    pub inputs: Vec<(String, PathBuf)>,
    /// End a hybrid search once it has settled
    /// ([`crate::optimize::Hybrid::settle`]), the generations a cap only.
    pub settle: bool,
}

impl Default for FitConfig {
    fn default() -> Self {
        FitConfig {
            de: DeConfig::default(),
            generations: 500,
            phase_generations: None,
            target_deviation: None,
            stagnation: None,
            jobs: std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1),
            mode: Mode::Fresh,
            start_radius: None,
            snapshot_every: 10,
            interrupt: None,
            inputs: Vec::new(),
            settle: false,
        }
    }
}

/// A generation's news, for progress displays and logs.
pub struct GenerationReport<'a> {
    pub generation: usize,
    pub total_generations: usize,
    pub evaluations: usize,
    pub best: Deviation,
    pub renders_per_second: f64,
    pub elapsed: f64,
    pub phase: u32,
    pub failures: &'a [String],
    /// The best parameters so far.
    pub params: serde_json::Map<String, serde_json::Value>,
    pub best_image: Option<&'a Image>,
}
