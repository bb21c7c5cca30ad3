//! The report page, section by section: summary, images, the paper's
//! Table I, difference heatmaps, fitted parameters, cost, convergence,
//! evolution strips, parameter trade-offs, files. Each section writes its
//! figures into the run directory and links them.

use super::format::{change, key, num, rel, signed, value};
use super::heatmap::{channel_bias, shared_limit, signed_luminance, Heatmap};
use super::html::Page;
use super::images::{evolution_strip, save_upscaled, scale_for};
use super::plots::{Convergence, Series};
use super::{figure, Run};
use crate::error::Result;
use crate::metric::Deviation;
use crate::raster::io as image_io;
use crate::rundir::{
    BEST, COMPARISON, FITTED_SCENE, HANDOVER, INPUT_SCENE, MASK, PROGRESS, RESULT, SNAPSHOTS,
    TARGET, TRACE,
};

/// The page of a loaded run.
pub fn render(run: &Run) -> Result<String> {
    let two = run.stages.len() == 2;
    let mut page = Page::new(if two {
        "scenefit report: two-stage fit"
    } else {
        "scenefit report: fit"
    });
    summary(&mut page, run);
    images(&mut page, run)?;
    table_i(&mut page, run);
    heatmaps(&mut page, run)?;
    parameters(&mut page, run);
    super::alternatives::section(&mut page, run);
    cost(&mut page, run);
    convergence(&mut page, run)?;
    evolution(&mut page, run)?;
    super::tradeoffs::section(&mut page, run)?;
    super::identifiability::section(&mut page, run);
    files(&mut page, run);
    Ok(page.finish())
}

fn deviation_row(label: &str, d: &Deviation) -> Vec<String> {
    vec![
        label.to_string(),
        format!("{:.2}", d.r),
        format!("{:.2}", d.g),
        format!("{:.2}", d.b),
        format!("{:.2}", d.average),
    ]
}

fn summary(page: &mut Page, run: &Run) {
    page.p(&format!("Run directory: {}", run.dir.display()));
    let Some(c) = &run.comparison else {
        let s = &run.stages[0];
        page.p(&format!(
            "One fit with the {} renderer: average deviation {:.2} % after {} renders ({} generations, {:.1} s).",
            s.result.renderer,
            s.result.deviation.average,
            s.result.evaluations,
            s.result.generations,
            s.result.wall_seconds
        ));
        return;
    };
    let (a, b) = (&c.stage1, &c.stage2);
    let verdict = if b.deviation.average < a.deviation.average {
        "lower"
    } else {
        "not lower"
    };
    page.p(&format!(
        "Stage 1 fitted with {} over the full bounds: {:.2} % average deviation in {} renders ({:.1} s). \
         Stage 2 refitted with {}: {:.2} % in {} renders ({:.1} s), {verdict} than stage 1.",
        a.renderer,
        a.deviation.average,
        a.evaluations,
        a.wall_seconds,
        b.renderer,
        b.deviation.average,
        b.evaluations,
        b.wall_seconds
    ));
    super::stage2::summary(page, c);
    let h = &c.handover;
    if c.stage2.method.as_deref() == Some("mapped") {
        page.p(&format!(
            "Handover: stage 2 started at the stage-1 values, with a trust region of ± {:.0} % of each parameter's original span around them, grown or shrunk by how well each step did.",
            100.0 * h.window.unwrap_or(0.0)
        ));
    } else if h.seeded {
        page.p(&format!(
            "Handover: stage 2 searched the stage-1 values ± {:.0} % of each parameter's original span (clamped to the original bounds), \
             its population started within radius {} (unit cube of those bounds) of the stage-1 values, which were individual 0.",
            100.0 * h.window.unwrap_or(0.0),
            h.start_radius.map(num).unwrap_or_else(|| "—".into())
        ));
    } else {
        page.p("Stage 2 started from scratch: full bounds, uniform initial population (no handover), for comparison with a seeded run.");
    }
    if let Some(d) = &h.deviation_at_handover {
        page.p(&format!(
            "The stage-1 values rendered by {} deviate {:.2} % from the target: that is where stage 2 started.",
            b.renderer, d.average
        ));
    }
}

