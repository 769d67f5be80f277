//! The conformance test every kind of scene object passes, run for every kind in the
//! registry ([`registry::kinds`]) on the examples each kind registers, with no list here: a
//! new kind registers itself and is checked like the rest. [`QuadraticSheet`] below is a kind
//! defined in this test module alone, registered at run time, to show that a kind needs no
//! other edit. The checks:
//!
//! 1. its GPU feed (the patches it hands the evaluator) reproduces the kind's own f64
//!    definition ([`ObjectKind::surface_point`]) to 1e-12 of its size, and its faces (the one
//!    surface interface) do too, with derivatives that agree with differences of points;
//! 2. the compute shaders, reached through the editor's sync layer, reproduce it to 1e-5;
//! 3. a drag through the document (the editor's transient edit) re-evaluates only the support
//!    the kind reports, gives bit for bit what a full evaluation of the moved object gives and
//!    still matches the f64 definition; committing makes one undo step, and undoing it brings
//!    back the document and every GPU vertex bit for bit;
//! 4. a project file with it reads back equal;
//! 5. it exports to glTF with triangles inside its control points' box, and the export reopens
//!    as the same object.

use crate::common;

use glam::{DAffine3, DVec3};
use knotwork::doc::{Command, Document, Touched};
use knotwork::gpu::records::CurveVertex;
use knotwork::gpu::{GpuContext, SceneSync, SurfaceVertex};
use knotwork::io::gltf::{self, ExportOptions};
use knotwork::io::project::{self, Project};
use knotwork::kernel::ffd::{Baked, Lattice};
use knotwork::kernel::parametric::PatchFace;
use knotwork::kernel::subdiv::{Options, SubdivisionSurface};
use knotwork::kernel::tess::{Tessellation, TriangleMesh};
use knotwork::kernel::{BezierPatch, BezierPatchSet, GeometryError, NurbsSurface, PolygonMesh};
use knotwork::scene::json::FormatError;
use knotwork::scene::polysurface::Polysurface;
use knotwork::scene::registry::{self, KindEntry};
use knotwork::scene::{Decomposition, KindFace, ObjectGeometry, ObjectKind, Scene, SceneObject};

/// A kind that lives only in this test: a biquadratic Bézier sheet of 3 × 3 points (row-major,
/// i along u), evaluated by its own Bernstein sums, written to projects as
/// `{"type": "quadratic_sheet", "points": [[x, y, z] × 9]}`.
#[derive(Debug, Clone, PartialEq)]
struct QuadraticSheet {
    points: [DVec3; 9],
}

/// The quadratic Bernstein polynomials at t (The NURBS Book, eq. 1.8).
fn bernstein2(t: f64) -> [f64; 3] {
    [(1.0 - t) * (1.0 - t), 2.0 * t * (1.0 - t), t * t]
}

impl QuadraticSheet {
    fn patch_set(&self) -> Result<BezierPatchSet, GeometryError> {
        BezierPatchSet::new(
            self.points.to_vec(),
            None,
            vec![BezierPatch::new(2, 2, (0..9).collect())],
        )
    }
}

