//! A scene as a user writes it: its serialised form with each material
//! field that holds the format's default left out, so that what scenefit
//! writes for a user to read or edit (an export's embedded scene, an
//! import's scene file) is the JSON the user wrote, not every default
//! spelled out.

/// Removes from every object's material of the serialised scene `scene`
/// the fields that hold their default value (read from `Material`'s own
/// defaults; `color`, which has none, is kept).
pub fn drop_default_material_fields(scene: &mut serde_json::Value) {
    let defaults =
        serde_json::from_value::<super::Material>(serde_json::json!({"color": [0.0, 0.0, 0.0]}))
            .ok()
            .and_then(|m| serde_json::to_value(m).ok());
    let Some(serde_json::Value::Object(defaults)) = defaults else {
        return;
    };
    let Some(objects) = scene.get_mut("objects").and_then(|o| o.as_array_mut()) else {
        return;
    };
    for material in objects.iter_mut().filter_map(|o| o.get_mut("material")) {
        if let Some(fields) = material.as_object_mut() {
            fields.retain(|k, v| k == "color" || defaults.get(k) != Some(v));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_go_and_set_values_stay() {
        let mut v = serde_json::json!({"objects": [{"material": {
            "color": [0.5, 0.5, 0.5], "diffuse": 1.0, "specular": 0.3}}]});
        let mut full = serde_json::to_value(
            serde_json::from_value::<super::super::Material>(v["objects"][0]["material"].clone())
                .unwrap(),
        )
        .unwrap();
        assert!(
            full.as_object().unwrap().len() > 3,
            "serde writes every field"
        );
        std::mem::swap(&mut v["objects"][0]["material"], &mut full);
        drop_default_material_fields(&mut v);
        let kept: Vec<&String> = v["objects"][0]["material"]
            .as_object()
            .unwrap()
            .keys()
            .collect();
        assert_eq!(kept, ["color", "specular"]);
    }
}
