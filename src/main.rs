//! The desktop editor and the headless CLI. (The web page starts the same app from `web.rs`.)

#[cfg(not(target_arch = "wasm32"))]
mod cli {
    use std::io::Read;
    use std::process::ExitCode;

    use clap::{Parser, Subcommand, ValueEnum};

    /// knotwork: a freeform-surface editor (Bézier, B-spline, NURBS) evaluated on the GPU.
    /// Without a subcommand it opens the editor window.
    #[derive(Parser)]
    #[command(name = "knotwork", version, about, long_about = None)]
    pub struct Cli {
        /// Open the editor, draw N frames (and let a pending autosave finish), close, and print
        /// the status as JSON (a smoke test; exit code 1 if the status has an error).
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
        pub exit_after_frames: Option<u64>,
        /// Start from the sample scene instead of the autosaved project, and do not autosave.
        #[arg(long)]
        pub fresh: bool,
        /// A file to open at start instead of the autosaved project: a project, a glTF (knotwork's
        /// own exports open as their editable model; other files' meshes as polygon meshes) or
        /// an OBJ.
        #[arg(long, value_name = "FILE")]
        pub open: Option<std::path::PathBuf>,
        #[command(subcommand)]
        pub command: Option<Command>,
    }

    #[derive(Subcommand)]
    pub enum Command {
        /// Evaluate a NURBS surface at parameters: reads {"surface": ..., "params": [[u, v], ...]}
        /// and prints {"results": [...]} with point, normal, derivatives and curvatures.
        Eval {
            /// The request file, or - for standard input.
            request: String,
            /// cpu: the f64 kernel; gpu: the WGSL compute shaders in f32 (headless, no window).
            #[arg(long, value_enum, default_value_t = Backend::Cpu)]
            backend: Backend,
        },
        /// Build a surface from curves or corner data: reads {"construct": "gordon", "u_curves":
        /// [...], "v_curves": [...], "degree": 3}, {"construct": "coons", "bottom", "top",
        /// "left", "right" (and "cross" for the bicubically blended patch)}, {"construct":
        /// "hermite", "points", "su", "sv", "twist"}, {"construct": "loft", "curves", "degree",
        /// "closed", "style"}, {"construct": "network", "u_curves", "v_curves", "degree"},
        /// {"construct": "sweep1", "rail", "profiles", "up"}, {"construct": "sweep2", "rails",
        /// "profiles"}, {"construct": "revolve", "profile", "axis": {"origin", "direction"},
        /// "angle"}, {"construct": "planar", "boundary"}, {"construct": "edge", "curves"} or {"construct":
        /// "extrude", "curve", "direction" or "path"} (curves
        /// as nurbs_curve objects) and
        /// prints the NURBS surface as a nurbs_surface object, or writes it as a knotwork file;
        /// {"construct": "interpolate", "points", "degree", "closed", "parametrization",
        /// "tangents"}, {"construct": "catmull_rom", "points", "alpha"}, circle, ellipse, arc,
        /// polyline, hermite_spline and the curve edits rebuild, fit, offset, project and
        /// extend print a nurbs_curve.
        Construct {
            /// The request file, or - for standard input.
            request: String,
            /// A knotwork JSON file to write instead of printing (the editor opens it).
            #[arg(short, long)]
            output: Option<std::path::PathBuf>,
        },
        /// Describe a STEP file: its bodies, faces per surface type, units, bounding box and
        /// warnings, as JSON. A file that cannot be read exits 1 with the message.
        Info {
            /// The .step/.stp file.
            input: std::path::PathBuf,
        },
        /// Export a project (or a surface in knotwork's JSON format, a .glb/.gltf, an .obj or a
        /// STEP file) as glTF 2.0: OUTPUT.glb, or OUTPUT.gltf with OUTPUT.bin beside it (the
        /// project is embedded, so knotwork can open the export again); or as STEP (AP214) when
        /// OUTPUT ends in .step or .stp. Without --tolerance or --segments the tolerance is 1e-3
        /// of the scene's size (for STEP, 1e-6 of it bounds the edge curves).
        Export {
            /// The file to export.
            input: std::path::PathBuf,
            /// The .glb, .gltf, .step or .stp to write.
            #[arg(short, long)]
            output: std::path::PathBuf,
            /// Largest distance from the triangles to the surface, in model units.
            #[arg(long, conflicts_with = "segments")]
            tolerance: Option<f64>,
            /// Segments per Bézier span edge instead of a tolerance.
            #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
            segments: Option<u32>,
            /// Add the _CURVATURE attribute (K, H, k1, k2 per vertex).
            #[arg(long)]
            curvature: bool,
            /// Add COLOR_0: this curvature on the viewport's colour ramp (automatic range).
            #[arg(long, value_enum)]
            colors: Option<ColorMode>,
        },
        /// Subdivide a cage: INPUT is an OBJ (OpenSubdiv crease tags `t crease 2/1/0 A B S` and
        /// `t corner 1/1/0 V S` are read) or a project (its first subdivision surface or polygon
        /// mesh). Writes OUT.obj with the refined vertices at level N (with --limit their limit
        /// positions and one `vn` limit normal per vertex) and the level's faces, 1-based.
        /// Schemes: catmull-clark, loop, doo-sabin, sqrt3 (Kobbelt) and butterfly (modified);
        /// Doo-Sabin's --limit writes the dual of the level (its faces' centroids, where the
        /// limit surface is known exactly).
        Subdivide {
            input: std::path::PathBuf,
            #[arg(long, value_enum, default_value_t = SchemeArg::CatmullClark)]
            scheme: SchemeArg,
            /// Refinement levels, 0 to 6.
            #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(0..=6))]
            levels: u32,
            /// Write limit positions and normals instead of the refined vertices.
            #[arg(long)]
            limit: bool,
            /// Write an efficient substitute's positions and normals instead: acc or gregory
            /// (Catmull-Clark), pn-triangles (Loop).
            #[arg(long, value_enum)]
            substitute: Option<SubstituteArg>,
            /// Write the adaptive limit instead: each piece refined only until its level's limit
            /// points lie within TOL (a fraction of the cage's diagonal, e.g. 0.002) of its
            /// triangles, up to --levels, crack-free; triangles only (catmull-clark, loop,
            /// butterfly).
            #[arg(long, value_name = "TOL", conflicts_with = "substitute")]
            adaptive: Option<f64>,
            #[arg(long, value_enum, default_value_t = BoundaryArg::EdgeOnly)]
            boundary: BoundaryArg,
            /// How semi-sharp creases decay: uniform (one less per level) or Chaikin's rule.
            #[arg(long, value_enum, default_value_t = CreasingArg::Uniform)]
            creasing: CreasingArg,
            /// cpu: the f64 stencil tables; gpu: the compute shaders the editor uses (f32).
            #[arg(long, value_enum, default_value_t = Backend::Cpu)]
            backend: Backend,
            /// The OBJ to write.
            #[arg(short, long)]
            output: std::path::PathBuf,
        },
        /// Measure continuity on every shared edge of a project's surfaces (boundary curves
        /// within 1e-2 of the smaller object's size of each other; the patches of a patch set
        /// count as surfaces): prints a JSON array, one entry per shared edge, with the largest
        /// gap, angle between the normals (degrees) and normal curvature difference across the
        /// edge, where each lies, and the verdict (open, G0, G1, G2). Tolerances default to the
        /// project's analysis settings (1e-3 of the size, 1°, 5 %).
        Continuity {
            /// The project (or any file knotwork opens).
            project: std::path::PathBuf,
            /// Only these objects (by name).
            #[arg(long, num_args = 1..)]
            objects: Vec<String>,
            /// Samples along each edge.
            #[arg(long, default_value_t = 33, value_parser = clap::value_parser!(u32).range(2..=100_000))]
            samples: u32,
            /// The largest gap that passes G0, as a fraction of the scene's size.
            #[arg(long)]
            distance: Option<f64>,
            /// The largest angle between the normals that passes G1, in degrees.
            #[arg(long)]
            angle: Option<f64>,
            /// The largest relative normal curvature difference that passes G2.
            #[arg(long)]
            curvature: Option<f64>,
        },
        /// Intersect two surfaces of a project (by name) by marching (a curve and a surface, or
        /// two curves: their points, under "points"): prints `{"curves":
        /// [{"closed", "points", "uv": {A: [[u, v], ...], B: [...]}}], "touching": [...]}`,
        /// every branch (closed loops, branches ending on boundaries or trims, several
        /// components), each point within T × the scene's size of both surfaces, chords within
        /// 1e-3 of the size of the curve; points where the surfaces touch are listed apart.
        Intersect {
            /// The project (or any file knotwork opens).
            project: std::path::PathBuf,
            /// The two objects, by name.
            #[arg(long, num_args = 2, required = true)]
            objects: Vec<String>,
            /// Points lie within this fraction of the scene's size of both surfaces.
            #[arg(long, default_value_t = 1e-6)]
            tolerance: f64,
        },
        /// Offset a surface by a signed distance along its normal: writes a project with the
        /// input's objects and the offset as "NAME offset" (exact for planes, spheres,
        /// cylinders, cones, tori and other revolutions of lines and arcs; fitted within T × the
        /// scene's size elsewhere, over the same domain), and
        /// prints how it was made, its deviation and where it folds as JSON.
        Offset {
            /// The project (or any file knotwork opens).
            project: std::path::PathBuf,
            /// The object, by name.
            #[arg(long)]
            object: String,
            /// The signed distance (positive along the normal).
            #[arg(long, allow_negative_numbers = true)]
            distance: f64,
            /// The offset lies within this fraction of the scene's size of the true offset.
            #[arg(long, default_value_t = 1e-4, allow_negative_numbers = true)]
            tolerance: f64,
            /// The project to write.
            #[arg(short, long)]
            output: std::path::PathBuf,
        },
        /// Roll a ball of radius R between two surfaces: writes a project with both trimmed
        /// back to where the ball touches them and the fillet surface named "fillet", and
        /// prints what was made as JSON.
        Fillet {
            /// The project (or any file knotwork opens).
            project: std::path::PathBuf,
            /// The two objects, by name.
            #[arg(long, num_args = 2, required = true)]
            objects: Vec<String>,
            /// The ball's radius.
            #[arg(long, allow_negative_numbers = true)]
            radius: f64,
            /// A radius that varies: R where the contact curve on A starts (its end of lower u,
            /// then lower v), this at its other end, linearly by length in between.
            #[arg(long, allow_negative_numbers = true)]
            radius_end: Option<f64>,
            /// The side of the first surface the ball lies on: front (where its normal points)
            /// or back.
            #[arg(long, default_value = "back", value_parser = ["front", "back"])]
            side_a: String,
            /// The side of the second surface the ball lies on.
            #[arg(long, default_value = "back", value_parser = ["front", "back"])]
            side_b: String,
            /// Contact and tangency within this fraction of the scene's size.
            #[arg(long, default_value_t = 1e-4, allow_negative_numbers = true)]
            tolerance: f64,
            /// The project to write.
            #[arg(short, long)]
            output: std::path::PathBuf,
        },
        /// Blend across the gap between an edge of one surface and an edge of another: writes a
        /// project with the blend surface named "blend" (G0, G1 or G2 to both) and prints how
        /// it was made as JSON.
        Blend {
            /// The project (or any file knotwork opens).
            project: std::path::PathBuf,
            /// The two objects, by name.
            #[arg(long, num_args = 2, required = true)]
            objects: Vec<String>,
            /// The edges, one of each object: a side of the face's parameter rectangle (u0, u1,
            /// v0 or v1), after "FACE:" for an object with several faces; by default the two
            /// edges nearest each other.
            #[arg(long, num_args = 2)]
            edges: Option<Vec<String>>,
            /// G0, G1 or G2.
            #[arg(long, default_value = "g2")]
            continuity: String,
            /// The tension at both edges (or, given twice, at each).
            #[arg(long, num_args = 1..=2, default_values_t = [1.0])]
            tension: Vec<f64>,
            /// The control rows lie within this fraction of the scene's size of the exact
            /// construction.
            #[arg(long, default_value_t = 1e-6, allow_negative_numbers = true)]
            tolerance: f64,
            /// The project to write.
            #[arg(short, long)]
            output: std::path::PathBuf,
        },
        /// Match an edge of a NURBS surface to an edge of another surface at G0, G1 or G2 by
        /// moving the control rows next to it: writes the project with the object changed and
        /// prints how as JSON. `knotwork continuity` confirms the result.
        Match {
            /// The project (or any file knotwork opens).
            project: std::path::PathBuf,
            /// The object whose edge moves, by name.
            #[arg(long)]
            object: String,
            /// The object it is matched to, by name.
            #[arg(long)]
            to: String,
            /// The edges, the moving one first (as for blend); by default the two nearest.
            #[arg(long, num_args = 2)]
            edges: Option<Vec<String>>,
            /// G0, G1 or G2.
            #[arg(long, default_value = "g2")]
            continuity: String,
            /// The new control rows lie within this fraction of the scene's size of the exact
            /// data.
            #[arg(long, default_value_t = 1e-6, allow_negative_numbers = true)]
            tolerance: f64,
            /// The project to write.
            #[arg(short, long)]
            output: std::path::PathBuf,
        },
        /// Join the surfaces that share edges into polysurfaces: writes the project with them
        /// joined and prints each polysurface's faces, shared and naked edges as JSON. Its
        /// export (`knotwork export`) is watertight where the faces were joined.
        Join {
            /// The project (or any file knotwork opens).
            project: std::path::PathBuf,
            /// Edges within this fraction of the scene's size of each other are shared.
            #[arg(long, default_value_t = 1e-6, allow_negative_numbers = true)]
            tolerance: f64,
            /// The project to write.
            #[arg(short, long)]
            output: std::path::PathBuf,
        },
        /// Measure the GPU evaluator: vertices per second of the compute pass (teapot at 64 and
        /// 128 segments, a 32 × 32 bicubic B-spline at 16) and edit latency.
        Bench {
            /// Timed repetitions per figure (the median is printed).
            #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u64).range(1..=10_000))]
            iterations: u64,
            /// Only one group of figures (or all): edit (the compute pass, edits, picking, drags),
            /// webgl2, frame, scale, export, subdivision, trim or analysis.
            #[arg(long, default_value = "all", value_parser = clap::builder::PossibleValuesParser::new(knotwork::bench::GROUPS))]
            only: String,
        },
    }

