//! The editor: an eframe app that is the same on the web and on the desktop. It owns the model,
//! runs the compute evaluation and the viewport render on eframe's wgpu device, and shows the
//! result as an egui image beside a control panel.

use std::sync::Arc;

use eframe::egui;
use eframe::egui_wgpu;

use glam::DVec3;

use crate::gpu::records::CURVATURE_RAMP;
use crate::gpu::timing::GpuTimer;
use crate::gpu::{
    self, GpuError, MAX_SEGMENTS, ObjectPatches, PatchEvaluator, PatchGeometry, ShadingMode,
};
use crate::render::{
    ControlNet, DrawOptions, Shading, ViewTarget, ViewportRenderer, scene_uniform,
};
use crate::scene::{Decomposition, Scene, robust_range};
use crate::status::{self, AppStatus, ExternalCommand};
use crate::view::OrbitCamera;

/// The per-object tessellation slider's range (segments per Bézier span edge).
pub const SLIDER_SEGMENTS: std::ops::RangeInclusive<u32> = 1..=128;
/// The global quality slider's range (a factor on every object's segments).
pub const QUALITY_RANGE: std::ops::RangeInclusive<f32> = 0.25..=4.0;
/// Curvature samples per patch edge for the automatic colour range.
const RANGE_SAMPLES: usize = 6;
/// Control point dot radius in logical pixels.
const POINT_RADIUS: f32 = 3.5;

/// eframe's wgpu setup for knotwork: the device of [`gpu::device_descriptor`]; on the web,
/// WebGPU only (no silent WebGL fallback: the page explains what is missing instead).
pub fn wgpu_configuration(web: bool) -> egui_wgpu::WgpuConfiguration {
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    if web {
        setup.instance_descriptor.backends = wgpu::Backends::BROWSER_WEBGPU;
    }
    setup.device_descriptor = Arc::new(gpu::device_descriptor);
    egui_wgpu::WgpuConfiguration {
        wgpu_setup: egui_wgpu::WgpuSetup::CreateNew(setup),
        ..Default::default()
    }
}

/// Everything that lives on the GPU for the viewport.
struct ViewportGpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    egui_renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    evaluator: PatchEvaluator,
    geometry: Option<PatchGeometry>,
    net: Option<ControlNet>,
    renderer: ViewportRenderer,
    target: Option<ViewTarget>,
    texture: Option<egui::TextureId>,
    timer: Option<GpuTimer>,
}

impl ViewportGpu {
    fn new(state: &egui_wgpu::RenderState) -> Self {
        let device = state.device.clone();
        Self {
            evaluator: PatchEvaluator::new(&device),
            renderer: ViewportRenderer::new(&device),
            timer: GpuTimer::new(&device, &state.queue),
            queue: state.queue.clone(),
            egui_renderer: Arc::clone(&state.renderer),
            device,
            geometry: None,
            net: None,
            target: None,
            texture: None,
        }
    }

    /// Makes the offscreen target `size` physical pixels; true when it was (re)created.
    fn ensure_target(&mut self, size: (u32, u32)) -> bool {
        if self.target.as_ref().is_some_and(|t| t.size() == size) {
            return false;
        }
        let target = ViewTarget::new(&self.device, size.0, size.1);
        let mut egui_renderer = self.egui_renderer.write();
        match self.texture {
            Some(id) => egui_renderer.update_egui_texture_from_wgpu_texture(
                &self.device,
                target.view(),
                wgpu::FilterMode::Linear,
                id,
            ),
            None => {
                self.texture = Some(egui_renderer.register_native_texture(
                    &self.device,
                    target.view(),
                    wgpu::FilterMode::Linear,
                ))
            }
        }
        self.target = Some(target);
        true
    }

