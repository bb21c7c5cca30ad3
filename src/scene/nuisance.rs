//! Nuisance parameters of a photograph: its exposure and white balance,
//! freed on request (`fit --nuisance exposure,white_balance`) so that a
//! camera's level and colour cast are not charged to the scene's lights
//! and materials. Both are image-space camera fields (`camera.exposure`,
//! `camera.white_balance`; docs/scene-format.md).

use super::{Bound, FreeParam, Scene};

/// A nuisance parameter a fit can free.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Nuisance {
    /// `camera.exposure`, searched over 0.25-4.
    Exposure,
    /// `camera.white_balance`, each channel searched over 0.5-2.
    #[value(name = "white_balance")]
    WhiteBalance,
}

/// Frees `which` in `scene`: the camera field is set to neutral where the
/// scene does not give it, and a free entry is added unless one exists.
pub fn add(scene: &mut Scene, which: &[Nuisance]) {
    for n in which {
        let (param, min, max) = match n {
            Nuisance::Exposure => {
                scene.camera.exposure.get_or_insert(1.0);
                ("camera.exposure", Bound::Scalar(0.25), Bound::Scalar(4.0))
            }
            Nuisance::WhiteBalance => {
                scene.camera.white_balance.get_or_insert([1.0; 3]);
                (
                    "camera.white_balance",
                    Bound::Vector([0.5; 3]),
                    Bound::Vector([2.0; 3]),
                )
            }
        };
        if scene.free.iter().any(|f| f.param == param) {
            continue;
        }
        scene.free.push(FreeParam {
            param: param.into(),
            min,
            max,
            space: Default::default(),
            phase: None,
            per_shot: false,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::ParamSpace;

    #[test]
    fn adds_neutral_fields_and_free_entries_once() {
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/diligent_ball.json"),
        )
        .unwrap();
        let mut s = crate::scene::parse(&text, "diligent_ball.json", &[]).unwrap();
        let dim = ParamSpace::from_scene(&s).dim();
        add(&mut s, &[Nuisance::Exposure, Nuisance::WhiteBalance]);
        add(&mut s, &[Nuisance::Exposure]);
        assert_eq!(s.camera.exposure, Some(1.0));
        assert_eq!(s.camera.white_balance, Some([1.0; 3]));
        assert_eq!(ParamSpace::from_scene(&s).dim(), dim + 4);
    }
}
