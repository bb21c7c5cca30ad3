//! Textures in the object's frame (docs/scene-format.md, "Textures"):
//! `material.color_map`, `specular_map`, `shininess_map` and `normal_map`,
//! each an image file (PNG, 8 or 16 bits, or OpenEXR) looked up by the
//! surface's texture coordinates (`uv.rs`): a mesh's own, or the
//! documented parametrisation of a primitive. A map multiplies its scalar
//! (colour, specular) or replaces it (shininess; normal, in tangent space),
//! so that every free parameter keeps its meaning.
//!
//! A scene holds the map's reference: a path, or `{"file", "encoding",
//! "scale", "range"}`. The path is made absolute when the scene is read
//! (relative to the scene file, as a mesh's); the texels are read once per
//! process (`read.rs`) and shared, since a fit clones the scene for every
//! candidate. Lookups are bilinear with repeat wrap (`sample.rs`).

mod read;
mod sample;
pub mod tangent;
pub mod uv;

pub use read::{check, get};
pub use sample::Texels;

use serde::{Deserialize, Serialize};

/// How a map's stored values become linear ones.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum Encoding {
    /// Through the sRGB transfer function (an 8- or 16-bit colour image).
    Srgb,
    /// As stored, a fraction of the format's maximum (EXR: as is).
    Linear,
}

/// A map as the scene writes it: a path, or a path with settings.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum TextureRef {
    File(String),
    Spec(TextureSpec),
}

/// A map with its settings; absent ones take their defaults.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TextureSpec {
    pub file: String,
    /// Default: sRGB for a colour map in PNG, linear otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub encoding: Option<Encoding>,
    /// Texture coordinates times these (repeats per unit; default 1, 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<[f64; 2]>,
    /// A stored value v (after decoding) means lo + v (hi - lo); default
    /// [0, 1]: the value itself.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<[f64; 2]>,
}

/// Which of a material's maps: how it is read and what it does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapKind {
    Color,
    Specular,
    Shininess,
    Normal,
}

impl MapKind {
    pub const ALL: [MapKind; 4] = [
        MapKind::Color,
        MapKind::Specular,
        MapKind::Shininess,
        MapKind::Normal,
    ];

    /// The material key.
    pub fn key(self) -> &'static str {
        match self {
            MapKind::Color => "color_map",
            MapKind::Specular => "specular_map",
            MapKind::Shininess => "shininess_map",
            MapKind::Normal => "normal_map",
        }
    }
}

impl TextureRef {
    pub fn file(&self) -> &str {
        match self {
            TextureRef::File(f) => f,
            TextureRef::Spec(s) => &s.file,
        }
    }

    pub fn file_mut(&mut self) -> &mut String {
        match self {
            TextureRef::File(f) => f,
            TextureRef::Spec(s) => &mut s.file,
        }
    }

    fn spec(&self) -> Option<&TextureSpec> {
        match self {
            TextureRef::File(_) => None,
            TextureRef::Spec(s) => Some(s),
        }
    }

    /// The encoding the map is read with: as declared, else sRGB for a
    /// colour map in an 8- or 16-bit format, linear for OpenEXR and for
    /// every other kind of map (its values are data, not colours).
    pub fn encoding(&self, kind: MapKind) -> Encoding {
        if let Some(e) = self.spec().and_then(|s| s.encoding) {
            return e;
        }
        let exr = self.file().to_ascii_lowercase().ends_with(".exr");
        if kind == MapKind::Color && !exr {
            Encoding::Srgb
        } else {
            Encoding::Linear
        }
    }

    /// Repeats per unit of the texture coordinates, (u, v).
    pub fn scale(&self) -> [f64; 2] {
        self.spec().and_then(|s| s.scale).unwrap_or([1.0, 1.0])
    }

    /// (lo, hi): a stored value v means lo + v (hi - lo).
    pub fn range(&self) -> [f64; 2] {
        self.spec().and_then(|s| s.range).unwrap_or([0.0, 1.0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_map_reads_as_a_path_or_with_settings_and_is_written_back_alike() {
        for json in [
            r#""wood.png""#,
            r#"{"file":"wood.png","encoding":"linear","scale":[2.0,3.0],"range":[1.0,100.0]}"#,
            r#"{"file":"wood.exr"}"#,
        ] {
            let t: TextureRef = serde_json::from_str(json).unwrap();
            assert_eq!(serde_json::to_string(&t).unwrap(), json);
        }
        let t: TextureRef = serde_json::from_str(r#""a.PNG""#).unwrap();
        assert_eq!(t.encoding(MapKind::Color), Encoding::Srgb);
        assert_eq!(t.encoding(MapKind::Specular), Encoding::Linear);
        let t: TextureRef = serde_json::from_str(r#""a.exr""#).unwrap();
        assert_eq!(t.encoding(MapKind::Color), Encoding::Linear);
        assert_eq!((t.scale(), t.range()), ([1.0, 1.0], [0.0, 1.0]));
        let bad = serde_json::from_str::<TextureRef>(r#"{"file":"a.png","tile":2}"#);
        assert!(bad.is_err());
    }
}
