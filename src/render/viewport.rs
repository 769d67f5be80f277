use glam::DVec3;
use wgpu::util::DeviceExt;

use crate::gpu::adaptive::ScreenError;
use crate::gpu::adaptive_pass::{ADAPTIVE_MAX_EDGE_PX, ADAPTIVE_MAX_SEGMENTS, AdaptiveTarget};
use crate::gpu::records::{CURVATURE_RAMP, CurveVertex, SceneUniform, SurfaceVertex};
use crate::gpu::{PatchBuffers, SurfaceBuffers};
use crate::shaders;
use crate::view::{
    AnalysisSettings, OrbitCamera, Overlays, ShadingMode, StripeFrame, ViewSettings, ZebraSource,
};

/// The viewport texture holds sRGB-encoded values (egui samples user textures as such).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// 4× MSAA, the default: guaranteed for these formats by WebGPU. A [`ViewTarget`] may use 1
/// instead (software adapters, where multisampling is most of a frame's cost).
pub const SAMPLE_COUNT: u32 = 4;

/// Checker cells per unit of u and v in the checker shading.
pub const CHECKER_CELLS: f32 = 8.0;

/// sRGB-encoded RGBA the viewport is cleared to.
pub const BACKGROUND: [f64; 4] = [0.13, 0.14, 0.16, 1.0];

/// What a view-adaptive tessellation of the scene seen by `camera` in a `width` × `height`
/// pixel image is measured against: the size of a pixel at unit depth (perspective:
/// 2 tan(fov_y / 2) / height; orthographic: the shown height / height anywhere), the near
/// plane, and `tolerance_px` of error.
pub fn adaptive_target(
    camera: &OrbitCamera,
    (width, height): (u32, u32),
    tolerance_px: f64,
) -> AdaptiveTarget {
    let height_px = f64::from(height.max(1));
    let half_tan = (f64::from(camera.fov_y) * 0.5).tan();
    let (pixel_scale, near) = if camera.orthographic {
        (2.0 * f64::from(camera.distance) * half_tan / height_px, 0.0)
    } else {
        (2.0 * half_tan / height_px, f64::from(camera.near()))
    };
    let (_, _, back) = camera.axes();
    AdaptiveTarget {
        error: ScreenError {
            eye: camera.eye().as_dvec3(),
            forward: -back.as_dvec3(),
            pixel_scale,
            orthographic: camera.orthographic,
            near,
            tolerance_px,
            max_edge_px: ADAPTIVE_MAX_EDGE_PX,
            max_segments: ADAPTIVE_MAX_SEGMENTS,
        },
        view_proj: camera.view_projection(width as f32 / height.max(1) as f32),
    }
}

/// The scene uniform for `view` (its camera and shading mode) seen in `target`, with the
/// colour ramp spanning `range` (the view's own range or the automatic one), `selected`
/// highlighted, the editor's colours (linear RGB) and control point dots of `point_radius_px`
/// physical pixels.
pub fn scene_uniform(
    view: &ViewSettings,
    target: &ViewTarget,
    point_radius_px: f32,
    range: (f64, f64),
    selected: Option<u32>,
) -> SceneUniform {
    let (w, h) = target.size();
    let camera: &OrbitCamera = &view.camera;
    let aspect = w as f32 / h.max(1) as f32;
    let (right, up, back) = camera.axes();
    let analysis = &view.analysis;
    let unit = |d| AnalysisSettings::unit(d).as_vec3().extend(0.0).to_array();
    SceneUniform {
        view_right: right.extend(0.0).to_array(),
        view_up: up.extend(0.0).to_array(),
        view_back: back
            .extend(if camera.orthographic { 1.0 } else { 0.0 })
            .to_array(),
        analysis: [
            analysis.zebra_pairs as f32,
            analysis.zebra_angle.to_radians() as f32,
            analysis.isophote_spacing as f32,
            analysis.draft_threshold as f32,
        ],
        isophote_direction: unit(analysis.isophote_direction),
        pull_direction: unit(analysis.pull_direction),
        analysis_flags: [
            match analysis.zebra_frame {
                StripeFrame::View => 0,
                StripeFrame::World => 1,
            },
            match analysis.zebra_source {
                ZebraSource::Reflection => 0,
                ZebraSource::Normal => 1,
            },
            0,
            0,
        ],
        shading: [view.shading as u32, selected.map_or(0, |s| s + 1), 0, 0],
        range: [range.0 as f32, range.1 as f32, CHECKER_CELLS, CHECKER_CELLS],
        ramp: CURVATURE_RAMP,
        view_proj: camera.view_projection(aspect).to_cols_array_2d(),
        eye: camera.eye().extend(1.0).to_array(),
        viewport: [w as f32, h as f32, point_radius_px, 0.0],
        surface_color: [0.50, 0.43, 0.35, 1.0],
        back_color: [0.22, 0.28, 0.45, 1.0],
        net_color: [0.70, 0.72, 0.78, 0.55],
        point_color: POINT_COLOR,
    }
}

