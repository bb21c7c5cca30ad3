//! The last block of a set fit: Levenberg–Marquardt over every coordinate
//! at once, the shared ones and every photograph's own.
//!
//! Block coordinate descent cannot follow a valley in which shared and
//! per-shot parameters trade: a camera response against the material's
//! colour and every photograph's light intensity moves each block only a
//! little before the other block's values hold it back. A joint step moves
//! them together. It is cheap because the Jacobian is block-sparse: a
//! shared coordinate changes every photograph's image, a photograph's own
//! coordinate only its own, so one Jacobian costs
//! Σ_s (1 + shared + own_s) renders, not shots × (1 + all coordinates).
//! The normal equations are summed per photograph (`lm::normal_equations`)
//! into one small dense system (~100 coordinates for 24 photographs).

use super::shots::Shot;
use super::state::FitState;
use super::{block_seed, varying, SetConfig};
use crate::error::{Error, Result};
use crate::fit::counted;
use crate::fit::render_seed;
use crate::metric::{residuals, Deviation};
use crate::optimize::lm::{self, Column, Normal};
use crate::render::{RenderSession, Renderer};
use crate::scene::{ParamSpace, Scene};

const LAMBDA_START: f64 = 1e-3;
const LAMBDA_MIN: f64 = 1e-9;
const LAMBDA_MAX: f64 = 1e8;
const LAMBDA_DOWN: f64 = 1.0 / 3.0;
const LAMBDA_UP: f64 = 8.0;
/// First difference step per coordinate (unit cube); adapted after.
const STEP_START: f64 = 0.01;
/// A step must lower the set's fitness by this fraction to count.
const GAIN_TOLERANCE: f64 = 1e-3;
/// Accepted steps in a row below the tolerance that end the block.
const STALL_STEPS: usize = 3;
/// Rejected trials in a row that end the block (the damping grown
/// `LAMBDA_UP^6` ≈ 2.6e5 times: the step is then a short gradient step
/// that still does not help).
const REJECTS: usize = 6;
/// Jacobians at most: the block polishes a point block descent found; it
/// is not a search.
const MAX_JACOBIANS: usize = 25;

/// Where each photograph's own coordinates sit in the joint vector, after
/// the shared ones.
struct Layout {
    shared: ParamSpace,
    own: Vec<ParamSpace>,
    offsets: Vec<usize>,
    dim: usize,
}

impl Layout {
    fn new(space: &ParamSpace, shots: &[Shot]) -> Layout {
        let shared = space.shared();
        let own: Vec<ParamSpace> = shots.iter().map(|s| s.own_space(space)).collect();
        let mut offsets = Vec::with_capacity(own.len());
        let mut at = shared.dim();
        for o in &own {
            offsets.push(at);
            at += o.dim();
        }
        Layout {
            shared,
            own,
            offsets,
            dim: at,
        }
    }

    fn pack(&self, state: &FitState) -> Vec<f64> {
        let mut x = state.shared.clone();
        for o in &state.own {
            x.extend_from_slice(o);
        }
        x
    }

    fn unpack(&self, x: &[f64], state: &mut FitState) {
        let ns = self.shared.dim();
        state.shared = x[..ns].to_vec();
        for (i, o) in self.own.iter().enumerate() {
            state.own[i] = x[self.offsets[i]..self.offsets[i] + o.dim()].to_vec();
        }
    }

    /// Photograph `i`'s scene at the joint point `x`.
    fn scene(&self, shot: &Shot, i: usize, x: &[f64]) -> Scene {
        let ns = self.shared.dim();
        let s = self.shared.scene_at(&shot.scene, &x[..ns]);
        let own = &self.own[i];
        own.scene_at(&s, &x[self.offsets[i]..self.offsets[i] + own.dim()])
    }

    /// The joint coordinates photograph `i`'s image depends on.
    fn columns_of(&self, i: usize) -> impl Iterator<Item = usize> {
        (0..self.shared.dim()).chain(self.offsets[i]..self.offsets[i] + self.own[i].dim())
    }
}