impl ObjectKind for QuadraticSheet {
    fn kind_name(&self) -> &'static str {
        "a quadratic sheet"
    }

    fn describe(&self) -> String {
        "biquadratic sheet, 3 × 3 points".into()
    }

    fn control_point_count(&self) -> usize {
        9
    }

    fn control_points(&self) -> Vec<DVec3> {
        self.points.to_vec()
    }

    fn weights(&self) -> Vec<f64> {
        vec![1.0; 9]
    }

    fn net_lines(&self) -> Vec<u32> {
        let mut lines = Vec::new();
        for i in 0..3u32 {
            for j in 0..2u32 {
                lines.extend([3 * i + j, 3 * i + j + 1, 3 * j + i, 3 * (j + 1) + i]);
            }
        }
        lines
    }

    fn net_grid(&self) -> Option<[usize; 2]> {
        Some([3, 3])
    }

    fn bounds(&self) -> Option<(DVec3, DVec3)> {
        knotwork::scene::points_box(self.points)
    }

    fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError> {
        if index >= 9 || !position.is_finite() {
            return Err(GeometryError::Construction {
                what: "quadratic sheet",
                message: format!("no point {index} at {position}"),
            });
        }
        self.points[index] = position;
        Ok(vec![0])
    }

    fn set_weight(&mut self, _index: usize, _weight: f64) -> Result<(), GeometryError> {
        Err(GeometryError::Construction {
            what: "quadratic sheet",
            message: "its points have no weights".into(),
        })
    }

    fn gpu_feed(&self) -> Result<Decomposition, GeometryError> {
        Ok(Decomposition {
            set: self.patch_set()?,
            domains: vec![[0.0, 1.0, 0.0, 1.0]],
            ..Default::default()
        })
    }

    fn surface_point(&self, patch: usize, s: f64, t: f64) -> Result<DVec3, GeometryError> {
        if patch != 0 {
            return Err(GeometryError::Construction {
                what: "quadratic sheet",
                message: format!("no patch {patch}"),
            });
        }
        let (bs, bt) = (bernstein2(s), bernstein2(t));
        Ok((0..9).map(|k| self.points[k] * bs[k / 3] * bt[k % 3]).sum())
    }

    fn update_gpu_feed(
        &self,
        feed: &mut Decomposition,
        _patches: &[usize],
    ) -> Result<(), GeometryError> {
        feed.sync_points(&self.points)
    }

    fn tessellate(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        knotwork::kernel::tess::tessellate_patches(&self.patch_set()?, tessellation, curvature)
    }

    fn faces(&self) -> Vec<KindFace<'_>> {
        self.patch_set()
            .map(|set| KindFace::whole(PatchFace { set, patch: 0 }))
            .into_iter()
            .collect()
    }

    fn transformed(&self, transform: &DAffine3) -> Result<ObjectGeometry, GeometryError> {
        Ok(ObjectGeometry::new(Self {
            points: self.points.map(|p| transform.transform_point3(p)),
        }))
    }

    fn bake_lattice(
        &self,
        _lattice: &Lattice,
        _tolerance: f64,
    ) -> Result<(ObjectGeometry, Baked), GeometryError> {
        Err(GeometryError::Construction {
            what: "quadratic sheet",
            message: "a lattice cannot be baked into it".into(),
        })
    }

    fn same_layout(&self, other: &ObjectGeometry) -> bool {
        other.downcast_ref::<Self>().is_some()
    }

    fn displacement_domain(&self) -> Option<[f64; 4]> {
        Some([0.0, 1.0, 0.0, 1.0])
    }

    fn nurbs_surface(&self) -> Option<&NurbsSurface> {
        None
    }

    fn cage(&self) -> Option<&PolygonMesh> {
        None
    }

    fn record(&self) -> serde_json::Value {
        serde_json::json!({
            "type": "quadratic_sheet",
            "points": self.points.iter().map(|p| p.to_array()).collect::<Vec<_>>(),
        })
    }
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SheetRecord {
    #[serde(rename = "type")]
    _kind: String,
    points: [[f64; 3]; 9],
}

fn read_sheet(path: &str, record: serde_json::Value) -> Result<ObjectGeometry, FormatError> {
    let raw: SheetRecord = registry::deserialize(path, record)?;
    let points = raw.points.map(DVec3::from_array);
    if !points.iter().all(|p| p.is_finite()) {
        return Err(FormatError::new(format!("{path}.points"), "not finite"));
    }
    Ok(ObjectGeometry::new(QuadraticSheet { points }))
}

/// A saddle-like sheet over [0, 2]² with its corner (i, j) at height z(i, j).
fn sheet(offset: DVec3, z: impl Fn(usize, usize) -> f64) -> QuadraticSheet {
    QuadraticSheet {
        points: std::array::from_fn(|k| {
            let (i, j) = (k / 3, k % 3);
            offset + DVec3::new(i as f64, j as f64, z(i, j))
        }),
    }
}

fn sheet_examples() -> Vec<SceneObject> {
    let saddle = sheet(DVec3::ZERO, |i, j| {
        0.4 * (i as f64 - 1.0) * (j as f64 - 1.0) + 0.1 * j as f64
    });
    vec![SceneObject::new(
        "quadratic sheet",
        ObjectGeometry::new(saddle),
    )]
}

/// Registers [`QuadraticSheet`] (once per test process).
fn register_sheet() {
    let entry = KindEntry {
        record_type: "quadratic_sheet",
        read: read_sheet,
        examples: sheet_examples,
    };
    match registry::register(entry) {
        Ok(()) | Err(registry::AlreadyRegistered(_)) => {}
    }
}

fn size(object: &SceneObject) -> f64 {
    let (lo, hi) = object.bounds().unwrap();
    (hi - lo).length()
}

/// Largest distance, over every vertex of object 0 on the GPU, from the kind's own f64 point
/// at that vertex's patch and (s, t), divided by the object's size.
fn gpu_deviation(sync: &SceneSync, vertices: &[SurfaceVertex], object: &SceneObject) -> f64 {
    let mut worst = 0.0f64;
    for (k, record) in sync.records().unwrap().iter().enumerate() {
        // A patch wholly trimmed away has no vertices.
        if record.trim_count == knotwork::gpu::trim_buffer::TRIM_CULLED {
            continue;
        }
        let n = record.segments_u as usize;
        for i in 0..=n {
            for j in 0..=n {
                let vertex = vertices[record.vertex_offset as usize + i * (n + 1) + j];
                let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                let exact = object.kind().surface_point(k, s, t).unwrap();
                let gpu = DVec3::from(vertex.position.map(f64::from));
                worst = worst.max(gpu.distance(exact));
            }
        }
    }
    worst / size(object)
}

