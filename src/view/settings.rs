//! What the viewport shows and how: the shading mode, the colour ramp's range, the overlays,
//! the tessellation quality and the camera, in one struct that the app holds, the renderer
//! reads and the project file saves (its `view` object).

use std::ops::RangeInclusive;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::OrbitCamera;
use std::f32::consts::FRAC_PI_2;

/// The adaptive tessellation's default error on screen, in pixels.
pub const DEFAULT_TOLERANCE_PX: f32 = 0.5;
/// The adaptive tessellation's error range, in pixels (the panel's slider, scripts, files).
pub const TOLERANCE_RANGE: std::ops::RangeInclusive<f32> = 0.1..=8.0;

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
    /// Zebra stripes: the reflection of parallel tube lights (or the normal's direction).
    Zebra = 7,
    /// Isophotes: lines of constant angle between the normal and a light direction.
    Isophotes = 8,
    /// The reflection of a procedural studio (soft boxes and a floor).
    Reflection = 9,
    /// Draft angle against a pull direction, with a threshold and the undercut marked.
    Draft = 10,
    /// Each subdivision patch in the colour of the level its vertices come from (adaptive
    /// refinement shows where it refined); other patches plain.
    Level = 11,
}

impl ShadingMode {
    pub const ALL: [ShadingMode; 12] = [
        Self::Plain,
        Self::Normals,
        Self::Checker,
        Self::Gaussian,
        Self::Mean,
        Self::K1,
        Self::K2,
        Self::Zebra,
        Self::Isophotes,
        Self::Reflection,
        Self::Draft,
        Self::Level,
    ];

    /// Whether the fragment shader evaluates the surface itself at every pixel (the analysis
    /// modes) rather than interpolating the vertices.
    pub fn per_pixel(self) -> bool {
        (Self::Gaussian as u32..=Self::Draft as u32).contains(&(self as u32))
    }

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
            Self::Zebra => "Zebra",
            Self::Isophotes => "Isophotes",
            Self::Reflection => "Environment reflection",
            Self::Draft => "Draft angle",
            Self::Level => "Refinement level",
        }
    }

    /// The curvature component it shows (index into [`crate::gpu::records::SurfaceVertex::curvature`]'s (K, H, k1, k2)), if any.
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
    /// "gaussian", "mean", "k1", "k2", "zebra", "isophotes", "reflection", "draft", "level".
    pub fn name(self) -> &'static str {
        match self {
            Self::Plain => "plain",
            Self::Normals => "normals",
            Self::Checker => "checker",
            Self::Gaussian => "gaussian",
            Self::Mean => "mean",
            Self::K1 => "k1",
            Self::K2 => "k2",
            Self::Zebra => "zebra",
            Self::Isophotes => "isophotes",
            Self::Reflection => "reflection",
            Self::Draft => "draft",
            Self::Level => "level",
        }
    }

    /// The mode called `name` (see [`Self::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// What the zebra stripes are fixed to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StripeFrame {
    /// The tube lights turn with the camera (horizontal stays horizontal on screen).
    #[default]
    View,
    /// The tube lights stand in the world (X right, Z up, seen from the front).
    World,
}

/// Which direction the zebra stripes follow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ZebraSource {
    /// The reflected view ray (Rhino's zebra: stripes move as the view turns).
    #[default]
    Reflection,
    /// The surface normal (stripes stay on the surface as the view turns).
    Normal,
}

/// The analysis modes' settings and the continuity tolerances (saved with the project's view).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AnalysisSettings {
    /// Black and white stripe pairs per half turn of the reflected ray, in [`ZEBRA_PAIRS`].
    pub zebra_pairs: u32,
    /// The stripes' direction in degrees: 0 horizontal, 90 vertical.
    pub zebra_angle: f64,
    pub zebra_frame: StripeFrame,
    pub zebra_source: ZebraSource,
    /// Degrees between isophotes, in [`ISOPHOTE_SPACING`].
    pub isophote_spacing: f64,
    /// The isophotes' light direction (any length above 0; used normalized).
    pub isophote_direction: [f64; 3],
    /// The mould's pull direction (any length above 0; used normalized).
    pub pull_direction: [f64; 3],
    /// The least acceptable draft angle in degrees, in [`DRAFT_THRESHOLD`].
    pub draft_threshold: f64,
    /// Continuity: the largest gap, as a fraction of the scene's size (its bounding box's
    /// diagonal), the largest angle between the normals in degrees and the largest relative
    /// difference of normal curvature across an edge that still pass.
    pub gap_tolerance: f64,
    pub angle_tolerance: f64,
    pub curvature_tolerance: f64,
    /// Curvature combs on the selected surface's iso-curves.
    pub combs: CombCurves,
    /// Iso-curves per direction (per patch of a patch set), in [`COMB_DENSITY`].
    pub comb_density: u32,
    /// Hair length factor: 1 makes the longest hair a tenth of the scene's size.
    pub comb_scale: f64,
    /// Combs on the selected surface's boundary edges too.
    pub comb_boundary: bool,
    /// The principal directions' line field on the selected surface.
    pub principal_directions: bool,
    /// Samples per direction of the line field, in [`COMB_DENSITY`].
    pub direction_density: u32,
    /// Continuity hair on every shared edge, coloured against the tolerances.
    pub continuity: bool,
    /// The continuity the hair asks of every edge.
    pub continuity_target: ContinuityTarget,
}