    /// Runs the compute pass if any patch needs it, then renders the viewport. Returns the
    /// number of patches evaluated.
    fn draw(
        &mut self,
        camera: &OrbitCamera,
        options: &DrawOptions,
        shading: &Shading,
        point_radius_px: f32,
    ) -> Option<u32> {
        let target = self.target.as_ref()?;
        let geometry = self.geometry.as_mut()?;
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("knotwork frame"),
            });
        let mut evaluated = None;
        if geometry.needs_evaluation() {
            let writes = self.timer.as_mut().and_then(GpuTimer::compute_pass_writes);
            evaluated = Some(geometry.encode(&self.queue, &mut encoder, &self.evaluator, writes));
        }
        let (w, h) = target.size();
        let aspect = w as f32 / h.max(1) as f32;
        let scene = scene_uniform(
            camera.view_projection(aspect),
            camera.eye(),
            target,
            point_radius_px,
            shading,
        );
        let writes = self.timer.as_mut().and_then(GpuTimer::render_pass_writes);
        self.renderer.set_scene(&self.queue, &scene);
        self.renderer.render(
            &mut encoder,
            target,
            geometry,
            self.net.as_ref(),
            options,
            writes,
        );
        if let Some(timer) = &mut self.timer {
            timer.resolve(&mut encoder);
        }
        self.queue.submit([encoder.finish()]);
        if let Some(timer) = &mut self.timer {
            timer.after_submit();
        }
        evaluated
    }
}

/// Builds with `build(quality)`; while the device's limits refuse that (a buffer too large, a
/// level beyond the dispatch limits) halves the quality and tries again, at most 16 times.
/// Returns what was built, the quality used, and the first refusal (`None` when `quality`
/// fitted). Any other error is returned at once.
pub fn fit_to_device<T>(
    quality: f32,
    mut build: impl FnMut(f32) -> Result<T, GpuError>,
) -> Result<(T, f32, Option<GpuError>), GpuError> {
    let mut q = quality;
    let mut refusal = None;
    for _ in 0..16 {
        match build(q) {
            Ok(built) => return Ok((built, q, refusal)),
            Err(e @ (GpuError::BufferTooLarge { .. } | GpuError::SegmentsOutOfRange { .. })) => {
                refusal.get_or_insert(e);
                q *= 0.5;
            }
            Err(e) => return Err(e),
        }
    }
    Err(refusal.unwrap_or(GpuError::SegmentsOutOfRange {
        segments: 0,
        max: MAX_SEGMENTS,
    }))
}

/// Segments per span edge of an object at quality `quality`, within 1..=[`MAX_SEGMENTS`].
fn effective_segments(segments: u32, quality: f32) -> u32 {
    ((segments as f32 * quality).round() as u32).clamp(1, MAX_SEGMENTS)
}

pub struct KnotworkApp {
    scene: Scene,
    /// Each object's Bézier patches, as uploaded.
    decompositions: Vec<Decomposition>,
    selected: Option<usize>,
    /// The control point the panel edits, in the selected object.
    edit_point: usize,
    quality: f32,
    /// The largest quality the device's limits allowed at the last tessellation change.
    quality_used: f32,
    shading: ShadingMode,
    manual_range: Option<(f64, f64)>,
    /// The automatic range of the current curvature mode (`None`: to be computed).
    auto_range: Option<(f64, f64)>,
    camera: OrbitCamera,
    options: DrawOptions,
    continuous: bool,
    gpu: Option<ViewportGpu>,
    status: AppStatus,
    /// The viewport must be rendered this frame.
    redraw: bool,
    /// Frame the model once the viewport's aspect ratio is known.
    frame_pending: bool,
    /// Ask for another frame (a GPU timing readback is on its way).
    redraw_soon: bool,
    logged_status: bool,
    /// Close the window after this many viewport frames (desktop smoke tests).
    exit_after_frames: Option<u64>,
}

