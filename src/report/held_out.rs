//! The held-out photographs' section of a set diagnosis's page: each
//! photograph no refit saw, marked as held out, beside its prediction by
//! the improved model (render_after_NAME.png) and the difference between
//! them (residual_after_NAME.png), with the prediction's deviation by the
//! fit's model and by the improved one (`fit::set::held_out`).

use super::heatmap::{colour, shared_limit, signed_luminance};
use super::html::{shot_row, Page};
use crate::error::Result;
use crate::fit::set::held_out::Compared;
use crate::fit::set::Shot;
use crate::raster::io::write_image;
use crate::raster::Image;
use crate::rundir::{shot_render_after, shot_residual_after};
use std::path::Path;

/// Writes each held-out photograph's prediction and its difference from
/// the photograph into `out`, and their table on `page`; nothing when
/// none was held out.
pub fn section(
    page: &mut Page,
    out: &Path,
    shots: &[Shot],
    compared: &[Compared],
    predictions: &[Image],
) -> Result<()> {
    if compared.is_empty() {
        return Ok(());
    }
    let diffs: Vec<Vec<Option<f64>>> = shots
        .iter()
        .zip(predictions)
        .map(|(s, p)| signed_luminance(&s.target.image, p, s.target.mask.as_ref()))
        .collect();
    let limit = shared_limit(&diffs.iter().map(Vec::as_slice).collect::<Vec<_>>());
    page.h2("Held-out photographs", "held_out");
    page.p(&format!(
        "Photographs no fit or refit saw, predicted from the model alone: each one's own values fitted with every shared value frozen. Their deviation is the measure to trust; compare it with the fitted photographs' above. Difference (photograph − prediction, 8-bit luminance): red where the photograph is brighter, blue where darker, full colour = {limit:.0} levels."
    ));
    let mut table = String::from("<table>\n<tr><th class=\"l\">shot</th><th>predicted by the fit's model</th><th>by the improved model</th><th>photograph − prediction</th><th>prediction</th></tr>\n");
    for ((c, diff), (shot, image)) in compared
        .iter()
        .zip(&diffs)
        .zip(shots.iter().zip(predictions))
    {
        let (w, h) = image.dimensions();
        write_image(
            &heatmap(diff, w, h, limit),
            &out.join(shot_residual_after(&c.name)),
        )?;
        write_image(image, &out.join(shot_render_after(&c.name)))?;
        table.push_str(&shot_row(
            &format!("{} (held out)", shot.name),
            &[c.deviation_fit.average, c.deviation_after.average],
            &[shot_residual_after(&c.name), shot_render_after(&c.name)],
        ));
    }
    table.push_str("</table>");
    page.raw(&table);
    Ok(())
}

/// The signed difference `diff` as an image, `limit` levels at full
/// colour, grey outside the mask.
fn heatmap(diff: &[Option<f64>], w: u32, h: u32, limit: f64) -> Image {
    Image::from_fn(w, h, |x, y| match diff[(y * w + x) as usize] {
        None => image::Rgb([128, 128, 128]),
        Some(d) => {
            let c = colour(d / limit.max(1e-9));
            image::Rgb([c.0, c.1, c.2])
        }
    })
}