/// One photograph's residuals at a point, or why it has none.
type Residuals = std::result::Result<Vec<f32>, String>;

/// What the block does with the renderer and the targets.
struct Joint<'a> {
    session: Box<dyn RenderSession>,
    shots: &'a [Shot],
    layout: Layout,
    seed: u64,
    batches: u64,
    renders: usize,
    failed: usize,
}

impl Joint<'_> {
    /// Renders `scenes` (photograph index, scene) as one batch; each one's
    /// residuals against its photograph.
    fn residuals(&mut self, scenes: Vec<(usize, Scene)>) -> Vec<Residuals> {
        let (index, scenes): (Vec<usize>, Vec<Scene>) = scenes.into_iter().unzip();
        let seed = render_seed(self.seed, self.batches as usize);
        self.batches += 1;
        self.renders += scenes.len();
        let rendered = self.session.render_batch(&scenes, seed);
        let mut out = Vec::with_capacity(index.len());
        for (i, r) in index.into_iter().zip(rendered) {
            let t = &self.shots[i].target;
            out.push(match r {
                Ok(img) if img.dimensions() == t.image.dimensions() => {
                    Ok(residuals(&t.image, &img, t.mask.as_ref()))
                }
                Ok(img) => Err(format!(
                    "image is {}x{}, expected {}x{}",
                    img.width(),
                    img.height(),
                    t.image.width(),
                    t.image.height()
                )),
                Err(f) => Err(f.to_string()),
            });
        }
        self.failed += out.iter().filter(|r| r.is_err()).count();
        out
    }

    /// Every photograph at `x`: residuals, and the set's fitness (infinite
    /// if any failed).
    fn centre(&mut self, x: &[f64]) -> (Vec<Residuals>, f64) {
        let scenes = (0..self.shots.len())
            .map(|i| (i, self.layout.scene(&self.shots[i], i, x)))
            .collect();
        let r = self.residuals(scenes);
        let f = fitness(self.shots, &r);
        (r, f)
    }

    /// The set's normal equations at `x` from the photographs' residuals
    /// there, rendering each coordinate's forward difference only for the
    /// photographs it changes; `steps` adapted to what they changed.
    fn normal(&mut self, x: &[f64], centre: &[Vec<f32>], steps: &mut [f64]) -> Normal {
        let mut scenes = Vec::new();
        // The signed step of each perturbed render, in render order.
        let mut moved = Vec::new();
        for (i, shot) in self.shots.iter().enumerate() {
            for j in self.layout.columns_of(i) {
                let mut y = x.to_vec();
                y[j] = if x[j] + steps[j] <= 1.0 {
                    x[j] + steps[j]
                } else {
                    x[j] - steps[j]
                };
                moved.push(y[j] - x[j]);
                scenes.push((i, self.layout.scene(shot, i, &y)));
            }
        }
        let perturbed = self.residuals(scenes);
        let n = self.layout.dim;
        let mut total = Normal {
            a: vec![vec![0.0; n]; n],
            g: vec![0.0; n],
            jtj: vec![vec![0.0; n]; n],
            scale: 0.0,
            wrr: 0.0,
        };
        let mut at = 0;
        for (i, r) in centre.iter().enumerate() {
            let cols: Vec<usize> = self.layout.columns_of(i).collect();
            let part = &perturbed[at..at + cols.len()];
            let steps_of = &moved[at..at + cols.len()];
            at += cols.len();
            let columns: Vec<Column> = part
                .iter()
                .zip(steps_of)
                .map(|(p, &h)| Column {
                    residuals: p.as_deref().ok(),
                    step: h,
                })
                .collect();
            let block = lm::normal_equations(r, &columns);
            total.wrr += block.wrr;
            for (a, &ja) in cols.iter().enumerate() {
                total.g[ja] += block.g[a];
                for (b, &jb) in cols.iter().enumerate() {
                    total.a[ja][jb] += block.a[a][b];
                    total.jtj[ja][jb] += block.jtj[a][b];
                }
            }
        }
        adapt(steps, &self.layout, centre, &perturbed);
        total
    }
}