impl KnotworkApp {
    /// `adapter_label` names the adapter where wgpu cannot (the browser reports no name).
    pub fn new(cc: &eframe::CreationContext<'_>, adapter_label: Option<String>) -> Self {
        status::set_repaint_context(&cc.egui_ctx);
        cc.egui_ctx.set_theme(egui::Theme::Dark);
        let mut status = AppStatus {
            quality: 1.0,
            ..Default::default()
        };
        let scene = Scene::demo().unwrap_or_else(|e| {
            status.error = Some(format!("the sample scene could not be built: {e}"));
            Scene::default()
        });
        let gpu = match &cc.wgpu_render_state {
            Some(state) => {
                let info = state.adapter.get_info();
                status.backend = gpu::backend_name(info.backend).to_owned();
                status.adapter = if info.name.is_empty() {
                    adapter_label
                        .filter(|label| !label.is_empty())
                        .unwrap_or_else(|| "(unnamed adapter)".to_owned())
                } else {
                    info.name.clone()
                };
                Some(ViewportGpu::new(state))
            }
            None => {
                status.error = Some("eframe started without a wgpu device".to_owned());
                None
            }
        };
        let mut app = Self {
            scene,
            decompositions: Vec::new(),
            selected: None,
            edit_point: 0,
            quality: 1.0,
            quality_used: 1.0,
            shading: ShadingMode::Plain,
            manual_range: None,
            auto_range: None,
            camera: OrbitCamera::default(),
            options: DrawOptions::default(),
            continuous: false,
            gpu,
            status,
            redraw: true,
            frame_pending: true,
            redraw_soon: false,
            logged_status: false,
            exit_after_frames: None,
        };
        match app.decompose_all() {
            Ok(()) => {
                if let Err(e) = app.rebuild_geometry(1.0) {
                    app.status.error = Some(e.to_string());
                }
            }
            Err(e) => app.status.error = Some(e),
        }
        app.select(None);
        app.refresh_status();
        status::publish(&app.status);
        log::info!("knotwork starting: {}", app.status.to_json());
        app
    }

    /// Redraws continuously and closes the window once `frames` viewport frames are drawn
    /// (`knotwork --exit-after-frames N`); the final status stays in [`status::current`].
    pub fn exit_after_frames(mut self, frames: u64) -> Self {
        self.exit_after_frames = Some(frames);
        self.continuous = true;
        self
    }

    fn decompose_all(&mut self) -> Result<(), String> {
        self.decompositions = self
            .scene
            .objects
            .iter()
            .map(|o| o.decompose().map_err(|e| format!("{}: {e}", o.name)))
            .collect::<Result<_, _>>()?;
        Ok(())
    }

    /// Uploads every object at `quality`; where the device's buffer or dispatch limits refuse
    /// that, halves the quality until they accept it and says so in the status. On any other
    /// failure the current geometry stays and the error is returned.
    fn rebuild_geometry(&mut self, quality: f32) -> Result<(), GpuError> {
        let Some(gpu) = &mut self.gpu else {
            return Ok(());
        };
        let (geometry, used, refusal) = fit_to_device(quality, |q| {
            let inputs: Vec<ObjectPatches<'_>> = self
                .scene
                .objects
                .iter()
                .zip(&self.decompositions)
                .map(|(object, d)| ObjectPatches {
                    set: &d.set,
                    domains: &d.domains,
                    segments: effective_segments(object.segments, q),
                })
                .collect();
            PatchGeometry::new(&gpu.device, &gpu.evaluator, &inputs)
        })?;
        gpu.geometry = Some(geometry);
        self.quality_used = used;
        self.status.notice = refusal.map(|e| {
            format!("tessellation lowered to quality {used:.2} (asked {quality:.2}): {e}")
        });
        self.redraw = true;
        Ok(())
    }

    /// Applies a tessellation change (`change` edits the scene's segments or the quality) and
    /// re-uploads; on failure everything returns to how it was and the error is shown.
    fn retessellate(&mut self, change: impl FnOnce(&mut Self)) {
        let saved_segments: Vec<u32> = self.scene.objects.iter().map(|o| o.segments).collect();
        let saved_quality = self.quality;
        change(self);
        match self.rebuild_geometry(self.quality) {
            Ok(()) => self.status.error = None,
            Err(e) => {
                for (o, s) in self.scene.objects.iter_mut().zip(saved_segments) {
                    o.segments = s;
                }
                self.quality = saved_quality;
                self.status.error = Some(e.to_string());
            }
        }
        self.refresh_status();
        self.redraw = true;
    }