/// The draft analysis's colours (linear RGB) for enough draft, too little and undercut
/// (`DRAFT_*` in `shaders/surface.wgsl`), for the legend.
pub const DRAFT_COLORS: [[f32; 3]; 3] =
    [[0.10, 0.55, 0.16], [0.90, 0.72, 0.08], [0.80, 0.08, 0.06]];

/// The refinement-level colours (linear RGB; `LEVEL_COLORS` in `shaders/shading.wgsl`): level
/// k in colour k, levels past the last in the last.
pub const LEVEL_COLORS: [[f32; 3]; 7] = [
    [0.55, 0.55, 0.58],
    [0.10, 0.25, 0.80],
    [0.05, 0.60, 0.75],
    [0.15, 0.62, 0.18],
    [0.85, 0.75, 0.10],
    [0.90, 0.42, 0.08],
    [0.80, 0.08, 0.08],
];

/// Linear RGBA of the control point dots.
pub const POINT_COLOR: [f32; 4] = [0.95, 0.78, 0.25, 1.0];

/// The offscreen textures one viewport renders into: multisampled colour and depth, and the
/// single-sampled colour they resolve to (with one sample, the pass draws into that directly).
pub struct ViewTarget {
    width: u32,
    height: u32,
    samples: u32,
    /// The multisampled colour; `None` with one sample.
    msaa_view: Option<wgpu::TextureView>,
    depth_view: wgpu::TextureView,
    resolved: wgpu::Texture,
    resolved_view: wgpu::TextureView,
}

impl ViewTarget {
    /// Textures of `width` × `height` physical pixels (each clamped to 1..=8192), with
    /// [`SAMPLE_COUNT`] samples per pixel.
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        Self::with_samples(device, width, height, SAMPLE_COUNT)
    }

    /// The same with `samples` per pixel: 1, or 4 for any other value.
    pub fn with_samples(device: &wgpu::Device, width: u32, height: u32, samples: u32) -> Self {
        let samples = if samples == 1 { 1 } else { SAMPLE_COUNT };
        let max = device.limits().max_texture_dimension_2d;
        let (width, height) = (width.clamp(1, max), height.clamp(1, max));
        let texture = |label: &str, format, samples, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let msaa = (samples > 1).then(|| {
            texture("viewport msaa", COLOR_FORMAT, samples, attachment)
                .create_view(&Default::default())
        });
        let depth = texture("viewport depth", DEPTH_FORMAT, samples, attachment);
        let resolved = texture(
            "viewport",
            COLOR_FORMAT,
            1,
            attachment | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
        );
        Self {
            width,
            height,
            samples,
            msaa_view: msaa,
            depth_view: depth.create_view(&Default::default()),
            resolved_view: resolved.create_view(&Default::default()),
            resolved,
        }
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Samples per pixel: 1 or [`SAMPLE_COUNT`].
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// The resolved colour texture (for copies and screenshots).
    pub fn texture(&self) -> &wgpu::Texture {
        &self.resolved
    }

    /// The resolved colour, for display.
    pub fn view(&self) -> &wgpu::TextureView {
        &self.resolved_view
    }

    /// Reads the resolved colour back as tightly packed RGBA8 rows (blocking; tests and CLI).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_rgba(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<u8>, crate::gpu::GpuError> {
        let row = self.width as u64 * 4;
        let padded = row.div_ceil(u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT))
            * u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("viewport readback"),
            size: padded * u64::from(self.height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            self.resolved.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded as u32),
                    rows_per_image: None,
                },
            },
            self.resolved.size(),
        );
        queue.submit([encoder.finish()]);
        let bytes = crate::gpu::readback::map_and_copy(device, &staging)?;
        Ok(bytes
            .chunks(padded as usize)
            .flat_map(|r| &r[..row as usize])
            .copied()
            .collect())
    }
}

