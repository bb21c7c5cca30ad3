//! A fit through the API: the scene fitted to a list of photographs. One
//! photograph given on its own (`fit --target`) is a list of one; what
//! differs between it and a set (`fit --shots`) is carried as data: the
//! run directory it writes and how many copies of each candidate the
//! memory check counts.

use crate::error::Result;
use crate::fit::set::shots::Shot;
use crate::fit::set::{SetConfig, SetOutcome};
use crate::fit::FitTarget;
use crate::fit::{FitConfig, FitOutcome, FitResult, Observer};
use crate::render::Renderer;
use crate::scene::memory::Population;
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// The photographs a fit matches.
#[derive(Clone, Debug)]
pub struct Photographs {
    pub shots: Vec<Shot>,
    /// The shots file they were read from (a set's run directory: its
    /// `shots.json`, one best image each, its state in `checkpoint.json`), or None for
    /// one photograph given on its own (`checkpoint.json`, `best.png`).
    pub file: Option<PathBuf>,
}

impl Photographs {
    /// One photograph of `scene`, given on its own.
    pub fn one(scene: &Scene, target: FitTarget) -> Photographs {
        Photographs {
            shots: vec![Shot::one(scene, target)],
            file: None,
        }
    }
}

/// Everything a fit needs besides its photographs and run directory.
pub struct FitRequest<'a> {
    pub scene: &'a Scene,
    /// The scene's file: named in messages, and never overwritten by the run.
    pub scene_file: &'a Path,
    /// Other input files the run must not overwrite, with the option that
    /// named each (a mask).
    pub inputs: Vec<(String, PathBuf)>,
    pub renderer: &'a dyn Renderer,
    /// The search; `mode` says what to do with an earlier run in the
    /// directory, `interrupt` stops the run after the current generation.
    pub config: FitConfig,
    /// A set's alternations of the shared and per-shot blocks at most.
    pub rounds: usize,
    /// A set ends with one joint Levenberg–Marquardt block.
    pub joint: bool,
}

/// What a fit returns: one photograph's outcome or a set's.
pub enum Fitted {
    One(Box<FitOutcome>),
    Set(Box<SetOutcome>),
}

impl Fitted {
    /// The fit's result.json as held in memory (over every photograph).
    pub fn result(&self) -> &FitResult {
        match self {
            Fitted::One(o) => &o.result,
            Fitted::Set(o) => &o.result,
        }
    }

    /// The largest average deviation of one photograph of a set.
    pub fn worst(&self) -> Option<f64> {
        match self {
            Fitted::One(_) => None,
            Fitted::Set(o) => Some(
                o.shots
                    .iter()
                    .map(|s| s.result.deviation.average)
                    .fold(0.0, f64::max),
            ),
        }
    }
}

/// Refuses the fit when its `shots` photographs would need more memory
/// than the machine has: the one estimate (`scene::memory`), from the
/// scene's image size, the population and the jobs. A caller may check
/// before it decodes any photograph (a huge image is then refused at
/// once); `fit` checks again with the photographs it is given.
pub fn check_memory(request: &FitRequest, shots: usize) -> Result<()> {
    let FitRequest { scene, config, .. } = request;
    let pop = Population {
        option: "--population",
        size: config.de.population,
        copies: shots,
    };
    let size = (scene.image.width, scene.image.height);
    let avail = crate::scene::memory::available();
    let file = request.scene_file.display().to_string();
    crate::scene::memory::check_fit(avail, &file, size, pop, config.jobs)
}

/// Fits `request.scene` to `photos` in the run directory `dir`, once the
/// memory it needs has been checked.
pub fn fit(
    request: FitRequest,
    photos: &Photographs,
    dir: &Path,
    observer: &mut dyn Observer,
) -> Result<Fitted> {
    check_memory(&request, photos.shots.len())?;
    let mut config = request.config;
    config.inputs = request.inputs;
    config
        .inputs
        .push(("the scene".into(), request.scene_file.to_path_buf()));
    let (renderer, scene) = (request.renderer, request.scene);
    // One photograph given on its own keeps one photograph's run
    // directory and is fitted phase after phase; a shots file's are
    // fitted by blocks. Both through the one fit path.
    let alone = photos.file.is_none() && photos.shots.len() == 1;
    config
        .inputs
        .extend(photos.file.iter().map(|f| ("--shots".into(), f.clone())));
    let run_dir = crate::fit::set::driver::open(dir, &photos.shots, alone, &config)?;
    let set = SetConfig {
        spread: Vec::new(),
        fit: config,
        rounds: request.rounds,
        warm: false,
        joint: request.joint,
    };
    let (dir, shots) = (Some(&run_dir), photos.shots.as_slice());
    if alone {
        crate::fit::set::phase::run_one(scene, &shots[0].target, renderer, &set.fit, dir, observer)
            .map(|o| Fitted::One(Box::new(o)))
    } else {
        crate::fit::set::run_in(scene, shots, renderer, &set, dir, observer)
            .map(|o| Fitted::Set(Box::new(o)))
    }
}
