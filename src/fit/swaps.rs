//! Which free coordinates a fit may swap without changing the image: two
//! lights of one kind whose free entries name the same fields over the
//! same bounds (two suns free over one box). Each pair is one permutation
//! of the search's unit coordinates, declared to the search
//! (`optimize/swaps.rs`), which renders the swapped ends of its descents
//! and reports the ones that fit alike as alternatives. Nothing else is
//! assumed: the lights' fixed values may differ, and then the swapped
//! render simply does not fit alike.

use crate::scene::field::{Field, LightField};
use crate::scene::{ParamSpace, ParamSpec, Scene};

/// The swaps of `space` (coordinates in its order) for lights of `scene`.
pub(crate) fn light_swaps(space: &ParamSpace, scene: &Scene) -> Vec<Vec<usize>> {
    // Each light's free entries: (field, first coordinate, spec).
    let mut offset = 0;
    let mut by_light: Vec<Vec<(LightField, usize, &ParamSpec)>> =
        vec![Vec::new(); scene.lights.len()];
    for spec in &space.specs {
        if let Field::Light(i, f) = spec.field {
            if let Some(entries) = by_light.get_mut(i) {
                entries.push((f, offset, spec));
            }
        }
        offset += spec.dim();
    }
    let dim = offset;
    let mut perms = Vec::new();
    for a in 0..by_light.len() {
        for b in a + 1..by_light.len() {
            if scene.lights[a].kind != scene.lights[b].kind {
                continue;
            }
            if let Some(perm) = swap(&by_light[a], &by_light[b], dim) {
                perms.push(perm);
            }
        }
    }
    perms
}

/// The permutation exchanging two lights' entries, when each field of
/// one has its match in the other (same bounds, same kind of entry).
fn swap(
    a: &[(LightField, usize, &ParamSpec)],
    b: &[(LightField, usize, &ParamSpec)],
    dim: usize,
) -> Option<Vec<usize>> {
    if a.is_empty() || a.len() != b.len() {
        return None;
    }
    let mut perm: Vec<usize> = (0..dim).collect();
    for &(field, at, spec) in a {
        let &(_, bt, other) = b.iter().find(|(f, _, _)| *f == field)?;
        let alike = spec.min == other.min
            && spec.max == other.max
            && spec.hsv == other.hsv
            && spec.per_shot == other.per_shot
            && spec.phase == other.phase;
        if !alike {
            return None;
        }
        for c in 0..spec.dim() {
            perm.swap(at + c, bt + c);
        }
    }
    Some(perm)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two suns, `b`'s direction free up to `max_b` in z, a material
    /// value free between them.
    fn space(max_b: f64) -> (ParamSpace, Scene) {
        let text = format!(
            r#"{{"format": "scenefit-scene/1", "image": {{"width": 8, "height": 6}},
              "camera": {{"type": "perspective", "position": [0, 0, 5], "look_at": [0, 0, 0], "fov_y_deg": 40}},
              "lights": [
                {{"name": "a", "type": "directional", "direction": [0, 1, 1], "intensity": 1}},
                {{"name": "b", "type": "directional", "direction": [1, 0, 1], "intensity": 1}}],
              "objects": [{{"name": "ball", "shape": {{"type": "sphere", "center": [0, 0, 0], "radius": 1}},
                           "material": {{"color": [0.5, 0.5, 0.5]}}}}],
              "free": [
                {{"param": "lights.a.direction", "min": [-1, -1, 0], "max": [1, 1, 1]}},
                {{"param": "objects.ball.material.specular", "min": 0, "max": 1}},
                {{"param": "lights.b.direction", "min": [-1, -1, 0], "max": [1, 1, {max_b}]}}]}}"#
        );
        let scene = crate::scene::parse(&text, "t.json", &[]).unwrap();
        (ParamSpace::from_scene(&scene), scene)
    }

    #[test]
    fn two_lights_free_alike_swap_and_unlike_ones_do_not() {
        let (s, scene) = space(1.0);
        assert_eq!(light_swaps(&s, &scene), vec![vec![4, 5, 6, 3, 0, 1, 2]]);
        let (s, scene) = space(2.0);
        assert!(light_swaps(&s, &scene).is_empty(), "bounds differ");
    }
}