/// The control net drawn over the surface: points (x, y, z, 1) and line index pairs.
pub struct ControlNet {
    points: wgpu::Buffer,
    lines: wgpu::Buffer,
    point_count: u32,
    line_index_count: u32,
}

/// The points as homogeneous vertices. Selected points are written with w = 2 (the same point:
/// the shaders divide by w), which the dot shader draws highlighted.
fn net_points(points: &[DVec3], selected: &dyn Fn(usize) -> bool) -> Vec<[f32; 4]> {
    points
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let w = if selected(k) { 2.0 } else { 1.0 };
            [
                (p.x * w) as f32,
                (p.y * w) as f32,
                (p.z * w) as f32,
                w as f32,
            ]
        })
        .collect()
}

impl ControlNet {
    /// The net of `points` joined by `lines` (index pairs); `selected(k)` highlights point k.
    pub fn new(
        device: &wgpu::Device,
        points: &[DVec3],
        selected: &dyn Fn(usize) -> bool,
        lines: &[u32],
    ) -> Self {
        let buffer = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: if contents.is_empty() {
                    &[0; 16]
                } else {
                    contents
                },
                usage,
            })
        };
        Self {
            points: buffer(
                "control net points",
                bytemuck::cast_slice(&net_points(points, selected)),
                wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            ),
            lines: buffer(
                "control net lines",
                bytemuck::cast_slice(lines),
                wgpu::BufferUsages::INDEX,
            ),
            point_count: points.len() as u32,
            line_index_count: lines.len() as u32,
        }
    }

    /// Moves the points and their highlight (same count as at creation; extra ones are
    /// ignored).
    pub fn update_points(
        &self,
        queue: &wgpu::Queue,
        points: &[DVec3],
        selected: &dyn Fn(usize) -> bool,
    ) {
        let n = points.len().min(self.point_count as usize);
        queue.write_buffer(
            &self.points,
            0,
            bytemuck::cast_slice(&net_points(&points[..n], selected)),
        );
    }
}

/// One vertex of the guide and analysis lines (`vs_lines` in `shaders/overlay.wgsl`): world
/// position (w unused) and linear RGBA.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LineVertex {
    pub position: [f32; 4],
    pub color: [f32; 4],
}

impl LineVertex {
    pub fn new(position: DVec3, color: [f32; 4]) -> Self {
        Self {
            position: position.as_vec3().extend(1.0).to_array(),
            color,
        }
    }
}

/// Line segments (vertex pairs) to draw: `depth_tested` ones hide behind the surface (the
/// grid), `on_top` ones are drawn over it (combs, directions, continuity hair).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GuideLines {
    pub depth_tested: Vec<LineVertex>,
    pub on_top: Vec<LineVertex>,
}

impl GuideLines {
    /// Adds the segment a–b in `color` on top of the surface.
    pub fn on_top(&mut self, a: DVec3, b: DVec3, color: [f32; 4]) {
        self.on_top.push(LineVertex::new(a, color));
        self.on_top.push(LineVertex::new(b, color));
    }

    /// Adds the segment a–b in `color`, hidden where the surface is in front.
    pub fn depth_tested(&mut self, a: DVec3, b: DVec3, color: [f32; 4]) {
        self.depth_tested.push(LineVertex::new(a, color));
        self.depth_tested.push(LineVertex::new(b, color));
    }

    /// Adds `other`'s lines after these.
    pub fn extend(&mut self, other: &GuideLines) {
        self.depth_tested.extend_from_slice(&other.depth_tested);
        self.on_top.extend_from_slice(&other.on_top);
    }
}

/// What the render pipelines are specialized for: samples per pixel, whether the surface
/// shader evaluates patches per fragment (the analysis modes) and whether it trims. Software
/// rasterizers run the plain shader about four times faster than one with those paths compiled
/// in (lavapipe, 1280 × 800, the demo scene: 458 ms against 112 ms a frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct PipelineVariant {
    samples: u32,
    per_pixel: bool,
    trimmed: bool,
}

/// The render pipelines for one [`PipelineVariant`].
struct RenderPipelines {
    surface: wgpu::RenderPipeline,
    net: wgpu::RenderPipeline,
    dot: wgpu::RenderPipeline,
    line_depth: wgpu::RenderPipeline,
    line_top: wgpu::RenderPipeline,
    curve: wgpu::RenderPipeline,
}