/// `doc` evaluated by the compute shaders, or by the CPU evaluator of the WebGL2 path (`cpu`).
fn on_gpu(context: &GpuContext, doc: &Document, cpu: bool) -> (SceneSync, Vec<SurfaceVertex>) {
    let mut sync = if cpu {
        SceneSync::on_cpu(&context.device, &context.queue)
    } else {
        SceneSync::new(&context.device, &context.queue)
    };
    sync.rebuild(&doc.scene, 1.0).unwrap();
    sync.evaluate_blocking().unwrap();
    let vertices = sync.read_vertices().unwrap();
    (sync, vertices)
}

/// Steps 2 and 3 of [`conforms`] on one evaluator: the vertices against the kind's own f64
/// points, then a drag (only its support re-evaluated, the same vertices as a full evaluation)
/// and its undo (every vertex restored). Leaves `doc` as it found it.
fn drag_and_undo(
    context: &GpuContext,
    doc: &mut Document,
    object: &SceneObject,
    name: &str,
    cpu: bool,
) {
    let scale = size(object);
    let (mut sync, original_vertices) = on_gpu(context, doc, cpu);
    let deviation = gpu_deviation(&sync, &original_vertices, object);
    eprintln!("{name}: GPU vs f64 {deviation:.2e} of its size");
    assert!(deviation <= 1e-5, "{name}: {deviation:e}");

    // A drag and its undo.
    let index = object.control_point_count() / 2;
    doc.begin_drag(0, &[index]).unwrap();
    let mut support = Vec::new();
    for step in 1..=3 {
        let moved = doc
            .drag_by(DVec3::new(0.05, -0.03, 0.08) * scale * f64::from(step))
            .unwrap();
        sync.points_moved(&doc.scene, &moved).unwrap();
        let evaluated = sync.evaluate_blocking().unwrap();
        assert_eq!(
            evaluated as usize,
            moved.patches.len(),
            "{name}: step {step}"
        );
        support = moved.patches;
    }
    assert!(
        !support.is_empty(),
        "{name}: a moved point changes something"
    );
    let dragged = sync.read_vertices().unwrap();
    let (_, full) = on_gpu(context, doc, cpu);
    assert!(
        dragged == full,
        "{name}: incremental and full evaluation differ"
    );
    let deviation = gpu_deviation(&sync, &dragged, &doc.scene.objects[0]);
    assert!(deviation <= 1e-5, "{name}: after the drag {deviation:e}");
    assert_eq!(
        doc.history.undo_depth(),
        0,
        "{name}: a drag step is not an undo step"
    );
    assert!(doc.commit_drag().is_some());
    assert_eq!(doc.history.undo_depth(), 1);
    let touched = doc.undo().unwrap().touched();
    // An object that works its layout out again when a drag ends (adaptive refinement) may
    // come back with another layout.
    if object.kind().resettled().is_none() {
        assert_eq!(touched, Touched::Points(0), "{name}");
    }
    assert_eq!(
        &doc.scene.objects[0], object,
        "{name}: undo restores the object"
    );
    sync.apply(&doc.scene, touched, 1.0).unwrap();
    sync.evaluate_blocking().unwrap();
    assert!(
        sync.read_vertices().unwrap() == original_vertices,
        "{name}: undo restores every GPU vertex"
    );
}

/// Largest distance, over every curve vertex on the GPU, from the kind's own f64 point at that
/// vertex's segment and parameter, divided by the object's size; also checks that exactly the
/// segments' last samples end a line (w = 0).
fn curve_gpu_deviation(sync: &SceneSync, vertices: &[CurveVertex], object: &SceneObject) -> f64 {
    let curves = sync.curves().unwrap();
    let first = curves.first_record(0).unwrap();
    let mut worst = 0.0f64;
    for (k, record) in curves.records().iter().enumerate() {
        let n = record.segments as usize;
        for i in 0..=n {
            let vertex = vertices[record.vertex_offset as usize + i];
            assert_eq!(vertex.record as usize, k);
            assert_eq!(vertex.position[3], if i == n { 0.0 } else { 1.0 });
            let s = i as f64 / n as f64;
            let exact = object.kind().surface_point(k - first, s, 0.0).unwrap();
            let gpu = DVec3::new(
                f64::from(vertex.position[0]),
                f64::from(vertex.position[1]),
                f64::from(vertex.position[2]),
            );
            worst = worst.max(gpu.distance(exact));
        }
    }
    worst / size(object)
}