    fn set_all_segments(&mut self, segments: u32) {
        if !(1..=MAX_SEGMENTS).contains(&segments) {
            self.status.error = Some(
                GpuError::SegmentsOutOfRange {
                    segments,
                    max: MAX_SEGMENTS,
                }
                .to_string(),
            );
            return;
        }
        self.retessellate(|app| {
            for o in &mut app.scene.objects {
                o.segments = segments;
            }
        });
    }

    fn set_quality(&mut self, quality: f32) {
        if !(quality.is_finite() && QUALITY_RANGE.contains(&quality)) {
            self.status.error = Some(format!(
                "quality {quality} is outside {}..={}",
                QUALITY_RANGE.start(),
                QUALITY_RANGE.end()
            ));
            return;
        }
        self.retessellate(|app| app.quality = quality);
    }

    fn select(&mut self, selected: Option<usize>) {
        let selected = selected.filter(|&s| s < self.scene.objects.len());
        self.selected = selected;
        self.edit_point = 0;
        if let Some(gpu) = &mut self.gpu {
            gpu.net = selected.map(|s| {
                let object = &self.scene.objects[s];
                ControlNet::new(&gpu.device, &object.control_points(), &object.net_lines())
            });
        }
        self.redraw = true;
    }

    /// Moves one control point; only the Bézier patches in its support are re-decomposed,
    /// uploaded and re-evaluated. A bad request changes nothing and shows the error.
    fn move_control_point(&mut self, object: usize, index: usize, position: DVec3) {
        let Some(target) = self.scene.objects.get_mut(object) else {
            self.status.error = Some(format!("there is no object {object}"));
            return;
        };
        let before = target.clone();
        let result = target
            .move_control_point(index, position)
            .map_err(|e| e.to_string())
            .and_then(|patches| {
                let d = target.decompose().map_err(|e| e.to_string())?;
                Ok((patches, d))
            });
        let (patches, decomposition) = match result {
            Ok(r) => r,
            Err(e) => {
                self.scene.objects[object] = before;
                self.status.error = Some(format!("{}: {e}", self.scene.objects[object].name));
                return;
            }
        };
        if let Some(gpu) = &mut self.gpu {
            if let Some(geometry) = &mut gpu.geometry {
                match geometry.update_object(&gpu.queue, object, &decomposition.set, Some(&patches))
                {
                    Ok(uploaded) => self.status.points_uploaded = uploaded as u32,
                    Err(e) => self.status.error = Some(e.to_string()),
                }
            }
            if self.selected == Some(object)
                && let Some(net) = &gpu.net
            {
                net.update_points(&gpu.queue, &self.scene.objects[object].control_points());
            }
        }
        self.decompositions[object] = decomposition;
        self.auto_range = None;
        self.redraw = true;
    }

    fn set_shading(&mut self, mode: ShadingMode) {
        if mode != self.shading {
            self.shading = mode;
            self.auto_range = None;
            self.redraw = true;
        }
    }

    /// The colour ramp's range in the current mode: the manual one, or the robust automatic one
    /// (area-weighted 2–98 % percentiles) over the f64 kernel's curvature samples of every
    /// object.
    fn color_range(&mut self) -> Option<(f64, f64)> {
        let component = self.shading.curvature_component()?;
        if let Some(range) = self.manual_range {
            return Some(range);
        }
        if self.auto_range.is_none() {
            let mut values = Vec::new();
            for object in &self.scene.objects {
                if let Ok(samples) = object.curvature_samples(RANGE_SAMPLES) {
                    values.extend(
                        samples
                            .iter()
                            .map(|(c, area)| ([c.gaussian, c.mean, c.k1, c.k2][component], *area)),
                    );
                }
            }
            self.auto_range = robust_range(values);
        }
        self.auto_range
    }

