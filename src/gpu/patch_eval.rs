//! The compute evaluator: uploads the Bézier patches of every object of a scene into one pool
//! and runs `shaders/eval_bezier.wgsl`, which writes every tessellation vertex (position, normal,
//! (u, v), curvature K/H/k1/k2) and the triangle indices straight into the buffers the render
//! pass draws from. No CPU tessellation on this path.
//!
//! # Why Bézier decomposition rather than de Boor in WGSL
//!
//! NURBS and B-spline surfaces reach the GPU as their Bézier patches: the kernel refines every
//! interior knot to full multiplicity (`NurbsSurface::to_bezier_patch_set`, The NURBS Book A5.7)
//! and one Bézier evaluator handles every object. We chose this over a de Boor evaluator in WGSL
//! because:
//! - the per-vertex work is a fixed Bernstein sum with no knot search, no knot-vector reads and no
//!   data-dependent loop bounds; the bicubic pipeline (the teapot, every bicubic B-spline) has no
//!   private arrays at all, which lavapipe needs: a private array slowed the whole kernel about
//!   8× there even on paths that never touched it;
//! - neighbouring patches share their boundary control points in the pool, which is what makes
//!   the canonical edge evaluation (below) bit-identical across seams;
//! - local support becomes a list of patches: moving one B-spline control point re-evaluates only
//!   the (p + 1)(q + 1) or fewer Bézier patches in its support.
//!
//! The cost is the decomposition on the CPU (0.36–0.50 ms for a 32 × 32 bicubic net, measured by
//! `knotwork bench`; it is redone on every edit, still well inside a frame) and a larger control
//! point pool (about p·q times the B-spline's points for a net with simple knots), which is far
//! below the vertex buffer's size.
//!
//! # Dispatches
//!
//! One compute pass per evaluation: `write_triangles` once after a tessellation change, then one
//! `evaluate_vertices` dispatch per patch kind and degree pair ([`PipelineKey`]) present (the
//! six demo objects have four, all Bézier: (3, 3), (2, 2), (2, 5) and (2, 3)), each over the
//! list of its patches that need it — the
//! whole scene after a change of tessellation, only the support of an edit afterwards. Each
//! dispatch runs a pipeline specialized to its degrees by override constants: constant loop
//! bounds let the driver unroll the Bernstein sums and keep them in registers. On lavapipe that
//! took the demo scene's compute pass from 104 ms (one pipeline reading the degrees from the
//! records) to 8–10 ms.

use std::collections::{BTreeMap, BTreeSet};

use wgpu::util::DeviceExt;

use super::adaptive_pass::{AdaptivePass, AdaptiveStats, AdaptiveTarget, SharedBuffers};
use super::error::GpuError;
use super::packing;
use super::pipelines::{PatchEvaluator, PipelineKey};
use super::records::{
    DISPLACEMENT_NONE, EVAL_GRID_ROWS, EVAL_WORKGROUP_SIZE, GPU_MAX_DEGREE, LATTICE_NONE,
    PATCH_KIND_ACC, PATCH_KIND_BEZIER, PATCH_KIND_GREGORY, PATCH_KIND_PN_TRIANGLE,
    PATCH_KIND_STENCIL_QUAD, PATCH_KIND_STENCIL_TRIANGLE, POINT_LIST_NONE, PatchRecord,
    STENCIL_NO_CURVATURE, SurfaceVertex,
};
use super::trim_buffer::{TRIM_CULLED, TRIM_PARTIAL, pack_index};
use crate::kernel::BezierPatchSet;
use crate::kernel::subdiv::patches::LimitFeed;
use crate::kernel::subdiv::substitutes::SubstituteKind;
use crate::kernel::trim::index::Coverage;
use crate::scene::TrimFeed;

pub use crate::scene::MAX_SEGMENTS;

/// The evaluated surface as the renderer takes it: vertices ([`SurfaceVertex`]) and triangle
/// indices (u32), whichever evaluator wrote them.
#[derive(Debug, Clone, Copy)]
pub struct SurfaceBuffers<'a> {
    pub vertices: &'a wgpu::Buffer,
    pub indices: &'a wgpu::Buffer,
    pub index_count: u32,
    /// The patch data the WebGPU surface pipeline reads per fragment (trims, per-pixel
    /// analysis); `None` from the CPU evaluator, whose renderer shades from the vertices alone.
    pub patches: Option<PatchBuffers<'a>>,
    /// Whether any patch is crossed by a trim loop (the renderer then trims per fragment).
    pub trimmed: bool,
    /// With a view-adaptive tessellation, the `draw_indexed_indirect` arguments (offset 0) the
    /// compute pass wrote; the draw then takes its count from there, not `index_count`.
    pub indirect: Option<&'a wgpu::Buffer>,
    /// The curves' vertices ([`super::curve_eval`]), where the scene has curves.
    pub curves: Option<super::curve_eval::CurveBuffers<'a>>,
}

/// The storage buffers of the patches, as the surface shader's group 1 binds them.
#[derive(Debug, Clone, Copy)]
pub struct PatchBuffers<'a> {
    /// The patch records (the fragment shader reads a record's trim fields).
    pub records: &'a wgpu::Buffer,
    /// The packed trim loops ([`super::trim_buffer`]).
    pub trims: &'a wgpu::Buffer,
    /// The control point pool and the records' control indices (the fragment shader evaluates
    /// the patches itself in the analysis modes).
    pub control_points: &'a wgpu::Buffer,
    pub control_indices: &'a wgpu::Buffer,
}

/// How a [`PatchGeometry`] tessellates its Bézier patches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tessellation {
    /// Each object's segment count, on every patch alike.
    Fixed,
    /// Levels per patch edge from the view ([`super::adaptive_pass`]), in buffers with room
    /// for `vertices` adaptive vertices (and six indices per vertex). Subdivision stencil
    /// patches keep their fixed levels.
    Adaptive { vertices: u32 },
}