/// What the render pipelines are made from: layouts and shader modules.
struct PipelineSources {
    layout: wgpu::PipelineLayout,
    surface_layout: wgpu::PipelineLayout,
    surface_module: wgpu::ShaderModule,
    /// Whether the surface shader is `surface.wgsl` (storage buffers; overrides per variant)
    /// rather than `surface_gl.wgsl`.
    storage: bool,
    overlay_module: wgpu::ShaderModule,
}

impl PipelineSources {
    /// Every pipeline of `variant`. The surface shader's overrides are set to match:
    /// `SAMPLE_COUNT` (it writes a sample mask for the trim edges' coverage), `PER_PIXEL` and
    /// `TRIMMED`.
    fn pipelines(&self, device: &wgpu::Device, variant: PipelineVariant) -> RenderPipelines {
        let flag = |on: bool| if on { 1.0 } else { 0.0 };
        let PipelineVariant {
            samples,
            per_pixel,
            trimmed,
        } = variant;
        let control_point_layout = wgpu::VertexBufferLayout {
            array_stride: 16,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x4],
        };
        let control_point_instances = wgpu::VertexBufferLayout {
            step_mode: wgpu::VertexStepMode::Instance,
            ..control_point_layout.clone()
        };
        let line_layout = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<LineVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x4, 1 => Float32x4],
        };
        let sample_constants = [
            ("SAMPLE_COUNT", f64::from(samples)),
            ("PER_PIXEL", flag(per_pixel)),
            ("TRIMMED", flag(trimmed)),
        ];
        let pipeline =
            |label: &str,
             layout: &wgpu::PipelineLayout,
             (module, constants): (&wgpu::ShaderModule, &[(&str, f64)]),
             (vs, fs): (&str, &str),
             buffers: &[Option<wgpu::VertexBufferLayout<'_>>],
             topology: wgpu::PrimitiveTopology,
             (depth_compare, depth_write): (wgpu::CompareFunction, bool)| {
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(label),
                    layout: Some(layout),
                    vertex: wgpu::VertexState {
                        module,
                        entry_point: Some(vs),
                        compilation_options: wgpu::PipelineCompilationOptions {
                            constants,
                            ..Default::default()
                        },
                        buffers,
                    },
                    primitive: wgpu::PrimitiveState {
                        topology,
                        // Two-sided: the surface shader shades back faces itself.
                        cull_mode: None,
                        ..Default::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(depth_write),
                        depth_compare: Some(depth_compare),
                        stencil: Default::default(),
                        bias: Default::default(),
                    }),
                    multisample: wgpu::MultisampleState {
                        count: samples,
                        ..Default::default()
                    },
                    fragment: Some(wgpu::FragmentState {
                        module,
                        entry_point: Some(fs),
                        compilation_options: wgpu::PipelineCompilationOptions {
                            constants,
                            ..Default::default()
                        },
                        targets: &[Some(wgpu::ColorTargetState {
                            format: COLOR_FORMAT,
                            blend: Some(wgpu::BlendState::ALPHA_BLENDING),
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            };
        // A curve's pairs of consecutive vertices: one instance each, both ends from the one
        // vertex buffer (bound a second time one vertex later).
        let curve_layouts = [
            Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<CurveVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Instance,
                attributes: &CurveVertex::ATTRIBUTES,
            }),
            Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<CurveVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Instance,
                attributes: &CurveVertex::NEXT_ATTRIBUTES,
            }),
        ];
        let on_top = (wgpu::CompareFunction::Always, false);
        let lines = wgpu::PrimitiveTopology::LineList;
        RenderPipelines {
            surface: pipeline(
                "surface",
                &self.surface_layout,
                (
                    &self.surface_module,
                    if self.storage { &sample_constants } else { &[] },
                ),
                if self.storage {
                    ("vs_surface", "fs_surface")
                } else {
                    ("vs_surface_gl", "fs_surface_gl")
                },
                &[Some(SurfaceVertex::layout())],
                wgpu::PrimitiveTopology::TriangleList,
                (wgpu::CompareFunction::Less, true),
            ),
            // The control net is drawn over the surface, unoccluded, as CAD tools do.
            net: pipeline(
                "control net",
                &self.layout,
                (&self.overlay_module, &[]),
                ("vs_net", "fs_net"),
                &[Some(control_point_layout)],
                lines,
                on_top,
            ),
            dot: pipeline(
                "control points",
                &self.layout,
                (&self.overlay_module, &[]),
                ("vs_dot", "fs_dot"),
                &[Some(control_point_instances)],
                wgpu::PrimitiveTopology::TriangleStrip,
                on_top,
            ),
            line_depth: pipeline(
                "guide lines (depth tested)",
                &self.layout,
                (&self.overlay_module, &[]),
                ("vs_lines", "fs_lines"),
                &[Some(line_layout.clone())],
                lines,
                (wgpu::CompareFunction::LessEqual, false),
            ),
            line_top: pipeline(
                "analysis lines (on top)",
                &self.layout,
                (&self.overlay_module, &[]),
                ("vs_lines", "fs_lines"),
                &[Some(line_layout)],
                lines,
                on_top,
            ),
            curve: pipeline(
                "curves",
                &self.layout,
                (&self.overlay_module, &[]),
                ("vs_curve", "fs_curve"),
                &curve_layouts,
                wgpu::PrimitiveTopology::TriangleStrip,
                (wgpu::CompareFunction::LessEqual, false),
            ),
        }
    }
}

