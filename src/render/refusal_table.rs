//! The table "What a backend refuses" in docs/renderers.md, checked
//! against the registry: for each row a scene exercising that field, and
//! the backends whose `supports` refuses it must be exactly those the row
//! names; no backend may refuse a field the table does not list.

use super::registry::ALL;
use crate::scene::test_scene::ball;
use crate::scene::{Falloff, LightKind, Scene, TextureRef};
use std::collections::BTreeSet;

/// The doc's rows: (field column, refused-by column).
fn rows() -> Vec<(String, String)> {
    let doc = include_str!("../../docs/renderers.md");
    let start = doc
        .find("### What a backend refuses")
        .expect("docs/renderers.md has the refusal table");
    doc[start..]
        .lines()
        .skip_while(|l| !l.starts_with("| Field"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            (cells[1].to_string(), cells[2].to_string())
        })
        .collect()
}

/// The plane through the origin, facing +z.
fn facing_plane() -> crate::scene::Shape {
    serde_json::from_value(
        serde_json::json!({"type": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}),
    )
    .unwrap()
}

/// A scene exercising the row whose field column starts with `field`.
fn scene_for(field: &str) -> Scene {
    let mut s = ball(r#""color": [0.5, 0.5, 0.5]"#, "");
    let m = &mut s.objects[0].material;
    match field {
        "`fresnel` (other than 1)" => m.fresnel = Some(0.1),
        "directional `radius`" => {
            s.lights[0].kind = LightKind::Directional;
            s.lights[0].radius = 0.05;
        }
        "point `radius` with `falloff_power` other than 2 or `falloff: none`" => {
            s.lights[0].kind = LightKind::Point;
            s.lights[0].radius = 0.2;
            s.lights[0].falloff = Falloff::None;
        }
        "`fresnel` or `specular2` with `transmission` > 0" => {
            m.transmission = 0.5;
            m.specular2 = Some(0.3);
        }
        "`render.max_depth` above 254" => s.render.max_depth = 255,
        "`material.diffuse_f90` (other than 1)" => m.diffuse_f90 = Some(0.5),
        "`material.albedo_map`" => m.albedo_map = Some("map.png".into()),
        "a `specular_map` or `shininess_map` with `specular2` > 0" => {
            m.specular_map = Some(TextureRef::File("t.png".into()));
            m.specular2 = Some(0.2);
        }
        "a `normal_map` on a `plane` whose `transform.scale` differs between axes" => {
            m.normal_map = Some(TextureRef::File("t.png".into()));
            s.objects[0].shape = facing_plane();
            s.objects[0].transform =
                serde_json::from_value(serde_json::json!({"scale": [1.0, 2.0, 1.0]})).unwrap();
        }
        "a `normal_map` on a `plane` more than 5 % of whose slopes are not a height field's there" => {
            m.normal_map = Some(TextureRef::File(twisted_normal_map()));
            s.objects[0].shape = facing_plane();
        }
        "a texture map on a material with `transmission` > 0" => {
            m.color_map = Some(TextureRef::File("t.png".into()));
            m.transmission = 0.5;
        }
        "`camera.fy` other than `camera.fx` (a pinhole's)" => {
            s.camera = serde_json::from_value(serde_json::json!({"type": "pinhole",
                "fx": 100.0, "fy": 90.0, "cx": 31.5, "cy": 23.5, "rotation": [0.0, 0.0, 0.0],
                "translation": [0.0, -0.5, 5.0]}))
            .unwrap()
        }
        "`camera.distortion` (a pinhole's, not all 0)" => {
            s.camera = serde_json::from_value(serde_json::json!({"type": "pinhole",
                "fx": 100.0, "fy": 100.0, "cx": 31.5, "cy": 23.5, "rotation": [0.0, 0.0, 0.0],
                "translation": [0.0, -0.5, 5.0], "distortion": [-0.1, 0.0, 0.0, 0.0, 0.0]}))
            .unwrap()
        }
        "`transform` of a `mesh` object" => {
            s.objects[0].shape = crate::scene::Shape::Mesh {
                file: "m.ply".into(),
            };
            s.objects[0].transform =
                serde_json::from_value(serde_json::json!({"translate": [0.1, 0.0, 0.0]})).unwrap();
        }
        other => panic!("docs/renderers.md refuses {other:?}: add a scene for it here"),
    }
    s
}

/// A normal map no height field has (the slope along u changes along v),
/// written once into the system's temporary folder.
fn twisted_normal_map() -> String {
    let path = std::env::temp_dir().join(format!("scenefit_twisted_{}.png", std::process::id()));
    let img = image::RgbImage::from_fn(16, 16, |_, y| {
        let x = 0.3 * (std::f64::consts::TAU * (y as f64 + 0.5) / 16.0).cos();
        image::Rgb([(255.0 * (x + 1.0) / 2.0).round() as u8, 128, 255])
    });
    img.save(&path).unwrap();
    path.to_string_lossy().into_owned()
}

/// The registry's names that a cell mentions.
fn named(cell: &str) -> BTreeSet<&'static str> {
    let words: BTreeSet<&str> = cell
        .split(|c: char| !c.is_ascii_alphanumeric() && c != ':')
        .collect();
    ALL.iter()
        .map(|b| b.name)
        .filter(|n| words.contains(n))
        .collect()
}

#[test]
fn the_docs_refusal_table_is_what_each_backend_refuses() {
    let rows = rows();
    assert!(rows.len() >= 7, "{rows:?}");
    let plain = ball(r#""color": [0.5, 0.5, 0.5]"#, "");
    for b in ALL {
        assert!(
            (b.supports)(&plain).is_empty(),
            "{} refuses a plain ball",
            b.name
        );
    }
    for (field, by) in &rows {
        let scene = scene_for(field);
        let refusing: BTreeSet<&str> = ALL
            .iter()
            .filter(|b| !(b.supports)(&scene).is_empty())
            .map(|b| b.name)
            .collect();
        assert_eq!(refusing, named(by), "docs/renderers.md row {field:?}");
    }
}
