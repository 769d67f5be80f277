//! The CPU evaluator, for devices without compute shaders (WebGL2, wgpu's GL backend): the f64
//! kernel evaluates the same patch records as `shaders/eval_bezier.wgsl` (same record layout,
//! same vertex and triangle layout, [`PatchLayout`]) and the result, rounded to f32, is uploaded
//! into the vertex and index buffers the renderer draws. Only the patches an edit touches are
//! evaluated again, as on the GPU.
//!
//! Differences from the compute path: positions and derivatives are computed in f64 (so shared
//! edges agree to f32 rounding rather than bit for bit), the curvature of a degenerate point is
//! sampled at the kernel's [`CURVATURE_NUDGE`], and a trimmed patch is trimmed per triangle (a
//! triangle whose centre lies outside the kept region is dropped) instead of per fragment.

use glam::DVec3;
use wgpu::util::DeviceExt;

use super::error::GpuError;
use super::patch_eval::{
    ObjectDisplacement, ObjectPatches, ObjectRange, PatchLayout, SurfaceBuffers,
};
use super::records::{
    PATCH_KIND_BEZIER, PatchRecord, SurfaceVertex, VERTEX_IRREGULAR, VERTEX_NO_CURVATURE,
    is_triangle_lattice,
};
use super::trim_buffer::{TRIM_CULLED, TRIM_PARTIAL};
use crate::kernel::BezierPatchSet;
use crate::kernel::diffgeo::{
    CURVATURE_NUDGE, CurvatureValues, FundamentalForms, SurfaceDerivatives,
};
use crate::kernel::ffd::Lattice;
use crate::kernel::subdiv::patches::LimitFeed;
use crate::kernel::subdiv::substitutes;
use crate::kernel::trim::index::TrimIndex;
use crate::scene::Decomposition;

/// A scene's patches evaluated on the CPU into GPU vertex and index buffers.
pub struct CpuGeometry {
    vertices: wgpu::Buffer,
    triangle_indices: wgpu::Buffer,
    records: Vec<PatchRecord>,
    objects: Vec<ObjectRange>,
    control_point_count: u32,
    /// Records to evaluate in the next [`Self::evaluate`].
    dirty: Vec<bool>,
    vertex_count: u32,
    index_count: u32,
    /// Whether the Bézier patches' vertices carry their curvature.
    curvature: bool,
    /// The vertices of the records being written, reused between evaluations.
    scratch: Vec<SurfaceVertex>,
    /// Each object's displacement.
    displacements: Vec<Option<ObjectDisplacement>>,
    /// Each object's free-form deformation lattice.
    lattices: Vec<Option<Lattice>>,
}

/// The curvature (K, H, k1, k2) from derivatives `d` and unit normal `n`, if defined.
fn curvature_of(d: &SurfaceDerivatives, n: DVec3) -> Option<[f32; 4]> {
    CurvatureValues::from_forms(&FundamentalForms::new(d, n))
        .map(|c| [c.gaussian, c.mean, c.k1, c.k2].map(|x| x as f32))
        .filter(|c| c.iter().all(|x| x.is_finite()))
}

/// The record a CPU evaluation writes: the record, its index and its object's displacement
/// and lattice.
#[derive(Clone, Copy)]
struct Target<'a> {
    record: &'a PatchRecord,
    index: u32,
    displacement: Option<&'a ObjectDisplacement>,
    lattice: Option<&'a Lattice>,
}

