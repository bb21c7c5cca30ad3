//! The files a diagnosis writes (names in `output.rs`): diagnosis.json,
//! improved_scene.json (the extended scene with refitted values), the
//! residual heatmaps before and after (on one scale: red, the target is
//! brighter; blue, darker), the render after, and the HTML report; for a
//! set of photographs, those of every photograph, in a grid.

use super::diagnosis::{Diagnosis, SetDiagnosis};
use super::inputs::SetInputs;
use super::model::Model;
use super::residual::Residual;
use crate::error::{Error, Result};
use crate::fsio::write_atomic;
use crate::metric::Deviation;
use crate::raster::io as image_io;
use crate::report::html::{shot_row, Page};
use crate::rundir;
use std::path::Path;

fn json(value: &impl serde::Serialize) -> Result<String> {
    serde_json::to_string_pretty(value).map_err(|e| Error::Run(e.to_string()))
}

/// Writes every file of the diagnosis `d` into `out`: diagnosis.json, the
/// improved scene, and for every photograph its residual before and after
/// (on one scale) and its render after; `residuals` are the residuals
/// before and after, one per photograph. A fit of one photograph keeps
/// its files without a shot name and diagnosis.json without `shots_after`.
pub fn write(
    out: &Path,
    d: &SetDiagnosis,
    model: &Model,
    inputs: &SetInputs,
    residuals: (&[Residual], &[Residual]),
) -> Result<()> {
    let (before, after) = residuals;
    let record = if inputs.single {
        json(&d.diagnosis)?
    } else {
        json(d)?
    };
    write_atomic(&out.join(rundir::DIAGNOSIS_JSON), record.as_bytes())?;
    let scene = super::map_file::beside(&model.scene, out);
    write_atomic(&out.join(rundir::IMPROVED_SCENE), json(&scene)?.as_bytes())?;
    let scale = before
        .iter()
        .chain(after)
        .map(Residual::peak)
        .fold(1e-3, f64::max);
    for (i, s) in inputs.shots.iter().enumerate() {
        let [b, a, r] = files(inputs.single, &s.name);
        image_io::write_image(&before[i].heatmap(scale), &out.join(b))?;
        image_io::write_image(&after[i].heatmap(scale), &out.join(a))?;
        image_io::write_image(&model.images[i], &out.join(r))?;
    }
    let mut page = if inputs.single {
        html(&d.diagnosis, scale)
    } else {
        set_html(d, scale)
    };
    crate::report::held_out::section(
        &mut page,
        out,
        &inputs.held_out,
        &d.held_out,
        &d.held_out_images,
    )?;
    candidates(&mut page, &d.diagnosis);
    write_atomic(&out.join(rundir::REPORT), page.finish().as_bytes())
}

/// A photograph's residual before, after, and render after, as named in
/// the run directory.
fn files(single: bool, name: &str) -> [String; 3] {
    if single {
        [
            rundir::RESIDUAL_BEFORE,
            rundir::RESIDUAL_AFTER,
            rundir::RENDER_AFTER,
        ]
        .map(String::from)
    } else {
        [
            rundir::shot_residual_before(name),
            rundir::shot_residual_after(name),
            rundir::shot_render_after(name),
        ]
    }
}

/// A set's page up to its candidates: the verdict, and every photograph's
/// deviations and images in a grid.
fn set_html(d: &SetDiagnosis, scale: f64) -> Page {
    let mut page = Page::new("scenefit diagnosis of a set of photographs");
    summary(&mut page, &d.diagnosis);
    page.h2("Every photograph", "shots");
    page.p(&format!(
        "Residual (target − render): red where the target is brighter, blue where darker; full colour = {scale:.4} linear, the same for every photograph."
    ));
    let mut grid = String::from("<table>\n<tr><th class=\"l\">shot</th><th>deviation before</th><th>after</th><th>residual before</th><th>residual after</th><th>render after</th></tr>\n");
    for s in &d.shots_after {
        grid.push_str(&shot_row(
            &s.name,
            &[s.deviation_before.average, s.deviation_after.average],
            &files(false, &s.name),
        ));
    }
    grid.push_str("</table>");
    page.raw(&grid);
    page
}

fn dev_row(name: &str, v: &Deviation) -> Vec<String> {
    let f = |x: f64| format!("{x:.3}");
    vec![name.into(), f(v.r), f(v.g), f(v.b), f(v.average)]
}

/// One photograph's page up to its candidates: the verdict and its
/// residual before and after.
fn html(d: &Diagnosis, scale: f64) -> Page {
    let mut page = Page::new("scenefit diagnosis");
    summary(&mut page, d);
    page.h2("Residual (target − render)", "residual");
    page.p(&format!(
        "Red: target brighter; blue: darker; full colour = {scale:.4} linear."
    ));
    page.figure_enlarged(rundir::RESIDUAL_BEFORE, "before", 384);
    page.figure_enlarged(rundir::RESIDUAL_AFTER, "after", 384);
    page
}

