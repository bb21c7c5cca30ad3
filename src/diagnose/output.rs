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