    fn refresh_status(&mut self) {
        self.status.objects = self.scene.objects.len() as u32;
        self.status.quality = self.quality;
        self.status.selected = self.selected.map(|s| s as u32);
        self.status.shading = self.shading.name().to_owned();
        self.status.range_auto = self.manual_range.is_none();
        self.status.range = self.color_range().map(|(lo, hi)| [lo, hi]);
        self.status.segments = self
            .scene
            .objects
            .iter()
            .map(|o| effective_segments(o.segments, self.quality_used))
            .collect();
        if let Some(g) = self.gpu.as_ref().and_then(|g| g.geometry.as_ref()) {
            self.status.patches = g.patch_count();
            self.status.control_points = g.control_point_count();
            self.status.vertices = g.vertex_count();
            self.status.triangles = g.index_count() / 3;
        }
    }

    fn apply(&mut self, command: ExternalCommand) {
        match command {
            ExternalCommand::SetSegments(n) => self.set_all_segments(n),
            ExternalCommand::SetQuality(q) => self.set_quality(q),
            ExternalCommand::SetShading(mode) => self.set_shading(mode),
            ExternalCommand::SetRange(range) => self.set_manual_range(range),
            ExternalCommand::Select(s) => self.select(s),
            ExternalCommand::MoveControlPoint {
                object,
                index,
                position,
            } => self.move_control_point(object, index, DVec3::from(position)),
            ExternalCommand::SetContinuous(on) => self.continuous = on,
            ExternalCommand::FrameModel => self.frame_pending = true,
        }
        self.redraw = true;
    }

    fn set_manual_range(&mut self, range: Option<(f64, f64)>) {
        match range {
            Some((lo, hi)) if !(lo.is_finite() && hi.is_finite() && lo < hi) => {
                self.status.error = Some(format!(
                    "a colour range needs finite low < high, got ({lo}, {hi})"
                ));
            }
            _ => self.manual_range = range,
        }
        self.redraw = true;
    }

    fn frame_model(&mut self, aspect: f32) {
        if let Some((lo, hi)) = self.scene.bounds() {
            self.camera.frame(lo.as_vec3(), hi.as_vec3(), aspect);
        }
        self.redraw = true;
    }