/// The curve's version of [`conforms`]: its feed (rational Bézier segments) against its own
/// definition, the curve pass (compute shaders and the CPU evaluator) against it, a drag that
/// re-evaluates only the moved point's segments and gives what a full evaluation gives, undo
/// restoring every vertex, save and reopen, and the export as a glTF line strip that reopens as
/// itself.
fn curve_conforms(context: &GpuContext, object: SceneObject) {
    let name = object.name.clone();
    let scale = size(&object);
    let feed = object.decompose().unwrap();
    let curve = feed.curve.as_ref().unwrap();
    assert!(curve.segment_count() > 0, "{name}: an empty feed");
    assert!(
        feed.set.patches().is_empty(),
        "{name}: a curve has no patches"
    );
    for k in 0..curve.segment_count() {
        for s in [0.0, 0.3, 0.5, 1.0] {
            let fed = curve.point(k, s).unwrap();
            let own = object.kind().surface_point(k, s, 0.0).unwrap();
            assert!(
                fed.distance(own) <= 1e-12 * scale,
                "{name}: segment {k} at {s}: {fed} vs {own}"
            );
        }
    }
    assert!(
        object
            .kind()
            .surface_point(curve.segment_count(), 0.5, 0.0)
            .is_err()
    );
    assert!(object.kind().faces().is_empty());

    let mut doc = Document::new(Scene {
        objects: vec![object.clone()],
        unit: None,
    });
    for cpu in [false, true] {
        let name = format!("{name}{}", if cpu { " (CPU evaluator)" } else { "" });
        let on = |doc: &Document| {
            let mut sync = if cpu {
                SceneSync::on_cpu(&context.device, &context.queue)
            } else {
                SceneSync::new(&context.device, &context.queue)
            };
            sync.rebuild(&doc.scene, 1.0).unwrap();
            sync.evaluate_blocking().unwrap();
            let vertices = sync.read_curve_vertices().unwrap();
            (sync, vertices)
        };
        let (mut sync, original) = on(&doc);
        let deviation = curve_gpu_deviation(&sync, &original, &object);
        eprintln!("{name}: GPU vs f64 {deviation:.2e} of its size");
        assert!(deviation <= 1e-5, "{name}: {deviation:e}");

        let index = object.control_point_count() / 2;
        doc.begin_drag(0, &[index]).unwrap();
        for step in 1..=3 {
            let moved = doc
                .drag_by(DVec3::new(0.05, -0.03, 0.08) * scale * f64::from(step))
                .unwrap();
            assert!(!moved.patches.is_empty());
            sync.points_moved(&doc.scene, &moved).unwrap();
            let evaluated = sync.evaluate_blocking().unwrap();
            assert_eq!(
                evaluated as usize,
                moved.patches.len(),
                "{name}: step {step}"
            );
        }
        let dragged = sync.read_curve_vertices().unwrap();
        let (_, full) = on(&doc);
        assert!(
            dragged == full,
            "{name}: incremental and full evaluation differ"
        );
        assert!(dragged != original, "{name}: the drag moved nothing");
        let deviation = curve_gpu_deviation(&sync, &dragged, &doc.scene.objects[0]);
        assert!(deviation <= 1e-5, "{name}: after the drag {deviation:e}");
        assert!(doc.commit_drag().is_some());
        let touched = doc.undo().unwrap().touched();
        assert_eq!(touched, Touched::Points(0), "{name}");
        assert_eq!(&doc.scene.objects[0], &object, "{name}: undo");
        sync.apply(&doc.scene, touched, 1.0).unwrap();
        sync.evaluate_blocking().unwrap();
        assert!(
            sync.read_curve_vertices().unwrap() == original,
            "{name}: undo restores every GPU vertex"
        );
    }

    let project = Project {
        scene: doc.scene.clone(),
        view: None,
    };
    let reopened = project::read(&project::write(&project)).unwrap();
    assert_eq!(
        reopened.scene.objects,
        vec![object.clone()],
        "{name}: save and reopen"
    );

    // Export: one line strip within the tolerance of the curve, which reopens as itself.
    let tolerance = 1e-3 * scale;
    let options = ExportOptions {
        tessellation: Tessellation::Tolerance(tolerance),
        curvature: false,
        colors: None,
    };
    let export = gltf::export(&project, &options).unwrap();
    assert_eq!((export.triangles, export.lines), (0, 1), "{name}");
    let glb = gltf::to_glb(&export);
    let document = ::gltf::Gltf::from_slice(&glb).unwrap();
    let primitive = document
        .meshes()
        .next()
        .unwrap()
        .primitives()
        .next()
        .unwrap();
    assert_eq!(primitive.mode(), ::gltf::mesh::Mode::LineStrip);
    let strip = knotwork::kernel::tess::curve_polyline(
        object.kind().space_curve().unwrap(),
        Tessellation::Tolerance(tolerance),
    )
    .unwrap();
    let space_curve = object.kind().space_curve().unwrap();
    for pair in strip.windows(2) {
        let middle = 0.5 * (pair[0] + pair[1]);
        let t = space_curve.closest_parameter(middle).unwrap();
        let distance = space_curve.point_at(t).unwrap().distance(middle);
        assert!(
            distance <= 1.01 * tolerance,
            "{name}: chord {distance:e} off"
        );
    }
    let no_companions = |name: &str| Err(format!("{name}: not expected"));
    let back = knotwork::io::open("conformance.glb", &glb, &no_companions).unwrap();
    assert_eq!(
        back.scene.objects,
        vec![object],
        "{name}: the export reopens as itself"
    );
}

