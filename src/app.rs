//! The editor: an eframe app that is the same on the web and on the desktop. It owns the model,
//! runs the compute evaluation and the viewport render on eframe's wgpu device, and shows the
//! result as an egui image beside a control panel.

use std::sync::Arc;

use eframe::egui;
use eframe::egui_wgpu;

use crate::gpu::timing::GpuTimer;
use crate::gpu::{self, PatchEvaluator, PatchGeometry};
use crate::kernel::{BezierPatchSet, samples};
use crate::render::{DrawOptions, ViewTarget, ViewportRenderer, scene_uniform};
use crate::status::{self, AppStatus, ExternalCommand};
use crate::view::OrbitCamera;

/// Segments per patch edge when the editor opens.
pub const DEFAULT_SEGMENTS: u32 = 32;
/// The tessellation slider's range.
pub const SLIDER_SEGMENTS: std::ops::RangeInclusive<u32> = 1..=128;
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
    geometry: PatchGeometry,
    renderer: ViewportRenderer,
    target: Option<ViewTarget>,
    texture: Option<egui::TextureId>,
    timer: Option<GpuTimer>,
    /// The compute pass must run before the next draw.
    evaluate: bool,
}

impl ViewportGpu {
    fn new(
        state: &egui_wgpu::RenderState,
        model: &BezierPatchSet,
        segments: u32,
    ) -> Result<Self, gpu::GpuError> {
        let device = state.device.clone();
        let evaluator = PatchEvaluator::new(&device);
        let geometry = PatchGeometry::new(&device, &evaluator, model, segments)?;
        Ok(Self {
            renderer: ViewportRenderer::new(&device),
            timer: GpuTimer::new(&device, &state.queue),
            queue: state.queue.clone(),
            egui_renderer: Arc::clone(&state.renderer),
            device,
            evaluator,
            geometry,
            target: None,
            texture: None,
            evaluate: true,
        })
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

    /// Runs the compute pass if the surface changed, then renders the viewport.
    fn draw(&mut self, camera: &OrbitCamera, options: &DrawOptions, point_radius_px: f32) {
        let Some(target) = &self.target else {
            return;
        };
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("knotwork frame"),
            });
        if self.evaluate {
            let writes = self.timer.as_mut().and_then(GpuTimer::compute_pass_writes);
            self.geometry.encode(&mut encoder, &self.evaluator, writes);
            self.evaluate = false;
        }
        let (w, h) = target.size();
        let aspect = w as f32 / h.max(1) as f32;
        let scene = scene_uniform(
            camera.view_projection(aspect),
            camera.eye(),
            target,
            point_radius_px,
        );
        let writes = self.timer.as_mut().and_then(GpuTimer::render_pass_writes);
        self.renderer.set_scene(&self.queue, &scene);
        self.renderer
            .render(&mut encoder, target, &self.geometry, options, writes);
        if let Some(timer) = &mut self.timer {
            timer.resolve(&mut encoder);
        }
        self.queue.submit([encoder.finish()]);
        if let Some(timer) = &mut self.timer {
            timer.after_submit();
        }
    }
}

pub struct KnotworkApp {
    model: BezierPatchSet,
    model_name: &'static str,
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
            segments: DEFAULT_SEGMENTS,
            ..Default::default()
        };
        let (model, model_name) = match samples::utah_teapot() {
            Ok(model) => (model, "Utah teapot"),
            Err(e) => {
                status.error = Some(format!("the sample model could not be loaded: {e}"));
                (BezierPatchSet::default(), "(none)")
            }
        };
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
                match ViewportGpu::new(state, &model, DEFAULT_SEGMENTS) {
                    Ok(gpu) => Some(gpu),
                    Err(e) => {
                        status.error = Some(e.to_string());
                        None
                    }
                }
            }
            None => {
                status.error = Some("eframe started without a wgpu device".to_owned());
                None
            }
        };
        let mut app = Self {
            model,
            model_name,
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
        app.refresh_counts();
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

    fn refresh_counts(&mut self) {
        if let Some(gpu) = &self.gpu {
            let g = &gpu.geometry;
            self.status.patches = g.patch_count();
            self.status.control_points = g.control_point_count();
            self.status.vertices = g.vertex_count();
            self.status.triangles = g.index_count() / 3;
            self.status.segments = g.segments();
        }
    }

    /// Re-tessellates at `segments` per patch edge. On failure the current tessellation stays and
    /// the error is shown.
    fn set_segments(&mut self, segments: u32) {
        let Some(gpu) = &mut self.gpu else {
            return;
        };
        match PatchGeometry::new(&gpu.device, &gpu.evaluator, &self.model, segments) {
            Ok(geometry) => {
                gpu.geometry = geometry;
                gpu.evaluate = true;
                self.status.error = None;
                self.refresh_counts();
            }
            Err(e) => self.status.error = Some(e.to_string()),
        }
        self.redraw = true;
    }

    fn apply(&mut self, command: ExternalCommand) {
        match command {
            ExternalCommand::SetSegments(n) => self.set_segments(n),
            ExternalCommand::SetContinuous(on) => self.continuous = on,
            ExternalCommand::FrameModel => self.frame_pending = true,
        }
        self.redraw = true;
    }

    fn frame_model(&mut self, aspect: f32) {
        if let Some((lo, hi)) = self.model.bounds() {
            self.camera.frame(lo.as_vec3(), hi.as_vec3(), aspect);
        }
        self.redraw = true;
    }

    fn controls(&mut self, ui: &mut egui::Ui) {
        ui.heading("knotwork");
        ui.label(egui::RichText::new("freeform surfaces on the GPU").weak());
        ui.separator();
        egui::Grid::new("info")
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                let rows = [
                    ("Model", self.model_name.to_owned()),
                    ("Backend", self.status.backend.clone()),
                    ("Adapter", self.status.adapter.clone()),
                    ("Patches", self.status.patches.to_string()),
                    ("Control points", self.status.control_points.to_string()),
                    ("Vertices", self.status.vertices.to_string()),
                    ("Triangles", self.status.triangles.to_string()),
                ];
                for (name, value) in rows {
                    ui.label(name);
                    ui.label(value);
                    ui.end_row();
                }
            });
        ui.separator();
        ui.label("Tessellation (segments per patch edge)");
        let mut segments = self.status.segments;
        let slider = ui.add(egui::Slider::new(&mut segments, SLIDER_SEGMENTS));
        if slider.changed() && segments != self.status.segments {
            self.set_segments(segments);
        }
        ui.separator();
        let before = self.options;
        ui.checkbox(&mut self.options.show_surface, "Surface");
        ui.checkbox(&mut self.options.show_net, "Control net");
        ui.checkbox(&mut self.options.show_points, "Control points");
        if self.options != before {
            self.redraw = true;
        }
        if ui.button("Frame model  (F)").clicked() {
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
                    ("F", "frame the model"),
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
        let Some(gpu) = &mut self.gpu else {
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
        if resized || self.redraw || self.continuous || gpu.evaluate {
            gpu.draw(&self.camera, &self.options, POINT_RADIUS * ppp);
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