    #[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
    pub enum SubstituteArg {
        Acc,
        Gregory,
        PnTriangles,
    }

    #[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
    pub enum SchemeArg {
        CatmullClark,
        Loop,
        DooSabin,
        Sqrt3,
        Butterfly,
    }

    #[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
    pub enum BoundaryArg {
        EdgeOnly,
        EdgeAndCorner,
    }

    #[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
    pub enum CreasingArg {
        Uniform,
        Chaikin,
    }

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
                match o.geometry.downcast_ref::<knotwork::scene::SubdivObject>() {
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
            let context =
                knotwork::gpu::GpuContext::headless_blocking().map_err(|e| e.to_string())?;
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

    /// Runs `knotwork bench`.
    pub fn bench(iterations: u64, only: &str) -> ExitCode {
        let context = match knotwork::gpu::GpuContext::headless_blocking() {
            Ok(c) => c,
            Err(e) => {
                eprintln!("knotwork bench: {e}");
                return ExitCode::FAILURE;
            }
        };
        match knotwork::bench::run(&context, iterations as usize, only, &mut std::io::stdout()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("knotwork bench: {e}");
                ExitCode::FAILURE
            }
        }
    }

    #[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
    pub enum ColorMode {
        Gaussian,
        Mean,
        K1,
        K2,
    }