    fn info_grid(&self, ui: &mut egui::Ui) {
        egui::Grid::new("info")
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                let rows = [
                    ("Backend", self.status.backend.clone()),
                    ("Adapter", self.status.adapter.clone()),
                    ("Objects", self.status.objects.to_string()),
                    ("Bézier patches", self.status.patches.to_string()),
                    ("Vertices", self.status.vertices.to_string()),
                    ("Triangles", self.status.triangles.to_string()),
                    (
                        "Re-evaluated",
                        format!("{} patches", self.status.patches_reevaluated),
                    ),
                ];
                for (name, value) in rows {
                    ui.label(name);
                    ui.label(value);
                    ui.end_row();
                }
            });
    }

    fn objects_panel(&mut self, ui: &mut egui::Ui) {
        ui.label(egui::RichText::new("Objects").strong());
        let mut clicked = None;
        for (k, object) in self.scene.objects.iter().enumerate() {
            let response = ui
                .selectable_label(self.selected == Some(k), &object.name)
                .on_hover_text(object.describe());
            if response.clicked() {
                clicked = Some(if self.selected == Some(k) {
                    None
                } else {
                    Some(k)
                });
            }
        }
        if let Some(selection) = clicked {
            self.select(selection);
        }
        let Some(s) = self.selected else {
            ui.label(egui::RichText::new("click an object to edit it").weak());
            return;
        };
        ui.label(egui::RichText::new(self.scene.objects[s].describe()).weak());
        let mut segments = self.scene.objects[s].segments;
        ui.label("Segments per span");
        if ui
            .add(egui::Slider::new(&mut segments, SLIDER_SEGMENTS))
            .changed()
            && segments != self.scene.objects[s].segments
        {
            self.retessellate(|app| app.scene.objects[s].segments = segments);
        }
        let points = self.scene.objects[s].control_points();
        if points.is_empty() {
            return;
        }
        ui.horizontal(|ui| {
            ui.label("Control point");
            ui.add(egui::DragValue::new(&mut self.edit_point).range(0..=points.len() - 1));
        });
        self.edit_point = self.edit_point.min(points.len() - 1);
        let mut p = points[self.edit_point];
        let before = p;
        ui.horizontal(|ui| {
            for (axis, value) in ["x", "y", "z"]
                .into_iter()
                .zip([&mut p.x, &mut p.y, &mut p.z])
            {
                ui.label(axis);
                ui.add(egui::DragValue::new(value).speed(0.01));
            }
        });
        if p != before {
            self.move_control_point(s, self.edit_point, p);
        }
    }

    fn shading_panel(&mut self, ui: &mut egui::Ui) {
        ui.label(egui::RichText::new("Shading").strong());
        let mut mode = self.shading;
        egui::ComboBox::from_id_salt("shading")
            .selected_text(mode.label())
            .show_ui(ui, |ui| {
                for m in ShadingMode::ALL {
                    ui.selectable_value(&mut mode, m, m.label());
                }
            });
        self.set_shading(mode);
        let Some((lo, hi)) = self.color_range() else {
            return;
        };
        legend(ui, lo, hi);
        let mut auto = self.manual_range.is_none();
        if ui.checkbox(&mut auto, "Automatic range (2–98 %)").changed() {
            self.set_manual_range(if auto { None } else { Some((lo, hi)) });
        }
        if let Some((mut a, mut b)) = self.manual_range {
            let speed = ((b - a).abs() * 0.01).max(1e-6);
            ui.horizontal(|ui| {
                ui.label("low");
                ui.add(egui::DragValue::new(&mut a).speed(speed));
                ui.label("high");
                ui.add(egui::DragValue::new(&mut b).speed(speed));
            });
            if (a, b) != (lo, hi) && a < b {
                self.set_manual_range(Some((a, b)));
            }
        }
    }

    fn controls(&mut self, ui: &mut egui::Ui) {
        ui.heading("knotwork");
        ui.label(egui::RichText::new("freeform surfaces on the GPU").weak());
        ui.separator();
        self.info_grid(ui);
        ui.separator();
        ui.label("Quality (× every object's segments)");
        let mut quality = self.quality;
        if ui
            .add(egui::Slider::new(&mut quality, QUALITY_RANGE).logarithmic(true))
            .changed()
            && quality != self.quality
        {
            self.set_quality(quality);
        }
        ui.separator();
        self.objects_panel(ui);
        ui.separator();
        self.shading_panel(ui);
        ui.separator();
        let before = self.options;
        ui.checkbox(&mut self.options.show_surface, "Surface");
        ui.checkbox(&mut self.options.show_net, "Control net (selected object)");
        ui.checkbox(&mut self.options.show_points, "Control points");
        if self.options != before {
            self.redraw = true;
        }
        if ui.button("Frame scene  (F)").clicked() {
            self.frame_pending = true;
        }
        ui.checkbox(&mut self.continuous, "Redraw every frame");
        ui.separator();
        ui.label("GPU time, last frame");
        let ms = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{v:.3} ms"));
        if self.gpu.as_ref().is_some_and(|g| g.timer.is_some()) {
            ui.label(format!("evaluate  {}", ms(self.status.gpu_eval_ms)));
            ui.label(format!("draw      {}", ms(self.status.gpu_render_ms)));
        } else {
            ui.label(egui::RichText::new("no timestamp queries on this device").weak());
        }
        ui.label(format!(
            "frame interval  {}",
            ms(self.status.frame_interval_ms)
        ));
        ui.label(format!("frames drawn  {}", self.status.frames));
        if let Some(notice) = self.status.notice.clone() {
            ui.separator();
            ui.colored_label(egui::Color32::from_rgb(240, 200, 90), notice);
        }
        if let Some(error) = self.status.error.clone() {
            ui.separator();
            ui.colored_label(egui::Color32::from_rgb(255, 110, 100), error);
            if ui.small_button("Dismiss").clicked() {
                self.status.error = None;
            }
        }
        ui.separator();
        egui::CollapsingHeader::new("Controls")
            .default_open(true)
            .show(ui, |ui| {
                for (key, action) in [
                    ("Left drag", "orbit"),
                    ("Middle drag, Shift + left drag", "pan"),
                    ("Wheel, pinch", "zoom"),
                    ("F", "frame the scene"),
                ] {
                    ui.label(format!("{key}: {action}"));
                }
            });
    }

    fn handle_input(&mut self, ui: &egui::Ui, response: &egui::Response, viewport_height: f32) {
        let shift = ui.input(|i| i.modifiers.shift);
        let delta = response.drag_delta();
        if delta != egui::Vec2::ZERO {
            if response.dragged_by(egui::PointerButton::Middle)
                || (shift && response.dragged_by(egui::PointerButton::Primary))
            {
                self.camera.pan(delta.x, delta.y, viewport_height);
                self.redraw = true;
            } else if response.dragged_by(egui::PointerButton::Primary) {
                self.camera.orbit(delta.x, delta.y);
                self.redraw = true;
            }
        }
        if response.hovered() {
            let (scroll, zoom) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            // One wheel notch is about 50 points of scroll.
            let steps = scroll / 50.0 + zoom.ln() / 0.15;
            if steps != 0.0 {
                self.camera.zoom(steps);
                self.redraw = true;
            }
        }
        let typing = ui.ctx().egui_wants_keyboard_input();
        if !typing && ui.input(|i| i.key_pressed(egui::Key::F)) {
            self.frame_pending = true;
        }
    }

    fn viewport(&mut self, ui: &mut egui::Ui) {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        let ppp = ui.ctx().pixels_per_point();
        let size = (
            (rect.width() * ppp).round().max(1.0) as u32,
            (rect.height() * ppp).round().max(1.0) as u32,
        );
        let aspect = rect.width() / rect.height().max(1.0);
        self.handle_input(ui, &response, rect.height());
        if std::mem::take(&mut self.frame_pending) {
            self.frame_model(aspect);
        }
        let range = self.color_range().unwrap_or((-1.0, 1.0));
        let shading = Shading {
            mode: self.shading,
            range: (range.0 as f32, range.1 as f32),
            selected: self.selected.map(|s| s as u32),
            ..Default::default()
        };
        let Some(gpu) = self.gpu.as_mut().filter(|g| g.geometry.is_some()) else {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "The GPU viewport is unavailable — see the panel for the reason.",
                egui::FontId::proportional(16.0),
                ui.visuals().text_color(),
            );
            return;
        };
        let resized = gpu.ensure_target(size);
        let pending = gpu
            .geometry
            .as_ref()
            .is_some_and(PatchGeometry::needs_evaluation);
        if resized || self.redraw || self.continuous || pending {
            if let Some(evaluated) =
                gpu.draw(&self.camera, &self.options, &shading, POINT_RADIUS * ppp)
            {
                self.status.patches_reevaluated = evaluated;
            }
            self.status.frames += 1;
            self.redraw = false;
        }
        if let Some(texture) = gpu.texture {
            let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
            ui.painter().image(texture, rect, uv, egui::Color32::WHITE);
        }
    }

    fn collect_timings(&mut self) {
        let Some(gpu) = &mut self.gpu else {
            return;
        };
        #[cfg(not(target_arch = "wasm32"))]
        {
            // Drives buffer-mapping callbacks on native; the browser does this by itself.
            let _ = gpu.device.poll(wgpu::PollType::Poll);
        }
        if let Some(timer) = &mut gpu.timer {
            if timer.collect() {
                self.status.gpu_eval_ms = timer.latest.eval_ms;
                self.status.gpu_render_ms = timer.latest.render_ms;
            }
            if timer.pending() {
                // Keep frames coming until the figures arrive.
                self.redraw_soon = true;
            }
        }
    }
}

