//! Geometry the fit placed is held through the diagnosis. The diagnosis
//! asks which optical effect the model lacks; where the objects and the
//! camera are is fixed by the silhouettes, which no such effect changes,
//! and a refit that moves geometry traces every camera ray again (about
//! ten times the cost of one that only re-shades; docs/benchmarks.md). So
//! the shared free entries that move geometry are taken out of the refits
//! at their fitted values and put back into improved_scene.json.
//! `diagnose --refit-geometry` keeps them free. Per-shot entries stay free:
//! each photograph's own values are refitted with them.

use crate::scene::{Field, FreeParam, Scene};

/// Takes the shared free entries of `scene` that move geometry out of its
/// free list, and returns them.
fn hold_geometry(scene: &mut Scene) -> Vec<FreeParam> {
    let moves = |f: &FreeParam| {
        !f.per_shot && Field::resolve(scene, &f.param).is_ok_and(|field| field.moves_geometry())
    };
    let (held, kept): (Vec<FreeParam>, Vec<FreeParam>) =
        scene.free.iter().cloned().partition(|f| moves(f));
    scene.free = kept;
    held
}

/// `scene` as the diagnosis refits it, and the entries held out of it
/// (none when `refit_geometry`).
pub fn split(scene: &Scene, refit_geometry: bool) -> (Scene, Vec<FreeParam>) {
    let mut scene = scene.clone();
    let held = match refit_geometry {
        true => Vec::new(),
        false => hold_geometry(&mut scene),
    };
    (scene, held)
}

/// `scene` with the held entries free again (at its values).
pub fn restore(scene: &Scene, held: &[FreeParam]) -> Scene {
    let mut out = scene.clone();
    out.free.extend(held.iter().cloned());
    out
}

/// The held entries' parameter paths, for diagnosis.json.
pub fn paths(held: &[FreeParam]) -> Vec<String> {
    held.iter().map(|f| f.param.clone()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::test_scene::ball;
    use crate::scene::ParamSpace;

    const CENTRE: &str = "objects.ball.shape.center";

    #[test]
    fn shared_geometry_is_held_at_its_value_and_restored() {
        let mut scene = ball(
            r#""color": [0.5, 0.5, 0.5]"#,
            r#"{"param": "lights.key.intensity", "min": 1, "max": 20},
               {"param": "objects.ball.shape.center", "min": [-0.1, 0.4, -0.1], "max": [0.1, 0.6, 0.1]}"#,
        );
        let held = hold_geometry(&mut scene);
        assert_eq!(paths(&held), vec![CENTRE.to_string()]);
        let left = ParamSpace::from_scene(&scene).fields();
        assert_eq!(left.len(), 1, "the intensity stays free");
        assert!(left.iter().all(|f| !f.moves_geometry()));
        let back = restore(&scene, &held);
        assert_eq!(back.free.len(), 2);
        assert_eq!(back.free[1].param, CENTRE);
    }

    #[test]
    fn per_shot_geometry_stays_free() {
        let mut scene = ball(
            r#""color": [0.5, 0.5, 0.5]"#,
            r#"{"param": "objects.ball.shape.center", "min": [-0.1, 0.4, -0.1], "max": [0.1, 0.6, 0.1], "per_shot": true}"#,
        );
        assert!(hold_geometry(&mut scene).is_empty());
        assert_eq!(scene.free.len(), 1);
    }
}