fn images(page: &mut Page, run: &Run) -> Result<()> {
    page.h2("Target and best renders", "images");
    let k = scale_for(run.stages[0].best.width());
    match &run.target {
        Ok(t) => {
            let f = save_upscaled(t, k, &run.dir, "fig_target.png")?;
            page.figure(&f, "Target", true, None);
        }
        Err(m) => page.note(&format!("No target shown: {m}")),
    }
    for (i, s) in run.stages.iter().enumerate() {
        let f = save_upscaled(
            &s.best,
            k,
            &run.dir,
            &format!("fig_{}_best.png", key(run, i)),
        )?;
        page.figure(
            &f,
            &format!(
                "{} best: {:.2} % average deviation",
                s.title(),
                s.result.deviation.average
            ),
            true,
            None,
        );
    }
    if let Some(c) = &run.comparison {
        let path = run.dir.join(&c.stage2.dir).join(HANDOVER);
        if let (Ok(img), Some(d)) = (
            image_io::read_image(&path, HANDOVER),
            &c.handover.deviation_at_handover,
        ) {
            let f = save_upscaled(&img, k, &run.dir, "fig_handover.png")?;
            page.figure(
                &f,
                &format!(
                    "Stage-1 values rendered by {} (the handover): {:.2} %",
                    c.stage2.renderer, d.average
                ),
                true,
                None,
            );
        }
    }
    page.note(&format!(
        "Renders shown {k}x their size, nearest neighbour (each square is one pixel)."
    ));
    Ok(())
}

fn table_i(page: &mut Page, run: &Run) {
    page.h2("Deviation (the paper's Table I format)", "deviation");
    let mut rows: Vec<Vec<String>> = run
        .stages
        .iter()
        .map(|s| deviation_row(&s.title(), &s.result.deviation))
        .collect();
    if let Some(s) = &run.stage2_de {
        rows.push(deviation_row(
            &format!("{}, DE (for comparison)", s.title()),
            &s.result.deviation,
        ));
    }
    if let Some(c) = &run.comparison {
        if let Some(d) = &c.handover.deviation_at_handover {
            rows.push(deviation_row(
                &format!("Stage-1 values rendered by {}", c.stage2.renderer),
                d,
            ));
        }
    }
    page.table(&["", "%R", "%G", "%B", "Average"], &rows);
    page.note("Deviation per channel: 100 · mean |target − render| / 255 over the mask (all pixels without one), on 8-bit sRGB values.");
    if let Ok(t) = &run.target {
        let rows: Vec<Vec<String>> = run
            .stages
            .iter()
            .map(|s| {
                let b = channel_bias(t, &s.best, run.mask.as_ref());
                vec![s.title(), signed(b[0]), signed(b[1]), signed(b[2])]
            })
            .collect();
        page.table(&["Mean target − render (8-bit)", "R", "G", "B"], &rows);
        page.note("Positive: the render is darker than the target in that channel on average.");
    }
}

fn heatmaps(page: &mut Page, run: &Run) -> Result<()> {
    page.h2("Where the renders differ from the target", "differences");
    let Ok(t) = &run.target else {
        page.note("No target, so no difference maps.");
        return Ok(());
    };
    let diffs: Vec<Vec<Option<f64>>> = run
        .stages
        .iter()
        .map(|s| signed_luminance(t, &s.best, run.mask.as_ref()))
        .collect();
    let limit = shared_limit(&diffs.iter().map(|d| d.as_slice()).collect::<Vec<_>>());
    let k = scale_for(t.width());
    for (i, (s, diff)) in run.stages.iter().zip(diffs).enumerate() {
        let map = Heatmap {
            title: format!("Target − {}", s.title()),
            diff,
            width: t.width(),
            height: t.height(),
            k,
            limit,
        };
        let (png, svg) = figure::save(&map, &run.dir, &format!("fig_diff_{}", key(run, i)))?;
        page.figure(
            &png,
            &format!("Signed luminance difference, target − {} best", s.title()),
            false,
            Some(&svg),
        );
    }
    page.note(&format!(
        "One scale for all maps, ±{limit:.0} levels (99 % of pixels fall inside); grey: outside the mask."
    ));
    Ok(())
}