/// Adapts each coordinate's difference step to the change it made, over
/// every photograph it changed.
fn adapt(steps: &mut [f64], layout: &Layout, centre: &[Vec<f32>], perturbed: &[Residuals]) {
    let mut changes = vec![lm::Change::default(); steps.len()];
    let mut at = 0;
    for (i, r) in centre.iter().enumerate() {
        for j in layout.columns_of(i) {
            changes[j].add(r, perturbed[at].as_deref().ok());
            at += 1;
        }
    }
    for (step, change) in steps.iter_mut().zip(&changes) {
        *step = change.next_step(*step);
    }
}

/// The set's fitness from every photograph's residuals (the pooled
/// deviation's, as the shared block scores); infinite if any failed.
fn fitness(shots: &[Shot], r: &[Residuals]) -> f64 {
    let mut parts = Vec::with_capacity(r.len());
    for (shot, ri) in shots.iter().zip(r) {
        let Ok(ri) = ri else {
            return f64::INFINITY;
        };
        parts.push((Deviation::of_residuals(ri), counted(&shot.target)));
    }
    Deviation::pooled(&parts).fitness()
}

/// Runs the joint block from the state's values; the set's average
/// deviation after it. The state moves only to a point that rendered and
/// scored better.
pub fn run(
    state: &mut FitState,
    shots: &[Shot],
    renderer: &dyn Renderer,
    config: &SetConfig,
    space: &ParamSpace,
    clear: &mut dyn FnMut() -> Result<()>,
) -> Result<f64> {
    let layout = Layout::new(space, shots);
    let mut x = layout.pack(state);
    let base = layout.scene(&shots[0], 0, &x);
    let session = renderer.session(&base, &varying(space, shots), config.fit.jobs)?;
    clear()?;
    let mut joint = Joint {
        session,
        shots,
        seed: block_seed(config.fit.de.seed, state.blocks_done, 0),
        layout,
        batches: 0,
        renders: 0,
        failed: 0,
    };
    let (first, mut fit) = joint.centre(&x);
    let mut centre = match first
        .into_iter()
        .collect::<std::result::Result<Vec<_>, _>>()
    {
        Ok(c) => c,
        Err(why) => {
            return Err(Error::Run(format!(
                "the set's joint step could not render its starting point: {why}"
            )))
        }
    };
    let mut steps = vec![STEP_START; x.len()];
    let mut lambda = LAMBDA_START;
    let (mut stalled, mut rejected) = (0, 0);
    let mut normal = joint.normal(&x, &centre, &mut steps);
    let mut jacobians = 1;
    while jacobians < MAX_JACOBIANS
        && stalled < STALL_STEPS
        && rejected < REJECTS
        && lambda <= LAMBDA_MAX
        && fit > 0.0
    {
        let Some(trial) = lm::bounded_trial(&normal, lambda, &x, &[]) else {
            break;
        };
        let (r, f) = joint.centre(&trial);
        if f < fit {
            let gain = (fit - f) / fit;
            stalled = if gain > GAIN_TOLERANCE {
                0
            } else {
                stalled + 1
            };
            rejected = 0;
            x = trial;
            fit = f;
            centre = r.into_iter().map(|v| v.unwrap_or_default()).collect();
            lambda = (lambda * LAMBDA_DOWN).max(LAMBDA_MIN);
            normal = joint.normal(&x, &centre, &mut steps);
            jacobians += 1;
        } else {
            rejected += 1;
            lambda *= LAMBDA_UP;
        }
    }
    joint.layout.unpack(&x, state);
    state.evaluations += joint.renders;
    state.failed_renders += joint.failed;
    Ok(fit / 3.0)
}