/// One vertex of a record's grid: its position, normal, curvature and flags, with (u, v) mapped
/// into the record's domain (`store_vertex` in `shaders/eval_bezier.wgsl`).
fn grid_vertex(
    target: Target<'_>,
    (s, t): (f64, f64),
    d: &SurfaceDerivatives,
    normal: DVec3,
    curvature: Option<[f32; 4]>,
    flags: u32,
) -> SurfaceVertex {
    let Target {
        record,
        index,
        displacement,
        lattice,
    } = target;
    let [u0, u1, v0, v1] = record.domain.map(f64::from);
    // A displaced vertex: the displaced point and normal, no curvature (as `store_vertex`).
    let (point, normal, curvature) = match displacement {
        Some(map) => {
            let (p, n) = map.apply(record, d, d.point, normal, (s, t));
            (p, n, None)
        }
        None => (d.point, normal, curvature),
    };
    // Then through the lattice: the point mapped, the normal by the Jacobian's cofactor, the
    // curvature of the deformed derivatives where it was defined (`lattice_deform`).
    let (point, normal, curvature) = match lattice {
        Some(lattice) => {
            let (deformed, moved) =
                lattice.deform_with_normal(&SurfaceDerivatives { point, ..*d }, normal);
            let curvature = curvature.and_then(|_| curvature_of(&deformed, moved));
            (deformed.point, moved, curvature)
        }
        None => (point, normal, curvature),
    };
    let position = point.as_vec3().to_array();
    let finite = position.iter().all(|x| x.is_finite());
    SurfaceVertex::new(
        if finite { position } else { [0.0; 3] },
        (
            (u0 * (1.0 - s) + u1 * s) as f32,
            (v0 * (1.0 - t) + v1 * t) as f32,
        ),
        normal.as_vec3().to_array(),
        curvature.unwrap_or([0.0; 4]),
        record.object,
        flags
            | if curvature.is_none() {
                VERTEX_NO_CURVATURE
            } else {
                0
            },
        index,
        record.level,
    )
}

/// Grid point k of a record: (i, j) row-major with i along u, and local (s, t).
fn grid_point(record: &PatchRecord, k: u32) -> (f64, f64) {
    let nv = record.segments_v + 1;
    let (i, j) = (k / nv, k % nv);
    (
        f64::from(i) / f64::from(record.segments_u),
        f64::from(j) / f64::from(record.segments_v),
    )
}

/// The vertices of Bézier patch `patch` of `set` (`target`), as `evaluate_vertices` writes
/// them: Su × Sv and the curvature at regular points; at degenerate ones the kernel's limit
/// normal ([`BezierPatchSet::normal_from`]) and the curvature [`CURVATURE_NUDGE`] inward.
fn bezier_vertices(
    set: &BezierPatchSet,
    patch: usize,
    target: Target<'_>,
    with_curvature: bool,
    out: &mut Vec<SurfaceVertex>,
) -> Result<(), GpuError> {
    let record = target.record;
    let geometry = |e: crate::kernel::GeometryError| GpuError::Geometry(e.to_string());
    let bezier = set.patches().get(patch).ok_or(GpuError::NoSuchPatch {
        object: record.object as usize,
        patch,
        count: set.patches().len(),
    })?;
    let count = (record.segments_u + 1) * (record.segments_v + 1);
    for k in 0..count {
        let (s, t) = grid_point(record, k);
        let d = set.evaluate(patch, s, t).map_err(geometry)?;
        let (normal, curvature, flags) = match d.regular_normal() {
            Some(n) => (n, with_curvature.then(|| curvature_of(&d, n)).flatten(), 0),
            None => {
                let n = set.normal_from(bezier, &d, s, t);
                let (sn, tn) = (
                    s + (0.5 - s) * CURVATURE_NUDGE,
                    t + (0.5 - t) * CURVATURE_NUDGE,
                );
                let inside = set.evaluate(patch, sn, tn).map_err(geometry)?;
                let k = with_curvature
                    .then(|| curvature_of(&inside, set.normal_from(bezier, &inside, sn, tn)))
                    .flatten();
                (n, k, VERTEX_IRREGULAR)
            }
        };
        out.push(grid_vertex(target, (s, t), &d, normal, curvature, flags));
    }
    Ok(())
}

/// The vertices of stencil patch `patch` of `feed` (`target`) over the cage `points`, as
/// `evaluate_stencil_vertices` writes them: each slot's position and derivatives gathered from
/// its stencil entries, then the normal and, where the stencils define it, the curvature.
fn stencil_vertices(
    feed: &LimitFeed,
    points: &[DVec3],
    patch: usize,
    target: Target<'_>,
    out: &mut Vec<SurfaceVertex>,
) -> Result<(), GpuError> {
    let record = target.record;
    let missing = || GpuError::Geometry(format!("stencil patch {patch} refers past its tables"));
    let stencil = feed.patches.get(patch).ok_or_else(missing)?;
    let first = stencil.first_slot as usize;
    let count = ((record.segments_u + 1) * (record.segments_v + 1)) as usize;
    for k in 0..count {
        let slot = first + k;
        let entries = feed.slot_entries(stencil, slot).ok_or_else(missing)?;
        let mut d = SurfaceDerivatives::default();
        for (point, w) in entries {
            let p = *points.get(point as usize).ok_or_else(missing)?;
            d.point += w[0] * p;
            d.su += w[1] * p;
            d.sv += w[2] * p;
            d.suu += w[3] * p;
            d.suv += w[4] * p;
            d.svv += w[5] * p;
        }
        let no_curvature = feed.no_curvature.get(slot).copied().unwrap_or(true);
        let (normal, curvature, flags) = match d.regular_normal() {
            None => (DVec3::Z, None, VERTEX_IRREGULAR),
            Some(n) if no_curvature => (n, None, 0),
            Some(n) => (n, curvature_of(&d, n), 0),
        };
        let st = grid_point(record, k as u32);
        out.push(grid_vertex(target, st, &d, normal, curvature, flags));
    }
    Ok(())
}

