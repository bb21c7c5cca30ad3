//! What the report says about stage 2 beyond the shared tables: how far it
//! moved each parameter from the handover point, how much of the deviation
//! change from stage 1 is the renderer's and how much the search's, and,
//! for the mapped method, its iterations (stage-2 render, surrogate
//! prediction, trust radius, accepted or not).

use super::html::Page;
use super::Run;
use crate::pipeline::spacemap::{Iteration, MappedResult};
use crate::pipeline::Comparison;
use crate::rundir::{RunDir, RESULT};

/// Below this fraction of its span a parameter counts as not moved.
const STILL: f64 = 1e-3;

/// The largest move of a parameter's components, as a fraction of span.
fn largest(m: &crate::pipeline::comparison::Move) -> f64 {
    m.span_fraction
        .iter()
        .fold(0.0, |a: f64, x| if x.abs() > a.abs() { *x } else { a })
}

/// The moves per parameter, "+1.2 %" of the original span (largest component).
pub fn move_of(c: &Comparison, param: &str) -> Option<String> {
    let m = c.moves.iter().find(|m| m.param == param)?;
    Some(format!("{:+.1} %", 100.0 * largest(m)))
}

/// Sentences for the summary: the method, whether the search moved
/// anything, and the renderer/search split of the deviation change.
pub fn summary(page: &mut Page, c: &Comparison) {
    let (a, b) = (&c.stage1, &c.stage2);
    if c.stage2.method.as_deref() == Some("mapped") {
        page.p(&format!(
            "Stage 2 ran by output space mapping: {} rendered {} times; between those renders {} (corrected by the last {} render) searched a trust region around the current point.",
            b.renderer, b.evaluations, a.renderer, b.renderer
        ));
    }
    if !c.moves.is_empty() {
        let moved: Vec<String> = c
            .moves
            .iter()
            .filter(|m| largest(m).abs() >= STILL)
            .map(|m| format!("{} {:+.1} %", m.param, 100.0 * largest(m)))
            .collect();
        if moved.is_empty() {
            page.p_bold(
                "",
                "The stage-2 search found nothing: ",
                "no parameter moved from the handover point by 0.1 % of its span or more; the stage-2 result is the handover point.",
            );
        } else {
            page.p(&format!(
                "Stage 2 moved from the handover point (largest component, in % of the original span): {}.",
                moved.join(", ")
            ));
        }
    }
    if let Some(h) = &c.handover.deviation_at_handover {
        let renderer = h.average - a.deviation.average;
        let search = b.deviation.average - h.average;
        page.p(&format!(
            "Deviation change from stage 1 to stage 2: {:+.3} points, of which {:+.3} is the renderer (the stage-1 values rendered by {}) and {:+.3} the search.",
            b.deviation.average - a.deviation.average,
            renderer,
            b.renderer,
            search
        ));
    }
}

/// The mapped stage 2's iterations, from its result.json.
pub fn iterations(run: &Run, c: &Comparison) -> Option<Vec<Iteration>> {
    let dir = RunDir::existing(&run.dir.join(&c.stage2.dir)).ok()?;
    let r: MappedResult = dir.read_json(RESULT, "a scenefit result").ok()?;
    Some(r.iterations)
}

/// The iteration table of a mapped stage 2.
pub fn iteration_table(page: &mut Page, run: &Run) {
    let Some(c) = &run.comparison else { return };
    let Some(its) = iterations(run, c) else {
        return;
    };
    let rows: Vec<Vec<String>> = its
        .iter()
        .enumerate()
        .map(|(i, it)| {
            vec![
                (i + 1).to_string(),
                format!("{:.3}", it.surrogate_deviation),
                format!("{:.3}", it.deviation),
                format!("{:.4}", it.radius),
                if it.accepted { "yes" } else { "no" }.into(),
                it.fine_renders.to_string(),
                it.coarse_renders.to_string(),
            ]
        })
        .collect();
    page.table(
        &[
            "Iteration",
            "Surrogate %",
            &format!("{} render %", c.stage2.renderer),
            "Trust radius",
            "Accepted",
            &format!("{} renders so far", c.stage2.renderer),
            &format!("{} renders", c.stage1.renderer),
        ],
        &rows,
    );
    page.note("Surrogate: the stage-1 renderer plus the per-pixel difference between the two renderers at the current point, at its optimum in the trust region (what the step predicted). The stage-2 render checks it; a step is accepted when that deviation fell. Trust radius: half-width in the unit cube of the original bounds. An iteration whose surrogate proposed no move renders nothing with the stage-2 renderer.");
}
