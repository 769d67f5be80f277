//! Data shared by Rust and WGSL: one definition per side, checked against each other by
//! `tests/it/shaders.rs` (`shared_records_have_the_same_layout_on_both_sides`: naga reflection of
//! `shaders/common.wgsl`).

use bytemuck::{Pod, Zeroable};

/// Highest degree per direction the WGSL Bézier evaluator accepts (`MAX_DEGREE` in
/// `shaders/eval_bezier.wgsl`; its basis arrays hold `GPU_MAX_DEGREE + 1` entries).
pub const GPU_MAX_DEGREE: u32 = 9;

/// How far toward the patch centre the WGSL evaluator samples the curvature of a degenerate point
/// (`CURVATURE_NUDGE` in `shaders/eval_bezier.wgsl`). Farther than the f64 kernel's
/// `diffgeo::CURVATURE_NUDGE`, because in f32 the fundamental forms there lose about ε/nudge².
pub const GPU_CURVATURE_NUDGE: f32 = 3e-2;

/// Workgroup size of both compute entry points (`WORKGROUP_SIZE` in `shaders/eval_bezier.wgsl`).
pub const EVAL_WORKGROUP_SIZE: u32 = 64;

/// Vertices of one grid column each `evaluate_vertices` invocation writes (`GRID_ROWS` in
/// `shaders/eval_bezier.wgsl`): the column's row sums are formed once for them all.
pub const EVAL_GRID_ROWS: u32 = 32;
// The shader marks a run's degenerate rows in the bits of one u32.
const _: () = assert!(EVAL_GRID_ROWS >= 1 && EVAL_GRID_ROWS <= 32);

/// [`PatchRecord::kind`] of a rational tensor-product Bézier patch over the control point pool
/// (today's only kind; subdivision will add regular B-spline and limit-stencil patches).
/// WGSL: `PATCH_KIND_BEZIER` in `shaders/common.wgsl`.
pub const PATCH_KIND_BEZIER: u32 = 0;

/// [`PatchRecord::kind`] of a grid of subdivision limit stencils. WGSL:
/// `PATCH_KIND_STENCIL_QUAD` in `shaders/common.wgsl`.
pub const PATCH_KIND_STENCIL_QUAD: u32 = 1;
/// [`PatchRecord::kind`] of a triangle of subdivision limit stencils. WGSL:
/// `PATCH_KIND_STENCIL_TRIANGLE`.
pub const PATCH_KIND_STENCIL_TRIANGLE: u32 = 2;
/// [`PatchRecord::kind`] of an ACC patch (40 control indices: geometry, u- and v-tangent
/// patches; `kernel::subdiv::substitutes`). WGSL: `PATCH_KIND_ACC`.
pub const PATCH_KIND_ACC: u32 = 3;
/// [`PatchRecord::kind`] of a Gregory patch (20 control indices). WGSL: `PATCH_KIND_GREGORY`.
pub const PATCH_KIND_GREGORY: u32 = 4;
/// [`PatchRecord::kind`] of a PN triangle (16 control indices: 10 positions, 6 normals) on the
/// triangular lattice. WGSL: `PATCH_KIND_PN_TRIANGLE`.
pub const PATCH_KIND_PN_TRIANGLE: u32 = 5;

/// Whether records of `kind` use the triangular lattice i + j ≤ segments.
pub fn is_triangle_lattice(kind: u32) -> bool {
    kind == PATCH_KIND_STENCIL_TRIANGLE || kind == PATCH_KIND_PN_TRIANGLE
}
/// Bit of a stencil slot's entry count: no curvature there. WGSL: `STENCIL_NO_CURVATURE`.
pub const STENCIL_NO_CURVATURE: u32 = 0x8000_0000;

/// [`PatchRecord::point_list`] of a patch whose stencil entries name control points. WGSL:
/// `POINT_LIST_NONE`.
pub const POINT_LIST_NONE: u32 = u32::MAX;