/// The vertices of substitute patch `patch` of `feed` (`target`) from its control points
/// in `points`, as `write_substitute_vertex` writes them: the position, the substitute's own
/// normal and the curvature of its geometry.
fn substitute_vertices(
    feed: &LimitFeed,
    points: &[DVec3],
    patch: usize,
    target: Target<'_>,
    out: &mut Vec<SurfaceVertex>,
) -> Result<(), GpuError> {
    let record = target.record;
    let missing = || GpuError::Geometry(format!("substitute patch {patch} refers past its points"));
    let sub = feed.substitutes.get(patch).ok_or_else(missing)?;
    let first = sub.first_point as usize;
    let control = points
        .get(first..first + sub.kind.point_count())
        .ok_or_else(missing)?;
    let count = (record.segments_u + 1) * (record.segments_v + 1);
    for k in 0..count {
        let st = grid_point(record, k);
        let sample = substitutes::evaluate(sub.kind, control, st.0, st.1);
        let d = sample.derivatives;
        // The curvature of the geometry, with its own normal Su × Sv.
        let geometric = d.regular_normal();
        let curvature = geometric
            .filter(|_| sample.curvature_defined)
            .and_then(|g| curvature_of(&d, g));
        let (normal, flags) = match (sample.normal, geometric) {
            (n, _) if n != DVec3::ZERO => (n, 0),
            (_, Some(g)) => (g, 0),
            (_, None) => (DVec3::Z, VERTEX_IRREGULAR),
        };
        out.push(grid_vertex(target, st, &d, normal, curvature, flags));
    }
    Ok(())
}

/// The triangle indices of one record (`write_triangles` in `shaders/eval_grid.wgsl`): two
/// counter-clockwise triangles per grid quad, the lattice i + j ≤ n of a triangular stencil
/// patch (unused corners degenerate), and on a patch a trim loop crosses, degenerate triangles
/// where the triangle's centre (in the surface's domain) is trimmed away by `trims`.
fn record_indices(
    record: &PatchRecord,
    trims: Option<&TrimIndex>,
    domain_point: impl Fn(u32, u32) -> (f64, f64),
    out: &mut Vec<u32>,
) {
    let (n, m) = (record.segments_u, record.segments_v);
    let nv = m + 1;
    let kept = |corners: [(u32, u32); 3]| match trims {
        Some(index) if record.trim_count == TRIM_PARTIAL => {
            let (mut u, mut v) = (0.0, 0.0);
            for (i, j) in corners {
                let (a, b) = domain_point(i, j);
                u += a / 3.0;
                v += b / 3.0;
            }
            index.contains(u, v)
        }
        _ => true,
    };
    // Corners of the two triangles of a cell, as (di, dj): a = (0, 0), b = (1, 0), c = (1, 1),
    // d = (0, 1).
    let triangle_lattice = is_triangle_lattice(record.kind);
    let shapes: [[(u32, u32); 3]; 2] = if triangle_lattice {
        [[(0, 0), (1, 0), (0, 1)], [(1, 0), (1, 1), (0, 1)]]
    } else {
        [[(0, 0), (1, 0), (1, 1)], [(0, 0), (1, 1), (0, 1)]]
    };
    for i in 0..n {
        for j in 0..m {
            // The triangular lattice keeps i + j <= n: its lower and upper triangles inside.
            let inside = [
                !triangle_lattice || i + j < n,
                !triangle_lattice || i + j + 2 <= n,
            ];
            let a = record.vertex_offset + i * nv + j;
            for (shape, inside) in shapes.iter().zip(inside) {
                let corners = shape.map(|(di, dj)| (i + di, j + dj));
                if inside && kept(corners) {
                    out.extend(corners.map(|(ci, cj)| record.vertex_offset + ci * nv + cj));
                } else {
                    out.extend([a; 3]);
                }
            }
        }
    }
}

