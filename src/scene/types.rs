//! The typed scene: the structs the JSON format (`scenefit-scene/1`)
//! deserialises into. Validation lives in `validate.rs`; these types only
//! say what keys exist and what their defaults are.

use serde::{Deserialize, Serialize};

pub use super::shape::Shape;
use super::texture::MapKind;
pub use super::texture::TextureRef;
pub use super::transform::{Scale, Transform};

pub use crate::math::Vec3;

/// The format tag every scene file carries.
pub const FORMAT: &str = "scenefit-scene/1";

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    pub format: String,
    pub image: ImageSize,
    pub camera: Camera,
    #[serde(default)]
    pub ambient: Vec3,
    #[serde(default)]
    pub render: RenderSettings,
    pub lights: Vec<Light>,
    pub objects: Vec<Object>,
    /// Strength of the built-in tracer's one-bounce inter-reflection
    /// (absent: none). See docs/scene-format.md "Effects".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indirect_light: Option<f64>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub free: Vec<FreeParam>,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(deny_unknown_fields)]
pub struct ImageSize {
    pub width: u32,
    pub height: u32,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum CameraKind {
    Perspective,
    Orthographic,
    /// A calibrated camera in OpenCV's conventions (scene/pinhole.rs).
    Pinhole,
}

/// One struct for every camera kind; `validate` checks that each kind has
/// its own fields and none of the others'. `perspective` and
/// `orthographic` are placed by `position`, `look_at` and `up`; `pinhole`
/// by `rotation` and `translation` (world to camera), with `fx`, `fy`,
/// `cx`, `cy` in pixels and optional `distortion`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    #[serde(rename = "type")]
    pub kind: CameraKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub look_at: Option<Vec3>,
    /// Not used by a pinhole camera (its rotation orients it), which then
    /// takes only the default.
    #[serde(default = "default_up")]
    pub up: Vec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov_y_deg: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
    /// A pinhole camera's calibration, as OpenCV's `calibrateCamera` /
    /// `solvePnP` return it (scene/pinhole.rs); absent for the other kinds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fx: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fy: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cx: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cy: Option<f64>,
    /// Rodrigues vector of the world-to-camera rotation (`rvec`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<Vec3>,
    /// World-to-camera translation (`tvec`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translation: Option<Vec3>,
    /// k1, k2, p1, p2, k3 (absent: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distortion: Option<[f64; 5]>,
    /// Image-space darkening towards the corners (absent: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vignetting: Option<Vignetting>,
    /// The camera's response curve on linear values (absent: identity).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub response: Option<Response>,
    /// A photograph's exposure: linear values times this (absent: 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exposure: Option<f64>,
    /// A photograph's white balance: linear R, G, B times these (absent: 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub white_balance: Option<Vec3>,
}

/// radiance x (1 - strength * r^2), r the distance from the image centre
/// over the half-diagonal.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Vignetting {
    pub strength: f64,
}

/// v -> black + gain * v^gamma on linear values, then written to the
/// image as `encoding` says.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Response {
    #[serde(default = "one")]
    pub gain: f64,
    #[serde(default = "one")]
    pub gamma: f64,
    /// Added after the curve; below 0 it is a black level subtracted (the
    /// result clipped at 0).
    #[serde(default)]
    pub black: f64,
    /// How the camera writes the curve's output into the file.
    #[serde(default, skip_serializing_if = "ResponseEncoding::is_srgb")]
    pub encoding: ResponseEncoding,
}

/// `srgb`: the curve's output is light, stored through the sRGB transfer
/// function (a camera's JPEG); `linear`: the output is stored as is, a
/// fraction of the file's maximum (a raw converter's linear output, many
/// photometric-stereo and light-stage data sets).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ResponseEncoding {
    #[default]
    Srgb,
    Linear,
}

impl ResponseEncoding {
    fn is_srgb(&self) -> bool {
        *self == ResponseEncoding::Srgb
    }
}

impl Default for Response {
    fn default() -> Self {
        Response {
            gain: 1.0,
            gamma: 1.0,
            black: 0.0,
            encoding: ResponseEncoding::Srgb,
        }
    }
}

fn default_up() -> Vec3 {
    [0.0, 1.0, 0.0]
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RenderSettings {
    /// Samples per pixel for sampling backends.
    #[serde(default = "default_samples")]
    pub samples: u32,
    /// Trace indirect light (false: direct light only, as Phong does).
    #[serde(default = "default_true")]
    pub indirect: bool,
    /// Supersampling of the built-in tracer: an n x n grid per pixel.
    #[serde(default = "default_one")]
    pub antialias: u32,
    /// Recursion limit of mirror reflection and refraction.
    #[serde(default = "default_depth")]
    pub max_depth: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            samples: default_samples(),
            indirect: true,
            antialias: 1,
            max_depth: default_depth(),
        }
    }
}