fn conforms(context: &GpuContext, object: SceneObject) {
    let name = object.name.clone();
    let scale = size(&object);

    // 1. The feed against the kind's own definition.
    let feed = object.decompose().unwrap();
    if feed.curve.is_some() {
        return curve_conforms(context, object);
    }
    let other_patches = feed
        .stencils
        .as_ref()
        .map_or(0, |f| f.patches.len() + f.substitutes.len());
    assert!(
        feed.set.patches().len() + other_patches > 0,
        "{name}: an empty feed"
    );
    for k in 0..feed.set.patches().len() {
        for (s, t) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.5), (0.5, 1.0), (1.0, 1.0)] {
            let fed = feed.set.evaluate(k, s, t).unwrap().point;
            let own = object.kind().surface_point(k, s, t).unwrap();
            assert!(
                fed.distance(own) <= 1e-12 * scale,
                "{name}: feed patch {k} at ({s}, {t}): {fed} vs {own}"
            );
        }
    }
    assert!(
        object
            .kind()
            .surface_point(
                feed.set.patches().len()
                    + feed
                        .stencils
                        .as_ref()
                        .map_or(0, |f| f.patches.len() + f.substitutes.len()),
                0.5,
                0.5
            )
            .is_err(),
        "{name}: a patch past the end is refused"
    );

    // 1b. The faces (the one surface interface) against the kind's own definition: a kind
    // with one face is that face over each feed patch's rectangle, one with several has face k
    // as feed patch k, and a triangular patch's face is over the square, u = s (1 − t), v = t.
    // Each face's derivatives agree with differences of its points.
    let kind_faces = object.kind().faces();
    let shown_faces = object.faces();
    assert_eq!(kind_faces.len(), shown_faces.len(), "{name}: faces");
    // A polysurface's face k is its k-th trimmed face over that face's own domain (several
    // feed patches): checked against the faces it was joined from in tests/it/surface_ops.rs.
    let polysurface = object.geometry.downcast_ref::<Polysurface>().is_some();
    for (n, (face, (patch, shown))) in kind_faces.iter().zip(shown_faces).enumerate() {
        assert_eq!(face.patch, patch, "{name}: face {n}");
        if polysurface {
            continue;
        }
        // A face of a stencil patch (a subdivision surface's boundary face) against the
        // stencils' exact limit points, which lie at the patch's grid points.
        let stencil = patch.is_some_and(|k| k >= feed.set.patches().len());
        let samples: &[(f64, f64)] = if stencil {
            &[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)]
        } else {
            &[(0.0, 0.0), (0.3, 0.7), (1.0, 0.5), (0.6, 0.2)]
        };
        for &(s, t) in samples {
            let (point, own) = match (patch, face.triangle) {
                (Some(k), _) => (shown.point(s, t), object.kind().surface_point(k, s, t)),
                (None, true) => (
                    shown.point(s, t),
                    object.kind().surface_point(0, s * (1.0 - t), t),
                ),
                (None, false) => {
                    let [u0, u1, v0, v1] = feed.domains[0];
                    (
                        shown.point(u0 + s * (u1 - u0), v0 + t * (v1 - v0)),
                        object.kind().surface_point(0, s, t),
                    )
                }
            };
            let (point, own) = (point.unwrap(), own.unwrap());
            assert!(
                point.distance(own) <= 1e-12 * scale,
                "{name}: face {n} at ({s}, {t}): {point} vs {own}"
            );
        }
        let [(u0, u1), (v0, v1)] = shown.domain();
        let (u, v) = (u0 + 0.4 * (u1 - u0), v0 + 0.55 * (v1 - v0));
        let h = 1e-5 * (u1 - u0).max(v1 - v0);
        let d = shown.derivatives(u, v).unwrap();
        let su = (shown.point(u + h, v).unwrap() - shown.point(u - h, v).unwrap()) / (2.0 * h);
        let sv = (shown.point(u, v + h).unwrap() - shown.point(u, v - h).unwrap()) / (2.0 * h);
        let slack = 1e-6 * (1.0 + d.su.length() + d.sv.length());
        assert!(
            d.su.distance(su) <= slack && d.sv.distance(sv) <= slack,
            "{name}: face {n}'s derivatives"
        );
    }
    drop(kind_faces);

    // 2. The GPU, through the sync layer: the compute shaders, and the CPU evaluator of the
    // WebGL2 path.
    let mut doc = Document::new(Scene {
        objects: vec![object.clone()],
        unit: None,
    });
    for cpu in [false, true] {
        let name = format!("{name}{}", if cpu { " (CPU evaluator)" } else { "" });
        drag_and_undo(context, &mut doc, &object, &name, cpu);
    }

    // 4. Save and reopen.
    let text = project::write(&Project {
        scene: doc.scene.clone(),
        view: None,
    });
    let reopened = project::read(&text).unwrap();
    assert_eq!(
        reopened.scene.objects,
        vec![object.clone()],
        "{name}: save and reopen"
    );

    // 5. Export.
    let project = Project {
        scene: doc.scene.clone(),
        view: None,
    };
    let options = ExportOptions {
        tessellation: Tessellation::Tolerance(1e-3 * scale),
        curvature: false,
        colors: None,
    };
    let export = gltf::export(&project, &options).unwrap();
    assert!(export.triangles > 0, "{name}: no triangles exported");
    let (lo, hi) = object.bounds().unwrap();
    let slack = DVec3::splat(1e-9 * scale);
    for mesh in object
        .tessellate(Tessellation::Tolerance(1e-3 * scale), false)
        .unwrap()
    {
        assert!(!mesh.triangles.is_empty(), "{name}");
        for p in &mesh.positions {
            assert!(
                p.cmpge(lo - slack).all() && p.cmple(hi + slack).all(),
                "{name}: exported vertex {p} outside the control points' box"
            );
        }
    }
    let glb = gltf::to_glb(&export);
    let no_companions = |name: &str| Err(format!("{name}: not expected"));
    let back = knotwork::io::open("conformance.glb", &glb, &no_companions).unwrap();
    assert_eq!(
        back.scene.objects,
        vec![object],
        "{name}: the export reopens as itself"
    );
}

