//! Reading a scene file: JSON text -> `--set` overrides -> typed `Scene` ->
//! validation. Errors name the file, the key path and what was expected.

use super::types::Scene;
use super::validate::validate;
use crate::error::{Error, Result};
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
            format!("--set {s}: expected PARAM=JSON, e.g. lights.key.position=[1,2,3]")
        })?;
        let value = serde_json::from_str(json)
            .map_err(|e| format!("--set {s}: the value is not JSON ({e})"))?;
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
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse(&text, &path.display().to_string(), overrides)
}

/// Parses scene text; `file` names it in messages.
pub fn parse(text: &str, file: &str, overrides: &[Override]) -> Result<Scene> {
    let mut value: serde_json::Value = serde_json::from_str(text).map_err(|e| {
        Error::invalid(
            file,
            format!("line {} column {}", e.line(), e.column()),
            format!("not valid JSON: {e}"),
        )
    })?;
    for o in overrides {
        apply_override(&mut value, o)
            .map_err(|m| Error::invalid(file, &o.path, format!("--set: {m}")))?;
    }
    from_value(value, file)
}

/// Types and validates a JSON value.
pub fn from_value(value: serde_json::Value, file: &str) -> Result<Scene> {
    let scene: Scene = serde_path_to_error::deserialize(value).map_err(|e| {
        let key = e.path().to_string();
        let key = if key == "." {
            "(top level)".to_string()
        } else {
            key
        };
        Error::invalid(file, key, e.into_inner().to_string())
    })?;
    validate(&scene, file)?;
    Ok(scene)
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
        let obj = node
            .as_object_mut()
            .ok_or_else(|| format!("\"{}\" is not an object", parts[..i].join(".")))?;
        if last {
            obj.insert(key.to_string(), o.value.clone());
            return Ok(());
        }
        if named_list {
            let name = parts[i + 1];
            let list = obj
                .get_mut(key)
                .and_then(|v| v.as_array_mut())
                .ok_or_else(|| format!("the scene has no list \"{key}\""))?;
            node = list
                .iter_mut()
                .find(|e| e.get("name").and_then(|n| n.as_str()) == Some(name))
                .ok_or_else(|| format!("no entry named \"{name}\" in {key}"))?;
            if i + 2 == parts.len() {
                return Err(format!("expected {key}.{name}.FIELD"));
            }
            i += 2;
        } else {
            node = obj
                .get_mut(key)
                .ok_or_else(|| format!("the scene has no \"{}\"", parts[..=i].join(".")))?;
            i += 1;
        }
    }
    Ok(())
}
