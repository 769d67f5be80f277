//! The command line: the arguments (clap) and one module per subcommand, each running it
//! and returning the exit code. `main.rs` dispatches to them.

use std::io::Read;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

mod apply;
mod bench;
mod boolean;
mod cage;
mod construct;
mod continuity;
mod edges;
mod eval;
mod export;
mod features;
mod fillet;
mod info;
mod intersect;
mod join;
mod offset;
mod subdivide;

pub use self::apply::apply;
pub use self::bench::bench;
pub use self::boolean::boolean;
pub use self::cage::{CageTool, cage};
pub use self::construct::construct;
pub use self::continuity::continuity;
pub use self::edges::{EdgeArgs, blend, match_edge};
pub use self::eval::eval;
pub use self::export::{ExportArgs, export};
pub use self::features::{Feature, feature, parse_point};
pub use self::fillet::{FilletArgs, fillet};
pub use self::info::info;
pub use self::intersect::intersect;
pub use self::join::join;
pub use self::offset::offset;
pub use self::subdivide::{SubdivideArgs, subdivide};

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

/// The boolean operations on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BooleanArg {
    Union,
    Difference,
    Intersection,
}

impl From<BooleanArg> for knotwork::kernel::boolean::BooleanOp {
    fn from(op: BooleanArg) -> Self {
        match op {
            BooleanArg::Union => Self::Union,
            BooleanArg::Difference => Self::Difference,
            BooleanArg::Intersection => Self::Intersection,
        }
    }
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
        /// The file: STEP (its bodies as the file has them), or a project, glTF or OBJ (its
        /// objects, each with its area and, closed, its volume and centroid).
        input: std::path::PathBuf,
        /// Also look for self-intersections (faces of a body crossing each other), each
        /// body's pairs of faces intersected: slower on large files.
        #[arg(long)]
        self_intersections: bool,
    },
    /// Export a project (or a surface in knotwork's JSON format, a .glb/.gltf, an .obj or a
    /// STEP file) as glTF 2.0: OUTPUT.glb, or OUTPUT.gltf with OUTPUT.bin beside it (the
    /// project is embedded, so knotwork can open the export again); as STEP (AP214) when
    /// OUTPUT ends in .step or .stp; for printing as binary STL (.stl) or 3MF (.3mf, with the
    /// document's unit and each object's colour), closed bodies watertight with outward
    /// normals. Without --tolerance or --segments the tolerance is 1e-3 of the scene's size
    /// (for STEP, 1e-6 of it bounds the edge curves).
    Export {
        /// The file to export.
        input: std::path::PathBuf,
        /// The .glb, .gltf, .step, .stp, .stl or .3mf to write.
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
        /// Who evaluates the tessellation grids: the GPU's compute shaders, the f64 kernel, or
        /// (auto) the GPU where a hardware adapter with compute shaders exists, else the CPU.
        /// The triangles are the same either way; the GPU's values agree within f32 precision.
        #[arg(long, value_enum, default_value_t = GridBackend::Auto)]
        backend: GridBackend,
    },
    /// Apply one topology tool to an OBJ cage and write the new cage as OBJ: `knotwork cage
    /// IN.obj -o OUT.obj extrude --faces 0,1 --offset 0.5`. Faces and vertices are named by
    /// their 0-based index in the file; vertices keep their indices where they survive, new
    /// ones follow, and faces keep their winding. OpenSubdiv crease tags are read and written.
    Cage {
        input: std::path::PathBuf,
        /// The OBJ to write.
        #[arg(short, long)]
        output: std::path::PathBuf,
        #[command(subcommand)]
        tool: CageTool,
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
    /// Apply any operation to a project: OPERATION is a JSON file (or - for standard input)
    /// holding {"op": NAME, ...its fields}, objects given by their index in the project, e.g.
    /// {"op": "offset", "object": 0, "distance": 0.5}. Writes the project with the result
    /// (one undo step of the editor's) and prints {"label", "added", "changed", "removed"} as
    /// JSON; exit 1 with the reason where the operation cannot be read or done.
    Apply {
        /// The operation's JSON value.
        operation: std::path::PathBuf,
        /// The project (or any file knotwork opens).
        project: std::path::PathBuf,
        /// What the operation adds keeps its history, so the editor makes it again when an
        /// object it was made from changes.
        #[arg(long)]
        history: bool,
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
    /// Combine solids: every closed body of A with every closed body of B (B may hold many
    /// tools that do not overlap one another), written to OUTPUT as STEP solids; prints the
    /// result's solids, faces and volume as JSON. An open body, a missing file or an empty
    /// result exits 1 with the message.
    Boolean {
        /// union, difference (A minus B) or intersection.
        #[arg(value_enum)]
        operation: BooleanArg,
        /// The first file (STEP, a project, or anything knotwork opens).
        a: std::path::PathBuf,
        /// The second file.
        b: std::path::PathBuf,
        /// The STEP file to write.
        #[arg(short, long)]
        output: std::path::PathBuf,
        /// Distances below this are one (model units); 1e-6 of the inputs' size by default.
        #[arg(long)]
        tolerance: Option<f64>,
    },
    /// Fillet a solid's edges with a rolling ball: each --near point picks the one edge
    /// nearest it; with none, every edge. Writes the solids to OUTPUT as STEP and prints the
    /// result's faces and volume as JSON; a fillet that cannot be built exits 1 with the
    /// reason.
    FilletEdges {
        /// The file (STEP, a project, or anything knotwork opens).
        input: std::path::PathBuf,
        /// The STEP file to write.
        #[arg(short, long)]
        output: std::path::PathBuf,
        /// The ball's radius (model units).
        #[arg(long, allow_negative_numbers = true)]
        radius: f64,
        /// A point X,Y,Z near an edge to fillet (repeatable).
        #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
        near: Vec<String>,
        /// The radius R at the end of a picked edge nearest X,Y,Z (repeatable): each picked
        /// edge's radius runs linearly from its value at one end to that at the other,
        /// --radius where none is set.
        #[arg(long, value_name = "X,Y,Z,R", allow_hyphen_values = true)]
        radius_at: Vec<String>,
    },
    /// Chamfer a solid's edges, set back the distance on both faces; --near as for
    /// fillet-edges.
    ChamferEdges {
        /// The file (STEP, a project, or anything knotwork opens).
        input: std::path::PathBuf,
        /// The STEP file to write.
        #[arg(short, long)]
        output: std::path::PathBuf,
        /// The set-back on each face (model units).
        #[arg(long, allow_negative_numbers = true)]
        distance: f64,
        /// A point X,Y,Z near an edge to chamfer (repeatable).
        #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
        near: Vec<String>,
    },
    /// Hollow a solid to a wall thickness: below 0 the wall lies inside the solid, above 0
    /// outside it; each --open point removes the face nearest it. Sharp walls where the
    /// offset faces meet.
    Shell {
        /// The file (STEP, a project, or anything knotwork opens).
        input: std::path::PathBuf,
        /// The STEP file to write.
        #[arg(short, long)]
        output: std::path::PathBuf,
        /// The wall thickness (model units; the sign picks the side).
        #[arg(long, allow_negative_numbers = true)]
        thickness: f64,
        /// A point X,Y,Z near a face to leave open (repeatable).
        #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
        open: Vec<String>,
    },
    /// Move faces of a solid along their normals (each --face point picks the face nearest
    /// it), the neighbouring faces extended or trimmed to them.
    OffsetFace {
        /// The file (STEP, a project, or anything knotwork opens).
        input: std::path::PathBuf,
        /// The STEP file to write.
        #[arg(short, long)]
        output: std::path::PathBuf,
        /// How far (model units; below 0 into the solid).
        #[arg(long, allow_negative_numbers = true)]
        distance: f64,
        /// A point X,Y,Z near a face to move (repeatable, at least one).
        #[arg(
            long,
            value_name = "X,Y,Z",
            allow_hyphen_values = true,
            required = true
        )]
        face: Vec<String>,
    },
    /// Draft faces of a solid: tilt each about the line where it meets the neutral plane, by
    /// the angle (degrees; above 0 the part narrows along the pull direction).
    DraftFace {
        /// The file (STEP, a project, or anything knotwork opens).
        input: std::path::PathBuf,
        /// The STEP file to write.
        #[arg(short, long)]
        output: std::path::PathBuf,
        /// The draft angle in degrees.
        #[arg(long, allow_negative_numbers = true)]
        angle: f64,
        /// A point X,Y,Z near a face to draft (repeatable, at least one).
        #[arg(
            long,
            value_name = "X,Y,Z",
            allow_hyphen_values = true,
            required = true
        )]
        face: Vec<String>,
        /// A point of the neutral plane.
        #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
        neutral: String,
        /// The pull direction, across the neutral plane.
        #[arg(
            long,
            value_name = "X,Y,Z",
            allow_hyphen_values = true,
            default_value = "0,0,1"
        )]
        pull: String,
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
        #[arg(long, default_value = "all", value_parser = clap::builder::PossibleValuesParser::new(self::bench::groups::GROUPS))]
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

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ColorMode {
    Gaussian,
    Mean,
    K1,
    K2,
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

/// The names of the objects an edit added, in order.
fn added_names(edit: &knotwork::doc::Edit) -> Vec<String> {
    edit.changes
        .iter()
        .filter_map(|c| match c {
            knotwork::doc::Change::Insert { object, .. } => Some(object.name.clone()),
            _ => None,
        })
        .collect()
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

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Backend {
    Cpu,
    Gpu,
}

/// Who evaluates an export's tessellation grids (`knotwork export --backend`).
#[derive(Clone, Copy, PartialEq, Eq, Debug, ValueEnum)]
pub enum GridBackend {
    /// The GPU on a hardware adapter with compute shaders, else the CPU.
    Auto,
    Cpu,
    Gpu,
}

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
