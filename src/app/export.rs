//! The Export glTF window: tessellation by tolerance or segments, curvature attributes, the
//! triangle count before writing, then a save dialog (desktop) or a download (web).

use eframe::egui;

use super::KnotworkApp;
use crate::gpu::records::curvature_ramp_rgb;
use crate::io::gltf::{self, CurvatureColors, ExportOptions};
use crate::io::project::Project;
use crate::kernel::tess::Tessellation;

/// What the Export window remembers.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportSettings {
    pub show: bool,
    /// Tolerance (true) or fixed segments (false).
    pub by_tolerance: bool,
    /// Model units; 0 means "not set yet" (the default is taken from the scene's size).
    pub tolerance: f64,
    pub segments: u32,
    /// COLOR_0 from the current curvature shading mode.
    pub colors: bool,
    /// The `_CURVATURE` attribute.
    pub curvature: bool,
    /// Desktop: `.gltf` + `.bin` instead of `.glb`.
    pub text_format: bool,
}

impl Default for ExportSettings {
    fn default() -> Self {
        Self {
            show: false,
            by_tolerance: true,
            tolerance: 0.0,
            segments: 16,
            colors: false,
            curvature: false,
            text_format: false,
        }
    }
}

/// The triangle count shown before writing, for the document revision and settings it was
/// computed for.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportEstimate {
    revision: u64,
    tessellation: Tessellation,
    pub result: Result<(usize, usize), String>,
}

impl ExportSettings {
    pub fn tessellation(&self) -> Tessellation {
        if self.by_tolerance {
            Tessellation::Tolerance(self.tolerance)
        } else {
            Tessellation::Segments(self.segments)
        }
    }
}

/// (triangles, vertices) of the visible objects at `tessellation`.
pub fn count_triangles(
    scene: &crate::scene::Scene,
    tessellation: Tessellation,
) -> Result<(usize, usize), String> {
    let (mut triangles, mut vertices) = (0, 0);
    for object in scene.objects.iter().filter(|o| o.visible) {
        let pieces = object
            .tessellate(tessellation, false)
            .map_err(|e| format!("{}: {e}", object.name))?;
        for piece in pieces {
            triangles += piece.triangles.len();
            vertices += piece.positions.len();
        }
        let limit = crate::kernel::tess::MAX_TRIANGLES;
        if triangles > limit {
            return Err(gltf::ExportError::TooManyTriangles { limit }.to_string());
        }
    }
    Ok((triangles, vertices))
}

impl KnotworkApp {
    /// The export options the window's settings and the current shading mode give.
    fn export_options(&mut self) -> ExportOptions {
        let colors = if self.export.colors {
            self.view
                .shading
                .curvature_component()
                .map(|component| CurvatureColors {
                    component,
                    range: self.color_range().unwrap_or((-1.0, 1.0)),
                    ramp: curvature_ramp_rgb(),
                })
        } else {
            None
        };
        ExportOptions {
            tessellation: self.export.tessellation(),
            curvature: self.export.curvature,
            colors,
        }
    }

    pub(super) fn export_window(&mut self, ctx: &egui::Context) {
        if !self.export.show {
            return;
        }
        if !(self.export.tolerance > 0.0) {
            self.export.tolerance = gltf::default_tolerance(&self.doc.scene);
        }
        let tessellation = self.export.tessellation();
        let stale = self
            .export_estimate
            .as_ref()
            .is_none_or(|e| e.revision != self.saved.revision || e.tessellation != tessellation);
        if stale {
            self.export_estimate = Some(ExportEstimate {
                revision: self.saved.revision,
                tessellation,
                result: count_triangles(&self.doc.scene, tessellation),
            });
        }
        let estimate = match self.export_estimate.as_ref().map(|e| &e.result) {
            Some(Ok((t, v))) => Ok(format!("{t} triangles, {v} vertices")),
            Some(Err(e)) => Err(e.clone()),
            None => Ok(String::new()),
        };
        self.status.export_estimate = Some(estimate.clone().unwrap_or_else(|e| e));
        let mut open = true;
        let mut write = false;
        let curvature_mode = self.view.shading.curvature_component().is_some();
        let settings = &mut self.export;
        let before = settings.clone();
        egui::Window::new("Export glTF")
            .open(&mut open)
            .resizable(false)
            .show(ctx, |ui| {
                ui.radio_value(&mut settings.by_tolerance, true, "By tolerance");
                ui.add_enabled(
                    settings.by_tolerance,
                    egui::Slider::new(&mut settings.tolerance, 1e-6..=10.0)
                        .logarithmic(true)
                        .text("max. distance (model units)"),
                );
                ui.radio_value(&mut settings.by_tolerance, false, "By segments");
                ui.add_enabled(
                    !settings.by_tolerance,
                    egui::Slider::new(&mut settings.segments, 1..=256)
                        .logarithmic(true)
                        .text("segments per span"),
                );
                ui.add_enabled(
                    curvature_mode,
                    egui::Checkbox::new(
                        &mut settings.colors,
                        "Curvature colours (COLOR_0, this shading mode)",
                    ),
                );
                ui.checkbox(
                    &mut settings.curvature,
                    "Raw curvature (_CURVATURE: K, H, k1, k2)",
                );
                if cfg!(not(target_arch = "wasm32")) {
                    ui.checkbox(&mut settings.text_format, ".gltf + .bin instead of .glb");
                }
                ui.separator();
                match &estimate {
                    Ok(text) => ui.label(text),
                    Err(e) => ui.colored_label(egui::Color32::from_rgb(255, 110, 100), e),
                };
                write = ui
                    .add_enabled(estimate.is_ok(), egui::Button::new("Export…"))
                    .clicked();
            });
        if *settings != before {
            ctx.request_repaint();
        }
        self.export.show = open;
        if !curvature_mode {
            self.export.colors = false;
        }
        if write {
            self.export_to_file();
        }
    }

    /// Builds the export and writes it (desktop: save dialog; web: download).
    fn export_to_file(&mut self) {
        let options = self.export_options();
        let project = Project {
            scene: self.doc.scene.clone(),
            view: Some(self.view),
        };
        let export = match gltf::export(&project, &options) {
            Ok(export) => export,
            Err(e) => {
                self.dialog = Some(("Could not export".into(), e.to_string()));
                self.status.error = Some(format!("export: {e}"));
                return;
            }
        };
        let summary = format!("{} triangles", export.triangles);
        #[cfg(not(target_arch = "wasm32"))]
        {
            let (filter, extension) = if self.export.text_format {
                ("glTF (text + .bin)", "gltf")
            } else {
                ("glTF binary", "glb")
            };
            let Some(path) = super::platform::choose_file_to_save(
                filter,
                &[extension],
                &format!("knotwork.{extension}"),
            ) else {
                return;
            };
            let mut path = path.display().to_string();
            if !path
                .to_ascii_lowercase()
                .ends_with(&format!(".{extension}"))
            {
                path.push('.');
                path.push_str(extension);
            }
            for (file, bytes) in gltf::files(&export, &path) {
                if let Err(e) = std::fs::write(&file, bytes) {
                    self.status.error = Some(format!("could not write {file}: {e}"));
                    return;
                }
            }
            self.status.notice = Some(format!("exported {summary} to {path}"));
        }
        #[cfg(target_arch = "wasm32")]
        {
            let bytes = gltf::to_glb(&export);
            match super::platform::download("knotwork.glb", &bytes, "model/gltf-binary") {
                Ok(()) => self.status.notice = Some(format!("downloaded knotwork.glb ({summary})")),
                Err(e) => self.status.error = Some(format!("could not download: {e}")),
            }
        }
    }
}