/// One scene object's patches, as [`PatchGeometry::new`] takes them.
#[derive(Debug, Clone)]
pub struct ObjectPatches<'a> {
    pub set: &'a BezierPatchSet,
    /// Each patch's parameter rectangle (u0, u1, v0, v1) in the object's own domain (the
    /// vertices' (u, v) are written in it); empty means (0, 1, 0, 1) for every patch.
    pub domains: &'a [[f64; 4]],
    /// Segments per patch edge, in both directions.
    pub segments: u32,
    /// A subdivision surface's stencil patches, evaluated after the Bézier patches.
    pub stencils: Option<&'a LimitFeed>,
    /// How many of the set's first points the stencils use (the cage).
    pub cage_points: usize,
    /// A trimmed surface's loops and each Bézier patch's coverage: patches wholly trimmed away
    /// are neither evaluated nor drawn, patches a loop crosses are classified per fragment.
    pub trims: Option<&'a TrimFeed>,
    /// The object's displacement along the normal, applied to every vertex it writes.
    pub displacement: Option<ObjectDisplacement>,
    /// The object's free-form deformation lattice, applied to every vertex it writes (after
    /// the displacement).
    pub lattice: Option<&'a crate::kernel::ffd::Lattice>,
}

/// An object's displacement as the evaluators apply it: the height map and the object's own
/// (u0, u1, v0, v1), over which the map's (x, y) ∈ [0, 1]² runs.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectDisplacement {
    pub map: crate::kernel::displace::Displacement,
    pub domain: [f64; 4],
}

impl ObjectDisplacement {
    /// The displaced position and normal of a vertex of `record` at local (s, t) with
    /// derivatives `d` (in (s, t)), `position` and unit `normal` ([`crate::kernel::displace`];
    /// `displace` in `shaders/eval_bezier.wgsl`).
    pub fn apply(
        &self,
        record: &PatchRecord,
        d: &crate::kernel::SurfaceDerivatives,
        position: glam::DVec3,
        normal: glam::DVec3,
        (s, t): (f64, f64),
    ) -> (glam::DVec3, glam::DVec3) {
        let [u0, u1, v0, v1] = record.domain.map(f64::from);
        let [du0, du1, dv0, dv1] = self.domain;
        let (su, sv) = (
            (du1 - du0).max(f64::MIN_POSITIVE),
            (dv1 - dv0).max(f64::MIN_POSITIVE),
        );
        let x = (u0 + (u1 - u0) * s - du0) / su;
        let y = (v0 + (v1 - v0) * t - dv0) / sv;
        let at = crate::kernel::SurfaceDerivatives {
            point: position,
            ..*d
        };
        self.map
            .apply(&at, normal, x, y, [(u1 - u0) / su, (v1 - v0) / sv])
    }
}

/// Where one object lives in the shared buffers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ObjectRange {
    pub first_point: usize,
    pub point_count: usize,
    pub first_patch: usize,
    pub patch_count: usize,
    /// Bézier patches among them (the rest are stencil patches).
    pub bezier_count: usize,
    pub cage_points: usize,
}