/// One patch to evaluate. WGSL: `struct PatchRecord` in `shaders/common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct PatchRecord {
    pub degree_u: u32,
    pub degree_v: u32,
    /// First entry of this patch's (degree_u + 1)(degree_v + 1) indices in the control-index
    /// buffer, row-major with i along u.
    pub control_offset: u32,
    /// First output vertex; the patch writes (segments_u + 1)(segments_v + 1) vertices,
    /// vertex (i, j) at `vertex_offset + i * (segments_v + 1) + j`.
    pub vertex_offset: u32,
    pub segments_u: u32,
    pub segments_v: u32,
    /// First output triangle index; the patch writes 6 · segments_u · segments_v of them.
    pub index_offset: u32,
    /// The scene object the patch belongs to (written into every vertex).
    pub object: u32,
    /// (u0, u1, v0, v1): the patch's parameter rectangle in its parent surface; the vertex (u, v)
    /// is written in these coordinates.
    pub domain: [f32; 4],
    /// What the patch is ([`PATCH_KIND_BEZIER`]); the evaluation pipelines are keyed by it and
    /// the degrees.
    pub kind: u32,
    /// The patch's trim loops: first entry and count in a trim buffer (0, 0: untrimmed).
    pub trim_offset: u32,
    pub trim_count: u32,
    /// 1 + the subdivision level a stencil patch's vertices come from (0: a patch of no level),
    /// written into every vertex ([`SurfaceVertex::level`]).
    pub level: u32,
    /// Where the object's displacement block lies in the control point buffer
    /// ([`super::packing::displacement_block`]), or [`DISPLACEMENT_NONE`].
    pub displacement: u32,
    /// Where the object's free-form deformation lattice block lies in the control point
    /// buffer ([`super::packing::lattice_block`]), or [`LATTICE_NONE`].
    pub lattice: u32,
    /// A stencil patch whose entries number points of its own: the first of its list of point
    /// numbers in the control-index buffer (entry point k is point `control_indices[point_list
    /// + k]`), or [`POINT_LIST_NONE`] where the entries number the object's points.
    pub point_list: u32,
    /// A stencil patch's point k is control point `first_point + k` (its object's first).
    pub first_point: u32,
}

/// [`PatchRecord::lattice`] of a patch whose object has no lattice. WGSL: `LATTICE_NONE`.
pub const LATTICE_NONE: u32 = u32::MAX;

/// [`PatchRecord::displacement`] of a patch whose object is not displaced. WGSL:
/// `DISPLACEMENT_NONE`.
pub const DISPLACEMENT_NONE: u32 = u32::MAX;

/// [`SurfaceVertex::flags`] bit: Su × Sv vanishes here (a pole or collapsed edge); the normal
/// and curvature are limits from the interior. WGSL: `VERTEX_IRREGULAR`.
pub const VERTEX_IRREGULAR: u32 = 1;
/// [`SurfaceVertex::flags`] bit: the curvature is undefined here and nearby (the values are 0 and
/// the curvature modes show the vertex neutrally). WGSL: `VERTEX_NO_CURVATURE`.
pub const VERTEX_NO_CURVATURE: u32 = 2;

/// Bits of [`SurfaceVertex::tag`] that hold the scene object (the low 24); the scene may hold at
/// most this many objects for the GPU. WGSL: `VERTEX_OBJECT_MASK`.
pub const VERTEX_OBJECT_MASK: u32 = (1 << 24) - 1;
/// Where [`SurfaceVertex::tag`] holds the record's level (4 bits). WGSL: `VERTEX_LEVEL_SHIFT`.
pub const VERTEX_LEVEL_SHIFT: u32 = 24;
/// Where [`SurfaceVertex::tag`] holds the flags (4 bits). WGSL: `VERTEX_FLAGS_SHIFT`.
pub const VERTEX_FLAGS_SHIFT: u32 = 28;

/// One tessellation vertex as the compute pass writes it and the render pass reads it: 48
/// bytes, position and normal in full f32 precision, the curvature as its Gaussian and mean
/// values (the principal ones follow, k1,2 = H ± √(H² − K): within √ε·|H| of the evaluator's
/// near umbilics, where that root cancels, exact elsewhere), and object, level and flags in
/// one word.
/// WGSL: `struct SurfaceVertex` in `shaders/common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SurfaceVertex {
    pub position: [f32; 3],
    /// u in the parent surface's own domain.
    pub u: f32,
    pub normal: [f32; 3],
    /// v in the parent surface's own domain.
    pub v: f32,
    /// (Gaussian K, mean H), positive toward the normal (the kernel's convention: a sphere with
    /// outward normals has H = −1/r); zero where the curvature is undefined.
    pub gaussian_mean: [f32; 2],
    /// The patch record that wrote the vertex (for highlighting the patches a drag changes).
    pub record: u32,
    /// The scene object ([`VERTEX_OBJECT_MASK`]), the record's [`PatchRecord::level`] (at
    /// [`VERTEX_LEVEL_SHIFT`], for the refinement-level colours) and [`VERTEX_IRREGULAR`] |
    /// [`VERTEX_NO_CURVATURE`] (at [`VERTEX_FLAGS_SHIFT`]).
    pub tag: u32,
}