    /// The options of `knotwork export`.
    pub struct ExportArgs<'a> {
        pub input: &'a std::path::Path,
        pub output: &'a std::path::Path,
        pub tolerance: Option<f64>,
        pub segments: Option<u32>,
        pub curvature: bool,
        pub colors: Option<ColorMode>,
    }

    /// `knotwork intersect`: every branch of the intersection of two named objects' faces (each
    /// face of one with each of the other), as JSON on standard output.
    pub fn intersect(path: &std::path::Path, names: &[String], tolerance: f64) -> ExitCode {
        use knotwork::kernel::intersect::IntersectOptions;
        let run = || -> Result<serde_json::Value, String> {
            if !(tolerance.is_finite() && tolerance > 0.0) {
                return Err(format!(
                    "--tolerance must be a number above 0 (got {tolerance})"
                ));
            }
            let project = open_project(path)?;
            let scene = &project.scene;
            let size = knotwork::doc::surface_ops::scene_size(scene);
            if let Some(points) = curve_points(scene, names, tolerance * size, 1e-2 * size)? {
                return Ok(serde_json::json!({
                    "curves": [],
                    "points": points,
                    "touching": [],
                }));
            }
            let object = |name: &String| surface_named(scene, name).map(|k| &scene.objects[k]);
            let (a, b) = (object(&names[0])?, object(&names[1])?);
            let options = IntersectOptions {
                tolerance: tolerance * size,
                ..IntersectOptions::for_size(size)
            };
            let started = std::time::Instant::now();
            let mut curves = Vec::new();
            let mut touching = Vec::new();
            let found_all = knotwork::doc::surface_ops::object_intersections(a, b, &options)
                .map_err(|e| e.to_string())?;
            for found in found_all {
                touching.extend(found.touching.iter().map(|p| p.to_array()));
                for c in found.curves {
                    let uv = |points: &[glam::DVec2]| -> Vec<[f64; 2]> {
                        points.iter().map(|p| p.to_array()).collect()
                    };
                    let mut by_name = serde_json::Map::new();
                    by_name.insert(a.name.clone(), serde_json::json!(uv(&c.uv_a)));
                    by_name.insert(b.name.clone(), serde_json::json!(uv(&c.uv_b)));
                    curves.push(serde_json::json!({
                        "closed": c.closed,
                        "points": c.points.iter().map(|p| p.to_array()).collect::<Vec<_>>(),
                        "uv": by_name,
                    }));
                }
            }
            eprintln!(
                "{} branch(es), {} touching point(s) in {:.1} ms (size {size:.4}, tolerance {:.3e})",
                curves.len(),
                touching.len(),
                started.elapsed().as_secs_f64() * 1e3,
                options.tolerance
            );
            Ok(serde_json::json!({ "curves": curves, "touching": touching }))
        };
        finish("intersect", run())
    }

    /// Where a curve meets a surface or another curve (`None` when neither named object is a
    /// curve): each point with the curve's parameter `t` (per curve, by name, for two curves)
    /// and the surface's `uv` by name.
    fn curve_points(
        scene: &knotwork::scene::Scene,
        names: &[String],
        tolerance: f64,
        smallest: f64,
    ) -> Result<Option<Vec<serde_json::Value>>, String> {
        use knotwork::kernel::intersect_curve::{intersect_curve_surface, intersect_curves};
        let find = |name: &String| {
            scene
                .objects
                .iter()
                .find(|o| &o.name == name)
                .ok_or_else(|| format!("no object named {name:?}"))
        };
        let (a, b) = (find(&names[0])?, find(&names[1])?);
        let (ca, cb) = (a.kind().space_curve(), b.kind().space_curve());
        let points = match (ca, cb) {
            (None, None) => return Ok(None),
            (Some(x), Some(y)) => intersect_curves(x, y, tolerance, smallest)
                .map_err(|e| e.to_string())?
                .into_iter()
                .map(|h| {
                    let mut t = serde_json::Map::new();
                    t.insert(a.name.clone(), h.t_a.into());
                    t.insert(b.name.clone(), h.t_b.into());
                    serde_json::json!({ "point": h.point.to_array(), "t": t })
                })
                .collect(),
            (Some(curve), None) | (None, Some(curve)) => {
                let (surface, curve_name) = if ca.is_some() {
                    (b, &a.name)
                } else {
                    (a, &b.name)
                };
                surface_named(scene, &surface.name)?;
                let mut out = Vec::new();
                for (_, face) in surface.faces() {
                    for h in intersect_curve_surface(curve, face.as_ref(), tolerance, smallest)
                        .map_err(|e| e.to_string())?
                    {
                        let mut uv = serde_json::Map::new();
                        uv.insert(surface.name.clone(), serde_json::json!(h.uv.to_array()));
                        let mut t = serde_json::Map::new();
                        t.insert(curve_name.clone(), h.t.into());
                        out.push(serde_json::json!({
                            "point": h.point.to_array(), "t": t, "uv": uv,
                        }));
                    }
                }
                out
            }
        };
        Ok(Some(points))
    }

    /// The project (or any file knotwork opens) at `path`.
    fn open_project(path: &std::path::Path) -> Result<knotwork::io::project::Project, String> {
        knotwork::app::open_path(path).map_err(|e| format!("cannot open {}: {e}", path.display()))
    }

    /// The index of the object named `name`, which must have faces.
    fn surface_named(scene: &knotwork::scene::Scene, name: &str) -> Result<usize, String> {
        let k = scene
            .objects
            .iter()
            .position(|o| o.name == name)
            .ok_or_else(|| format!("no object named {name:?}"))?;
        let o = &scene.objects[k];
        if o.faces().is_empty() {
            return Err(format!(
                "{name} is {}, which has no faces",
                o.kind().kind_name()
            ));
        }
        Ok(k)
    }

    /// Writes `project` to `output`.
    fn write_project(
        project: &knotwork::io::project::Project,
        output: &std::path::Path,
    ) -> Result<(), String> {
        std::fs::write(output, knotwork::io::project::write(project))
            .map_err(|e| format!("cannot write {}: {e}", output.display()))
    }

    /// Prints `result`'s JSON on standard output (exit code 0) or its error on standard error
    /// (exit code 1), after `knotwork COMMAND: `.
    fn finish(command: &str, result: Result<serde_json::Value, String>) -> ExitCode {
        match result {
            Ok(json) => {
                println!("{json}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("knotwork {command}: {e}");
                ExitCode::FAILURE
            }
        }
    }

    /// `knotwork offset`: the project with the offset of the named object added.
    pub fn offset(
        path: &std::path::Path,
        name: &str,
        distance: f64,
        tolerance: f64,
        output: &std::path::Path,
    ) -> ExitCode {
        use knotwork::doc::surface_ops::{offset_geometry, offset_summary};
        let run = || -> Result<serde_json::Value, String> {
            let mut project = open_project(path)?;
            let k = surface_named(&project.scene, name)?;
            let started = std::time::Instant::now();
            let made = offset_geometry(&project.scene, k, distance, tolerance)
                .map_err(|e| e.to_string())?;
            let millis = started.elapsed().as_secs_f64() * 1e3;
            let offsets: Vec<_> = made.iter().map(|(_, o)| o.clone()).collect();
            let mut names = Vec::new();
            for (geometry, _) in made {
                let object_name = project.scene.unique_name(&format!("{name} offset"));
                names.push(object_name.clone());
                project
                    .scene
                    .objects
                    .push(knotwork::scene::SceneObject::new(object_name, geometry));
            }
            write_project(&project, output)?;
            let summary = offset_summary(&offsets, distance);
            eprintln!("{summary} in {millis:.1} ms; wrote {}", output.display());
            let folds: Vec<_> = offsets
                .iter()
                .flat_map(|o| &o.folds)
                .map(|f| {
                    serde_json::json!({
                        "point": f.point.to_array(),
                        "uv": f.uv.to_array(),
                        "radius": f.radius,
                    })
                })
                .collect();
            Ok(serde_json::json!({
                "objects": names,
                "exact": offsets.iter().all(|o| o.is_exact()),
                "deviation": offsets.iter().map(|o| o.deviation).fold(0.0, f64::max),
                "fold_samples": offsets.iter().map(|o| o.fold_samples).sum::<usize>(),
                "folds": folds,
                "summary": summary,
            }))
        };
        finish("offset", run())
    }

    /// The options of `knotwork fillet`.
    pub struct FilletArgs<'a> {
        pub input: &'a std::path::Path,
        pub names: &'a [String],
        pub radius: f64,
        pub radius_end: Option<f64>,
        pub sides: [&'a str; 2],
        pub tolerance: f64,
        pub output: &'a std::path::Path,
    }

    /// `knotwork fillet`: the project with both objects trimmed back and the fillet added.
    pub fn fillet(args: FilletArgs) -> ExitCode {
        use knotwork::doc::surface_ops::{FilletRequest, fillet_objects};
        let run = || -> Result<serde_json::Value, String> {
            let mut project = open_project(args.input)?;
            let a = surface_named(&project.scene, &args.names[0])?;
            let b = surface_named(&project.scene, &args.names[1])?;
            let request = FilletRequest {
                a,
                b,
                radius: args.radius,
                radius_end: args.radius_end,
                front_a: args.sides[0] == "front",
                front_b: args.sides[1] == "front",
                tolerance: args.tolerance,
            };
            let started = std::time::Instant::now();
            let made = fillet_objects(&project.scene, &request).map_err(|e| e.to_string())?;
            let millis = started.elapsed().as_secs_f64() * 1e3;
            let mut trimmed = Vec::new();
            for (index, after) in [a, b].into_iter().zip(made.trimmed) {
                if let Some(after) = after {
                    trimmed.push(after.name.clone());
                    project.scene.objects[index] = after;
                }
            }
            let name = project.scene.unique_name("fillet");
            project
                .scene
                .objects
                .push(knotwork::scene::SceneObject::new(
                    name.clone(),
                    knotwork::scene::ObjectGeometry::new(made.fillet.surface.clone()),
                ));
            write_project(&project, args.output)?;
            eprintln!(
                "{} sections in {millis:.1} ms; wrote {}",
                made.fillet.centres.len(),
                args.output.display()
            );
            for note in &made.notes {
                eprintln!("knotwork fillet: {note}");
            }
            Ok(serde_json::json!({
                "fillet": name,
                "trimmed": trimmed,
                "sections": made.fillet.centres.len(),
                "closed": made.fillet.closed,
                "branches": made.fillet.branches,
                "notes": made.notes,
            }))
        };
        finish("fillet", run())
    }

    /// An edge named "v0" or "FACE:v0".
    fn parse_edge(text: &str) -> Result<knotwork::doc::surface_ops::FaceSide, String> {
        use knotwork::kernel::continuity::Side;
        let (face, side) = match text.split_once(':') {
            Some((f, s)) => (
                f.trim()
                    .parse::<usize>()
                    .map_err(|_| format!("edge {text:?}: {f:?} is not a face number"))?,
                s,
            ),
            None => (0, text),
        };
        let side = Side::ALL
            .into_iter()
            .find(|k| k.name() == side.trim().to_ascii_lowercase())
            .ok_or_else(|| format!("edge {text:?}: the side must be u0, u1, v0 or v1"))?;
        Ok((face, side))
    }

    /// The edges of `--edges`, parsed.
    fn parse_edges(
        edges: Option<&[String]>,
    ) -> Result<Option<[knotwork::doc::surface_ops::FaceSide; 2]>, String> {
        edges
            .map(|e| Ok([parse_edge(&e[0])?, parse_edge(&e[1])?]))
            .transpose()
    }

    fn parse_continuity(text: &str) -> Result<knotwork::kernel::blend::EdgeContinuity, String> {
        knotwork::kernel::blend::EdgeContinuity::parse(text)
            .ok_or_else(|| format!("the continuity must be g0, g1 or g2, not {text:?}"))
    }

    /// Applies `command` to the project at `input`, writes it to `output` and prints the
    /// command's label with `what` of the scene after it.
    fn apply_and_write(
        name: &str,
        input: &std::path::Path,
        output: &std::path::Path,
        command: impl FnOnce(&knotwork::scene::Scene) -> Result<knotwork::doc::Command, String>,
        what: impl FnOnce(&knotwork::scene::Scene) -> serde_json::Value,
    ) -> ExitCode {
        let run = || -> Result<serde_json::Value, String> {
            let mut project = open_project(input)?;
            let command = command(&project.scene)?;
            let started = std::time::Instant::now();
            let edit =
                knotwork::doc::apply(&mut project.scene, &command).map_err(|e| e.to_string())?;
            let millis = started.elapsed().as_secs_f64() * 1e3;
            write_project(&project, output)?;
            eprintln!(
                "{} in {millis:.1} ms; wrote {}",
                edit.label,
                output.display()
            );
            let mut json = what(&project.scene);
            json["summary"] = edit.label.into();
            Ok(json)
        };
        finish(name, run())
    }

    /// The options of `knotwork blend` and `knotwork match`.
    pub struct EdgeArgs<'a> {
        pub input: &'a std::path::Path,
        /// The two objects (for a match: the one that moves first).
        pub names: [&'a str; 2],
        pub edges: Option<&'a [String]>,
        pub continuity: &'a str,
        pub tension: &'a [f64],
        pub tolerance: f64,
        pub output: &'a std::path::Path,
    }

    /// `knotwork blend`: the project with the blend between two objects' edges added.
    pub fn blend(args: EdgeArgs) -> ExitCode {
        use knotwork::doc::surface_ops::BlendRequest;
        let tension = [
            args.tension.first().copied().unwrap_or(1.0),
            args.tension
                .get(1)
                .or(args.tension.first())
                .copied()
                .unwrap_or(1.0),
        ];
        apply_and_write(
            "blend",
            args.input,
            args.output,
            |scene| {
                Ok(knotwork::doc::Command::Blend(BlendRequest {
                    a: surface_named(scene, args.names[0])?,
                    b: surface_named(scene, args.names[1])?,
                    edges: parse_edges(args.edges)?,
                    continuity: parse_continuity(args.continuity)?,
                    tension,
                    tolerance: args.tolerance,
                }))
            },
            |scene| {
                let name = scene.objects.last().map(|o| o.name.clone());
                serde_json::json!({ "blend": name })
            },
        )
    }

    /// `knotwork match`: the project with one object's edge matched to another's.
    pub fn match_edge(args: EdgeArgs) -> ExitCode {
        use knotwork::doc::surface_ops::MatchRequest;
        apply_and_write(
            "match",
            args.input,
            args.output,
            |scene| {
                Ok(knotwork::doc::Command::Match(MatchRequest {
                    object: surface_named(scene, args.names[0])?,
                    target: surface_named(scene, args.names[1])?,
                    edges: parse_edges(args.edges)?,
                    continuity: parse_continuity(args.continuity)?,
                    tolerance: args.tolerance,
                }))
            },
            |_| serde_json::json!({ "matched": args.names[0] }),
        )
    }

    /// `knotwork join`: the project with its surfaces joined where they share edges.
    pub fn join(path: &std::path::Path, tolerance: f64, output: &std::path::Path) -> ExitCode {
        use knotwork::scene::polysurface::Polysurface;
        let run = || -> Result<serde_json::Value, String> {
            let mut project = open_project(path)?;
            let started = std::time::Instant::now();
            let command = knotwork::doc::Command::Join {
                objects: Vec::new(),
                tolerance,
            };
            let edit =
                knotwork::doc::apply(&mut project.scene, &command).map_err(|e| e.to_string())?;
            let millis = started.elapsed().as_secs_f64() * 1e3;
            let mut joined = Vec::new();
            for object in &project.scene.objects {
                let Some(p) = object.geometry.downcast_ref::<Polysurface>() else {
                    continue;
                };
                let topology = p.topology().map_err(|e| e.to_string())?;
                joined.push(serde_json::json!({
                    "name": object.name,
                    "faces": p.faces().len(),
                    "shared_edges": topology.shared.len(),
                    "naked_edges": topology.naked.len(),
                    "closed": topology.is_closed(),
                }));
            }
            write_project(&project, output)?;
            eprintln!(
                "{} in {millis:.1} ms; wrote {}",
                edit.label,
                output.display()
            );
            Ok(serde_json::json!({ "polysurfaces": joined }))
        };
        finish("join", run())
    }

    /// Runs `knotwork export`: exit code 0 with a summary on stdout, 1 with the error on stderr.
    /// `knotwork continuity`: the shared edges' numbers as JSON on standard output.
    pub fn continuity(
        path: &std::path::Path,
        names: &[String],
        samples: u32,
        [distance, angle, curvature]: [Option<f64>; 3],
    ) -> ExitCode {
        use knotwork::scene::continuity::{ContinuityOptions, analyse};
        let run = || -> Result<String, String> {
            let project = knotwork::app::open_path(path)
                .map_err(|e| format!("cannot open {}: {e}", path.display()))?;
            let scene = &project.scene;
            let mut objects = Vec::new();
            for name in names {
                let k = scene
                    .objects
                    .iter()
                    .position(|o| &o.name == name)
                    .ok_or_else(|| format!("no object named {name:?}"))?;
                objects.push(k);
            }
            let saved = project
                .view
                .map(|v| v.analysis)
                .unwrap_or_default()
                .continuity_options();
            let options = ContinuityOptions {
                gap: distance.unwrap_or(saved.gap),
                angle_degrees: angle.unwrap_or(saved.angle_degrees),
                curvature: curvature.unwrap_or(saved.curvature),
                samples: samples as usize,
            };
            for (name, value) in [
                ("--distance", options.gap),
                ("--angle", options.angle_degrees),
                ("--curvature", options.curvature),
            ] {
                if !(value.is_finite() && value > 0.0) {
                    return Err(format!("{name} must be a number above 0 (got {value})"));
                }
            }
            let started = std::time::Instant::now();
            let report = analyse(
                scene,
                (!objects.is_empty()).then_some(&objects[..]),
                &options,
            );
            eprintln!(
                "{} shared edges among {} faces in {:.1} ms (size {:.4}, gap tolerance {:.3e}, angle {}°, curvature {})",
                report.edges.len(),
                report.faces.len(),
                started.elapsed().as_secs_f64() * 1e3,
                report.size,
                report.tolerances.distance,
                report.tolerances.angle_degrees,
                report.tolerances.curvature
            );
            serde_json::to_string_pretty(&report.to_json(scene)).map_err(|e| e.to_string())
        };
        match run() {
            Ok(json) => {
                println!("{json}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("knotwork continuity: {e}");
                ExitCode::FAILURE
            }
        }
    }

    pub fn export(args: ExportArgs<'_>) -> ExitCode {
        match export_files(&args) {
            Ok(summary) => {
                println!("{summary}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("knotwork export: {e}");
                ExitCode::FAILURE
            }
        }
    }

    /// Runs `knotwork info`: the STEP file's description as JSON.
    pub fn info(input: &std::path::Path) -> ExitCode {
        let result = std::fs::read(input)
            .map_err(|e| format!("cannot read {}: {e}", input.display()))
            .and_then(|bytes| knotwork::io::step::info(&bytes).map_err(|e| e.to_string()));
        match result {
            Ok(json) => {
                println!("{json:#}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("knotwork info: {e}");
                ExitCode::FAILURE
            }
        }
    }

    fn export_files(args: &ExportArgs<'_>) -> Result<String, String> {
        use knotwork::io::gltf;
        use knotwork::kernel::tess::Tessellation;
        let started = std::time::Instant::now();
        let input = args.input.display().to_string();
        let project = knotwork::app::open_path(args.input)
            .map_err(|e| format!("cannot open {input}: {e}"))?;
        let extension = knotwork::io::formats::extension(&args.output.display().to_string());
        if extension == "step" || extension == "stp" {
            let tolerance = args
                .tolerance
                .unwrap_or_else(|| knotwork::io::step::default_tolerance(&project.scene));
            let name = args
                .output
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let knotwork::io::step::StepExport {
                text,
                left_out,
                approximated,
            } = knotwork::io::step::export_scene(&project.scene, &name, tolerance)
                .map_err(|e| e.to_string())?;
            for note in &approximated {
                eprintln!("knotwork export: {note}");
            }
            std::fs::write(args.output, &text)
                .map_err(|e| format!("cannot write {}: {e}", args.output.display()))?;
            for why in &left_out {
                eprintln!("knotwork export: left out {why}");
            }
            return Ok(format!(
                "wrote {} ({} bytes), in {:.0} ms",
                args.output.display(),
                text.len(),
                started.elapsed().as_secs_f64() * 1e3
            ));
        }
        let tessellation = match (args.tolerance, args.segments) {
            (_, Some(n)) => Tessellation::Segments(n),
            (Some(t), None) => Tessellation::Tolerance(t),
            (None, None) => Tessellation::Tolerance(gltf::default_tolerance(&project.scene)),
        };
        let colors = args.colors.map(|mode| {
            gltf::CurvatureColors::automatic(
                &project.scene,
                mode as usize,
                knotwork::gpu::records::curvature_ramp_rgb(),
            )
        });
        let options = gltf::ExportOptions {
            tessellation,
            curvature: args.curvature,
            colors,
        };
        let export = gltf::export(&project, &options).map_err(|e| e.to_string())?;
        let output = args.output.display().to_string();
        let mut written = Vec::new();
        for (path, bytes) in gltf::files(&export, &output) {
            std::fs::write(&path, &bytes).map_err(|e| format!("cannot write {path}: {e}"))?;
            written.push(format!("{path} ({} bytes)", bytes.len()));
        }
        let how = match tessellation {
            Tessellation::Tolerance(t) => format!("tolerance {t:.3e}"),
            Tessellation::Segments(n) => format!("{n} segments per span"),
        };
        Ok(format!(
            "wrote {}: {} objects, {} triangles, {} vertices, {how}, in {:.0} ms",
            written.join(", "),
            project.scene.objects.iter().filter(|o| o.visible).count(),
            export.triangles,
            export.vertices,
            started.elapsed().as_secs_f64() * 1e3
        ))
    }

    #[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
    pub enum Backend {
        Cpu,
        Gpu,
    }

    /// Runs `knotwork eval`: exit code 0 with the results on stdout, 1 with the error on stderr.
    /// A request file's text, or standard input's for `-`.
    fn read_request(path: &str) -> Result<String, String> {
        if path == "-" {
            let mut text = String::new();
            std::io::stdin()
                .read_to_string(&mut text)
                .map(|_| text)
                .map_err(|e| format!("cannot read standard input: {e}"))
        } else {
            std::fs::read_to_string(path).map_err(|e| format!("cannot read {path}: {e}"))
        }
    }

    pub fn eval(path: &str, backend: Backend) -> ExitCode {
        let text = match read_request(path) {
            Ok(text) => text,
            Err(message) => {
                eprintln!("knotwork eval: {message}");
                return ExitCode::FAILURE;
            }
        };
        let response = match backend {
            Backend::Cpu => knotwork::io::eval::evaluate_request(&text).map_err(|e| e.to_string()),
            Backend::Gpu => eval_gpu(&text),
        };
        match response {
            Ok(response) => {
                println!("{response}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("knotwork eval: {e}");
                ExitCode::FAILURE
            }
        }
    }

    /// Runs `knotwork construct`: the surface as JSON on standard output, or a knotwork file
    /// at `output` (which the editor opens).
    pub fn construct(path: &str, output: Option<&std::path::Path>) -> ExitCode {
        let result = read_request(path).and_then(|text| {
            let knotwork::io::construct::Built {
                geometry,
                name,
                report,
            } = knotwork::io::construct::build(&text).map_err(|e| e.to_string())?;
            if let Some(report) = report {
                eprintln!("knotwork construct: {report}");
            }
            match output {
                None => Ok(knotwork::io::construct::geometry_value(geometry, name).to_string()),
                Some(_) if matches!(geometry, knotwork::scene::json::Geometry::Curve(_)) => {
                    Err(format!(
                        "the {name} is a curve, and the editor opens surfaces only: leave out -o \
                         to print it"
                    ))
                }
                Some(out) => {
                    let objects = [knotwork::scene::json::NamedGeometry {
                        name: Some(name.to_string()),
                        geometry,
                    }];
                    std::fs::write(out, knotwork::scene::json::write(&objects))
                        .map_err(|e| format!("cannot write {}: {e}", out.display()))?;
                    Ok(format!("wrote {} ({name})", out.display()))
                }
            }
        });
        match result {
            Ok(text) => {
                println!("{text}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("knotwork construct: {e}");
                ExitCode::FAILURE
            }
        }
    }

    /// The request evaluated by the compute shaders on a headless device.
    fn eval_gpu(text: &str) -> Result<serde_json::Value, String> {
        use knotwork::io::eval;
        let request = eval::parse_request(text).map_err(|e| e.to_string())?;
        let context = knotwork::gpu::GpuContext::headless_blocking().map_err(|e| e.to_string())?;
        let mut failure = None;
        let response = eval::respond(&request, |surface, pairs| {
            match knotwork::gpu::point_eval::evaluate_points(
                &context.device,
                &context.queue,
                surface,
                pairs,
            ) {
                Ok(results) => results
                    .into_iter()
                    .map(|r| r.map_err(|e| e.to_string()))
                    .collect(),
                Err(e) => {
                    failure = Some(e.to_string());
                    Vec::new()
                }
            }
        });
        match failure {
            Some(e) => Err(e),
            None => Ok(response),
        }
    }
}

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    use clap::Parser;
    use std::process::ExitCode;

    let cli = cli::Cli::parse();
    match &cli.command {
        Some(cli::Command::Eval { request, backend }) => return cli::eval(request, *backend),
        Some(cli::Command::Bench { iterations, only }) => return cli::bench(*iterations, only),
        Some(cli::Command::Construct { request, output }) => {
            return cli::construct(request, output.as_deref());
        }
        Some(cli::Command::Subdivide {
            input,
            scheme,
            levels,
            limit,
            substitute,
            adaptive,
            boundary,
            creasing,
            backend,
            output,
        }) => {
            return cli::subdivide(cli::SubdivideArgs {
                input,
                output,
                scheme: *scheme,
                levels: *levels,
                limit: *limit,
                substitute: *substitute,
                adaptive: *adaptive,
                boundary: *boundary,
                creasing: *creasing,
                backend: *backend,
            });
        }
        Some(cli::Command::Intersect {
            project,
            objects,
            tolerance,
        }) => {
            return cli::intersect(project, objects, *tolerance);
        }
        Some(cli::Command::Offset {
            project,
            object,
            distance,
            tolerance,
            output,
        }) => {
            return cli::offset(project, object, *distance, *tolerance, output);
        }
        Some(cli::Command::Join {
            project,
            tolerance,
            output,
        }) => {
            return cli::join(project, *tolerance, output);
        }
        Some(cli::Command::Blend {
            project,
            objects,
            edges,
            continuity,
            tension,
            tolerance,
            output,
        }) => {
            return cli::blend(cli::EdgeArgs {
                input: project,
                names: [&objects[0], &objects[1]],
                edges: edges.as_deref(),
                continuity,
                tension,
                tolerance: *tolerance,
                output,
            });
        }
        Some(cli::Command::Match {
            project,
            object,
            to,
            edges,
            continuity,
            tolerance,
            output,
        }) => {
            return cli::match_edge(cli::EdgeArgs {
                input: project,
                names: [object, to],
                edges: edges.as_deref(),
                continuity,
                tension: &[],
                tolerance: *tolerance,
                output,
            });
        }
        Some(cli::Command::Fillet {
            project,
            objects,
            radius,
            radius_end,
            side_a,
            side_b,
            tolerance,
            output,
        }) => {
            return cli::fillet(cli::FilletArgs {
                input: project,
                names: objects,
                radius: *radius,
                radius_end: *radius_end,
                sides: [side_a, side_b],
                tolerance: *tolerance,
                output,
            });
        }
        Some(cli::Command::Continuity {
            project,
            objects,
            samples,
            distance,
            angle,
            curvature,
        }) => {
            return cli::continuity(project, objects, *samples, [*distance, *angle, *curvature]);
        }
        Some(cli::Command::Info { input }) => return cli::info(input),
        Some(cli::Command::Export {
            input,
            output,
            tolerance,
            segments,
            curvature,
            colors,
        }) => {
            return cli::export(cli::ExportArgs {
                input,
                output,
                tolerance: *tolerance,
                segments: *segments,
                curvature: *curvature,
                colors: *colors,
            });
        }
        None => {}
    }
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("knotwork=info,warn"),
    )
    .init();
    let exit_after_frames = cli.exit_after_frames;
    let restore = !cli.fresh;
    let open = match &cli.open {
        // A file that cannot be read stops here; one that cannot be parsed opens the editor
        // with the sample scene and the error shown, as opening it from the editor would.
        Some(path) => match std::fs::metadata(path) {
            Ok(_) => Some((path.display().to_string(), knotwork::app::open_path(path))),
            Err(e) => {
                eprintln!("knotwork: could not open {}: {e}", path.display());
                return ExitCode::FAILURE;
            }
        },
        None => None,
    };
    let options = eframe::NativeOptions {
        viewport: eframe::egui::ViewportBuilder::default()
            .with_title("knotwork")
            .with_inner_size([1280.0, 800.0]),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: knotwork::app::wgpu_configuration(false),
        ..Default::default()
    };
    let result = eframe::run_native(
        "knotwork",
        options,
        Box::new(move |cc| {
            let mut app = knotwork::app::KnotworkApp::new(cc, None, restore);
            if let Some((name, project)) = open {
                app.open_result(&name, project);
            }
            Ok(Box::new(match exit_after_frames {
                Some(frames) => app.exit_after_frames(frames),
                None => app,
            }))
        }),
    );
    if let Err(e) = result {
        eprintln!("knotwork: the editor could not start: {e}");
        return ExitCode::FAILURE;
    }
    if exit_after_frames.is_some() {
        let status = knotwork::status::current();
        println!("{}", status.to_json());
        if status.error.is_some() {
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}

#[cfg(target_arch = "wasm32")]
fn main() {}