/// The verdict and the deviations before, refitted and after.
fn summary(page: &mut Page, d: &Diagnosis) {
    let acc = if d.accepted.is_empty() {
        "none".to_string()
    } else {
        d.accepted.join(", ")
    };
    let tail = format!(". {} renders in {:.1} s.", d.renders, d.wall_seconds);
    page.p_bold("Accepted: ", &acc, &tail);
    if !d.held.is_empty() {
        page.p(&format!(
            "Held where the fit put them (geometry): {}.",
            d.held.join(", ")
        ));
    }
    // The same lines as diagnosis.json's `imitations` and `removed`.
    for line in d.imitations.iter().map(|i| &i.reason) {
        page.p(&format!("Imitation: {line}."));
    }
    for line in d.removed.iter().map(|r| &r.reason) {
        page.p(&format!("Removed: {line}."));
    }
    page.h2("Deviation per channel (%)", "deviation");
    page.table(
        &["", "r", "g", "b", "average"],
        &[
            dev_row("before", &d.deviation_before),
            dev_row("refitted, no effect", &d.deviation_refined),
            dev_row("after", &d.deviation_after),
        ],
    );
}

/// The candidates of every round and the parameters after.
fn candidates(page: &mut Page, d: &Diagnosis) {
    page.h2(
        "Candidates, ranked by evidence within each round",
        "candidates",
    );
    page.table(
        &[
            "round",
            "effect",
            "evidence (R²)",
            "params added",
            "ΔBIC",
            "ĉ",
            "SAD drop",
            "deviation after",
            "refit",
            "accepted",
        ],
        &d.candidates.iter().map(candidate_row).collect::<Vec<_>>(),
    );
    page.h2("Parameters after", "params");
    let params: Vec<Vec<String>> = d
        .params_after
        .iter()
        .map(|(k, v)| vec![k.clone(), v.to_string()])
        .collect();
    page.table(&["parameter", "value"], &params);
}

fn candidate_row(c: &super::Candidate) -> Vec<String> {
    vec![
        c.round.to_string(),
        c.effect.clone(),
        format!("{:.3}", c.evidence),
        c.added_params.to_string(),
        c.delta_bic.map_or("-".into(), |v| format!("{v:.1}")),
        c.overdispersion.map_or("-".into(), |v| format!("{v:.2}")),
        c.gain.map_or("-".into(), |v| format!("{:.1} %", 100.0 * v)),
        c.deviation_after
            .map_or("-".into(), |v| format!("{:.3}", v.average)),
        c.refit.clone(),
        if c.accepted { "yes" } else { "" }.into(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::Candidate;

    #[test]
    fn the_page_shows_the_verdict_deviations_heatmaps_candidates_and_params() {
        let dev = |a: f64| Deviation {
            r: a,
            g: a,
            b: a,
            average: a,
        };
        let candidate = Candidate {
            effect: "vignetting".into(),
            evidence: 0.4567,
            deviation_after: Some(dev(0.01)),
            round: 1,
            delta_bic: Some(-123.45),
            overdispersion: Some(1.0),
            gain: Some(0.5),
            added_params: 1,
            accepted: true,
            refit: "from scratch".into(),
            footing: None,
        };
        let mut params = serde_json::Map::new();
        params.insert("camera.vignetting.strength".into(), serde_json::json!(0.4));
        let d = Diagnosis {
            deviation_before: dev(0.64),
            deviation_after: dev(0.001),
            candidates: vec![candidate],
            accepted: vec!["vignetting".into()],
            params_after: params,
            deviation_refined: dev(0.6),
            unexplained: false,
            renders: 1234,
            wall_seconds: 5.0,
            min_gain: 0.05,
            held: Vec::new(),
            removed: Vec::new(),
            imitations: vec![super::super::diagnosis::Imitation {
                round: 1,
                chosen: "vignetting".into(),
                other: "ambient".into(),
                correlation: 0.9,
                reason: "vignetting and ambient explain the same residual".into(),
            }],
        };
        let mut page = html(&d, 0.05);
        candidates(&mut page, &d);
        let page = page.finish();
        for part in [
            "<b>vignetting</b>. 1234 renders in 5.0 s.",
            "Imitation: vignetting and ambient explain the same residual.",
            "<td class=\"l\">refitted, no effect</td><td>0.600</td>",
            "full colour = 0.0500 linear",
            "src=\"residual_before.png\"",
            "src=\"residual_after.png\"",
            "<td>0.457</td>",
            "<td>-123.5</td><td>1.00</td><td>50.0 %</td><td>0.010</td><td class=\"l\">from scratch</td><td class=\"l\">yes</td>",
            "<td class=\"l\">camera.vignetting.strength</td><td>0.4</td>",
        ] {
            assert!(page.contains(part), "missing {part}:\n{page}");
        }
    }
}
