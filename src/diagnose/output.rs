//! The names of everything a diagnosis writes under its output directory,
//! in one place.

/// The diagnosis itself (the `Diagnosis` fields).
pub const DIAGNOSIS_JSON: &str = "diagnosis.json";
/// The extended scene with its refitted values.
pub const IMPROVED_SCENE: &str = "improved_scene.json";
/// Heatmaps of the residual before and after, on one scale.
pub const RESIDUAL_BEFORE: &str = "residual_before.png";
pub const RESIDUAL_AFTER: &str = "residual_after.png";
/// The render of the improved scene.
pub const RENDER_AFTER: &str = "render_after.png";
/// The page that shows it all.
pub const REPORT_HTML: &str = "report.html";

/// A set's per-photograph files: the render after, and the residual
/// heatmaps before and after (one scale for the whole set).
pub fn shot_render_after(shot: &str) -> String {
    format!("render_after_{shot}.png")
}
pub fn shot_residual_before(shot: &str) -> String {
    format!("residual_before_{shot}.png")
}
pub fn shot_residual_after(shot: &str) -> String {
    format!("residual_after_{shot}.png")
}

/// True for a name a diagnosis writes: what `diagnose --overwrite`
/// replaces, and what no input inside its output directory may be.
pub fn owns(name: &str) -> bool {
    let per_shot = |prefix: &str| {
        name.strip_prefix(prefix)
            .and_then(|n| n.strip_suffix(".png"))
            .is_some_and(|shot| !shot.is_empty())
    };
    [
        DIAGNOSIS_JSON,
        IMPROVED_SCENE,
        RESIDUAL_BEFORE,
        RESIDUAL_AFTER,
        RENDER_AFTER,
        REPORT_HTML,
    ]
    .contains(&name)
        || per_shot("render_after_")
        || per_shot("residual_before_")
        || per_shot("residual_after_")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn owns_every_name_a_diagnosis_writes_and_nothing_else() {
        for n in [
            DIAGNOSIS_JSON.to_string(),
            REPORT_HTML.into(),
            shot_render_after("s1"),
            shot_residual_before("s1"),
            shot_residual_after("s1"),
        ] {
            assert!(owns(&n), "{n}");
        }
        for n in ["photo.png", "render_after_.png", "notes.txt", "result.json"] {
            assert!(!owns(n), "{n}");
        }
    }
}
