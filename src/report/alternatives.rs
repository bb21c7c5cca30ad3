//! The alternatives section: other answers that fit the photograph alike
//! the fitted one (result.json's `alternatives`), side by side with it, so
//! that an ambiguous fit reads as ambiguous rather than as one answer.

use super::format::{num, value};
use super::html::Page;
use super::Run;

pub fn section(page: &mut Page, run: &Run) {
    let stages: Vec<_> = run
        .stages
        .iter()
        .filter(|s| !s.result.alternatives.is_empty())
        .collect();
    if stages.is_empty() {
        return;
    }
    page.h2("Answers that fit alike", "alternatives");
    for stage in stages {
        let result = &stage.result;
        page.p(&format!(
            "{}: the search saw {} other answer(s) whose deviation is within the noise of the \
             fitted one's (docs/usage.md, `alternatives`). The photograph does not tell them \
             apart; another view, a calibrated value or a mask may.",
            stage.title(),
            result.alternatives.len()
        ));
        let mut header = vec!["Parameter".to_string(), "Fitted".to_string()];
        header.extend((1..=result.alternatives.len()).map(|i| format!("Alternative {i}")));
        let mut rows: Vec<Vec<String>> = result
            .params
            .iter()
            .map(|(k, v)| {
                let mut row = vec![k.clone(), value(v)];
                row.extend(
                    result
                        .alternatives
                        .iter()
                        .map(|a| a.params.get(k).map(value).unwrap_or_else(|| "—".into())),
                );
                row
            })
            .collect();
        let mut deviations = vec!["deviation (%)".into(), num(result.deviation.average)];
        deviations.extend(result.alternatives.iter().map(|a| num(a.deviation)));
        rows.push(deviations);
        let header: Vec<&str> = header.iter().map(String::as_str).collect();
        page.table(&header, &rows);
    }
}