/// Which iso-curves carry curvature combs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CombCurves {
    #[default]
    None,
    /// Curves of constant v (running along u).
    U,
    /// Curves of constant u.
    V,
    Both,
}

/// The continuity continuity hair checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ContinuityTarget {
    G0,
    #[default]
    G1,
    G2,
}

/// Iso-curves or samples per direction.
pub const COMB_DENSITY: RangeInclusive<u32> = 1..=64;

/// The zebra's stripe pairs per half turn.
pub const ZEBRA_PAIRS: RangeInclusive<u32> = 1..=64;
/// Isophote spacing in degrees.
pub const ISOPHOTE_SPACING: RangeInclusive<f64> = 0.5..=90.0;
/// Draft threshold in degrees.
pub const DRAFT_THRESHOLD: RangeInclusive<f64> = 0.0..=89.0;

impl Default for AnalysisSettings {
    fn default() -> Self {
        let continuity = crate::scene::continuity::ContinuityOptions::default();
        Self {
            zebra_pairs: 8,
            zebra_angle: 0.0,
            zebra_frame: StripeFrame::View,
            zebra_source: ZebraSource::Reflection,
            isophote_spacing: 10.0,
            isophote_direction: [0.0, 0.0, 1.0],
            pull_direction: [0.0, 0.0, 1.0],
            draft_threshold: 3.0,
            gap_tolerance: continuity.gap,
            angle_tolerance: continuity.angle_degrees,
            curvature_tolerance: continuity.curvature,
            combs: CombCurves::None,
            comb_density: 5,
            comb_scale: 1.0,
            comb_boundary: true,
            principal_directions: false,
            direction_density: 12,
            continuity: false,
            continuity_target: ContinuityTarget::G1,
        }
    }
}

/// `Err("NAME VALUE is outside LO..=HI UNIT")` unless `value` lies in `range`.
fn within<T: PartialOrd + std::fmt::Display>(
    name: &str,
    value: T,
    range: &RangeInclusive<T>,
    unit: &str,
) -> Result<(), String> {
    if range.contains(&value) {
        Ok(())
    } else {
        Err(format!(
            "{name} {value} is outside {}..={}{unit}",
            range.start(),
            range.end()
        ))
    }
}

impl AnalysisSettings {
    /// Checks every number: ranges above, finite non-zero directions, positive tolerances.
    pub fn validate(&self) -> Result<(), String> {
        within("zebra_pairs", self.zebra_pairs, &ZEBRA_PAIRS, "")?;
        if !self.zebra_angle.is_finite() {
            return Err("zebra_angle must be finite".into());
        }
        within(
            "isophote_spacing",
            self.isophote_spacing,
            &ISOPHOTE_SPACING,
            " degrees",
        )?;
        within(
            "draft_threshold",
            self.draft_threshold,
            &DRAFT_THRESHOLD,
            " degrees",
        )?;
        for (name, d) in [
            ("isophote_direction", self.isophote_direction),
            ("pull_direction", self.pull_direction),
        ] {
            let v = DVec3::from(d);
            if !v.is_finite() || v.length_squared() == 0.0 {
                return Err(format!("{name} must be finite and not zero"));
            }
        }
        within("comb_density", self.comb_density, &COMB_DENSITY, "")?;
        within(
            "direction_density",
            self.direction_density,
            &COMB_DENSITY,
            "",
        )?;
        for (name, t) in [
            ("comb_scale", self.comb_scale),
            ("gap_tolerance", self.gap_tolerance),
            ("angle_tolerance", self.angle_tolerance),
            ("curvature_tolerance", self.curvature_tolerance),
        ] {
            if !(t.is_finite() && t > 0.0) {
                return Err(format!("{name} must be finite and above 0"));
            }
        }
        Ok(())
    }