impl SurfaceVertex {
    /// Vertex attributes: position (0), u (1), normal (2), v (3), (K, H) (4), record (5),
    /// tag (6).
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 7] = wgpu::vertex_attr_array![
        0 => Float32x3,
        1 => Float32,
        2 => Float32x3,
        3 => Float32,
        4 => Float32x2,
        5 => Uint32,
        6 => Uint32,
    ];

    /// A vertex from its parts; `curvature` is (K, H, k1, k2), of which K and H are kept;
    /// `level` is kept to 4 bits and `object` to [`VERTEX_OBJECT_MASK`]. WGSL: `surface_vertex`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        position: [f32; 3],
        (u, v): (f32, f32),
        normal: [f32; 3],
        curvature: [f32; 4],
        object: u32,
        flags: u32,
        record: u32,
        level: u32,
    ) -> Self {
        Self {
            position,
            u,
            normal,
            v,
            gaussian_mean: [curvature[0], curvature[1]],
            record,
            tag: (object & VERTEX_OBJECT_MASK)
                | (level.min(15) << VERTEX_LEVEL_SHIFT)
                | ((flags & 15) << VERTEX_FLAGS_SHIFT),
        }
    }

    /// (Gaussian K, mean H, k1, k2), k1 ≥ k2: k1,2 = H ± √(max(H² − K, 0)). WGSL:
    /// `vertex_curvature`.
    pub fn curvature(&self) -> [f32; 4] {
        let [k, h] = self.gaussian_mean;
        let root = (h * h - k).max(0.0).sqrt();
        [k, h, h + root, h - root]
    }

    /// The scene object.
    pub fn object(&self) -> u32 {
        self.tag & VERTEX_OBJECT_MASK
    }

    /// The record's level.
    pub fn level(&self) -> u32 {
        (self.tag >> VERTEX_LEVEL_SHIFT) & 15
    }

    /// [`VERTEX_IRREGULAR`] | [`VERTEX_NO_CURVATURE`].
    pub fn flags(&self) -> u32 {
        self.tag >> VERTEX_FLAGS_SHIFT
    }

    pub fn layout() -> wgpu::VertexBufferLayout<'static> {
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Self>() as wgpu::BufferAddress,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &Self::ATTRIBUTES,
        }
    }
}

/// Per-view uniforms of the render pipelines. WGSL: `struct SceneUniform` in
/// `shaders/common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SceneUniform {
    /// Column-major clip-from-world matrix (wgpu depth range 0..1).
    pub view_proj: [[f32; 4]; 4],
    /// Camera position in world space (w = 1).
    pub eye: [f32; 4],
    /// (width, height, control point radius, 0) in physical pixels.
    pub viewport: [f32; 4],
    /// Linear RGBA of the front side of the surface.
    pub surface_color: [f32; 4],
    /// Linear RGBA of the back side of the surface.
    pub back_color: [f32; 4],
    /// Linear RGBA of the control net lines.
    pub net_color: [f32; 4],
    /// Linear RGBA of the control point dots.
    pub point_color: [f32; 4],
    /// ([`crate::view::ShadingMode`] as u32, selected object + 1 or 0, 0, 0).
    pub shading: [u32; 4],
    /// (low, high) of the colour ramp's range, (checker cells per unit of u and v).
    pub range: [f32; 4],
    /// The colour ramp's stops (linear RGB, alpha unused), evenly spaced from low to high.
    pub ramp: [[f32; 4]; RAMP_STOPS],
    /// The camera's right, up and back (toward the viewer) axes in world space; `view_back[3]`
    /// is 1 for an orthographic view.
    pub view_right: [f32; 4],
    pub view_up: [f32; 4],
    pub view_back: [f32; 4],
    /// (zebra stripe pairs per half turn, zebra angle in radians, isophote spacing in degrees,
    /// draft threshold in degrees).
    pub analysis: [f32; 4],
    /// The isophotes' light direction (unit, world).
    pub isophote_direction: [f32; 4],
    /// The draft analysis's pull direction (unit, world).
    pub pull_direction: [f32; 4],
    /// (zebra frame: 0 view, 1 world; zebra source: 0 reflection, 1 normal; 0; 0).
    pub analysis_flags: [u32; 4],
}

/// What the view-adaptive tessellation measures its levels against: the camera and the error
/// rule of [`super::adaptive::ScreenError`]. WGSL: `struct AdaptiveView` in
/// `shaders/common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct AdaptiveView {
    /// Column-major clip-from-world matrix (the control hulls are culled against it).
    pub view_proj: [[f32; 4]; 4],
    /// The eye and the unit view direction in world space (w unused).
    pub eye: [f32; 4],
    pub forward: [f32; 4],
    /// (world units per pixel at unit depth, or anywhere when orthographic; the near depth;
    /// the tolerated error in pixels; the longest triangle edge in pixels).
    pub error: [f32; 4],
    /// (orthographic 0/1, most segments per edge, slot count, vertex capacity).
    pub counts: [u32; 4],
    /// (index capacity, first adaptive vertex, first adaptive index, 0).
    pub bases: [u32; 4],
}

