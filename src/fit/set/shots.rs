//! Sets of photographs of one scene (`fit --shots FILE`): the shots file
//! read and checked, each shot turned into its own scene (the scene with the
//! shot's `set` values) and its own target. Paths in the file are relative
//! to the file.
//!
//! ```json
//! {"format": "scenefit-shots/1",
//!  "shots": [{"name": "001", "target": "001.png", "mask": "mask.png",
//!             "encoding": "srgb", "set": {"lights.led.intensity": 2.5}},
//!            {"name": "002", "target": "002.png", "hold_out": true}]}
//! ```
//!
//! A shot marked `hold_out` takes no part in the fit; it is predicted
//! after it (`held_out`).

use crate::error::{Error, Result};
use crate::fit::FitTarget;
use crate::fsio::{self, CappedRead};
use crate::scene::limits::{quote, valid_name, NAME_CHARS};
use crate::scene::load::with_overrides;
use crate::scene::{Field, Override, ParamSpace, Scene};
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub const FORMAT: &str = "scenefit-shots/1";
/// The largest shots file read, bytes.
const MAX_BYTES: u64 = 16 << 20;
/// The most photographs in one set.
pub const MAX_SHOTS: usize = 4096;

/// The file as written.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShotsFile {
    pub format: String,
    pub shots: Vec<Entry>,
}

/// One photograph as the file lists it.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Entry {
    pub name: String,
    pub target: PathBuf,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mask: Option<PathBuf>,
    /// `srgb` (the default, except for OpenEXR) or `linear`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub encoding: Option<String>,
    /// Known values of this photograph (param paths, as `--set` takes).
    #[serde(default, skip_serializing_if = "serde_json::Map::is_empty")]
    pub set: serde_json::Map<String, serde_json::Value>,
    /// Held out of the fit, and predicted after it (`held_out`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub hold_out: bool,
}

/// One photograph, ready to fit.
#[derive(Clone, Debug)]
pub struct Shot {
    pub name: String,
    /// The scene with this shot's `set` values.
    pub scene: Scene,
    /// Shared: a shot is cloned for every model the diagnosis refits,
    /// and its photograph need not be.
    pub target: Arc<FitTarget>,
    /// The entry with absolute paths (written into the run directory so
    /// that `diagnose` finds the photographs).
    pub entry: Entry,
}

impl Shot {
    /// One photograph of `scene`, given on its own (`fit --target`): a
    /// list of one.
    pub fn one(scene: &Scene, target: FitTarget) -> Shot {
        let entry = Entry {
            name: "target".into(),
            target: target.path.clone().unwrap_or_default(),
            mask: None,
            encoding: None,
            set: Default::default(),
            hold_out: false,
        };
        Shot {
            name: entry.name.clone(),
            scene: scene.clone(),
            target: Arc::new(target),
            entry,
        }
    }

    /// This shot's own free parameters: the per-shot ones its `set` does
    /// not fix.
    pub fn own_space(&self, space: &ParamSpace) -> ParamSpace {
        space.filtered(|s| s.per_shot && !self.entry.set.contains_key(&s.name))
    }
}

/// Reads the shots file at `path` for `scene`: the shots, and a line for
/// each photograph whose saturated pixels were left out.
pub fn load(path: &Path, scene: &Scene) -> Result<(Vec<Shot>, Vec<String>)> {
    let file = path.display().to_string();
    let file_data = read(path, &file)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let space = ParamSpace::from_scene(scene);
    let mut names = BTreeSet::new();
    let mut shots = Vec::with_capacity(file_data.shots.len());
    let mut notes = Vec::new();
    for (i, e) in file_data.shots.into_iter().enumerate() {
        let at = format!("shots[{i}]");
        if !valid_name(&e.name) {
            return Err(Error::invalid(
                &file,
                format!("{at}.name"),
                format!("expected {NAME_CHARS}, got {}", quote(&e.name)),
            ));
        }
        if !names.insert(e.name.clone()) {
            return Err(Error::invalid(
                &file,
                format!("{at}.name"),
                format!(
                    "{} names two shots; expected each name once",
                    quote(&e.name)
                ),
            ));
        }
        let (s, note) = shot(e, dir, scene, &space, &file, &at)?;
        shots.push(s);
        notes.extend(note);
    }
    Ok((shots, notes))
}