/// The patches of one degree pair, evaluated by one specialized pipeline.
struct PatchGroup {
    key: PipelineKey,
    /// Global record indices of the group's patches.
    records: Vec<u32>,
    /// The records evaluated by the next dispatch (written by [`PatchGeometry::encode`]).
    list: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

/// The records and buffer layout of a scene's patches, shared by the compute evaluator
/// ([`PatchGeometry`]) and the CPU one ([`super::cpu_eval::CpuGeometry`]): each patch's record
/// (degrees, control block, vertex and index offsets, fixed levels, domain, trim state), where
/// each object lives, the control index blocks, the homogeneous control points, the stencil
/// entries and the packed trim loops. `adaptive`: the Bézier patches get no fixed grid (their room
/// comes after the fixed patches'). `max_groups` bounds the dispatches (the CPU passes
/// `u32::MAX`). Checks the degrees and levels.
pub(crate) struct PatchLayout {
    pub records: Vec<PatchRecord>,
    pub objects: Vec<ObjectRange>,
    pub control_indices: Vec<u32>,
    pub points: Vec<[f32; 4]>,
    pub entry_data: Vec<[f32; 4]>,
    /// Where the stencil entries start in `entry_data`: the objects' displacement and lattice
    /// blocks come before.
    pub stencil_start: usize,
    /// Each object's lattice block: where it starts in the control point buffer, and its words.
    pub lattices: Vec<Option<(u32, Vec<[f32; 4]>)>>,
    pub trim_words: Vec<u32>,
    /// Vertices and triangle indices of the fixed patches.
    pub vertices: u64,
    pub indices: u64,
    /// Workgroups along x of the largest grid's quads.
    pub quad_groups_x: u64,
}

impl PatchLayout {
    pub fn new(
        objects: &[ObjectPatches<'_>],
        adaptive: bool,
        max_groups: u32,
    ) -> Result<Self, GpuError> {
        let total_patches: usize = objects
            .iter()
            .map(|o| o.set.patches().len() + stencil_count(o))
            .sum();
        if total_patches > max_groups as usize {
            return Err(GpuError::TooManyPatches {
                count: total_patches,
                max: max_groups,
            });
        }
        // A vertex names its object in 24 bits (SurfaceVertex::tag).
        let max_objects = super::records::VERTEX_OBJECT_MASK as usize + 1;
        if objects.len() > max_objects {
            return Err(GpuError::TooManyObjects {
                count: objects.len(),
                max: max_objects,
            });
        }
        // Sized ahead: on a large subdivision surface they hold millions of words, and each
        // doubling would copy them again.
        let bezier_indices: usize = objects
            .iter()
            .flat_map(|o| o.set.patches())
            .map(|p| p.indices().len())
            .sum();
        let total_points = objects.iter().map(|o| o.set.points().len()).sum();
        let mut layout = Self {
            records: Vec::with_capacity(total_patches),
            objects: Vec::with_capacity(objects.len()),
            control_indices: Vec::with_capacity(bezier_indices),
            points: Vec::with_capacity(total_points),
            entry_data: Vec::new(),
            stencil_start: 0,
            lattices: Vec::with_capacity(objects.len()),
            trim_words: Vec::new(),
            vertices: 0,
            indices: 0,
            quad_groups_x: 0,
        };
        let context = LayoutContext {
            // Stencil entries and the displacement and lattice blocks follow the points in the
            // control point buffer.
            total_points,
            adaptive,
            max_groups,
        };
        // Every object's displacement and lattice blocks come first, then the stencil entries:
        // the entries can then be paged ([`super::stencil_pages`]) behind one copy of the
        // points and blocks.
        let blocks: Vec<Blocks> = objects
            .iter()
            .map(|input| layout.push_blocks(input, &context))
            .collect();
        layout.stencil_start = layout.entry_data.len();
        for ((object, input), blocks) in objects.iter().enumerate().zip(blocks) {
            layout.push_object(object, input, blocks, &context)?;
        }
        Ok(layout)
    }

    /// Where the next entry of the control point buffer after the points goes.
    fn next_entry(&self, context: &LayoutContext) -> u32 {
        (context.total_points + self.entry_data.len()) as u32
    }

    /// Object `object`'s range, records, control indices and points (its blocks are
    /// `blocks`).
    fn push_object(
        &mut self,
        object: usize,
        input: &ObjectPatches<'_>,
        blocks: Blocks,
        context: &LayoutContext,
    ) -> Result<(), GpuError> {
        let trim_headers: Vec<u32> = input.trims.map_or_else(Vec::new, |t| {
            t.indices
                .iter()
                .map(|index| pack_index(index, &mut self.trim_words))
                .collect()
        });
        let segments = input.segments;
        if !(1..=MAX_SEGMENTS).contains(&segments) {
            return Err(GpuError::SegmentsOutOfRange {
                segments,
                max: MAX_SEGMENTS,
            });
        }
        if workgroups(u64::from(segments + 1).pow(2)) > u64::from(context.max_groups) {
            return Err(GpuError::SegmentsOutOfRange {
                segments,
                max: MAX_SEGMENTS,
            });
        }
        let first_point = self.points.len();
        self.objects.push(ObjectRange {
            first_point,
            point_count: input.set.points().len(),
            first_patch: self.records.len(),
            patch_count: input.set.patches().len() + stencil_count(input),
            bezier_count: input.set.patches().len(),
            cage_points: input.cage_points,
        });
        self.push_bezier_patches(object, input, first_point, &trim_headers, blocks, context)?;
        if let Some(feed) = input.stencils {
            self.push_stencil_patches(object, feed, first_point, blocks, context)?;
            self.push_substitutes(object, input, feed, first_point, blocks, context)?;
        }
        self.points.extend(homogeneous_points(input.set));
        Ok(())
    }

    /// The object's displacement and lattice blocks, after the points and the blocks of the
    /// objects before: where each starts ([`DISPLACEMENT_NONE`], [`LATTICE_NONE`] without one).
    fn push_blocks(&mut self, input: &ObjectPatches<'_>, context: &LayoutContext) -> Blocks {
        let displacement = match &input.displacement {
            Some(d) => {
                let at = self.next_entry(context);
                self.entry_data
                    .extend(packing::displacement_block(&d.map, d.domain));
                at
            }
            None => DISPLACEMENT_NONE,
        };
        let lattice = match input.lattice {
            Some(l) => {
                let at = self.next_entry(context);
                let block = packing::lattice_block(l);
                self.entry_data.extend_from_slice(&block);
                self.lattices.push(Some((at, block)));
                at
            }
            None => {
                self.lattices.push(None);
                LATTICE_NONE
            }
        };
        Blocks {
            displacement,
            lattice,
        }
    }

    /// The object's Bézier patches: one record each with its domain and trim state, and its
    /// fixed grid's room (none for a culled patch; an adaptive one's room comes after the fixed
    /// patches').
    fn push_bezier_patches(
        &mut self,
        object: usize,
        input: &ObjectPatches<'_>,
        first_point: usize,
        trim_headers: &[u32],
        blocks: Blocks,
        context: &LayoutContext,
    ) -> Result<(), GpuError> {
        let segments = input.segments;
        let grid_vertices = u64::from(segments + 1).pow(2);
        let grid_quads = u64::from(segments).pow(2);
        self.quad_groups_x = self.quad_groups_x.max(workgroups(grid_quads));
        for (k, patch) in input.set.patches().iter().enumerate() {
            let (du, dv) = (patch.degree_u(), patch.degree_v());
            if du > GPU_MAX_DEGREE as usize || dv > GPU_MAX_DEGREE as usize {
                return Err(GpuError::DegreeTooHigh {
                    object,
                    patch: k,
                    degree_u: du,
                    degree_v: dv,
                    max: GPU_MAX_DEGREE,
                });
            }
            let domain = input
                .domains
                .get(k)
                .copied()
                .unwrap_or([0.0, 1.0, 0.0, 1.0])
                .map(|x| x as f32);
            let coverage = input
                .trims
                .and_then(|t| t.coverage.get(k).copied())
                .unwrap_or(Coverage::Inside);
            let trim_header = input
                .trims
                .and_then(|t| t.patch_index.get(k))
                .and_then(|&i| trim_headers.get(i as usize).copied());
            let (trim_offset, trim_count) = match (coverage, trim_header) {
                (Coverage::Outside, _) => (0, TRIM_CULLED),
                (Coverage::Partial, Some(header)) => (header, TRIM_PARTIAL),
                _ => (0, 0),
            };
            // Adaptive patches have no fixed grid: write_triangles skips them.
            let grid = if context.adaptive { 0 } else { segments };
            self.records.push(PatchRecord {
                degree_u: du as u32,
                degree_v: dv as u32,
                domain,
                trim_offset,
                trim_count,
                ..self.next_record(PATCH_KIND_BEZIER, grid, 0, blocks, object)
            });
            self.control_indices
                .extend(patch.indices().iter().map(|&i| i + first_point as u32));
            if trim_count != TRIM_CULLED && !context.adaptive {
                self.vertices += grid_vertices;
                self.indices += 6 * grid_quads;
            }
        }
        Ok(())
    }

    /// A subdivision surface's exact limit patches: their stencil entries (after the points),
    /// the point lists of patches whose entries number points of their own (in the control
    /// indices), and per patch a record (reading the object's points from `first_point` on)
    /// and its slots' (first entry, count) pairs.
    fn push_stencil_patches(
        &mut self,
        object: usize,
        feed: &LimitFeed,
        first_point: usize,
        blocks: Blocks,
        context: &LayoutContext,
    ) -> Result<(), GpuError> {
        let entry_base = context.total_points + self.entry_data.len();
        self.entry_data.reserve(2 * feed.entries.len());
        for &(point, w) in &feed.entries {
            self.entry_data
                .push([f32::from_bits(point), w[0] as f32, w[1] as f32, w[2] as f32]);
            self.entry_data
                .push([w[3] as f32, w[4] as f32, w[5] as f32, 0.0]);
        }
        let lists = self.control_indices.len();
        self.control_indices.extend_from_slice(&feed.point_lists);
        for patch in &feed.patches {
            let s = patch.segments;
            let slots = grid_slots(s, context.max_groups)?;
            let kind = if patch.triangle {
                PATCH_KIND_STENCIL_TRIANGLE
            } else {
                PATCH_KIND_STENCIL_QUAD
            };
            let level = if patch.level == u32::MAX {
                0
            } else {
                patch.level + 1
            };
            self.push_grid_record(kind, s, level, blocks, object, slots);
            if let Some(record) = self.records.last_mut() {
                record.first_point = first_point as u32;
                if patch.points != u32::MAX {
                    record.point_list = (lists + patch.points as usize) as u32;
                }
            }
            let first = patch.first_slot as usize;
            for k in first..first + slots as usize {
                let [start, count] = feed.slots[k];
                let flag = if feed.no_curvature[k] {
                    STENCIL_NO_CURVATURE
                } else {
                    0
                };
                self.control_indices
                    .push((entry_base + 2 * start as usize) as u32);
                self.control_indices.push(count | flag);
            }
        }
        Ok(())
    }

    /// A subdivision surface's substitute patches (ACC, Gregory, PN triangles): a record each
    /// and the indices of its points.
    fn push_substitutes(
        &mut self,
        object: usize,
        input: &ObjectPatches<'_>,
        feed: &LimitFeed,
        first_point: usize,
        blocks: Blocks,
        context: &LayoutContext,
    ) -> Result<(), GpuError> {
        for patch in &feed.substitutes {
            let s = patch.segments;
            let slots = grid_slots(s, context.max_groups)?;
            let count = patch.kind.point_count();
            let last = patch.first_point as usize + count;
            if last > input.set.points().len() {
                return Err(GpuError::Geometry(format!(
                    "a substitute patch reads point {last} of {}",
                    input.set.points().len()
                )));
            }
            let kind = substitute_record_kind(patch.kind);
            self.push_grid_record(kind, s, 0, blocks, object, slots);
            self.control_indices
                .extend((patch.first_point as usize..last).map(|k| (k + first_point) as u32));
        }
        Ok(())
    }

    /// The record of a stencil or substitute patch on an `s` × `s` grid of `slots` vertices,
    /// whose control block starts at the next control index; its vertices and triangles take
    /// the next room.
    fn push_grid_record(
        &mut self,
        kind: u32,
        s: u32,
        level: u32,
        blocks: Blocks,
        object: usize,
        slots: u64,
    ) {
        self.quad_groups_x = self.quad_groups_x.max(workgroups(u64::from(s).pow(2)));
        let record = self.next_record(kind, s, level, blocks, object);
        self.records.push(record);
        self.vertices += slots;
        self.indices += 6 * u64::from(s).pow(2);
    }

    /// A record of `kind` on an `s` × `s` grid over (0, 1)², untrimmed, of degree 1 (grid
    /// patches ignore it), whose control block, vertices and triangles start at the next free
    /// place.
    fn next_record(
        &self,
        kind: u32,
        s: u32,
        level: u32,
        blocks: Blocks,
        object: usize,
    ) -> PatchRecord {
        PatchRecord {
            degree_u: 1,
            degree_v: 1,
            control_offset: self.control_indices.len() as u32,
            vertex_offset: self.vertices as u32,
            segments_u: s,
            segments_v: s,
            index_offset: self.indices as u32,
            object: object as u32,
            domain: [0.0, 1.0, 0.0, 1.0],
            kind,
            trim_offset: 0,
            trim_count: 0,
            level,
            displacement: blocks.displacement,
            lattice: blocks.lattice,
            point_list: POINT_LIST_NONE,
            first_point: 0,
        }
    }
}

/// What every object's layout reads: the scene's point count (the entries after it), the
/// tessellation and the dispatch limit.
struct LayoutContext {
    total_points: usize,
    adaptive: bool,
    max_groups: u32,
}

/// Where an object's displacement and lattice blocks start in the control point buffer.
#[derive(Debug, Clone, Copy)]
struct Blocks {
    displacement: u32,
    lattice: u32,
}

/// The stencil and substitute patches of an object (a subdivision surface's).
fn stencil_count(o: &ObjectPatches<'_>) -> usize {
    o.stencils
        .map_or(0, |f| f.patches.len() + f.substitutes.len())
}

/// The bytes one storage binding may hold on a device with `limits`.
fn binding_limit(limits: &wgpu::Limits) -> u64 {
    limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size)
}

/// Refuses a buffer larger than the device binds (`buffers`: what and bytes), and more
/// triangle indices than the index buffer's u32 offsets reach.
fn check_buffer_sizes(
    limits: &wgpu::Limits,
    buffers: &[(&'static str, u64)],
    indices: u64,
) -> Result<(), GpuError> {
    let limit = binding_limit(limits);
    for &(what, bytes) in buffers {
        if bytes > limit || indices > u64::from(u32::MAX) / 2 {
            return Err(GpuError::BufferTooLarge { what, bytes, limit });
        }
    }
    Ok(())
}

/// Record indices by the [`PipelineKey`] of the pipeline that evaluates them.
type RecordsByKey = BTreeMap<PipelineKey, Vec<u32>>;

/// The records each pipeline evaluates: those on the fixed grid, and (with `adaptive`) the
/// Bézier patches the adaptive passes take. Culled patches are in neither.
fn records_by_key(records: &[PatchRecord], adaptive: bool) -> (RecordsByKey, RecordsByKey) {
    let (mut fixed, mut view_adaptive) = (RecordsByKey::new(), RecordsByKey::new());
    for (k, r) in records.iter().enumerate() {
        if r.trim_count != TRIM_CULLED {
            let map = if adaptive && r.kind == PATCH_KIND_BEZIER {
                &mut view_adaptive
            } else {
                &mut fixed
            };
            map.entry(PipelineKey::of(r)).or_default().push(k as u32);
        }
    }
    (fixed, view_adaptive)
}

/// GPU buffers of a scene's patches at one tessellation.
pub struct PatchGeometry {
    control_points: wgpu::Buffer,
    /// Stencil pages 1, 2, … ([`super::stencil_pages`]): each begins with a copy of the points
    /// and blocks at the start of `control_points`, which every upload there also updates.
    page_buffers: Vec<wgpu::Buffer>,
    control_index_buffer: wgpu::Buffer,
    record_buffer: wgpu::Buffer,
    trim_buffer: wgpu::Buffer,
    vertices: wgpu::Buffer,
    triangle_indices: wgpu::Buffer,
    groups: Vec<PatchGroup>,
    triangles_bind_group: wgpu::BindGroup,
    records: Vec<PatchRecord>,
    objects: Vec<ObjectRange>,
    /// What the control point buffer holds, to upload only the points an edit changed.
    uploaded: Vec<[f32; 4]>,
    /// Each object's lattice block as uploaded (its start in the control point buffer).
    lattices: Vec<Option<(u32, Vec<[f32; 4]>)>>,
    /// The control index buffer's contents (global pool indices, each record's block at its
    /// `control_offset`), to find the points an edit changed.
    control_indices: Vec<u32>,
    /// Records to evaluate in the next [`Self::encode`].
    dirty: Vec<bool>,
    vertex_count: u32,
    index_count: u32,
    quad_groups_x: u32,
    triangles_written: bool,
    /// The view-adaptive passes ([`Tessellation::Adaptive`]).
    adaptive: Option<AdaptivePass>,
    /// Whether the Bézier patches' vertices carry their curvature.
    curvature: bool,
}

/// The slots of a grid patch of `segments` per edge (stencil or substitute), checked against
/// the level range and the dispatch limit.
fn grid_slots(segments: u32, max_groups: u32) -> Result<u64, GpuError> {
    let slots = u64::from(segments + 1).pow(2);
    if !(1..=MAX_SEGMENTS).contains(&segments) || workgroups(slots) > u64::from(max_groups) {
        return Err(GpuError::SegmentsOutOfRange {
            segments,
            max: MAX_SEGMENTS,
        });
    }
    Ok(slots)
}

/// The record kind of a substitute patch.
pub(crate) fn substitute_record_kind(kind: SubstituteKind) -> u32 {
    match kind {
        SubstituteKind::Acc => PATCH_KIND_ACC,
        SubstituteKind::Gregory => PATCH_KIND_GREGORY,
        SubstituteKind::PnTriangle => PATCH_KIND_PN_TRIANGLE,
    }
}

/// Homogeneous control points (wx, wy, wz, w) in f32, as the shaders read them.
fn homogeneous_points(set: &BezierPatchSet) -> impl ExactSizeIterator<Item = [f32; 4]> + '_ {
    set.points().iter().zip(set.weights()).map(|(p, &w)| {
        let h = *p * w;
        [h.x as f32, h.y as f32, h.z as f32, w as f32]
    })
}

/// Workgroups of [`EVAL_WORKGROUP_SIZE`] covering `items`.
fn workgroups(items: u64) -> u64 {
    items.div_ceil(u64::from(EVAL_WORKGROUP_SIZE))
}

/// Workgroups evaluating `record`'s vertices: for a Bézier patch (`evaluate_vertices`) one
/// invocation per column and run of [`EVAL_GRID_ROWS`] rows, for a stencil patch
/// (`evaluate_stencil_vertices`) one per vertex.
fn vertex_groups(record: &PatchRecord) -> u32 {
    let rows = u64::from(record.segments_u + 1);
    let runs = if record.kind == PATCH_KIND_BEZIER {
        rows.div_ceil(u64::from(EVAL_GRID_ROWS))
    } else {
        rows
    };
    workgroups(runs * u64::from(record.segments_v + 1)) as u32
}

impl PatchGeometry {
    /// Uploads the patches of `objects` (object k's vertices carry `object = k`) for evaluation
    /// at their fixed segment counts. Checks the degrees, the levels and the device's buffer
    /// and dispatch limits; nothing is created when a check fails.
    pub fn new(
        device: &wgpu::Device,
        evaluator: &PatchEvaluator,
        objects: &[ObjectPatches<'_>],
    ) -> Result<Self, GpuError> {
        Self::with_tessellation(device, evaluator, objects, Tessellation::Fixed)
    }

    /// As [`Self::new`], tessellated as `tessellation` says.
    pub fn with_tessellation(
        device: &wgpu::Device,
        evaluator: &PatchEvaluator,
        objects: &[ObjectPatches<'_>],
        tessellation: Tessellation,
    ) -> Result<Self, GpuError> {
        let adaptive_room = match tessellation {
            Tessellation::Fixed => None,
            Tessellation::Adaptive { vertices } => Some(vertices.max(1)),
        };
        let limits = device.limits();
        let max_groups = limits.max_compute_workgroups_per_dimension;
        let PatchLayout {
            records,
            objects: ranges,
            mut control_indices,
            points,
            entry_data,
            stencil_start,
            lattices,
            trim_words,
            vertices: mut vertex_offset,
            indices: mut index_offset,
            quad_groups_x,
        } = PatchLayout::new(objects, adaptive_room.is_some(), max_groups)?;
        // Stencil entries beyond one binding go into pages, each behind its own copy of the
        // points and blocks.
        let capacity = (binding_limit(&limits) / 16) as usize;
        // The head of every page's buffer: the points, then the blocks (and, unpaged, the
        // entries), written straight into each mapped buffer rather than joined first.
        let pages = if points.len() + entry_data.len() > capacity {
            Some(super::stencil_pages::paginate(
                &records,
                &mut control_indices,
                (&entry_data, points.len()),
                points.len() + stencil_start,
                capacity,
            )?)
        } else {
            None
        };
        let head_entries = match pages {
            Some(_) => &entry_data[..stencil_start],
            None => &entry_data[..],
        };
        let head = [&points[..], head_entries];
        let head_len = points.len() + head_entries.len();
        let first_page = pages.as_ref().map_or(0, |p| p.entries[0].len());
        let point_bytes = (head_len + first_page) as u64 * 16;

        let (fixed_vertices, fixed_indices) = (vertex_offset, index_offset);
        if let Some(room) = adaptive_room {
            vertex_offset += u64::from(room);
            index_offset += 6 * u64::from(room);
        }
        let vertex_bytes = vertex_offset * std::mem::size_of::<SurfaceVertex>() as u64;
        let index_bytes = index_offset * 4;
        check_buffer_sizes(
            &limits,
            &[
                ("vertex", vertex_bytes),
                ("index", index_bytes),
                ("control point and stencil", point_bytes),
                ("trim", trim_words.len() as u64 * 4),
            ],
            index_offset,
        )?;

        let storage = wgpu::BufferUsages::STORAGE;
        // wgpu refuses bindings smaller than one element of the shader's array: an empty scene
        // still gets one zeroed element (the largest, a patch record).
        let one_element = std::mem::size_of::<PatchRecord>()
            .max(std::mem::size_of::<SurfaceVertex>())
            .max(16);
        let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            let zeros = vec![0u8; one_element];
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: if contents.is_empty() {
                    &zeros
                } else {
                    contents
                },
                usage,
            })
        };
        // The points and blocks, then (paged) the page's entries.
        let points_then = |label: &str, entries: &[[f32; 4]]| {
            let bytes = ((head_len + entries.len()) * 16).max(one_element);
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes as u64,
                usage: storage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: true,
            });
            {
                let mut view = buffer
                    .get_mapped_range_mut(..)
                    .map_err(|e| GpuError::Geometry(format!("a new buffer did not map: {e}")))?;
                let mut at = 0;
                for part in head.iter().chain([&entries]) {
                    let end = at + part.len() * 16;
                    view.slice(at..end)
                        .copy_from_slice(bytemuck::cast_slice(part));
                    at = end;
                }
            }
            buffer.unmap();
            Ok::<_, GpuError>(buffer)
        };
        let no_entries: &[[f32; 4]] = &[];
        let control_points = points_then(
            "control points",
            pages.as_ref().map_or(no_entries, |p| &p.entries[0]),
        )?;
        let control_index_buffer = init(
            "control indices",
            bytemuck::cast_slice(&control_indices),
            storage,
        );
        let record_buffer = init("patch records", bytemuck::cast_slice(&records), storage);
        let trim_buffer = init("trim loops", bytemuck::cast_slice(&trim_words), storage);
        let output = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(one_element as u64),
                usage: storage | wgpu::BufferUsages::COPY_SRC | usage,
                mapped_at_creation: false,
            })
        };
        let vertices = output("surface vertices", vertex_bytes, wgpu::BufferUsages::VERTEX);
        let triangle_indices = output("triangle indices", index_bytes, wgpu::BufferUsages::INDEX);

        // Page k's buffer: the head, then the page's entries (page 0 is `control_points`).
        let (page_buffers, record_page) = match pages {
            Some(pages) => {
                let buffers = pages.entries[1..]
                    .iter()
                    .map(|entries| points_then("stencil page", entries))
                    .collect::<Result<_, _>>()?;
                (buffers, pages.record_page)
            }
            None => (Vec::new(), vec![0; records.len()]),
        };
        let (by_key, adaptive_by_key) = records_by_key(&records, adaptive_room.is_some());
        let by_page = by_key.into_iter().flat_map(|(key, members)| {
            let mut pages: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
            for r in members {
                pages.entry(record_page[r as usize]).or_default().push(r);
            }
            pages
                .into_iter()
                .map(move |(page, members)| (key, page, members))
        });
        let groups = by_page
            .map(|(key, page, members)| {
                let list = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("patch list"),
                    size: members.len() as u64 * 4,
                    usage: storage | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                let points = match page {
                    0 => &control_points,
                    k => &page_buffers[k as usize - 1],
                };
                let bind_group = evaluator.bind_group(&[
                    (0, points),
                    (1, &control_index_buffer),
                    (2, &record_buffer),
                    (3, &vertices),
                    (5, &list),
                ]);
                PatchGroup {
                    key,
                    records: members,
                    list,
                    bind_group,
                }
            })
            .collect();
        let triangles_bind_group =
            evaluator.bind_group(&[(2, &record_buffer), (4, &triangle_indices)]);
        let adaptive = adaptive_room.map(|_| {
            let groups = adaptive_by_key.into_iter().collect();
            AdaptivePass::new(
                device,
                evaluator,
                SharedBuffers {
                    control_points: &control_points,
                    control_indices: &control_index_buffer,
                    records: &record_buffer,
                    vertices: &vertices,
                    triangle_indices: &triangle_indices,
                },
                groups,
                [
                    vertex_offset as u32,
                    index_offset as u32,
                    fixed_vertices as u32,
                    fixed_indices as u32,
                ],
            )
        });

        Ok(Self {
            control_points,
            page_buffers,
            control_index_buffer,
            record_buffer,
            trim_buffer,
            vertices,
            triangle_indices,
            groups,
            triangles_bind_group,
            dirty: vec![true; records.len()],
            records,
            objects: ranges,
            uploaded: points,
            lattices,
            control_indices,
            vertex_count: fixed_vertices as u32,
            index_count: fixed_indices as u32,
            quad_groups_x: quad_groups_x as u32,
            triangles_written: false,
            adaptive,
            curvature: true,
        })
    }

    fn object_range(&self, object: usize) -> Result<ObjectRange, GpuError> {
        self.objects
            .get(object)
            .copied()
            .ok_or(GpuError::NoSuchObject {
                object,
                count: self.objects.len(),
            })
    }

    /// Takes new control points and weights of object `object` (same count as at creation) and
    /// marks `patches` (the object's patch indices) for re-evaluation by the next
    /// [`Self::encode`]; with `None`, the patches with a changed control point. Uploads only the
    /// points that changed; returns how many.
    pub fn update_object(
        &mut self,
        queue: &wgpu::Queue,
        object: usize,
        set: &BezierPatchSet,
        patches: Option<&[usize]>,
    ) -> Result<usize, GpuError> {
        let range = self.object_range(object)?;
        if set.points().len() != range.point_count || set.patches().len() != range.bezier_count {
            return Err(GpuError::ControlPointCountChanged {
                expected: range.point_count,
                found: set.points().len(),
            });
        }
        let explicit = patches.is_some();
        let all: Vec<usize>;
        let patches = match patches {
            Some(p) => p,
            None => {
                all = (0..range.patch_count).collect();
                &all
            }
        };
        if let Some(&bad) = patches.iter().find(|&&p| p >= range.patch_count) {
            return Err(GpuError::NoSuchPatch {
                object,
                patch: bad,
                count: range.patch_count,
            });
        }
        let fresh: Vec<[f32; 4]> = homogeneous_points(set).collect();
        let mut changed = BTreeSet::new();
        // The cage points the stencil patches read.
        let mut cage_changed = false;
        for (local, point) in fresh.iter().enumerate().take(range.cage_points) {
            let global = range.first_point + local;
            if self.uploaded[global] != *point {
                changed.insert(global);
                cage_changed = true;
            }
        }
        for &p in patches {
            let record = range.first_patch + p;
            if p >= range.bezier_count {
                if explicit || cage_changed {
                    self.dirty[record] = true;
                }
                continue;
            }
            let r = &self.records[record];
            let block = (r.degree_u as usize + 1) * (r.degree_v as usize + 1);
            let first = r.control_offset as usize;
            let mut patch_changed = false;
            for &global in &self.control_indices[first..first + block] {
                let local = global as usize - range.first_point;
                if self.uploaded[global as usize] != fresh[local] {
                    changed.insert(global as usize);
                    patch_changed = true;
                }
            }
            // Named patches are always re-evaluated; otherwise only those whose points changed.
            if explicit || patch_changed {
                self.dirty[record] = true;
            }
        }
        // One write per run of consecutive changed points.
        let changed: Vec<usize> = changed.into_iter().collect();
        for run in changed.chunk_by(|a, b| b == &(a + 1)) {
            let (first, last) = (run[0], run[run.len() - 1]);
            for &g in run {
                self.uploaded[g] = fresh[g - range.first_point];
            }
            self.write_head(
                queue,
                first as u64,
                bytemuck::cast_slice(&self.uploaded[first..=last]),
            );
        }
        Ok(changed.len())
    }

    /// Takes object `object`'s lattice (with the degrees it had at creation, or none as then):
    /// uploads its block where it changed and marks the object's patches. Returns whether it
    /// changed.
    pub fn update_lattice(
        &mut self,
        queue: &wgpu::Queue,
        object: usize,
        lattice: Option<&crate::kernel::ffd::Lattice>,
    ) -> Result<bool, GpuError> {
        let range = self.object_range(object)?;
        let slot = &mut self.lattices[object];
        match (slot, lattice) {
            (None, None) => Ok(false),
            (Some((at, uploaded)), Some(lattice)) => {
                let block = packing::lattice_block(lattice);
                if block.len() != uploaded.len() {
                    return Err(GpuError::Geometry(
                        "the lattice's degrees changed without a rebuild".into(),
                    ));
                }
                if block == *uploaded {
                    return Ok(false);
                }
                let at = u64::from(*at);
                *uploaded = block.clone();
                self.write_head(queue, at, bytemuck::cast_slice(&block));
                self.dirty[range.first_patch..range.first_patch + range.patch_count].fill(true);
                Ok(true)
            }
            _ => Err(GpuError::Geometry(
                "a lattice was added or removed without a rebuild".into(),
            )),
        }
    }

    /// Writes `bytes` at vec4 `at` of the points and blocks: in the control point buffer and
    /// in every stencil page's copy.
    fn write_head(&self, queue: &wgpu::Queue, at: u64, bytes: &[u8]) {
        for buffer in std::iter::once(&self.control_points).chain(&self.page_buffers) {
            queue.write_buffer(buffer, at * 16, bytes);
        }
    }

    /// Marks every patch for re-evaluation.
    pub fn invalidate(&mut self) {
        self.dirty.fill(true);
    }

    /// Whether the next [`Self::encode`] has work to do.
    pub fn needs_evaluation(&self) -> bool {
        let dirty = self.dirty.iter().any(|&d| d);
        !self.triangles_written
            || dirty
            || self
                .adaptive
                .as_ref()
                .is_some_and(|a| a.needs_evaluation(dirty))
    }

    /// Whether the Bézier patches' vertices carry their curvature (K, H, k1, k2). Off, the
    /// compute pass skips the second derivatives and the fundamental forms, and the vertices
    /// carry 0 with [`super::records::VERTEX_NO_CURVATURE`]; a change re-evaluates everything.
    /// Subdivision stencil patches always carry theirs.
    pub fn set_vertex_curvature(&mut self, on: bool) {
        if self.curvature != on {
            self.curvature = on;
            self.invalidate();
        }
    }

    /// Whether the Bézier patches are tessellated for the view.
    pub fn is_adaptive(&self) -> bool {
        self.adaptive.is_some()
    }

    /// The view the next [`Self::encode`] tessellates the adaptive patches for (ignored by a
    /// fixed tessellation). Nothing adaptive is drawn before the first view.
    pub fn set_view(&mut self, target: AdaptiveTarget) {
        if let Some(adaptive) = &mut self.adaptive {
            adaptive.wanted = Some(target);
        }
    }

    /// While `frozen` (a drag lasts), edits re-evaluate only their patches at the levels last
    /// measured; everything is measured again after (see [`AdaptivePass::freeze_levels`]).
    pub fn freeze_levels(&mut self, frozen: bool) {
        if let Some(adaptive) = &mut self.adaptive {
            adaptive.freeze_levels(frozen);
        }
    }

    /// Call after submitting the encoder given to [`Self::encode`] (starts the asynchronous
    /// readback of the adaptive statistics).
    pub fn after_submit(&mut self) {
        if let Some(adaptive) = &mut self.adaptive {
            adaptive.after_submit();
        }
    }

    /// The adaptive tessellation's latest statistics, taking any that arrived.
    pub fn adaptive_stats(&mut self) -> Option<AdaptiveStats> {
        self.adaptive.as_mut().and_then(AdaptivePass::stats)
    }

    /// The adaptive passes (tests, benchmarks).
    pub fn adaptive_pass(&mut self) -> Option<&mut AdaptivePass> {
        self.adaptive.as_mut()
    }

    /// Records one compute pass that evaluates the patches marked for it (all of them after
    /// creation or [`Self::invalidate`]) and, the first time, writes the triangle indices.
    /// Writes the patch lists through `queue`, so call it once per submission. `timestamps`
    /// brackets the pass for GPU timing. Returns the number of patches evaluated.
    pub fn encode(
        &mut self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        evaluator: &PatchEvaluator,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) -> u32 {
        let dirty = self.dirty.iter().any(|&d| d);
        let adaptive_due = self
            .adaptive
            .as_ref()
            .is_some_and(|a| a.needs_evaluation(dirty));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("evaluate patches"),
            timestamp_writes: timestamps,
        });
        if !self.triangles_written && !self.records.is_empty() {
            pass.set_pipeline(&evaluator.triangles_pipeline);
            pass.set_bind_group(0, &self.triangles_bind_group, &[]);
            pass.dispatch_workgroups(self.quad_groups_x, self.records.len() as u32, 1);
        }
        self.triangles_written = true;
        let mut evaluated = 0;
        for group in &self.groups {
            let list: Vec<u32> = group
                .records
                .iter()
                .copied()
                .filter(|&r| self.dirty[r as usize])
                .collect();
            if list.is_empty() {
                continue;
            }
            let groups_x = list
                .iter()
                .map(|&r| vertex_groups(&self.records[r as usize]))
                .max()
                .unwrap_or(1);
            queue.write_buffer(&group.list, 0, bytemuck::cast_slice(&list));
            let pipeline = evaluator.eval_pipeline(group.key, "evaluate_vertices", self.curvature);
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group.bind_group, &[]);
            pass.dispatch_workgroups(groups_x, list.len() as u32, 1);
            evaluated += list.len() as u32;
        }
        if let Some(adaptive) = self.adaptive.as_mut().filter(|_| adaptive_due) {
            evaluated += adaptive.encode(queue, &mut pass, evaluator, self.curvature, &self.dirty);
            drop(pass);
            adaptive.record_readback(encoder);
        }
        self.dirty.fill(false);
        evaluated
    }

    /// What the renderer draws: the vertex and index buffers the compute pass writes.
    pub fn surface_buffers(&self) -> SurfaceBuffers<'_> {
        SurfaceBuffers {
            vertices: &self.vertices,
            indices: &self.triangle_indices,
            index_count: self.index_count,
            patches: Some(PatchBuffers {
                records: &self.record_buffer,
                trims: &self.trim_buffer,
                control_points: &self.control_points,
                control_indices: &self.control_index_buffer,
            }),
            trimmed: self.records.iter().any(|r| r.trim_count == TRIM_PARTIAL),
            indirect: self.adaptive.as_ref().map(AdaptivePass::draw_arguments),
            curves: None,
        }
    }

    /// Every patch record, objects in order.
    pub fn records(&self) -> &[PatchRecord] {
        &self.records
    }

    /// The record index of object `object`'s first patch.
    pub fn first_patch(&self, object: usize) -> Option<usize> {
        self.objects.get(object).map(|o| o.first_patch)
    }

    pub fn patch_count(&self) -> u32 {
        self.records.len() as u32
    }

    pub fn control_point_count(&self) -> u32 {
        self.uploaded.len() as u32
    }

    /// Vertices written: the fixed patches', plus the adaptive ones' as the latest statistics
    /// say.
    pub fn vertex_count(&self) -> u32 {
        match self.adaptive.as_ref().and_then(AdaptivePass::latest_stats) {
            Some(stats) => stats.vertices,
            None => self.vertex_count,
        }
    }

    /// Triangle indices written (see [`Self::vertex_count`]).
    pub fn index_count(&self) -> u32 {
        match self.adaptive.as_ref().and_then(AdaptivePass::latest_stats) {
            Some(stats) => stats.indices,
            None => self.index_count,
        }
    }

    /// Bytes of GPU memory the geometry holds: control points (and stencil pages), indices,
    /// records, trims, vertices, triangles and the patch lists.
    pub fn buffer_bytes(&self) -> u64 {
        [
            &self.control_points,
            &self.control_index_buffer,
            &self.record_buffer,
            &self.trim_buffer,
            &self.vertices,
            &self.triangle_indices,
        ]
        .iter()
        .map(|b| b.size())
        .chain(self.page_buffers.iter().map(wgpu::Buffer::size))
        .chain(self.groups.iter().map(|g| g.list.size()))
        .sum::<u64>()
            + self.adaptive.as_ref().map_or(0, AdaptivePass::buffer_bytes)
    }

    /// Evaluates points, `samples` giving a patch record and local (s, t) each (blocking; the
    /// `eval --backend gpu` command and tests). Derivatives are with respect to (s, t).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn evaluate_points(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        evaluator: &PatchEvaluator,
        samples: &[super::records::PointSample],
    ) -> Result<Vec<super::records::PointResult>, GpuError> {
        if samples.is_empty() {
            return Ok(Vec::new());
        }
        let (results, size) = self.dispatch_points(device, queue, evaluator, samples)?;
        let bytes = super::readback::read_buffer(device, queue, &results, size)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// Submits the evaluation of `samples` ([`Self::evaluate_points`]) without waiting for it:
    /// the buffer its [`super::records::PointResult`]s are written to (`COPY_SRC`, one per
    /// sample, in order) and its size in bytes. Refuses an empty list.
    pub fn dispatch_points(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        evaluator: &PatchEvaluator,
        samples: &[super::records::PointSample],
    ) -> Result<(wgpu::Buffer, u64), GpuError> {
        if samples.is_empty() {
            return Err(GpuError::Readback("no points to evaluate".to_owned()));
        }
        if let Some(bad) = samples
            .iter()
            .find(|s| s.patch_index as usize >= self.records.len())
        {
            return Err(GpuError::NoSuchPatch {
                object: 0,
                patch: bad.patch_index as usize,
                count: self.records.len(),
            });
        }
        let groups = workgroups(samples.len() as u64);
        let max = device.limits().max_compute_workgroups_per_dimension;
        if groups > u64::from(max) {
            return Err(GpuError::TooManyPatches {
                count: samples.len(),
                max: max * EVAL_WORKGROUP_SIZE,
            });
        }
        let size = samples.len() as u64 * std::mem::size_of::<super::records::PointResult>() as u64;
        let sample_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("point samples"),
            contents: bytemuck::cast_slice(samples),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let results = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("point results"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind = evaluator.bind_group(&[
            (0, &self.control_points),
            (1, &self.control_index_buffer),
            (2, &self.record_buffer),
            (6, &sample_buffer),
            (7, &results),
        ]);
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&evaluator.samples_pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(groups as u32, 1, 1);
        }
        queue.submit([encoder.finish()]);
        Ok((results, size))
    }

    /// Reads the evaluated vertices back (blocking; tests, benchmarks, CLI).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_vertices(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<SurfaceVertex>, GpuError> {
        super::readback::read_elements(device, queue, &self.vertices, self.vertex_count())
    }

    /// Reads the triangle indices back (blocking; tests, benchmarks, CLI).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_triangle_indices(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<u32>, GpuError> {
        super::readback::read_elements(device, queue, &self.triangle_indices, self.index_count())
    }
}