/// The render pipelines and the scene uniform; one per device.
pub struct ViewportRenderer {
    sources: PipelineSources,
    /// The pipelines per variant, made on first use.
    pipelines: std::sync::Mutex<
        std::collections::HashMap<PipelineVariant, std::sync::Arc<RenderPipelines>>,
    >,
    /// Whether the shading mode of the last [`Self::set_scene`] evaluates per fragment.
    per_pixel: std::sync::atomic::AtomicBool,
    scene_buffer: wgpu::Buffer,
    scene_layout: wgpu::BindGroupLayout,
    scene_bind_group: wgpu::BindGroup,
    /// Group 1 of the surface pipeline: the patch records, the packed trim loops
    /// (`shaders/trim.wgsl`), the control points and control indices (the per-pixel analysis),
    /// bound per frame from the geometry drawn. `None` on a device without storage buffers
    /// (WebGL2), whose surface pipeline shades from the vertices alone.
    trim_layout: Option<wgpu::BindGroupLayout>,
    /// The last group 1 made, with the buffers it binds (records, trims, points, indices).
    trim_group: std::sync::Mutex<Option<([wgpu::Buffer; 4], wgpu::BindGroup)>>,
    device: wgpu::Device,
    /// One bit per patch record: the highlighted patches (surface.wgsl `highlight`; a uniform
    /// of [`GL_HIGHLIGHT_WORDS`] in surface_gl.wgsl).
    highlight: wgpu::Buffer,
    /// Whether any bit of `highlight` is set.
    highlighting: bool,
    /// Per scene object, its own colour (linear RGB, w = 1) or none (w = 0): surface.wgsl's
    /// `object_colors` (a uniform of [`GL_OBJECT_COLORS`] in surface_gl.wgsl).
    object_colors: wgpu::Buffer,
    /// What `object_colors` holds (to skip writing it again).
    object_colors_written: Vec<[f32; 4]>,
    /// The guide lines' vertices (depth-tested ones first) and the two counts.
    lines: Option<wgpu::Buffer>,
    line_counts: (u32, u32),
}

fn scene_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    scene: &wgpu::Buffer,
    highlight: &wgpu::Buffer,
    object_colors: &wgpu::Buffer,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("scene"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: scene.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: highlight.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: object_colors.as_entire_binding(),
            },
        ],
    })
}

/// The highlight bits of the WebGL2 surface pipeline: a uniform of this many words
/// (`surface_gl.wgsl`), so the first 32,768 patch records can be highlighted there.
pub const GL_HIGHLIGHT_WORDS: usize = 1024;

/// The object colours of the WebGL2 surface pipeline: a uniform of this many vec4s
/// (`surface_gl.wgsl`), so the first 256 objects show their own colours there.
pub const GL_OBJECT_COLORS: usize = 256;

fn highlight_buffer(device: &wgpu::Device, words: usize, storage: bool) -> wgpu::Buffer {
    shading_buffer(
        device,
        "patch highlight bits",
        words * 4,
        storage,
        GL_HIGHLIGHT_WORDS * 4,
    )
}

fn object_color_buffer(device: &wgpu::Device, objects: usize, storage: bool) -> wgpu::Buffer {
    shading_buffer(
        device,
        "object colours",
        objects * 16,
        storage,
        GL_OBJECT_COLORS * 16,
    )
}