/// The colour ramp as a bar with its low, middle and high values.
fn legend(ui: &mut egui::Ui, lo: f64, hi: f64) {
    let width = ui.available_width().min(240.0);
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, 14.0), egui::Sense::hover());
    let mut mesh = egui::Mesh::default();
    let stops = CURVATURE_RAMP.len();
    for (k, stop) in CURVATURE_RAMP.iter().enumerate() {
        let x = rect.left() + rect.width() * k as f32 / (stops - 1) as f32;
        let color = egui::Rgba::from_rgb(stop[0], stop[1], stop[2]).into();
        mesh.colored_vertex(egui::pos2(x, rect.top()), color);
        mesh.colored_vertex(egui::pos2(x, rect.bottom()), color);
        if k > 0 {
            let i = (2 * k) as u32;
            mesh.add_triangle(i - 2, i - 1, i);
            mesh.add_triangle(i - 1, i + 1, i);
        }
    }
    ui.painter().add(egui::Shape::mesh(mesh));
    ui.horizontal(|ui| {
        let text = |v: f64| format!("{v:.3e}");
        ui.label(text(lo));
        ui.add_space((width - 180.0).max(4.0) / 2.0);
        ui.label(text(0.5 * (lo + hi)));
        ui.add_space((width - 180.0).max(4.0) / 2.0);
        ui.label(text(hi));
    });
}