fn default_samples() -> u32 {
    16
}
fn default_true() -> bool {
    true
}
fn default_one() -> u32 {
    1
}
fn default_depth() -> u32 {
    5
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    Point,
    Directional,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Falloff {
    #[default]
    InverseSquare,
    None,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Light {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: LightKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<Vec3>,
    /// Towards the light (directional lights).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<Vec3>,
    #[serde(default = "white")]
    pub color: Vec3,
    /// Point: radiant intensity, W/sr. Directional: irradiance, W/m^2.
    pub intensity: f64,
    #[serde(default)]
    pub falloff: Falloff,
    #[serde(default)]
    pub radius: f64,
    /// Point lights: irradiance falls as 1/d^p (overrides `falloff`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub falloff_power: Option<f64>,
    /// Directional lights: a near light, at this distance from the origin
    /// along `direction`, whose irradiance at the origin is `intensity`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distance: Option<f64>,
}

impl Light {
    /// Where a directional light with a `distance` is (`None`: at infinity,
    /// or a point light).
    pub fn near_position(&self) -> Option<Vec3> {
        let (d, dist) = (self.direction?, self.distance?);
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        Some(d.map(|x| x / n * dist))
    }
}

fn white() -> Vec3 {
    [1.0, 1.0, 1.0]
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Object {
    pub name: String,
    pub shape: Shape,
    pub material: Material,
    /// Where the shape is placed (absent: as written).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<Transform>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Linear RGB albedo.
    pub color: Vec3,
    #[serde(default = "one")]
    pub diffuse: f64,
    #[serde(default)]
    pub specular: f64,
    #[serde(default = "default_shininess")]
    pub shininess: f64,
    #[serde(default)]
    pub reflection: f64,
    #[serde(default)]
    pub transmission: f64,
    #[serde(default = "default_ior")]
    pub ior: f64,
    /// Schlick Fresnel on the specular lobe: reflectance at normal
    /// incidence F0 in (0, 1]; the lobe is scaled by F(H.V)/F0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fresnel: Option<f64>,
    /// A second Blinn-Phong lobe: its strength and exponent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub specular2: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shininess2: Option<f64>,
    /// The diffuse term's factor at grazing angles (Burley's F_D90): the
    /// diffuse term × (1 + (f90 − 1)(1 − cos θl)⁵)(1 + (f90 − 1)(1 − cos θv)⁵);
    /// below 1 a smooth dielectric's darkening, above 1 a rough
    /// surface's brightening, 1 = Lambertian.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diffuse_f90: Option<f64>,
    /// An OpenEXR image of the camera's size multiplying the diffuse
    /// colour per pixel, in the image's frame (`albedo_map.rs`); made
    /// absolute when the scene is read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub albedo_map: Option<String>,
    /// Textures in the object's frame (`texture/`, docs/scene-format.md
    /// "Textures"): the colour times the map, the specular strengths times
    /// the map, the shininess replaced by the map, the normal replaced by
    /// the map's (tangent space). Paths made absolute when the scene is read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color_map: Option<TextureRef>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub specular_map: Option<TextureRef>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shininess_map: Option<TextureRef>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_map: Option<TextureRef>,
}

fn one() -> f64 {
    1.0
}
fn default_shininess() -> f64 {
    10.0
}
fn default_ior() -> f64 {
    1.5
}

impl Material {
    /// Diffuse only: the same Lambertian BSDF in every backend.
    pub fn is_lambertian(&self) -> bool {
        self.specular == 0.0 && self.reflection == 0.0 && self.transmission == 0.0
    }
}

impl Material {
    /// The material's map of `kind`, if it has one.
    pub fn map(&self, kind: MapKind) -> Option<&TextureRef> {
        match kind {
            MapKind::Color => self.color_map.as_ref(),
            MapKind::Specular => self.specular_map.as_ref(),
            MapKind::Shininess => self.shininess_map.as_ref(),
            MapKind::Normal => self.normal_map.as_ref(),
        }
    }

    /// [`Material::map`], writable.
    pub fn map_mut(&mut self, kind: MapKind) -> Option<&mut TextureRef> {
        self.map_slot(kind).as_mut()
    }

    /// The material's slot for a map of `kind` (to set or clear it): the
    /// kind-to-field table written once for writing, as [`Material::map`]
    /// writes it for reading (a shared borrow cannot come from this one).
    pub fn map_slot(&mut self, kind: MapKind) -> &mut Option<TextureRef> {
        match kind {
            MapKind::Color => &mut self.color_map,
            MapKind::Specular => &mut self.specular_map,
            MapKind::Shininess => &mut self.shininess_map,
            MapKind::Normal => &mut self.normal_map,
        }
    }

    /// True when any map is present.
    pub fn has_maps(&self) -> bool {
        MapKind::ALL.iter().any(|&k| self.map(k).is_some())
    }
}

/// A bound of a free parameter: a number, or one per component.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum Bound {
    Scalar(f64),
    Vector(Vec3),
}

impl Bound {
    /// The bound of component `i` (a number bounds every component).
    pub fn at(self, i: usize) -> f64 {
        match self {
            Bound::Scalar(x) => x,
            Bound::Vector(v) => v[i],
        }
    }

    /// The bounds of the first `n` components (at most three for a
    /// vector).
    pub fn components(self, n: usize) -> Vec<f64> {
        match self {
            Bound::Scalar(x) => vec![x; n],
            Bound::Vector(v) => v[..n.min(3)].to_vec(),
        }
    }
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum ColorSpace {
    #[default]
    Rgb,
    Hsv,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FreeParam {
    pub param: String,
    pub min: Bound,
    pub max: Bound,
    #[serde(default, skip_serializing_if = "is_rgb")]
    pub space: ColorSpace,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase: Option<u32>,
    /// In a set of photographs (`fit --shots`), each photograph gets its
    /// own value; every other free parameter is shared by all of them.
    #[serde(default, skip_serializing_if = "is_false")]
    pub per_shot: bool,
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn is_rgb(space: &ColorSpace) -> bool {
    *space == ColorSpace::Rgb
}

impl Scene {
    pub fn light_index(&self, name: &str) -> Option<usize> {
        self.lights.iter().position(|l| l.name == name)
    }
    pub fn object_index(&self, name: &str) -> Option<usize> {
        self.objects.iter().position(|o| o.name == name)
    }
}