/// A buffer the surface shader reads: storage of `bytes` (at least 16), or, without storage
/// buffers, a uniform of the fixed `gl_bytes` the WebGL2 shader declares.
fn shading_buffer(
    device: &wgpu::Device,
    label: &str,
    bytes: usize,
    storage: bool,
    gl_bytes: usize,
) -> wgpu::Buffer {
    let (size, usage) = if storage {
        (bytes.max(16), wgpu::BufferUsages::STORAGE)
    } else {
        (gl_bytes, wgpu::BufferUsages::UNIFORM)
    };
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl ViewportRenderer {
    /// The renderer with the plain pipelines for [`SAMPLE_COUNT`] made; the others are made
    /// when a frame first needs them. On a device without compute shaders and storage buffers
    /// (WebGL2, see [`crate::gpu::has_compute`]) it is [`Self::for_vertices_only`].
    pub fn new(device: &wgpu::Device) -> Self {
        Self::with_storage(device, crate::gpu::has_compute(device))
    }

    /// The renderer of a WebGL2 device (on any device, for tests): the surface is shaded from
    /// its vertices alone (`surface_gl.wgsl`), for geometry the CPU evaluated
    /// ([`crate::gpu::CpuGeometry`]): no storage buffers, no per-fragment analysis or trims.
    pub fn for_vertices_only(device: &wgpu::Device) -> Self {
        Self::with_storage(device, false)
    }

    /// Whether the surface pipeline reads the patches per fragment (`surface.wgsl`), rather
    /// than shading from the vertices alone (`surface_gl.wgsl`).
    pub fn reads_patches(&self) -> bool {
        self.trim_layout.is_some()
    }

    fn with_storage(device: &wgpu::Device, storage: bool) -> Self {
        let scene_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("scene uniform"),
            size: std::mem::size_of::<SceneUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // The highlight bits and the object colours ([`shading_buffer`]): storage, or
        // uniforms on WebGL2.
        let shading_entry = |binding, visibility| wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: wgpu::BindingType::Buffer {
                ty: if storage {
                    wgpu::BufferBindingType::Storage { read_only: true }
                } else {
                    wgpu::BufferBindingType::Uniform
                },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let scene_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                shading_entry(1, wgpu::ShaderStages::VERTEX),
                shading_entry(2, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let highlight = highlight_buffer(device, 1, storage);
        let object_colors = object_color_buffer(device, 1, storage);
        let scene_bind_group = scene_bind_group(
            device,
            &scene_layout,
            &scene_buffer,
            &highlight,
            &object_colors,
        );
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("viewport"),
            bind_group_layouts: &[Some(&scene_layout)],
            immediate_size: 0,
        });
        let storage_entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let trim_layout = storage.then(|| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("trim loops"),
                entries: &[
                    storage_entry(0),
                    storage_entry(1),
                    storage_entry(2),
                    storage_entry(3),
                ],
            })
        });
        let surface_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("viewport surface"),
            bind_group_layouts: &[Some(&scene_layout), trim_layout.as_ref()],
            immediate_size: 0,
        });
        let surface_shader = if storage {
            shaders::SURFACE_SHADER
        } else {
            shaders::SURFACE_GL_SHADER
        };
        let sources = PipelineSources {
            layout,
            surface_layout,
            surface_module: shaders::create_module(device, &surface_shader),
            storage,
            overlay_module: shaders::create_module(device, &shaders::OVERLAY_SHADER),
        };
        let plain = PipelineVariant {
            samples: SAMPLE_COUNT,
            per_pixel: false,
            trimmed: false,
        };
        let pipelines = std::collections::HashMap::from([(
            plain,
            std::sync::Arc::new(sources.pipelines(device, plain)),
        )]);
        Self {
            sources,
            pipelines: std::sync::Mutex::new(pipelines),
            per_pixel: std::sync::atomic::AtomicBool::new(false),
            lines: None,
            line_counts: (0, 0),
            scene_buffer,
            scene_layout,
            scene_bind_group,
            trim_layout,
            trim_group: std::sync::Mutex::new(None),
            device: device.clone(),
            highlight,
            highlighting: false,
            object_colors,
            object_colors_written: Vec::new(),
        }
    }

    /// The pipelines of `variant`, made on first use.
    fn pipelines(&self, variant: PipelineVariant) -> std::sync::Arc<RenderPipelines> {
        let mut cache = self
            .pipelines
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        std::sync::Arc::clone(
            cache.entry(variant).or_insert_with(|| {
                std::sync::Arc::new(self.sources.pipelines(&self.device, variant))
            }),
        )
    }

    /// Highlights the patch records `patches` (global record indices) until the next call;
    /// an empty list clears the highlight.
    pub fn set_highlight(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, patches: &[usize]) {
        if patches.is_empty() && !self.highlighting {
            return;
        }
        let storage = self.reads_patches();
        // The WebGL2 pipeline's uniform holds the first GL_HIGHLIGHT_WORDS words.
        let shown = || {
            patches
                .iter()
                .copied()
                .filter(move |&p| storage || p < GL_HIGHLIGHT_WORDS * 32)
        };
        let words = shown().max().map_or(1, |m| m / 32 + 1);
        let mut bits = vec![0u32; words];
        for p in shown() {
            bits[p / 32] |= 1 << (p % 32);
        }
        let capacity = (self.highlight.size() / 4) as usize;
        if words > capacity {
            self.highlight = highlight_buffer(device, words.next_power_of_two(), storage);
            self.rebind_scene(device);
        }
        // Clear the rest of the buffer too.
        bits.resize((self.highlight.size() / 4) as usize, 0);
        queue.write_buffer(&self.highlight, 0, bytemuck::cast_slice(&bits));
        self.highlighting = !patches.is_empty();
    }

    /// Makes group 0 again after one of its buffers was replaced.
    fn rebind_scene(&mut self, device: &wgpu::Device) {
        self.scene_bind_group = scene_bind_group(
            device,
            &self.scene_layout,
            &self.scene_buffer,
            &self.highlight,
            &self.object_colors,
        );
    }

    /// Gives scene object k the colour `colors[k]` (sRGB, 0 to 1) in the lit shading modes,
    /// or the surface colour where it is `None`, until the next call. Only the first
    /// [`GL_OBJECT_COLORS`] objects have their own colours on a WebGL2 device.
    pub fn set_object_colors(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        colors: &[Option<[f32; 3]>],
    ) {
        let storage = self.reads_patches();
        let mut values: Vec<[f32; 4]> = colors
            .iter()
            .map(|c| match c {
                Some(rgb) => {
                    let [r, g, b] = rgb.map(crate::scene::srgb_to_linear);
                    [r, g, b, 1.0]
                }
                None => [0.0; 4],
            })
            .collect();
        if !storage {
            values.truncate(GL_OBJECT_COLORS);
        }
        while values.last() == Some(&[0.0; 4]) {
            values.pop();
        }
        if values == self.object_colors_written {
            return;
        }
        let capacity = (self.object_colors.size() / 16) as usize;
        if values.len() > capacity {
            self.object_colors =
                object_color_buffer(device, values.len().next_power_of_two(), storage);
            self.rebind_scene(device);
        }
        let mut padded = values.clone();
        padded.resize((self.object_colors.size() / 16) as usize, [0.0; 4]);
        queue.write_buffer(&self.object_colors, 0, bytemuck::cast_slice(&padded));
        self.object_colors_written = values;
    }

    /// The guide and analysis lines drawn by every [`Self::render`] until the next call.
    pub fn set_lines(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, lines: &GuideLines) {
        let vertices: Vec<LineVertex> = lines
            .depth_tested
            .iter()
            .chain(&lines.on_top)
            .copied()
            .collect();
        self.line_counts = (lines.depth_tested.len() as u32, lines.on_top.len() as u32);
        if vertices.is_empty() {
            return;
        }
        let bytes: &[u8] = bytemuck::cast_slice(&vertices);
        if self
            .lines
            .as_ref()
            .is_none_or(|b| b.size() < bytes.len() as u64)
        {
            self.lines = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("guide lines"),
                size: (bytes.len() as u64).next_power_of_two(),
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        if let Some(buffer) = &self.lines {
            queue.write_buffer(buffer, 0, bytes);
        }
    }

    /// Sets the camera, viewport size and colours for the next [`Self::render`].
    pub fn set_scene(&self, queue: &wgpu::Queue, scene: &SceneUniform) {
        let per_pixel = ShadingMode::ALL
            .iter()
            .any(|m| m.per_pixel() && *m as u32 == scene.shading[0]);
        self.per_pixel
            .store(per_pixel, std::sync::atomic::Ordering::Relaxed);
        queue.write_buffer(&self.scene_buffer, 0, bytemuck::bytes_of(scene));
    }

    /// Group 1 of the surface pipeline for `surface`'s records and trim loops: made when the
    /// geometry's buffers change (a rebuild), reused for every frame in between.
    fn trim_bind_group(
        &self,
        layout: &wgpu::BindGroupLayout,
        patches: &PatchBuffers<'_>,
    ) -> wgpu::BindGroup {
        let mut cached = self
            .trim_group
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let buffers = [
            patches.records,
            patches.trims,
            patches.control_points,
            patches.control_indices,
        ];
        if let Some((bound, group)) = cached.as_ref()
            && bound.iter().zip(buffers).all(|(a, b)| a == b)
        {
            return group.clone();
        }
        let entries: Vec<wgpu::BindGroupEntry<'_>> = buffers
            .iter()
            .enumerate()
            .map(|(binding, buffer)| wgpu::BindGroupEntry {
                binding: binding as u32,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("surface patches"),
            layout,
            entries: &entries,
        });
        *cached = Some((buffers.map(wgpu::Buffer::clone), group.clone()));
        group
    }

    /// Records one render pass into `target`: the surface from the evaluated vertex and index
    /// buffers, then `net` (lines and points) as `overlays` ask, seen as [`Self::set_scene`]
    /// said, over [`BACKGROUND`].
    pub fn render(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &ViewTarget,
        surface: SurfaceBuffers<'_>,
        net: Option<&ControlNet>,
        overlays: Overlays,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let [r, g, b, a] = BACKGROUND;
        let storage = self.reads_patches();
        let pipelines = self.pipelines(PipelineVariant {
            samples: target.samples,
            per_pixel: storage && self.per_pixel.load(std::sync::atomic::Ordering::Relaxed),
            trimmed: storage && surface.trimmed,
        });
        // With one sample the pass draws straight into the resolved texture.
        let (view, resolve_target, store) = match &target.msaa_view {
            Some(msaa) => (msaa, Some(&target.resolved_view), wgpu::StoreOp::Discard),
            None => (&target.resolved_view, None, wgpu::StoreOp::Store),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("viewport"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a }),
                    store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &self.scene_bind_group, &[]);
        // The WebGPU pipeline needs the patches' buffers (the compute evaluator's geometry);
        // the WebGL2 one draws from the vertices alone.
        let patch_group = self
            .trim_layout
            .as_ref()
            .zip(surface.patches.as_ref())
            .map(|(layout, patches)| self.trim_bind_group(layout, patches));
        let drawable = patch_group.is_some() || !storage;
        if drawable && overlays.surface && (surface.index_count > 0 || surface.indirect.is_some()) {
            pass.set_pipeline(&pipelines.surface);
            if let Some(group) = &patch_group {
                pass.set_bind_group(1, group, &[]);
            }
            pass.set_vertex_buffer(0, surface.vertices.slice(..));
            pass.set_index_buffer(surface.indices.slice(..), wgpu::IndexFormat::Uint32);
            match surface.indirect {
                Some(arguments) => pass.draw_indexed_indirect(arguments, 0),
                None => pass.draw_indexed(0..surface.index_count, 0, 0..1),
            }
        }
        if let Some(curves) = surface.curves {
            let stride = std::mem::size_of::<CurveVertex>() as u64;
            pass.set_pipeline(&pipelines.curve);
            pass.set_vertex_buffer(0, curves.vertices.slice(..));
            pass.set_vertex_buffer(1, curves.vertices.slice(stride..));
            pass.draw(0..4, 0..curves.vertex_count - 1);
        }
        if let Some(lines) = &self.lines {
            let (depth, top) = self.line_counts;
            pass.set_vertex_buffer(0, lines.slice(..));
            if depth > 0 {
                pass.set_pipeline(&pipelines.line_depth);
                pass.draw(0..depth, 0..1);
            }
            if top > 0 {
                pass.set_pipeline(&pipelines.line_top);
                pass.draw(depth..depth + top, 0..1);
            }
        }
        let Some(net) = net else {
            return;
        };
        if overlays.net && net.line_index_count > 0 {
            pass.set_pipeline(&pipelines.net);
            pass.set_vertex_buffer(0, net.points.slice(..));
            pass.set_index_buffer(net.lines.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..net.line_index_count, 0, 0..1);
        }
        if overlays.points && net.point_count > 0 {
            pass.set_pipeline(&pipelines.dot);
            pass.set_vertex_buffer(0, net.points.slice(..));
            pass.draw(0..4, 0..net.point_count);
        }
    }
}