impl eframe::App for KnotworkApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        for command in status::take_commands() {
            self.apply(command);
        }
        self.collect_timings();
        egui::Panel::left("controls")
            .resizable(true)
            .default_size(250.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.controls(ui));
            });
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| self.viewport(ui));

        let dt = ui.input(|i| i.unstable_dt);
        if self.continuous {
            self.status.frame_interval_ms = Some(f64::from(dt) * 1e3);
            ui.ctx().request_repaint();
        }
        if self.redraw || std::mem::take(&mut self.redraw_soon) {
            ui.ctx().request_repaint();
        }
        self.refresh_status();
        status::publish(&self.status);
        if !self.logged_status && self.status.frames > 0 {
            log::info!("knotwork status: {}", self.status.to_json());
            self.logged_status = true;
        }
        if self
            .exit_after_frames
            .is_some_and(|frames| self.status.frames >= frames)
        {
            ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quality_is_lowered_until_the_device_accepts_it() {
        // A device that holds at most 1000 vertices per object of 10 patches at 16 segments.
        let build = |q: f32| {
            let segments = effective_segments(16, q);
            let bytes = 10 * u64::from(segments + 1).pow(2) * 64;
            if bytes > 64_000 {
                Err(GpuError::BufferTooLarge {
                    what: "vertex",
                    bytes,
                    limit: 64_000,
                })
            } else {
                Ok(segments)
            }
        };
        let (segments, used, refusal) = fit_to_device(2.0, build).unwrap();
        assert_eq!((segments, used), (8, 0.5));
        assert!(matches!(refusal, Some(GpuError::BufferTooLarge { .. })));
        let (_, used, refusal) = fit_to_device(0.25, build).unwrap();
        assert_eq!((used, refusal), (0.25, None));
        // Other errors are not retried.
        let mut calls = 0;
        let other = fit_to_device(1.0, |_| -> Result<(), GpuError> {
            calls += 1;
            Err(GpuError::NoSuchObject {
                object: 1,
                count: 0,
            })
        });
        assert!(matches!(other, Err(GpuError::NoSuchObject { .. })) && calls == 1);
        // A device that never fits gives up with the first refusal.
        let never = fit_to_device(1.0, |_| -> Result<(), GpuError> {
            Err(GpuError::BufferTooLarge {
                what: "index",
                bytes: 1,
                limit: 0,
            })
        });
        assert!(matches!(
            never,
            Err(GpuError::BufferTooLarge { what: "index", .. })
        ));
    }
}
