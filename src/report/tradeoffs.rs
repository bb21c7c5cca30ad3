//! The report's section on what the image does not determine: the final
//! population's spread per parameter, light-versus-albedo correlations
//! with the spread of their product, a scatter of the strongest pair, and
//! every strongly correlated pair (see `population.rs` for the numbers).

use super::data::Stage;
use super::format::{key, num};
use super::html::Page;
use super::plots::Scatter;
use super::population::{self, Population, TradeOff};
use super::{figure, Run};
use crate::error::Result;
use crate::rundir::CHECKPOINT;

pub fn section(page: &mut Page, run: &Run) -> Result<()> {
    page.h2("What the image does not determine", "trade-offs");
    page.p("A converged population spreads along the directions in which the deviation barely changes. \
            Light intensity and albedo are the classic pair: a diffuse surface shows their product, \
            so the population spreads along I · ρ = const (negative correlation) while the product stays put.");
    for (i, s) in run.stages.iter().enumerate() {
        match population::load(&s.dir) {
            Ok(p) => population_section(page, run, i, s, &p)?,
            Err(why) => page.note(&format!(
                "{}: no final population ({why}). A finished fit keeps it in its {CHECKPOINT}.",
                s.title()
            )),
        }
    }
    Ok(())
}

fn opt_pct(x: Option<f64>) -> String {
    x.map(|v| format!("{:.1} %", 100.0 * v))
        .unwrap_or_else(|| "—".into())
}

fn population_section(
    page: &mut Page,
    run: &Run,
    i: usize,
    s: &Stage,
    p: &Population,
) -> Result<()> {
    page.raw(&format!(
        "<h3>{}: final population ({} individuals, phase {}, from {})</h3>",
        super::html::esc(&s.title()),
        p.rows.len(),
        p.phase,
        super::html::esc(&p.file)
    ));
    spread_table(page, p);
    let trades = p.trade_offs();
    if trades.is_empty() {
        page.note("No light intensity or colour is free together with an albedo-type parameter (colour, diffuse, specular), so there is no intensity–albedo trade-off to show.");
    } else {
        trade_off_table(page, &trades);
        trade_off_verdicts(page, &trades);
        strongest_scatter(page, run, i, s, p, &trades)?;
    }
    strong_pairs_table(page, p);
    Ok(())
}

/// Mean, spread and range of every free parameter over the population.
fn spread_table(page: &mut Page, p: &Population) {
    let rows: Vec<Vec<String>> = p
        .spreads()
        .into_iter()
        .map(|sp| {
            vec![
                sp.name.clone(),
                num(sp.mean),
                num(sp.std),
                opt_pct(sp.relative()),
                num(sp.min),
                num(sp.max),
            ]
        })
        .collect();
    page.table(
        &["Parameter", "Mean", "Std", "Std / |mean|", "Min", "Max"],
        &rows,
    );
}

fn trade_off_table(page: &mut Page, trades: &[TradeOff]) {
    let rows: Vec<Vec<String>> = trades
        .iter()
        .map(|t| {
            vec![
                t.light.clone(),
                t.albedo.clone(),
                t.correlation
                    .map(|r| format!("{r:+.2}"))
                    .unwrap_or_else(|| "—".into()),
                opt_pct(t.relative_spread[0]),
                opt_pct(t.relative_spread[1]),
                opt_pct(t.relative_spread[2]),
            ]
        })
        .collect();
    page.table(
        &[
            "Light",
            "Albedo",
            "Correlation",
            "Spread light",
            "Spread albedo",
            "Spread product",
        ],
        &rows,
    );
}

/// A sentence for every pair whose product is pinned while each factor is not.
fn trade_off_verdicts(page: &mut Page, trades: &[TradeOff]) {
    for t in trades {
        if let (Some(r), [Some(a), Some(b), Some(prod)]) = (t.correlation, t.relative_spread) {
            if r < -0.5 && prod < 0.5 * a.min(b) {
                page.p(&format!(
                    "{} and {} trade off (correlation {r:+.2}): their product varies {:.1} % over the population, each alone {:.1} % and {:.1} %. \
                     The image fixes the product; their split rests on the bounds and the rest of the scene.",
                    t.light, t.albedo, 100.0 * prod, 100.0 * a, 100.0 * b
                ));
            }
        }
    }
}

/// The scatter of the most strongly correlated light–albedo pair.
fn strongest_scatter(
    page: &mut Page,
    run: &Run,
    i: usize,
    s: &Stage,
    p: &Population,
    trades: &[TradeOff],
) -> Result<()> {
    let strongest = trades
        .iter()
        .filter(|t| t.correlation.is_some())
        .max_by(|a, b| {
            a.correlation
                .unwrap_or(0.0)
                .abs()
                .total_cmp(&b.correlation.unwrap_or(0.0).abs())
        });
    let Some(t) = strongest else { return Ok(()) };
    let Some(points) = p.pairs(&t.light, &t.albedo) else {
        return Ok(());
    };
    let scatter = Scatter {
        title: format!("{}: final population", s.title()),
        x_label: t.light.clone(),
        y_label: t.albedo.clone(),
        points,
    };
    let (png, svg) = figure::save(
        &scatter,
        &run.dir,
        &format!("fig_population_{}", key(run, i)),
    )?;
    page.figure(
        &png,
        &format!(
            "{} against {} over the final population (darker: lower deviation)",
            t.albedo, t.light
        ),
        false,
        Some(&svg),
    );
    Ok(())
}

fn strong_pairs_table(page: &mut Page, p: &Population) {
    let strong = p.strong_pairs(0.7);
    if !strong.is_empty() {
        let rows: Vec<Vec<String>> = strong
            .iter()
            .take(12)
            .map(|(a, b, r)| vec![a.clone(), b.clone(), format!("{r:+.2}")])
            .collect();
        page.table(
            &["Parameter", "Parameter", "Correlation (|r| ≥ 0.7)"],
            &rows,
        );
    }
}