fn parameters(page: &mut Page, run: &Run) {
    page.h2("Fitted parameters", "parameters");
    let first = &run.stages[0].result.params;
    if run.stages.len() == 1 {
        let rows: Vec<Vec<String>> = first
            .iter()
            .map(|(k, v)| vec![k.clone(), value(v)])
            .collect();
        page.table(&["Parameter", "Fitted"], &rows);
    } else {
        let second = &run.stages[1].result.params;
        let mut names: Vec<&String> = first.keys().collect();
        names.extend(second.keys().filter(|k| !first.contains_key(*k)));
        let rows: Vec<Vec<String>> = names
            .iter()
            .map(|k| {
                let (a, b) = (first.get(*k), second.get(*k));
                vec![
                    (*k).clone(),
                    a.map(value).unwrap_or_else(|| "—".into()),
                    b.map(value).unwrap_or_else(|| "—".into()),
                    match (a, b) {
                        (Some(a), Some(b)) => change(a, b),
                        _ => "—".into(),
                    },
                    run.comparison
                        .as_ref()
                        .and_then(|c| super::stage2::move_of(c, k))
                        .unwrap_or_else(|| "—".into()),
                ]
            })
            .collect();
        let h1 = run.stages[0].title();
        let h2 = run.stages[1].title();
        page.table(
            &["Parameter", &h1, &h2, "Change", "Stage-2 move (% of span)"],
            &rows,
        );
        page.note("Stage-2 move: from where stage 2 started (the handover point) to its result, the largest component, as a fraction of the parameter's original span in the space it is searched in.");
    }
    page.note("Scene units: colours as linear RGB whatever space they were searched in; light intensity in W/sr. Every backend reads these same values and converts them itself (docs/renderers.md).");
}

fn cost(page: &mut Page, run: &Run) {
    page.h2("Time and renders", "cost");
    let de = run.stage2_de.iter().map(|s| (2, s));
    let rows: Vec<Vec<String>> = run
        .stages
        .iter()
        .enumerate()
        .chain(de)
        .map(|(i, s)| {
            let r = &s.result;
            let wall = match &run.comparison {
                Some(c) if i == 0 => c.stage1.wall_seconds,
                Some(c) if i == 2 => c.stage2_de.as_ref().map_or(0.0, |d| d.wall_seconds),
                Some(c) => c.stage2.wall_seconds,
                None => r.wall_seconds,
            };
            vec![
                if i == 2 {
                    format!("{}, DE (for comparison)", s.title())
                } else {
                    s.title()
                },
                r.evaluations.to_string(),
                r.generations.to_string(),
                format!("{wall:.1}"),
                format!("{:.1}", r.wall_seconds),
                format!("{:.0}", r.evaluations as f64 / r.wall_seconds.max(1e-9)),
                r.failed_renders.to_string(),
                r.stop_reason.clone(),
            ]
        })
        .collect();
    page.table(
        &[
            "",
            "Renders",
            "Generations",
            "Wall s",
            "In generations s",
            "Renders/s",
            "Failed",
            "Stopped by",
        ],
        &rows,
    );
    page.note(&if run.comparison.is_some() {
        format!("Wall s: the whole stage, renderer start-up included; in generations s: {RESULT}'s wall_seconds, rendering and comparing only.")
    } else {
        format!("Seconds: {RESULT}'s wall_seconds, the time spent in generations (renderer start-up not included).")
    });
}

fn convergence(page: &mut Page, run: &Run) -> Result<()> {
    page.h2("Convergence", "convergence");
    let method = run
        .comparison
        .as_ref()
        .and_then(|c| c.stage2.method.clone());
    let series = |f: &dyn Fn(&super::data::CurvePoint) -> f64| curves(run, f);
    let mut references: Vec<(String, f64)> = match run.stages.as_slice() {
        [s1, _] => vec![(format!("{} final", s1.title()), s1.result.deviation.average)],
        _ => Vec::new(),
    };
    if let Some(d) = run
        .comparison
        .as_ref()
        .and_then(|c| c.handover.deviation_at_handover)
    {
        references.push(("handover".into(), d.average));
    }
    let by_renders = Convergence {
        title: "Best deviation against renders".into(),
        x_label: "renders (within the stage; stage 2: its own renderer's only)".into(),
        series: series(&|p| p.evaluations as f64),
        references: references.clone(),
    };
    let (png, svg) = figure::save(&by_renders, &run.dir, "fig_convergence_renders")?;
    page.figure(
        &png,
        "Deviation against renders, log-log",
        false,
        Some(&svg),
    );
    let by_seconds = Convergence {
        title: "Best deviation against seconds".into(),
        x_label: "seconds in generations (within the stage)".into(),
        series: series(&|p| p.seconds),
        references,
    };
    let (png, svg) = figure::save(&by_seconds, &run.dir, "fig_convergence_seconds")?;
    page.figure(
        &png,
        "Deviation against seconds, log-log",
        false,
        Some(&svg),
    );
    if method.as_deref() == Some("mapped") {
        page.note("Stage 2 by space mapping: one point per iteration; its renders are the stage-2 renderer's only (the stage-1 renderer's surrogate renders are in the table below).");
        super::stage2::iteration_table(page, run);
    }
    for s in &run.stages {
        if !s.seconds_measured {
            page.note(&format!(
                "{}: no {TRACE}, so the curve is {PROGRESS}'s (every 10 generations) and its seconds assume every generation took the same time (wall_seconds / generations).",
                s.title()
            ));
        }
    }
    Ok(())
}

