//! Reading a scene file: JSON text -> `--set` overrides -> typed `Scene` ->
//! validation. Errors name the file, the key path and what was expected.

use super::limits::{self, quote, MAX_MAGNITUDE, MAX_SCENE_BYTES};
use super::types::Scene;
use super::validate::validate;
use crate::error::{Error, Result};
use crate::fsio::{self, CappedRead};
use std::path::Path;

/// One `--set PARAM=JSON` override.
#[derive(Clone, Debug)]
pub struct Override {
    pub path: String,
    pub value: serde_json::Value,
}

impl std::str::FromStr for Override {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let (path, json) = s.split_once('=').ok_or_else(|| {
            format!(
                "--set {}: expected PARAM=JSON, e.g. lights.key.position=[1,2,3]",
                quote(s)
            )
        })?;
        let value = serde_json::from_str(json)
            .map_err(|e| format!("--set {}: the value is not JSON ({e})", quote(s)))?;
        Ok(Override {
            path: path.trim().to_string(),
            value,
        })
    }
}

/// Reads and validates the scene at `path`.
pub fn load(path: &Path) -> Result<Scene> {
    load_with(path, &[])
}

/// Reads the scene at `path`, applies `overrides`, and validates the result.
pub fn load_with(path: &Path, overrides: &[Override]) -> Result<Scene> {
    let file = path.display().to_string();
    let text = read_capped(path, &file)?;
    parse(&text, &file, overrides)
}

/// The file's text, refusing directories, more than `MAX_SCENE_BYTES`
/// (`/dev/zero` would otherwise fill memory) and bytes that are not UTF-8.
fn read_capped(path: &Path, file: &str) -> Result<String> {
    let bytes = fsio::read_capped(path, MAX_SCENE_BYTES).map_err(|e| match e {
        CappedRead::Io(e) => Error::io(path, e),
        CappedRead::Directory => Error::invalid(
            file,
            "(file)",
            "is a directory; expected a scene file (JSON)",
        ),
        CappedRead::TooLarge => Error::invalid(
            file,
            "(file)",
            format!(
                "larger than {} MiB; expected a scene file (JSON)",
                MAX_SCENE_BYTES >> 20
            ),
        ),
    })?;
    String::from_utf8(bytes).map_err(|e| {
        Error::invalid(
            file,
            "(file)",
            format!(
                "not UTF-8 text (invalid byte at offset {}); expected a scene file (JSON)",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// Parses scene text; `file` names it in messages.
pub fn parse(text: &str, file: &str, overrides: &[Override]) -> Result<Scene> {
    // A byte-order mark is not JSON, but editors write one: accept it.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut value: serde_json::Value = serde_json::from_str(text).map_err(|e| {
        Error::invalid(
            file,
            format!("line {} column {}", e.line(), e.column()),
            format!("not valid JSON: {e}"),
        )
    })?;
    for o in overrides {
        apply_override(&mut value, o)
            .map_err(|m| Error::invalid(file, quote(&o.path), format!("--set: {m}")))?;
    }
    from_value(value, file)
}

/// `scene` with `overrides` applied (as `--set` would), validated again;
/// `file` and `at` name where the overrides came from in messages.
pub fn with_overrides(
    scene: &Scene,
    overrides: &[Override],
    file: &str,
    at: &str,
) -> Result<Scene> {
    let mut value = serde_json::to_value(scene)
        .map_err(|e| Error::Run(format!("cannot serialise the scene: {e}")))?;
    for o in overrides {
        apply_override(&mut value, o)
            .map_err(|m| Error::invalid(file, format!("{at}.{}", o.path), m))?;
    }
    from_value(value, file)
}

/// Types and validates a JSON value.
pub fn from_value(value: serde_json::Value, file: &str) -> Result<Scene> {
    if !value.is_object() {
        return Err(Error::invalid(
            file,
            "(top level)",
            format!(
                "expected a JSON object {{\"format\": \"{}\", ...}}, got {}",
                super::types::FORMAT,
                kind(&value)
            ),
        ));
    }
    let mut at = String::new();
    numbers_in_range(&value, &mut at).map_err(|(key, x)| {
        Error::invalid(
            file,
            key,
            format!(
                "expected a number between -{MAX_MAGNITUDE:e} and {MAX_MAGNITUDE:e}, got {x:e}"
            ),
        )
    })?;
    let mut scene: Scene = serde_path_to_error::deserialize(value).map_err(|e| {
        let key = e.path().to_string();
        let key = if key == "." {
            "(top level)".to_string()
        } else {
            limits::key(&key)
        };
        // serde echoes the file's own text (an unknown variant or key):
        // escaped and cut like any quoted value
        let message = limits::one_line(&e.into_inner().to_string());
        let message = if message.contains("untagged enum Bound") {
            "expected a number or an array of three numbers".to_string()
        } else if message.contains("untagged enum TextureRef") {
            "expected an image file's path or {\"file\": PATH, \"encoding\", \"scale\", \"range\"} (docs/scene-format.md, \"Textures\")".to_string()
        } else {
            message
        };
        Error::invalid(file, key, message)
    })?;
    for o in &mut scene.objects {
        if let Some(p) = o.material.albedo_map.as_mut() {
            *p = super::albedo_map::resolve(p, file).display().to_string();
        }
        for kind in super::texture::MapKind::ALL {
            if let Some(t) = o.material.map_mut(kind) {
                let p = t.file_mut();
                *p = super::albedo_map::resolve(p, file).display().to_string();
            }
        }
        if let super::shape::Shape::Mesh { file: p } = &mut o.shape {
            *p = super::albedo_map::resolve(p, file).display().to_string();
        }
    }
    validate(&scene, file)?;
    Ok(scene)
}

/// "an array", "a string", ... for messages.
fn kind(v: &serde_json::Value) -> &'static str {
    match v {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "a boolean",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Array(_) => "an array",
        serde_json::Value::Object(_) => "an object",
    }
}

/// Every number of the document within +-MAX_MAGNITUDE (so spans, squares
/// and sums of valid values stay finite); else the key path and the number.
fn numbers_in_range(
    v: &serde_json::Value,
    at: &mut String,
) -> std::result::Result<(), (String, f64)> {
    match v {
        serde_json::Value::Number(n) => {
            let x = n.as_f64().unwrap_or(f64::INFINITY);
            if x.is_nan() || x.abs() > MAX_MAGNITUDE {
                return Err((at.clone(), x));
            }
        }
        serde_json::Value::Array(a) => {
            for (i, e) in a.iter().enumerate() {
                let len = at.len();
                at.push_str(&format!("[{i}]"));
                numbers_in_range(e, at)?;
                at.truncate(len);
            }
        }
        serde_json::Value::Object(o) => {
            for (k, e) in o {
                let len = at.len();
                if !at.is_empty() {
                    at.push('.');
                }
                at.push_str(k);
                numbers_in_range(e, at)?;
                at.truncate(len);
            }
        }
        _ => {}
    }
    Ok(())
}

/// `camera.distortion.k1|k2|p1|p2|k3`: its slot in the five-number array
/// (the field path names it, the file holds a list).
fn distortion_slot<'a>(
    node: &'a mut serde_json::Value,
    key: &str,
) -> Option<&'a mut serde_json::Value> {
    let i = super::field::DISTORTION_KEYS
        .iter()
        .position(|k| *k == key)?;
    node.as_array_mut()?.get_mut(i)
}