    /// The continuity analysis's options these settings give.
    pub fn continuity_options(&self) -> crate::scene::continuity::ContinuityOptions {
        crate::scene::continuity::ContinuityOptions {
            gap: self.gap_tolerance,
            angle_degrees: self.angle_tolerance,
            curvature: self.curvature_tolerance,
            ..Default::default()
        }
    }

    /// A unit vector along `d` (+Z for a zero or non-finite one).
    pub fn unit(d: [f64; 3]) -> DVec3 {
        DVec3::from(d)
            .try_normalize()
            .filter(|v| v.is_finite())
            .unwrap_or(DVec3::Z)
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
    /// The ground grid in the XY plane.
    #[serde(default = "shown")]
    pub grid: bool,
    /// The axis triad in the viewport's corner.
    #[serde(default = "shown")]
    pub axes: bool,
}

fn shown() -> bool {
    true
}

impl Default for Overlays {
    fn default() -> Self {
        Self {
            surface: true,
            net: true,
            points: true,
            grid: true,
            axes: true,
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
    /// Tessellate the patches for the view (levels per patch edge from its size and curvature
    /// on screen) instead of each object's fixed segment count.
    pub adaptive: bool,
    /// The adaptive tessellation's tolerated error, in pixels, in [`TOLERANCE_RANGE`].
    pub tolerance_px: f32,
    pub overlays: Overlays,
    /// The analysis modes' settings.
    pub analysis: AnalysisSettings,
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            camera: OrbitCamera::default(),
            shading: ShadingMode::Plain,
            range: None,
            quality: 1.0,
            adaptive: true,
            tolerance_px: DEFAULT_TOLERANCE_PX,
            overlays: Overlays::default(),
            analysis: AnalysisSettings::default(),
        }
    }
}

/// The `view` object of a project file: `{"target": [x, y, z], "distance": d, "yaw": a,
/// "pitch": b, "shading": "mean", "quality": q}`, optionally `"range": [low, high]` and
/// `"overlays": {"surface": true, "net": true, "points": true}` (all shown when absent) and
/// `"analysis": {...}` ([`AnalysisSettings`]; defaults for what is absent); `"orthographic":
/// true` for a parallel projection.
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
    #[serde(default)]
    analysis: AnalysisSettings,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    orthographic: bool,
    /// "adaptive" (the default) or "fixed".
    #[serde(default = "adaptive_name")]
    tessellation: String,
    #[serde(default = "default_tolerance")]
    tolerance_px: f64,
}

fn adaptive_name() -> String {
    "adaptive".to_owned()
}

fn default_tolerance() -> f64 {
    f64::from(DEFAULT_TOLERANCE_PX)
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
            analysis: view.analysis,
            orthographic: camera.orthographic,
            tessellation: if view.adaptive { "adaptive" } else { "fixed" }.to_owned(),
            tolerance_px: f64::from(view.tolerance_px),
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
        saved
            .analysis
            .validate()
            .map_err(|e| format!("analysis: {e}"))?;
        let adaptive = match saved.tessellation.as_str() {
            "adaptive" => true,
            "fixed" => false,
            other => {
                return Err(format!(
                    "unknown tessellation {other:?} (\"adaptive\" or \"fixed\")"
                ));
            }
        };
        let tolerance_px = saved.tolerance_px as f32;
        if !TOLERANCE_RANGE.contains(&tolerance_px) {
            return Err(format!(
                "tolerance_px {} is outside {}..={}",
                saved.tolerance_px,
                TOLERANCE_RANGE.start(),
                TOLERANCE_RANGE.end()
            ));
        }
        Ok(Self {
            camera: OrbitCamera {
                target: DVec3::from(saved.target).as_vec3(),
                distance: saved.distance as f32,
                yaw: saved.yaw as f32,
                pitch: (saved.pitch as f32).clamp(-FRAC_PI_2, FRAC_PI_2),
                orthographic: saved.orthographic,
                ..OrbitCamera::default()
            },
            shading,
            range: saved.range.map(|[lo, hi]| (lo, hi)),
            quality,
            adaptive,
            tolerance_px,
            overlays: saved.overlays,
            analysis: saved.analysis,
        })
    }
}