/// The file's typed contents, with its format and size checked.
fn read(path: &Path, file: &str) -> Result<ShotsFile> {
    let bytes = fsio::read_capped(path, MAX_BYTES).map_err(|e| match e {
        CappedRead::Io(e) => Error::io(path, e),
        CappedRead::Directory => Error::invalid(
            file,
            "(file)",
            "is a directory; expected a shots file (JSON)",
        ),
        CappedRead::TooLarge => Error::invalid(
            file,
            "(file)",
            format!(
                "larger than {} MiB; expected a shots file (JSON)",
                MAX_BYTES >> 20
            ),
        ),
    })?;
    let text = String::from_utf8_lossy(&bytes);
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    // serde reads a struct from an array too, and then names an element
    if !text.trim_start().starts_with('{')
        && serde_json::from_str::<serde::de::IgnoredAny>(text).is_ok()
    {
        return Err(Error::invalid(
            file,
            "(top level)",
            format!("expected a JSON object {{\"format\": \"{FORMAT}\", \"shots\": [...]}}"),
        ));
    }
    let de = &mut serde_json::Deserializer::from_str(text);
    let parsed: ShotsFile = serde_path_to_error::deserialize(de).map_err(|e| {
        let key = e.path().to_string();
        let inner = e.into_inner();
        let key = if inner.is_syntax() || inner.is_eof() {
            format!("line {} column {}", inner.line(), inner.column())
        } else if key == "." {
            "(top level)".into()
        } else {
            crate::scene::limits::key(&key)
        };
        Error::invalid(
            file,
            key,
            crate::scene::limits::one_line(&inner.to_string()),
        )
    })?;
    if parsed.format != FORMAT {
        return Err(Error::invalid(
            file,
            "format",
            format!("expected {}, got {}", quote(FORMAT), quote(&parsed.format)),
        ));
    }
    if parsed.shots.is_empty() || parsed.shots.len() > MAX_SHOTS {
        return Err(Error::invalid(
            file,
            "shots",
            format!(
                "expected 1 to {MAX_SHOTS} shots, got {}",
                parsed.shots.len()
            ),
        ));
    }
    Ok(parsed)
}

/// A shot's scene refused with its `set` values: the error names the
/// shots file, the shot and the `set` key whose value alone is refused
/// (the scene's own key path in the message), or the shot's whole `set`.
fn blame_set(e: Error, scene: &Scene, overrides: &[Override], file: &str, at: &str) -> Error {
    let Error::Invalid { key, message, .. } = e else {
        return e;
    };
    // an override that could not be applied is named already, by its path
    if let Some(path) = key.strip_prefix(&format!("{at}.")) {
        return Error::invalid(file, format!("{at}.set.{path}"), message);
    }
    for o in overrides {
        if let Err(Error::Invalid { key, message, .. }) =
            with_overrides(scene, std::slice::from_ref(o), file, at)
        {
            return Error::invalid(
                file,
                format!("{at}.set.{}", o.path),
                format!("{message} (the scene's {key})"),
            );
        }
    }
    Error::invalid(
        file,
        format!("{at}.set"),
        format!("{message} (the scene's {key})"),
    )
}

/// One entry checked and loaded: its scene, its target, its mask.
fn shot(
    mut e: Entry,
    dir: &Path,
    scene: &Scene,
    space: &ParamSpace,
    file: &str,
    at: &str,
) -> Result<(Shot, Option<String>)> {
    let mut overrides = Vec::with_capacity(e.set.len());
    for (param, value) in &e.set {
        let key = format!("{at}.set.{param}");
        Field::resolve(scene, param).map_err(|m| Error::invalid(file, &key, m))?;
        if space.specs.iter().any(|s| &s.name == param && !s.per_shot) {
            return Err(Error::invalid(
                file,
                &key,
                "is a shared free parameter of the scene; expected a per-shot one (\"per_shot\": true) or a field that is not free",
            ));
        }
        overrides.push(Override {
            path: param.clone(),
            value: value.clone(),
        });
    }
    let shot_scene = with_overrides(scene, &overrides, file, at)
        .map_err(|e| blame_set(e, scene, &overrides, file, at))?;
    e.target = dir.join(&e.target);
    e.mask = e.mask.map(|m| dir.join(m));
    let encoding = e
        .encoding
        .as_deref()
        .map(|s| s.parse())
        .transpose()
        .map_err(|m: String| Error::invalid(file, format!("{at}.encoding"), m))?;
    let size = (shot_scene.image.width, shot_scene.image.height);
    let what = format!("{at}.target");
    let mask_what = format!("{at}.mask");
    let mask = e.mask.as_deref().map(|m| (m, mask_what.as_str()));
    let (target, note) = FitTarget::from_photo(&e.target, &what, mask, encoding, size)?;
    Ok((
        Shot {
            name: e.name.clone(),
            scene: shot_scene,
            target: Arc::new(target),
            entry: e,
        },
        note,
    ))
}
