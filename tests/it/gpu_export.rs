//! Export grids evaluated by the compute shaders (lavapipe here) against the f64 kernel's:
//! the same triangles, and positions, normals and curvatures within f32 precision, on random
//! rational surfaces in general position, on the demo scene's objects, and through
//! `knotwork export --backend gpu` into a file the Khronos validator accepts.

use crate::common::{self, Rng, random_motion};

use glam::{DAffine3, DVec3};
use knotwork::gpu::export_grids::GpuGrids;
use knotwork::kernel::tess::{
    self, DeferredGridSampler, GridValues, KernelGrids, ParameterGrid, PendingGridValues,
    Tessellation, TriangleMesh,
};
use knotwork::kernel::{GeometryError, NurbsSurface};

/// Sin² of the angle between Su and Sv at normalized (u, v) of `surface`: where f32 normals
/// and curvatures are meaningful to compare (as in `gpu_eval`).
fn sin2_at(surface: &NurbsSurface, uv: [f64; 2]) -> f64 {
    let [(u0, u1), (v0, v1)] = surface.domain();
    let d = surface
        .evaluate(u0 + uv[0] * (u1 - u0), v0 + uv[1] * (v1 - v0))
        .unwrap();
    let (a, b) = (d.su.length_squared(), d.sv.length_squared());
    if a == 0.0 || b == 0.0 {
        return 0.0;
    }
    d.su.cross(d.sv).length_squared() / (a * b)
}

/// The largest deviations of `gpu` from `cpu`, both of `surface`: position / size, normal
/// angle where sin² > 1e-6, and curvature (|Δk| · size / max(1, |k1|, |k2|) · size) where
/// sin² > 1e-4.
/// Asserts the two have the same vertices' (u, v) and the same triangles.
fn deviations(surface: &NurbsSurface, cpu: &TriangleMesh, gpu: &TriangleMesh) -> [f64; 3] {
    assert_eq!(cpu.triangles, gpu.triangles, "the same triangles");
    assert_eq!(cpu.uvs, gpu.uvs, "the same (u, v)");
    assert_eq!(cpu.curvatures.len(), gpu.curvatures.len());
    let size = surface.size();
    let mut worst = [0.0f64; 3];
    for k in 0..cpu.positions.len() {
        worst[0] = worst[0].max((gpu.positions[k] - cpu.positions[k]).length() / size);
        let sin2 = sin2_at(surface, cpu.uvs[k]);
        if sin2 > 1e-6 {
            worst[1] = worst[1].max(gpu.normals[k].angle_between(cpu.normals[k]));
        }
        if sin2 > 1e-4 && !cpu.curvatures.is_empty() {
            // Compared against the larger principal curvature (the smaller one of a very
            // curved point is a difference of two large numbers), as lengths⁻¹ of the size:
            // K against its square.
            let (a, b) = (cpu.curvatures[k], gpu.curvatures[k]);
            let scale = (a.k1.abs().max(a.k2.abs()) * size).max(1.0);
            for (x, y, s) in [
                (
                    a.gaussian * size * size,
                    b.gaussian * size * size,
                    scale * scale,
                ),
                (a.mean * size, b.mean * size, scale),
                (a.k1 * size, b.k1 * size, scale),
                (a.k2 * size, b.k2 * size, scale),
            ] {
                worst[2] = worst[2].max((y - x).abs() / s);
            }
        }
    }
    worst
}