/// One curve per stage (and the DE stage 2 beside a mapped one), each
/// labelled with its method, with `f` of each point as its x.
fn curves(run: &Run, f: &dyn Fn(&super::data::CurvePoint) -> f64) -> Vec<Series> {
    let method = run
        .comparison
        .as_ref()
        .and_then(|c| c.stage2.method.clone());
    let label = |i: usize, s: &super::data::Stage| match (&method, i) {
        (Some(m), 1) if m == "mapped" => format!("{}, space mapping", s.title()),
        (Some(m), 1) => format!("{}, {}", s.title(), m.to_uppercase()),
        _ => s.title(),
    };
    let points = |s: &super::data::Stage| -> Vec<(f64, f64)> {
        s.curve
            .iter()
            .map(|p| (f(p), p.deviation.average))
            .collect()
    };
    let mut v: Vec<Series> = run
        .stages
        .iter()
        .enumerate()
        .map(|(i, s)| Series {
            label: label(i, s),
            points: points(s),
        })
        .collect();
    if let Some(s) = &run.stage2_de {
        v.push(Series {
            label: format!("{}, DE (for comparison)", s.title()),
            points: points(s),
        });
    }
    v
}

fn evolution(page: &mut Page, run: &Run) -> Result<()> {
    page.h2("Evolution (the paper's Fig. 4)", "evolution");
    for (i, s) in run.stages.iter().enumerate() {
        let name = format!("fig_evolution_{}.png", key(run, i));
        match evolution_strip(&s.dir, &s.snapshots, &run.dir, &name)? {
            Some(f) => page.figure(
                &f,
                &format!(
                    "{}: the best image every 10 generations ({SNAPSHOTS})",
                    s.title()
                ),
                true,
                None,
            ),
            None => page.note(&format!("{}: no {SNAPSHOTS} snapshots.", s.title())),
        }
    }
    Ok(())
}

fn files(page: &mut Page, run: &Run) {
    page.h2("Files", "files");
    let mut list: Vec<(String, String)> = Vec::new();
    let mut add = |path: String, what: &str| {
        if run.dir.join(&path).is_file() {
            list.push((path, what.to_string()));
        }
    };
    add(
        COMPARISON.into(),
        "both stages' deviation, renders and seconds",
    );
    add(TARGET.into(), "the target both stages were compared with");
    add(MASK.into(), "the mask (white: pixels that count)");
    for i in 0..run.stages.len() {
        let r = rel(run, i);
        add(
            format!("{r}{INPUT_SCENE}"),
            "the scene stage 2 searched (narrowed bounds)",
        );
        add(
            format!("{r}{RESULT}"),
            "fitted values, deviation, renders, seconds",
        );
        add(
            format!("{r}{FITTED_SCENE}"),
            "the scene with the fitted values",
        );
        add(format!("{r}{BEST}"), "the best render, full size");
        add(
            format!("{r}{PROGRESS}"),
            "best deviation and parameters every 10 generations",
        );
        add(
            format!("{r}{TRACE}"),
            "best deviation and seconds every generation",
        );
    }
    for stem in [
        "fig_diff_stage1",
        "fig_diff_stage2",
        "fig_diff_fit",
        "fig_convergence_renders",
        "fig_convergence_seconds",
        "fig_population_stage1",
        "fig_population_stage2",
        "fig_population_fit",
    ] {
        add(format!("{stem}.svg"), "figure, vector");
    }
    page.links(&list);
    page.note(&format!("Regenerate this page with: scenefit report DIR. Render a fitted scene large with: scenefit render {FITTED_SCENE} --renderer blender --width 1280 --height 960 -o big.png"));
}
