//! How a diagnosis searches: the budgets of its refits and the criterion's
//! thresholds.

/// How a diagnosis searches.
#[derive(Clone, Debug)]
pub struct DiagnoseConfig {
    pub renderer: String,
    /// DE population of each refit.
    pub population: usize,
    /// DE population while searching the new effect's parameters.
    pub search_population: usize,
    /// Generations searching the new effect's parameters alone.
    pub search_generations: usize,
    /// Generations refining every parameter together.
    pub refine_generations: usize,
    /// Unit-cube radius of the warm start of the joint refit.
    pub start_radius: f64,
    /// Generations of the final refit of an accepted effect's model (every
    /// parameter, warm-started within `polish_radius`): the refits that
    /// choose between effects are short and start close, so parameters the
    /// fit without the effect had bent far to absorb it stay bent.
    pub polish_generations: usize,
    pub polish_radius: f64,
    /// Generations of a refit from scratch (every parameter over its
    /// bounds, the current values one individual of the start) of each
    /// extended model, besides its warm refit: a fit without an effect may
    /// sit in a basin where other parameters fake it (a response faked by
    /// a broad specular lobe and a tilted light) that no warm start
    /// leaves. The unchanged model gets the same restart, so that a better
    /// basin is not credited to an effect. 0: none.
    pub restart_generations: usize,
    pub restart_population: usize,
    /// Effects accepted at most.
    pub max_rounds: usize,
    /// The effects tried, by name (None: every effect in the registry);
    /// a user's own baseline, e.g. a per-texel Lambertian model as
    /// `albedo_map` alone on a matte fit.
    pub effects: Option<Vec<String>>,
    /// Least relative drop of the residual sum of squares to accept.
    pub min_gain: f64,
    /// BIC must drop by more than this.
    pub bic_margin: f64,
    pub seed: u64,
    pub jobs: usize,
    /// How renderer processes run (timeouts, worker restarts, Python).
    pub render_options: crate::render::RenderOptions,
    /// Refit the shared free entries that move geometry too, instead of
    /// holding them where the fit put them (`held.rs`).
    pub refit_geometry: bool,
    /// The side of the colour maps `albedo_map` solves, texels (None:
    /// chosen from how many pixels see each object, `texel_layout.rs`).
    pub map_size: Option<u32>,
}

impl Default for DiagnoseConfig {
    fn default() -> Self {
        DiagnoseConfig {
            renderer: "phong".into(),
            population: 16,
            search_population: 24,
            search_generations: 40,
            refine_generations: 40,
            start_radius: 0.2,
            polish_generations: 80,
            polish_radius: 0.25,
            restart_generations: 250,
            restart_population: 40,
            max_rounds: 3,
            effects: None,
            min_gain: 0.05,
            bic_margin: 10.0,
            seed: 1,
            jobs: std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1),
            render_options: Default::default(),
            refit_geometry: false,
            map_size: None,
        }
    }
}
