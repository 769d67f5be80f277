//! What the viewport shows and how: the shading mode, the colour ramp's range, the overlays,
//! the tessellation quality and the camera, in one struct that the app holds, the renderer
//! reads and the project file saves (its `view` object).

use std::ops::RangeInclusive;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::OrbitCamera;
use super::camera::PITCH_LIMIT;

/// The global tessellation quality factor's range (the panel's slider, scripts, files).
pub const QUALITY_RANGE: RangeInclusive<f32> = 0.25..=4.0;

/// How the surface is coloured. WGSL: the `MODE_*` constants of `shaders/surface.wgsl`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ShadingMode {
    /// Lit, one colour.
    #[default]
    Plain = 0,
    /// The unit normal as RGB.
    Normals = 1,
    /// A lit checkerboard in the surface's (u, v).
    Checker = 2,
    /// Gaussian curvature K on the colour ramp.
    Gaussian = 3,
    /// Mean curvature H.
    Mean = 4,
    /// Maximum principal curvature k1.
    K1 = 5,
    /// Minimum principal curvature k2.
    K2 = 6,
}

impl ShadingMode {
    pub const ALL: [ShadingMode; 7] = [
        Self::Plain,
        Self::Normals,
        Self::Checker,
        Self::Gaussian,
        Self::Mean,
        Self::K1,
        Self::K2,
    ];

    /// The name in the panel.
    pub fn label(self) -> &'static str {
        match self {
            Self::Plain => "Plain (lit)",
            Self::Normals => "Normals",
            Self::Checker => "(u, v) checker",
            Self::Gaussian => "Gaussian curvature K",
            Self::Mean => "Mean curvature H",
            Self::K1 => "Max principal k1",
            Self::K2 => "Min principal k2",
        }
    }

    /// The curvature component it shows (index into [`crate::gpu::records::SurfaceVertex::curvature`]), if any.
    pub fn curvature_component(self) -> Option<usize> {
        match self {
            Self::Gaussian => Some(0),
            Self::Mean => Some(1),
            Self::K1 => Some(2),
            Self::K2 => Some(3),
            _ => None,
        }
    }

    /// The lowercase name scripts and the status use: "plain", "normals", "checker",
    /// "gaussian", "mean", "k1", "k2".
    pub fn name(self) -> &'static str {
        match self {
            Self::Plain => "plain",
            Self::Normals => "normals",
            Self::Checker => "checker",
            Self::Gaussian => "gaussian",
            Self::Mean => "mean",
            Self::K1 => "k1",
            Self::K2 => "k2",
        }
    }

    /// The mode called `name` (see [`Self::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// What is drawn over (and including) the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Overlays {
    pub surface: bool,
    /// The selected object's control net.
    pub net: bool,
    pub points: bool,
}

impl Default for Overlays {
    fn default() -> Self {
        Self {
            surface: true,
            net: true,
            points: true,
        }
    }
}

/// The view: camera, shading, ramp, overlays and quality.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SavedView", into = "SavedView")]
pub struct ViewSettings {
    pub camera: OrbitCamera,
    pub shading: ShadingMode,
    /// The colour ramp's (low, high) set by hand; `None`: the scene's automatic range.
    pub range: Option<(f64, f64)>,
    /// The global tessellation quality factor, in [`QUALITY_RANGE`].
    pub quality: f32,
    pub overlays: Overlays,
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            camera: OrbitCamera::default(),
            shading: ShadingMode::Plain,
            range: None,
            quality: 1.0,
            overlays: Overlays::default(),
        }
    }
}

/// The `view` object of a project file: `{"target": [x, y, z], "distance": d, "yaw": a,
/// "pitch": b, "shading": "mean", "quality": q}`, optionally `"range": [low, high]` and
/// `"overlays": {"surface": true, "net": true, "points": true}` (all shown when absent).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SavedView {
    target: [f64; 3],
    distance: f64,
    yaw: f64,
    pitch: f64,
    shading: String,
    quality: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    range: Option<[f64; 2]>,
    #[serde(default)]
    overlays: Overlays,
}

impl From<ViewSettings> for SavedView {
    fn from(view: ViewSettings) -> Self {
        let camera = view.camera;
        Self {
            target: camera.target.as_dvec3().to_array(),
            distance: f64::from(camera.distance),
            yaw: f64::from(camera.yaw),
            pitch: f64::from(camera.pitch),
            shading: view.shading.name().to_owned(),
            quality: f64::from(view.quality),
            range: view.range.map(|(lo, hi)| [lo, hi]),
            overlays: view.overlays,
        }
    }
}

impl TryFrom<SavedView> for ViewSettings {
    type Error = String;

    /// Checks the saved numbers: the camera finite with a positive distance, the quality in
    /// [`QUALITY_RANGE`], the range finite and increasing, the shading a known mode.
    fn try_from(saved: SavedView) -> Result<Self, String> {
        let camera = [saved.distance, saved.yaw, saved.pitch];
        if saved.target.iter().chain(&camera).any(|x| !x.is_finite()) || saved.distance <= 0.0 {
            return Err("the camera must be finite and positive (its distance above 0)".into());
        }
        let quality = saved.quality as f32;
        if !QUALITY_RANGE.contains(&quality) {
            return Err(format!(
                "quality {} is outside {}..={}",
                saved.quality,
                QUALITY_RANGE.start(),
                QUALITY_RANGE.end()
            ));
        }
        let shading = ShadingMode::from_name(&saved.shading).ok_or_else(|| {
            format!(
                "unknown shading {:?} (one of {})",
                saved.shading,
                ShadingMode::ALL.map(ShadingMode::name).join(", ")
            )
        })?;
        if let Some([lo, hi]) = saved.range
            && !(lo.is_finite() && hi.is_finite() && lo < hi)
        {
            return Err(format!("range [{lo}, {hi}] must be finite and increasing"));
        }
        Ok(Self {
            camera: OrbitCamera {
                target: DVec3::from(saved.target).as_vec3(),
                distance: saved.distance as f32,
                yaw: saved.yaw as f32,
                pitch: (saved.pitch as f32).clamp(-PITCH_LIMIT, PITCH_LIMIT),
                ..OrbitCamera::default()
            },
            shading,
            range: saved.range.map(|[lo, hi]| (lo, hi)),
            quality,
            overlays: saved.overlays,
        })
    }
}