#[test]
fn every_object_kind_conforms() {
    register_sheet();
    let context = common::gpu();
    let kinds = registry::kinds();
    let mut names = Vec::new();
    for entry in &kinds {
        let examples = (entry.examples)();
        assert!(!examples.is_empty(), "{}: no examples", entry.record_type);
        for object in examples {
            // Each example is written as its entry's records and read back by it.
            assert_eq!(
                object.kind().record()["type"],
                entry.record_type,
                "{}",
                object.name
            );
            names.push(object.kind().kind_name());
            conforms(&context, object);
        }
    }
    eprintln!("checked: {names:?}");
    // The built-in kinds (eight, two of which share the NURBS records) and the test's own.
    assert_eq!(kinds.len(), 8, "{names:?}");
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), 9, "{names:?}");
}

/// A kind registered from this module alone is edited, analysed and saved by the rest of the
/// editor: a transform and a displacement through the document's commands (each one undo
/// step), the continuity of two sheets that meet with one tangent plane, and a project with an
/// unknown record type refused with the types the registry knows.
#[test]
fn a_kind_defined_in_a_test_works_everywhere() {
    register_sheet();
    // Two sheets sharing the edge x = 2: the second continues the first's cross-boundary
    // tangent (its first interior row mirrors the first's last one), so they meet with G1.
    let left = sheet(DVec3::ZERO, |i, j| 0.3 * (i as f64) * (j as f64 - 1.0));
    let right = QuadraticSheet {
        points: std::array::from_fn(|k| {
            let (i, j) = (k / 3, k % 3);
            match i {
                0 => left.points[6 + j],
                1 => 2.0 * left.points[6 + j] - left.points[3 + j],
                _ => left.points[6 + j] + DVec3::new(2.0, 0.0, -0.2 * j as f64),
            }
        }),
    };
    let scene = Scene {
        objects: vec![
            SceneObject::new("left", ObjectGeometry::new(left.clone())),
            SceneObject::new("right", ObjectGeometry::new(right)),
        ],
        unit: None,
    };
    let report = knotwork::scene::continuity::analyse(
        &scene,
        None,
        &knotwork::scene::continuity::ContinuityOptions::default(),
    );
    assert_eq!(report.edges.len(), 1, "{:?}", report.edges);
    let edge = &report.edges[0];
    eprintln!(
        "sheets: gap {:.2e}, angle {:.2e}°",
        edge.max_gap.value, edge.max_angle_degrees.value
    );
    // One tangent plane along the edge, up to the rounding of the angle's arc cosine.
    assert!(edge.max_gap.value < 1e-12);
    assert!(edge.max_angle_degrees.value < 1e-4);
    assert!(matches!(
        edge.verdict,
        knotwork::kernel::continuity::Continuity::G1 | knotwork::kernel::continuity::Continuity::G2
    ));

    let mut doc = Document::new(scene);
    let moved = DAffine3::from_translation(DVec3::new(0.0, 0.0, 1.5));
    doc.execute(&Command::operation(
        knotwork::ops::transform::Transform::new(0, &moved),
    ))
    .unwrap();
    let lifted = doc.scene.objects[0]
        .geometry
        .downcast_ref::<QuadraticSheet>()
        .unwrap();
    assert_eq!(lifted.points[4], left.points[4] + DVec3::new(0.0, 0.0, 1.5));
    doc.undo().unwrap();
    assert_eq!(doc.scene.objects[0].geometry, ObjectGeometry::new(left));

    let text = project::write(&Project {
        scene: doc.scene.clone(),
        view: None,
    });
    assert!(text.contains("\"quadratic_sheet\""));
    assert_eq!(project::read(&text).unwrap().scene, doc.scene);
    let unknown = text.replace("quadratic_sheet", "cubic_sheet");
    let error = project::read(&unknown).unwrap_err().to_string();
    assert!(
        error.contains("cubic_sheet") && error.contains("\"quadratic_sheet\""),
        "{error}"
    );
}