/// One view-adaptively tessellated patch: its levels and its place in the vertex and index
/// buffers, written by the levels pass and the scan. WGSL: `struct AdaptiveSlot`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
pub struct AdaptiveSlot {
    /// Segments of the edges t = 0, s = 1, t = 1, s = 0 ([`super::adaptive::PatchLevels`]).
    pub edges: [u32; 4],
    /// (nu, nv) of the interior grid.
    pub inner: [u32; 2],
    /// The patch record.
    pub record: u32,
    /// 1 when the control hull lies outside the view.
    pub culled: u32,
    pub vertex_offset: u32,
    pub index_offset: u32,
    pub vertex_count: u32,
    pub triangle_count: u32,
}

/// Stops of the curvature colour ramp. WGSL: `RAMP_STOPS`.
pub const RAMP_STOPS: usize = 5;

/// The curvature ramp (linear RGB), low to high: blue, cyan, green, yellow, red — the order
/// Rhino and most CAD tools use for curvature analysis.
pub const CURVATURE_RAMP: [[f32; 4]; RAMP_STOPS] = [
    [0.02, 0.10, 0.85, 1.0],
    [0.02, 0.65, 0.80, 1.0],
    [0.10, 0.72, 0.10, 1.0],
    [0.90, 0.80, 0.05, 1.0],
    [0.85, 0.05, 0.03, 1.0],
];

/// [`CURVATURE_RAMP`]'s stops as RGB (what the glTF export's curvature colours use).
pub fn curvature_ramp_rgb() -> Vec<[f32; 3]> {
    CURVATURE_RAMP.iter().map(|c| [c[0], c[1], c[2]]).collect()
}

/// One point to evaluate: local (s, t) of patch record `patch_index`. WGSL: `struct PointSample`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct PointSample {
    pub patch_index: u32,
    pub s: f32,
    pub t: f32,
    pub reserved: u32,
}

/// What point evaluation writes; derivatives with respect to the patch's local (s, t).
/// WGSL: `struct PointResult`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct PointResult {
    pub point: [f32; 4],
    pub normal: [f32; 4],
    pub su: [f32; 4],
    pub sv: [f32; 4],
    pub suu: [f32; 4],
    pub suv: [f32; 4],
    pub svv: [f32; 4],
    /// (K, H, k1, k2).
    pub curvature: [f32; 4],
    /// (vertex flags, 0, 0, 0).
    pub flags: [u32; 4],
}

/// The highest curve degree the curve evaluator takes (`CURVE_MAX_DEGREE` in
/// `shaders/common.wgsl`): the kernel's own limit.
pub const CURVE_MAX_DEGREE: u32 = 32;

/// Invocations per workgroup of `eval_curves` (`CURVE_WORKGROUP_SIZE` in `shaders/common.wgsl`).
pub const CURVE_WORKGROUP_SIZE: u32 = 64;

/// One rational Bézier segment of a curve for the curve evaluator. WGSL: `struct CurveRecord` in
/// `shaders/common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
pub struct CurveRecord {
    pub degree: u32,
    /// The segment's first homogeneous point in the curve point pool.
    pub control_offset: u32,
    /// Its first vertex; it writes `segments + 1`.
    pub vertex_offset: u32,
    /// Line segments it is drawn with.
    pub segments: u32,
    /// The scene object it belongs to.
    pub object: u32,
    pub reserved0: u32,
    pub reserved1: u32,
    pub reserved2: u32,
}

/// One sample of a curve, as the curve evaluator writes it and the viewport draws it. WGSL:
/// `struct CurveVertex` in `shaders/common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct CurveVertex {
    /// (x, y, z, 1), or w = 0 at a segment's last sample (no line from it to the next vertex).
    pub position: [f32; 4],
    pub object: u32,
    /// The record that wrote it and its parameter s ∈ [0, 1] along that segment.
    pub record: u32,
    pub s: f32,
    pub reserved: u32,
}

impl CurveVertex {
    /// The attributes of one end of a drawn pair: position and object (the other end's
    /// position is attribute 2, from the same buffer one vertex later).
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 2] = wgpu::vertex_attr_array![
        0 => Float32x4,
        1 => Uint32,
    ];
    /// The attribute of the pair's second end.
    pub const NEXT_ATTRIBUTES: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![
        2 => Float32x4,
    ];
}