#[test]
fn gpu_export_grids_agree_with_the_kernel_on_random_surfaces_in_general_position() {
    let context = common::gpu();
    let started = std::time::Instant::now();
    let grids = GpuGrids::new(&context.device, &context.queue);
    eprintln!(
        "GpuGrids::new: {:.0} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    let mut rng = Rng(0x6060_e590);
    let mut surfaces = Vec::new();
    let mut plans = Vec::new();
    for case in 0..24 {
        let (p, q) = (1 + rng.below(5), 1 + rng.below(5));
        let surface = common::random_surface(p, q, rng.next())
            .transformed(&random_motion(&mut rng))
            .unwrap();
        let tessellation = if case % 2 == 0 {
            Tessellation::Segments(1 + rng.below(12) as u32)
        } else {
            Tessellation::Tolerance(surface.size() * 10f64.powf(rng.range(-2.5, -1.5)))
        };
        let grid = tess::grid_for(&surface, tessellation).unwrap();
        surfaces.push(surface);
        plans.push(grid);
    }
    let jobs: Vec<(&NurbsSurface, &ParameterGrid)> = surfaces.iter().zip(&plans).collect();
    let vertices: usize = plans.iter().map(|g| g.us.len() * g.vs.len()).sum();
    for curvature in [false, true] {
        let cpu = tess::triangulate_all(&jobs, curvature, &KernelGrids).unwrap();
        let started = std::time::Instant::now();
        let gpu = tess::triangulate_all(&jobs, curvature, &grids).unwrap();
        eprintln!(
            "{vertices} vertices on the GPU (curvature {curvature}): {:.0} ms",
            started.elapsed().as_secs_f64() * 1e3
        );
        assert_eq!(grids.fallbacks(), 0, "the GPU evaluated every grid");
        let mut worst = [0.0f64; 3];
        for (k, surface) in surfaces.iter().enumerate() {
            let d = deviations(surface, &cpu[k], &gpu[k]);
            for (w, d) in worst.iter_mut().zip(d) {
                *w = w.max(d);
            }
        }
        eprintln!(
            "largest deviations: position {:.2e} of the size, normal {:.2e} rad, curvature \
             {:.2e}",
            worst[0], worst[1], worst[2]
        );
        assert!(worst[0] < 1e-5, "positions within f32 precision: {worst:?}");
        assert!(worst[1] < 1e-3, "normals within 1e-3 rad: {worst:?}");
        assert!(
            !curvature || worst[2] < 1e-2,
            "curvatures within 1e-2: {worst:?}"
        );
    }
}

/// A rational (3, 2) surface with a small elliptic hole: most of its tolerance grid's
/// crossings are kept, so the export takes them from one grid evaluation.
fn surface_with_a_hole() -> knotwork::scene::SceneObject {
    use knotwork::kernel::trim::shapes;
    let base = common::random_surface(3, 2, 2024);
    let [(u0, u1), (v0, v1)] = base.domain();
    let (lo, hi) = (glam::DVec2::new(u0, v0), glam::DVec2::new(u1, v1));
    let loops = vec![
        shapes::rectangle(lo, hi).unwrap(),
        shapes::ellipse(0.5 * (lo + hi), 0.1 * (hi - lo)).unwrap(),
    ];
    let trimmed = knotwork::kernel::TrimmedSurface::new(base, loops).unwrap();
    knotwork::scene::SceneObject::new(
        "surface with a hole",
        knotwork::scene::ObjectGeometry::from_trimmed(trimmed),
    )
}

/// The demo scene's objects (the teapot's patch set with its poles, rational and polynomial
/// NURBS surfaces) and a trimmed surface (the grid's crossings from the GPU, the cut cells
/// clipped on the CPU) through the objects' own export tessellation, placed far from the origin:
/// GPU and CPU give the same triangles (the poles' empty ones left out by both), and positions
/// within f32 precision of each object's size.
#[test]
fn every_demo_object_exports_the_same_triangles_from_gpu_grids() {
    let context = common::gpu();
    let grids = GpuGrids::new(&context.device, &context.queue);
    let mut scene = knotwork::scene::Scene::demo().unwrap();
    scene.objects.push(surface_with_a_hole());
    let far = DAffine3::from_translation(DVec3::new(1234.5, -678.9, 250.0));
    let mut checked = 0;
    for object in &mut scene.objects {
        if let Ok(moved) = object.geometry.kind().transformed(&far) {
            object.geometry = moved;
        }
        let size = object
            .tessellate(Tessellation::Segments(2), false)
            .unwrap()
            .iter()
            .flat_map(|m| &m.positions)
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let size = (size.1 - size.0).length();
        // The random surface under the hole is crumpled: 1e-3 of its size is fine enough.
        let fraction = if object.name == "surface with a hole" {
            1e-3
        } else {
            1e-4
        };
        let tessellation = Tessellation::Tolerance(fraction * size);
        let cpu = object.tessellate(tessellation, true).unwrap();
        let gpu = object.tessellate_with(tessellation, true, &grids).unwrap();
        assert_eq!(cpu.len(), gpu.len(), "{}", object.name);
        let mut worst: f64 = 0.0;
        for (a, b) in cpu.iter().zip(&gpu) {
            assert_eq!(
                a.triangles, b.triangles,
                "{}: the same triangles",
                object.name
            );
            assert_eq!(a.uvs, b.uvs, "{}", object.name);
            for (p, q) in a.positions.iter().zip(&b.positions) {
                worst = worst.max((*p - *q).length() / size);
            }
            checked += a.positions.len();
        }
        eprintln!(
            "{}: position deviation {worst:.2e} of the size",
            object.name
        );
        assert!(worst < 1e-5, "{}: {worst:.2e}", object.name);
        assert!(worst > 0.0, "{}: the GPU evaluated its grid", object.name);
    }
    assert_eq!(grids.fallbacks(), 0);
    assert!(checked > 10_000, "{checked} vertices compared");
}

/// `knotwork export --backend gpu` writes a file the Khronos validator accepts, with the
/// `--backend cpu` file's counts, and says which evaluated the grids.
#[test]
fn the_command_line_exports_through_gpu_grids() {
    let dir = crate::common::scratch_dir("gpu-export-cli");
    let project = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/reference/projects/history-2026-11-28.json");
    let mut summaries = Vec::new();
    for backend in ["gpu", "cpu"] {
        let out = dir.join(format!("{backend}.glb"));
        let output = common::knotwork_ok(&[
            "export".as_ref(),
            project.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
            "--tolerance".as_ref(),
            "1e-3".as_ref(),
            "--curvature".as_ref(),
            "--backend".as_ref(),
            backend.as_ref(),
        ]);
        summaries.push(String::from_utf8_lossy(&output.stdout).into_owned());
    }
    eprintln!("{summaries:?}");
    assert!(
        summaries[0].contains("grids on the GPU"),
        "{}",
        summaries[0]
    );
    assert!(
        summaries[1].contains("grids on the CPU"),
        "{}",
        summaries[1]
    );
    let counts = |s: &str| {
        let start = s.find("objects").unwrap();
        s[start..s.find("tolerance").unwrap()].to_owned()
    };
    assert_eq!(counts(&summaries[0]), counts(&summaries[1]));
    common::validate_gltf(&[dir.join("gpu.glb")]);
    std::fs::remove_dir_all(&dir).ok();
}

/// A deferred sampler that holds each request's values back for `hold` polls (frames in the
/// page) and, when `fail`, fails every request or every poll in turn.
struct Held {
    grids: GpuGrids,
    hold: usize,
    fail: bool,
    requests: std::cell::Cell<usize>,
    /// Polls answered "not yet" because of the hold, over all requests.
    held: std::rc::Rc<std::cell::Cell<usize>>,
}

struct HeldGrids {
    pending: Box<dyn PendingGridValues>,
    hold: usize,
    fail: bool,
    held: std::rc::Rc<std::cell::Cell<usize>>,
}

impl PendingGridValues for HeldGrids {
    fn poll(&mut self) -> Option<Result<Vec<GridValues>, GeometryError>> {
        if self.hold > 0 {
            self.hold -= 1;
            self.held.set(self.held.get() + 1);
            return None;
        }
        if self.fail {
            return Some(Err(GeometryError::Construction {
                what: "grid evaluation on the GPU",
                message: "the device was lost (a test's)".into(),
            }));
        }
        self.pending.poll()
    }
}

impl DeferredGridSampler for Held {
    fn request(
        &self,
        jobs: &[(&NurbsSurface, &ParameterGrid)],
        curvature: bool,
    ) -> Result<Box<dyn PendingGridValues>, GeometryError> {
        let k = self.requests.get();
        self.requests.set(k + 1);
        if self.fail && k.is_multiple_of(2) {
            return Err(GeometryError::Construction {
                what: "grid evaluation on the GPU",
                message: "a buffer over the device's limits (a test's)".into(),
            });
        }
        Ok(Box::new(HeldGrids {
            pending: DeferredGridSampler::request(&self.grids, jobs, curvature)?,
            hold: self.hold,
            fail: self.fail,
            held: self.held.clone(),
        }))
    }

    fn position_slack(&self, surface: &NurbsSurface) -> f64 {
        DeferredGridSampler::position_slack(&self.grids, surface)
    }
}

/// The glTF export as the page runs it, asking for the grids of several objects ahead and
/// writing each once they are back, frames later, writes the same file, byte for byte, as the
/// export that waits for the same GPU, and one whose GPU refuses or fails writes the kernel's file. The scene: the demo
/// objects, a trimmed surface, a displaced surface and one in a bent lattice, moved to a
/// random place, exported at a tolerance with curvature.
#[test]
fn an_export_that_does_not_wait_for_the_gpu_writes_the_file_of_one_that_does() {
    use knotwork::io::gltf::{self, ExportJob, ExportOptions};
    use knotwork::io::project::Project;
    use std::rc::Rc;
    use std::sync::Arc;

    let context = common::gpu();
    let mut rng = Rng(0x0e59_0a77);
    let mut scene = knotwork::scene::Scene::demo().unwrap();
    scene.objects.push(surface_with_a_hole());
    let mut displaced = scene.objects[3].clone();
    displaced.name = "displaced".into();
    displaced.displacement = Some(
        knotwork::kernel::displace::Displacement::new(
            knotwork::kernel::displace::Pattern::ALL[0],
            0.05,
            3.0,
        )
        .unwrap(),
    );
    scene.objects.push(displaced);
    let mut bent = scene.objects[4].clone();
    bent.name = "in a lattice".into();
    let box_ = bent.tessellate(Tessellation::Segments(2), false).unwrap()[0]
        .positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let mut lattice = knotwork::kernel::ffd::Lattice::around(box_.0, box_.1, [2, 2, 2]).unwrap();
    let corner = lattice.points()[0];
    lattice
        .set_point(0, corner + DVec3::new(0.1, 0.2, -0.15))
        .unwrap();
    bent.lattice = Some(lattice);
    scene.objects.push(bent);
    let motion = random_motion(&mut rng);
    for object in &mut scene.objects {
        if let Ok(moved) = object.geometry.kind().transformed(&motion) {
            object.geometry = moved;
        }
    }
    let project = Project { scene, view: None };
    let options = ExportOptions {
        tessellation: Tessellation::Tolerance(gltf::default_tolerance(&project.scene)),
        curvature: true,
        colors: None,
    };
    // Steps as the page takes them: while an object waits for its grids, the next step comes
    // a frame later (a millisecond here).
    let export = |mut job: ExportJob| -> (Vec<u8>, usize) {
        let started = std::time::Instant::now();
        let mut waits = 0;
        while !job.step().unwrap() {
            if job.is_waiting() {
                waits += 1;
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
            assert!(
                started.elapsed().as_secs() < 300,
                "an export that never ends"
            );
        }
        (gltf::to_glb(&job.finish().unwrap()), waits)
    };
    let objects = project.scene.objects.len();

    let mut waiting =
        ExportJob::new(project.clone(), options.clone(), tess::MAX_TRIANGLES).unwrap();
    let grids = Arc::new(GpuGrids::new(&context.device, &context.queue));
    waiting.sample_grids_with(grids.clone());
    let (waited, _) = export(waiting);
    assert_eq!(grids.fallbacks(), 0);

    let kernel = ExportJob::new(project.clone(), options.clone(), tess::MAX_TRIANGLES).unwrap();
    let (on_the_cpu, _) = export(kernel);
    assert_ne!(waited, on_the_cpu, "the GPU's grids are not the kernel's");

    for (hold, fail) in [(0, false), (3, false), (2, true)] {
        let held = Rc::new(Held {
            grids: GpuGrids::new(&context.device, &context.queue),
            hold,
            fail,
            requests: Default::default(),
            held: Default::default(),
        });
        let mut job =
            ExportJob::new(project.clone(), options.clone(), tess::MAX_TRIANGLES).unwrap();
        job.sample_grids_deferred(held.clone());
        let (file, waits) = export(job);
        // Every object but the polygon meshes and curves plans grids: the demo's six, the
        // trimmed, displaced and deformed surfaces.
        assert_eq!(held.requests.get(), objects, "hold {hold}");
        eprintln!("held {hold} polls, failing {fail}: {waits} steps waited");
        if fail {
            assert_eq!(
                file, on_the_cpu,
                "a GPU that fails leaves the kernel's file"
            );
        } else {
            assert_eq!(
                held.held.get(),
                hold * objects,
                "every object's grids were held"
            );
            assert_eq!(
                file, waited,
                "held {hold}: the same file as the export that waits"
            );
        }
    }
}