/// The transfinite surfaces of the Create dialog (Gordon, bicubic Coons, Hermite) are NURBS
/// objects and pass the same checks: GPU, drag, undo, save, export.
#[test]
fn created_transfinite_surfaces_conform() {
    use knotwork::doc::create::{Primitive, PrimitiveParams};
    let context = common::gpu();
    for kind in [
        Primitive::Gordon,
        Primitive::BicubicCoons,
        Primitive::Hermite,
    ] {
        let mut object = PrimitiveParams {
            kind,
            ..Default::default()
        }
        .build()
        .unwrap();
        object.segments = 5;
        conforms(&context, object);
    }
}

/// The efficient substitutes as a cage's display: ACC on a cube, Gregory patches on an
/// icosahedron under Catmull-Clark (on level 1, not all quads) and on an open cylinder (its
/// boundary faces exact), PN triangles on a Loop icosahedron.
#[test]
fn subdivision_substitutes_conform() {
    use knotwork::kernel::subdiv::patches::Display;
    use knotwork::kernel::subdiv::{Scheme, cages};
    use knotwork::scene::SubdivObject;
    let context = common::gpu();
    let surface = |mesh: PolygonMesh, scheme: Scheme, level: u32| {
        let options = Options {
            scheme,
            ..Options::default()
        };
        SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), options, level).unwrap()
    };
    let center = DVec3::new(0.1, -0.2, 0.3);
    // A 12 × 8 torus with its quads split: big enough that a drag moves only some patches.
    let torus = cages::torus(center, 2.0, 0.7, 12, 8).unwrap();
    let split: Vec<Vec<u32>> = torus
        .faces()
        .flat_map(|f| [vec![f[0], f[1], f[2]], vec![f[0], f[2], f[3]]])
        .collect();
    let triangles = PolygonMesh::new(torus.points().to_vec(), &split).unwrap();
    let cases = [
        (
            "ACC triangulated torus",
            surface(triangles.clone(), Scheme::CatmullClark, 2),
            Display::Acc,
        ),
        (
            "PN torus",
            surface(triangles, Scheme::Loop, 2),
            Display::PnTriangles,
        ),
        (
            "ACC cube",
            surface(cages::cube(center, 2.0).unwrap(), Scheme::CatmullClark, 2),
            Display::Acc,
        ),
        (
            "Gregory icosahedron",
            surface(
                cages::icosahedron(center, 1.5).unwrap(),
                Scheme::CatmullClark,
                2,
            ),
            Display::Gregory,
        ),
        (
            "Gregory cylinder",
            surface(
                cages::cylinder(center, 1.0, 2.0, 5, 3).unwrap(),
                Scheme::CatmullClark,
                2,
            ),
            Display::Gregory,
        ),
        (
            "PN icosahedron",
            surface(cages::icosahedron(center, 1.5).unwrap(), Scheme::Loop, 3),
            Display::PnTriangles,
        ),
    ];
    for (name, s, display) in cases {
        let object = SceneObject::new(
            name,
            ObjectGeometry::boxed(Box::new(SubdivObject::checked(s, display).unwrap())),
        );
        conforms(&context, object);
    }
}