impl CpuGeometry {
    /// Lays out the patches of `objects` as [`super::PatchGeometry::new`] does (fixed levels),
    /// writes the triangle indices and creates the vertex buffer; the vertices are written by
    /// the first [`Self::evaluate`]. Checks the degrees, the levels and the device's buffer
    /// size; nothing is created when a check fails.
    pub fn new(device: &wgpu::Device, objects: &[ObjectPatches<'_>]) -> Result<Self, GpuError> {
        let layout = PatchLayout::new(objects, false, u32::MAX)?;
        let limit = device.limits().max_buffer_size;
        let vertex_bytes = layout.vertices * std::mem::size_of::<SurfaceVertex>() as u64;
        let index_bytes = layout.indices * 4;
        for (what, bytes) in [("vertex", vertex_bytes), ("index", index_bytes)] {
            if bytes > limit || layout.indices > u64::from(u32::MAX) / 2 {
                return Err(GpuError::BufferTooLarge { what, bytes, limit });
            }
        }
        let mut indices = Vec::with_capacity(layout.indices as usize);
        // Each object's records come in its patches' order: count them to know the patch.
        let mut next_patch = vec![0usize; objects.len()];
        for record in &layout.records {
            let patch = next_patch
                .get_mut(record.object as usize)
                .map_or(0, |k| std::mem::replace(k, *k + 1));
            if record.trim_count == TRIM_CULLED {
                continue;
            }
            let trims = objects
                .get(record.object as usize)
                .and_then(|o| o.trims)
                .and_then(|t| t.index_for(patch));
            let [u0, u1, v0, v1] = record.domain.map(f64::from);
            let (n, m) = (
                f64::from(record.segments_u.max(1)),
                f64::from(record.segments_v.max(1)),
            );
            let point = |i: u32, j: u32| {
                let (s, t) = (f64::from(i) / n, f64::from(j) / m);
                (u0 + (u1 - u0) * s, v0 + (v1 - v0) * t)
            };
            record_indices(record, trims, point, &mut indices);
        }
        let vertices = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("surface vertices (CPU evaluated)"),
            size: vertex_bytes.max(4),
            usage: wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let triangle_indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("triangle indices (CPU)"),
            contents: if indices.is_empty() {
                &[0; 4]
            } else {
                bytemuck::cast_slice(&indices)
            },
            usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_SRC,
        });
        Ok(Self {
            vertices,
            triangle_indices,
            dirty: vec![true; layout.records.len()],
            control_point_count: layout.points.len() as u32,
            records: layout.records,
            objects: layout.objects,
            vertex_count: layout.vertices as u32,
            index_count: indices.len() as u32,
            curvature: true,
            scratch: Vec::new(),
            displacements: objects.iter().map(|o| o.displacement.clone()).collect(),
            lattices: objects.iter().map(|o| o.lattice.cloned()).collect(),
        })
    }

    /// Takes object `object`'s lattice and marks its patches where it changed (see
    /// [`super::PatchGeometry::update_lattice`]).
    pub fn update_lattice(
        &mut self,
        object: usize,
        lattice: Option<&Lattice>,
    ) -> Result<(), GpuError> {
        let slot = self
            .lattices
            .get_mut(object)
            .ok_or(GpuError::NoSuchObject {
                object,
                count: self.objects.len(),
            })?;
        if slot.as_ref() != lattice {
            *slot = lattice.cloned();
            self.update_object(object, None)?;
        }
        Ok(())
    }

    /// Marks `patches` of object `object` (`None`: all of them, stencil patches included) for
    /// the next [`Self::evaluate`], which reads the points from the feeds it is given.
    pub fn update_object(
        &mut self,
        object: usize,
        patches: Option<&[usize]>,
    ) -> Result<(), GpuError> {
        let range = self
            .objects
            .get(object)
            .copied()
            .ok_or(GpuError::NoSuchObject {
                object,
                count: self.objects.len(),
            })?;
        let first = range.first_patch;
        let Some(patches) = patches else {
            self.dirty[first..first + range.patch_count].fill(true);
            return Ok(());
        };
        if let Some(&bad) = patches.iter().find(|&&p| p >= range.patch_count) {
            return Err(GpuError::NoSuchPatch {
                object,
                patch: bad,
                count: range.patch_count,
            });
        }
        for &p in patches {
            self.dirty[first + p] = true;
        }
        Ok(())
    }

    /// Marks every patch for re-evaluation.
    pub fn invalidate(&mut self) {
        self.dirty.fill(true);
    }

    /// Whether the next [`Self::evaluate`] has work to do.
    pub fn needs_evaluation(&self) -> bool {
        self.dirty.iter().any(|&d| d)
    }

    /// See [`super::PatchGeometry::set_vertex_curvature`].
    pub fn set_vertex_curvature(&mut self, on: bool) {
        if self.curvature != on {
            self.curvature = on;
            self.invalidate();
        }
    }

    /// Evaluates the marked records from `feeds` (the objects' Bézier patches and stencil
    /// tables, as laid out at creation) and uploads their vertices, one write per run of
    /// consecutive records. Returns the number of patches evaluated.
    pub fn evaluate(
        &mut self,
        queue: &wgpu::Queue,
        feeds: &[Decomposition],
    ) -> Result<u32, GpuError> {
        let mut evaluated = 0;
        let mut k = 0;
        while k < self.records.len() {
            if !self.dirty[k] || self.records[k].trim_count == TRIM_CULLED {
                k += 1;
                continue;
            }
            // A run of consecutive dirty records shares one upload.
            let first = self.records[k].vertex_offset;
            self.scratch.clear();
            while k < self.records.len()
                && self.dirty[k]
                && self.records[k].trim_count != TRIM_CULLED
            {
                self.evaluate_record(k, feeds)?;
                self.dirty[k] = false;
                evaluated += 1;
                k += 1;
            }
            queue.write_buffer(
                &self.vertices,
                u64::from(first) * std::mem::size_of::<SurfaceVertex>() as u64,
                bytemuck::cast_slice(&self.scratch),
            );
        }
        self.dirty.fill(false);
        Ok(evaluated)
    }

    /// Appends the vertices of record `k` to the scratch buffer.
    fn evaluate_record(&mut self, k: usize, feeds: &[Decomposition]) -> Result<(), GpuError> {
        let record = self.records[k];
        let object = record.object as usize;
        let range = self.objects[object];
        let feed = feeds.get(object).ok_or(GpuError::NoSuchObject {
            object,
            count: feeds.len(),
        })?;
        let local = k - range.first_patch;
        let target = Target {
            record: &record,
            index: k as u32,
            displacement: self.displacements.get(object).and_then(Option::as_ref),
            lattice: self.lattices.get(object).and_then(Option::as_ref),
        };
        if record.kind == PATCH_KIND_BEZIER {
            bezier_vertices(&feed.set, local, target, self.curvature, &mut self.scratch)
        } else {
            let tables = feed
                .stencils
                .as_deref()
                .ok_or_else(|| GpuError::Geometry("a stencil patch without tables".into()))?;
            let stencil = local - range.bezier_count;
            if let Some(which) = stencil.checked_sub(tables.patches.len()) {
                return substitute_vertices(
                    tables,
                    feed.set.points(),
                    which,
                    target,
                    &mut self.scratch,
                );
            }
            stencil_vertices(
                tables,
                feed.set.points(),
                stencil,
                target,
                &mut self.scratch,
            )
        }
    }

    /// What the renderer draws: the vertex and index buffers (no patch data: the renderer's
    /// GL pipeline shades from the vertices alone).
    pub fn surface_buffers(&self) -> SurfaceBuffers<'_> {
        SurfaceBuffers {
            vertices: &self.vertices,
            indices: &self.triangle_indices,
            index_count: self.index_count,
            patches: None,
            trimmed: false,
            indirect: None,
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
        self.control_point_count
    }

    pub fn vertex_count(&self) -> u32 {
        self.vertex_count
    }

    pub fn index_count(&self) -> u32 {
        self.index_count
    }

    /// Bytes of GPU memory the geometry holds (vertices and triangle indices).
    pub fn buffer_bytes(&self) -> u64 {
        self.vertices.size() + self.triangle_indices.size()
    }

    /// Reads the uploaded vertices back (blocking; tests, benchmarks).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_vertices(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<SurfaceVertex>, GpuError> {
        super::readback::read_elements(device, queue, &self.vertices, self.vertex_count)
    }

    /// Reads the triangle indices back (blocking; tests).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_triangle_indices(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<u32>, GpuError> {
        super::readback::read_elements(device, queue, &self.triangle_indices, self.index_count)
    }
}