/// Sets the JSON value at a dotted path in which `lights.NAME` and
/// `objects.NAME` select list entries by name.
fn apply_override(root: &mut serde_json::Value, o: &Override) -> std::result::Result<(), String> {
    let parts: Vec<&str> = o.path.split('.').collect();
    let mut node = root;
    let mut i = 0;
    while i < parts.len() {
        let key = parts[i];
        let last = i + 1 == parts.len();
        let named_list = (key == "lights" || key == "objects") && i == 0;
        if last && parts[..i] == ["camera", "distortion"] {
            if let Some(slot) = distortion_slot(node, key) {
                *slot = o.value.clone();
                return Ok(());
            }
        }
        let obj = node
            .as_object_mut()
            .ok_or_else(|| format!("{} is not an object", quote(&parts[..i].join("."))))?;
        if last {
            obj.insert(key.to_string(), o.value.clone());
            return Ok(());
        }
        if named_list {
            let name = parts[i + 1];
            let list = obj
                .get_mut(key)
                .and_then(|v| v.as_array_mut())
                .ok_or_else(|| format!("the scene has no list {}", quote(key)))?;
            node = list
                .iter_mut()
                .find(|e| e.get("name").and_then(|n| n.as_str()) == Some(name))
                .ok_or_else(|| format!("no entry named {} in {key}", quote(name)))?;
            if i + 2 == parts.len() {
                return Err(format!("expected {key}.NAME.FIELD"));
            }
            i += 2;
        } else {
            node = obj
                .get_mut(key)
                .ok_or_else(|| format!("the scene has no {}", quote(&parts[..=i].join("."))))?;
            i += 1;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `camera.distortion.p1` names the third of the file's five numbers.
    #[test]
    fn a_distortion_coefficient_is_set_by_its_name() {
        let text = std::fs::read_to_string("scenes/pinhole_crate.json").unwrap();
        let o = Override {
            path: "camera.distortion.p1".into(),
            value: serde_json::json!(0.004),
        };
        let s = parse(&text, "pinhole_crate.json", &[o]).unwrap();
        assert_eq!(s.camera.distortion, Some([-0.1, 0.02, 0.004, 0.0, 0.0]));
    }
}
