//! `knotwork subdivide`: a cage subdivided, written as OBJ.

use std::process::ExitCode;

use super::*;

/// The options of `knotwork subdivide`.
pub struct SubdivideArgs<'a> {
    pub input: &'a std::path::Path,
    pub output: &'a std::path::Path,
    pub scheme: SchemeArg,
    pub levels: u32,
    pub limit: bool,
    pub substitute: Option<SubstituteArg>,
    pub adaptive: Option<f64>,
    pub boundary: BoundaryArg,
    pub creasing: CreasingArg,
    pub backend: Backend,
}

/// Runs `knotwork subdivide`: exit code 0 with a summary, 1 with the error.
pub fn subdivide(args: SubdivideArgs<'_>) -> ExitCode {
    match subdivide_file(&args) {
        Ok(summary) => {
            println!("{summary}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("knotwork subdivide: {e}");
            ExitCode::FAILURE
        }
    }
}

fn subdivide_file(args: &SubdivideArgs<'_>) -> Result<String, String> {
    use knotwork::kernel::subdiv::{Boundary, Creasing, Options, Scheme, SubdivisionSurface};
    let text = std::fs::read_to_string(args.input)
        .map_err(|e| format!("{}: {e}", args.input.display()))?;
    let is_obj = args
        .input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    let options = Options {
        scheme: match args.scheme {
            SchemeArg::CatmullClark => Scheme::CatmullClark,
            SchemeArg::Loop => Scheme::Loop,
            SchemeArg::DooSabin => Scheme::DooSabin,
            SchemeArg::Sqrt3 => Scheme::Sqrt3,
            SchemeArg::Butterfly => Scheme::Butterfly,
        },
        boundary: match args.boundary {
            BoundaryArg::EdgeOnly => Boundary::EdgeOnly,
            BoundaryArg::EdgeAndCorner => Boundary::EdgeAndCorner,
        },
        creasing: match args.creasing {
            CreasingArg::Uniform => Creasing::Uniform,
            CreasingArg::Chaikin => Creasing::Chaikin,
        },
    };
    let surface = if is_obj {
        let parsed = knotwork::io::obj::parse(&text).map_err(|e| e.to_string())?;
        let faces = parsed.all_faces();
        let mesh = knotwork::kernel::PolygonMesh::new(parsed.vertices, &faces)
            .map_err(|e| e.to_string())?;
        SubdivisionSurface::new(mesh, parsed.creases, parsed.corners, options, 0)
    } else {
        let project = knotwork::io::project::read(&text).map_err(|e| e.to_string())?;
        let found = project.scene.objects.iter().find_map(|o| {
            match o.geometry.as_subdivision() {
                // A subdivision surface keeps its creases and corners.
                Some(s) => Some(s.surface.with(
                    options,
                    0,
                    s.surface.creases().to_vec(),
                    s.surface.corners().to_vec(),
                )),
                None => o.kind().cage().map(|cage| {
                    SubdivisionSurface::new(cage.clone(), Vec::new(), Vec::new(), options, 0)
                }),
            }
        });
        found.ok_or("the project has no subdivision surface or polygon mesh")?
    }
    .map_err(|e| e.to_string())?;
    let on_gpu = args.backend == Backend::Gpu && args.levels > 0;
    use knotwork::kernel::subdiv::patches::Display;
    let display = match (args.substitute, args.limit) {
        (Some(SubstituteArg::Acc), _) => Display::Acc,
        (Some(SubstituteArg::Gregory), _) => Display::Gregory,
        (Some(SubstituteArg::PnTriangles), _) => Display::PnTriangles,
        _ if args.adaptive.is_some() => Display::Limit,
        (None, true) => Display::Limit,
        (None, false) => Display::Refined,
    };
    // The adaptive limit: the level's limit points, then the triangles the pieces show.
    let adaptive = match args.adaptive {
        Some(tolerance) => {
            if args.levels == 0 {
                return Err("adaptive refinement needs --levels 1 or more".into());
            }
            let layout = surface
                .adaptive_layout(args.levels, tolerance)
                .map_err(|e| e.to_string())?;
            let triangles = surface
                .adaptive_triangles(args.levels, &layout)
                .map_err(|e| e.to_string())?;
            Some((tolerance, layout, triangles))
        }
        None => None,
    };
    // On the GPU the CPU gives the topology and the points on no face.
    let shown = match display.substitute() {
        Some(kind) => {
            kind.check_scheme(surface.options.scheme)
                .map_err(|e| e.to_string())?;
            if args.levels == 0 {
                return Err("a substitute needs --levels 1 or more".into());
            }
            surface.substitute_mesh(args.levels, kind)
        }
        None => surface.display_mesh(args.levels, display),
    }
    .map_err(|e| e.to_string())?;
    let mut positions = shown.positions;
    let mut normals = if display != Display::Refined {
        shown.normals
    } else {
        Vec::new()
    };
    if on_gpu {
        let context = knotwork::gpu::GpuContext::headless_blocking().map_err(|e| e.to_string())?;
        let gpu = match &adaptive {
            Some((tolerance, _, _)) => knotwork::gpu::subdiv_eval::evaluate_adaptive(
                &context.device,
                &context.queue,
                &surface,
                args.levels,
                *tolerance,
            ),
            None => knotwork::gpu::subdiv_eval::evaluate_level(
                &context.device,
                &context.queue,
                &surface,
                args.levels,
                display,
            ),
        }
        .map_err(|e| e.to_string())?;
        for (v, result) in gpu.into_iter().enumerate() {
            if let (Some((p, n, _)), Some(slot)) = (result, positions.get_mut(v)) {
                *slot = p;
                if let Some(normal) = normals.get_mut(v) {
                    *normal = n;
                }
            }
        }
    }
    let mut polygons = shown.polygons;
    let mut note = String::new();
    if let Some((_, layout, triangles)) = &adaptive {
        let mesh = knotwork::kernel::subdiv::display::DisplayMesh::from_triangles(
            &positions, &normals, triangles,
        );
        (positions, normals, polygons) = (mesh.positions, mesh.normals, mesh.polygons);
        note = format!("; pieces per {}", layout.describe());
    }
    let faces: Vec<&[u32]> = polygons.iter().map(Vec::as_slice).collect();
    let obj = knotwork::io::obj::write(&positions, &normals, &faces);
    std::fs::write(args.output, obj).map_err(|e| format!("{}: {e}", args.output.display()))?;
    Ok(format!(
        "wrote {} ({} vertices, {} faces{note})",
        args.output.display(),
        positions.len(),
        faces.len()
    ))
}