/// Adaptive subdivision as a cage's display (pieces at different depths, crack-free fans where
/// they meet): Catmull-Clark on a torus with a spike and on a cube with a corner pulled out,
/// Loop on an icosahedron with one point pulled out. The GPU writes each vertex's refinement
/// level. (The butterfly's limit leaves the control points' box, which `conforms` checks; its
/// GPU evaluation is checked in tests/it/adaptive_subdivision.rs.)
#[test]
fn subdivision_adaptive_conforms() {
    use knotwork::kernel::subdiv::patches::Display;
    use knotwork::kernel::subdiv::{Scheme, cages};
    use knotwork::scene::SubdivObject;
    let context = common::gpu();
    let center = DVec3::new(0.1, -0.2, 0.3);
    let pulled = |mesh: PolygonMesh, point: usize, by: DVec3| {
        let mut points = mesh.points().to_vec();
        points[point] += by;
        let faces: Vec<Vec<u32>> = mesh.faces().map(<[u32]>::to_vec).collect();
        PolygonMesh::new(points, &faces).unwrap()
    };
    let surface = |mesh: PolygonMesh, scheme: Scheme, level: u32| {
        let options = Options {
            scheme,
            ..Options::default()
        };
        SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), options, level).unwrap()
    };
    let torus = pulled(
        cages::torus(center, 2.0, 0.7, 12, 8).unwrap(),
        5,
        DVec3::new(0.3, 0.2, 1.5),
    );
    let icosahedron = pulled(
        cages::icosahedron(center, 1.5).unwrap(),
        3,
        DVec3::new(0.8, -0.4, 0.9),
    );
    let cube = pulled(
        cages::cube(center, 2.0).unwrap(),
        6,
        DVec3::new(0.9, 0.7, 1.1),
    );
    let cases = [
        (
            "adaptive torus",
            surface(torus, Scheme::CatmullClark, 3),
            0.004,
        ),
        (
            "adaptive Loop icosahedron",
            surface(icosahedron, Scheme::Loop, 3),
            0.004,
        ),
        (
            "adaptive cube",
            surface(cube, Scheme::CatmullClark, 4),
            0.02,
        ),
    ];
    for (name, s, tolerance) in cases {
        let object = SubdivObject::checked(s, Display::Adaptive)
            .unwrap()
            .with_tolerance_checked(tolerance)
            .unwrap();
        let layout = object.adaptive_layout().unwrap().unwrap();
        let histogram = layout.histogram();
        assert!(
            histogram.iter().filter(|&&n| n > 0).count() >= 2,
            "{name}: one level only ({histogram:?})"
        );
        let object = SceneObject::new(name, ObjectGeometry::boxed(Box::new(object)));

        // The vertices' levels as the compute pass writes them: 1 + each piece's level.
        let doc = Document::new(Scene {
            objects: vec![object.clone()],
            unit: None,
        });
        let (_, vertices) = on_gpu(&context, &doc, false);
        let mut seen = vec![0usize; histogram.len() + 1];
        for v in &vertices {
            seen[v.level() as usize] += 1;
        }
        for (level, &pieces) in histogram.iter().enumerate() {
            assert_eq!(
                seen[level + 1] > 0,
                pieces > 0,
                "{name}: level {level}: {pieces} pieces, {} vertices",
                seen[level + 1]
            );
        }
        conforms(&context, object);
    }
}

/// A kind defined here brings its own panel with its registration: selected in the editor,
/// the sheet shows the panel registered for it under *Selected object*, and a NURBS surface
/// does not; its button runs a document command (one undo step).
#[test]
fn a_kind_defined_in_a_test_shows_its_own_panel_in_the_editor() {
    use egui_kittest::kittest::Queryable;
    use knotwork::app::panels::kinds::{self, KindPanel};
    use knotwork::app::{AppCommand, KnotworkApp};
    register_sheet();
    kinds::register(KindPanel {
        kinds: &["a quadratic sheet"],
        show: |app: &mut KnotworkApp, ui, s| {
            ui.label("Quadratic sheet: 9 points");
            if ui.button("Lift the sheet").clicked() {
                app.apply(AppCommand::Edit(Command::operation(
                    knotwork::ops::transform::Transform::new(
                        s,
                        &DAffine3::from_translation(DVec3::Z),
                    ),
                )));
            }
        },
    });
    let _one = crate::editor_ui::ONE_EDITOR_AT_A_TIME
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let mut harness = crate::editor_ui::editor();
    let page = harness.state().command_sender();
    let sheet = SceneObject::new(
        "sheet",
        ObjectGeometry::new(sheet(DVec3::ZERO, |i, j| 0.2 * (i * j) as f64)),
    );
    page.send(AppCommand::Edit(Command::Add {
        object: sheet.clone(),
    }));
    harness.run_steps(2);
    let k = harness.state().document().scene.objects.len() - 1;
    page.send(AppCommand::Select(Some(k)));
    harness.run_steps(3);
    assert!(
        harness
            .query_by_label("Quadratic sheet: 9 points")
            .is_some()
    );
    let depth = harness.state().document().history.undo_depth();
    harness.get_by_label("Lift the sheet").scroll_to_me();
    harness.run_steps(1);
    harness.get_by_label("Lift the sheet").click_accesskit();
    harness.run_steps(3);
    let lifted = &harness.state().document().scene.objects[k];
    assert_eq!(harness.state().document().history.undo_depth(), depth + 1);
    let (lo, _) = lifted.bounds().unwrap();
    let (was, _) = sheet.bounds().unwrap();
    assert!((lo.z - was.z - 1.0).abs() < 1e-12, "{lo} {was}");
    // The teapot (object 0) is not a sheet: no sheet panel.
    page.send(AppCommand::Select(Some(0)));
    harness.run_steps(3);
    assert!(
        harness
            .query_by_label("Quadratic sheet: 9 points")
            .is_none()
    );
}
