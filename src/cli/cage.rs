//! `knotwork cage`: one topology tool applied to an OBJ cage, the new cage written as OBJ.

use std::process::ExitCode;

use clap::Subcommand;
use knotwork::kernel::subdiv::cage_edit::{Cage, Tool};

/// The tools of `knotwork cage`, with faces and vertices named by their 0-based index in the
/// file.
#[derive(Subcommand, Clone, Debug)]
pub enum CageTool {
    /// Extrude faces as one region along the region's average normal (--faces, --offset; each
    /// along its own with --individual), or open edges into a strip of quads (--edges, --by).
    #[command(group(clap::ArgGroup::new("what").required(true).multiple(false)))]
    Extrude {
        /// Faces, e.g. 0,4,5.
        #[arg(long, group = "what", requires = "offset")]
        faces: Option<String>,
        /// How far the region moves (negative: into the cage).
        #[arg(long, allow_negative_numbers = true)]
        offset: Option<f64>,
        /// Each face on its own, along its own normal.
        #[arg(long, requires = "faces")]
        individual: bool,
        /// Open edges, as A-B,C-D.
        #[arg(long, group = "what", requires = "by")]
        edges: Option<String>,
        /// The edges' move, as X,Y,Z.
        #[arg(long, allow_hyphen_values = true)]
        by: Option<String>,
    },
    /// Spin faces (as a region) or open edges round an axis in steps (Screw with --advance).
    #[command(group(clap::ArgGroup::new("what").required(true).multiple(false)))]
    Spin {
        #[arg(long, group = "what")]
        faces: Option<String>,
        /// Open edges, as A-B,C-D.
        #[arg(long, group = "what")]
        edges: Option<String>,
        /// The angle in degrees (right-handed about the axis; 360: a full turn, closed).
        #[arg(long, allow_negative_numbers = true)]
        angle: f64,
        #[arg(long, default_value_t = 12)]
        steps: u32,
        /// A point of the axis, as X,Y,Z.
        #[arg(long, allow_hyphen_values = true)]
        centre: String,
        /// The axis's direction, as X,Y,Z.
        #[arg(long, allow_hyphen_values = true)]
        axis: String,
        /// How far the spin moves along the axis over its whole angle.
        #[arg(long, allow_negative_numbers = true, default_value_t = 0.0)]
        advance: f64,
    },
    /// Inset faces as one region (or each on its own with --individual), the strip even.
    Inset {
        #[arg(long)]
        faces: String,
        /// The strip's width, ≥ 0.
        #[arg(long)]
        thickness: f64,
        /// How far the inner faces then move out of the surface (negative: in).
        #[arg(long, allow_negative_numbers = true, default_value_t = 0.0)]
        depth: f64,
        #[arg(long)]
        individual: bool,
    },
    /// Cut the edge ring through the edge between vertices A and B N times, evenly.
    Loopcut {
        /// The edge, as A,B.
        #[arg(long)]
        edge: String,
        #[arg(long, default_value_t = 1)]
        cuts: u32,
        /// Slide the cuts together along the ring, towards B's side (-1 < F < 1; 0: evenly
        /// spaced), as Blender's Loop Cut and Slide.
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        slide: f64,
    },
    /// Bevel edges (each becomes a band of S segments, its sides W from the edge) or vertices
    /// (each cut off W along its edges, a face where it was; with S > 1 a rounded corner).
    #[command(group(clap::ArgGroup::new("what").required(true).multiple(false)))]
    Bevel {
        /// Edges, as A-B,C-D.
        #[arg(long, group = "what")]
        edges: Option<String>,
        /// Vertices, as I,J.
        #[arg(long, group = "what")]
        vertices: Option<String>,
        #[arg(long)]
        width: f64,
        #[arg(long, default_value_t = 1)]
        segments: u32,
    },
    /// Join two closed loops of open edges with a band of quads (of triangles where the loops'
    /// lengths differ), paired at the least length that lays no face over the cage's.
    Bridge {
        /// The first loop's vertices in order, e.g. 0,1,2,3.
        #[arg(long)]
        loop1: String,
        #[arg(long)]
        loop2: String,
    },
    /// Merge vertices into the first named, at their centre or where the first is (or into the
    /// last named, where it is, with --at last); or, with
    /// --distance, merge the points within that distance of each other (among --vertices, or
    /// all).
    Merge {
        #[arg(long, required_unless_present = "distance")]
        vertices: Option<String>,
        #[arg(long, value_enum, default_value_t = MergeAt::Centre, conflicts_with = "distance")]
        at: MergeAt,
        #[arg(long)]
        distance: Option<f64>,
    },
    /// Dissolve edges (the faces on both sides become one), faces (each joined region
    /// becomes one face), or vertices (the faces round each become one).
    #[command(group(clap::ArgGroup::new("what").required(true).multiple(false)))]
    Dissolve {
        /// Edges, as A-B,C-D.
        #[arg(long, group = "what")]
        edges: Option<String>,
        /// Faces, as I,J.
        #[arg(long, group = "what")]
        faces: Option<String>,
        /// Vertices, as I,J.
        #[arg(long, group = "what")]
        vertices: Option<String>,
    },
    /// Delete faces, vertices (with their faces) or edges (with their faces), and the
    /// vertices only those faces used.
    #[command(group(clap::ArgGroup::new("what").required(true).multiple(false)))]
    Delete {
        #[arg(long, group = "what")]
        faces: Option<String>,
        #[arg(long, group = "what")]
        vertices: Option<String>,
        /// Edges, as A-B,C-D.
        #[arg(long, group = "what")]
        edges: Option<String>,
    },
    /// Tris to quads: pairs of the triangles joined into quads, the squarest first.
    TrisToQuads {
        #[arg(long)]
        faces: String,
        /// Triangles whose normals differ by more (degrees) are not joined.
        #[arg(long, default_value_t = 40.0)]
        face_angle: f64,
        /// Quads with a corner further off square (degrees) are not made.
        #[arg(long, default_value_t = 40.0)]
        shape_angle: f64,
    },
    /// Fill a closed loop of open edges with a face.
    Fill {
        /// The loop's vertices in order, e.g. 0,1,2,3.
        #[arg(long = "loop")]
        vertices: String,
    },
    /// Grid fill: a grid of quads over a hole, between two chains of open edges (--loop1,
    /// --loop2, the rails found along the rim) or over a whole rim (--loop, cut into sides at
    /// --offset with --span edges along each rail).
    #[command(group(clap::ArgGroup::new("what").required(true).multiple(false)))]
    GridFill {
        /// The first chain's vertices in order, e.g. 0,1,2.
        #[arg(long, group = "what", requires = "loop2")]
        loop1: Option<String>,
        /// The second chain's vertices in order.
        #[arg(long)]
        loop2: Option<String>,
        /// The whole rim's vertices in order (an even number of edges).
        #[arg(long = "loop", group = "what")]
        rim: Option<String>,
        /// Edges along each rail (default: to the rim's next sharp corner).
        #[arg(long, requires = "rim")]
        span: Option<u32>,
        /// The position in --loop of the grid's first corner (default: the sharpest corner).
        #[arg(long, requires = "rim")]
        offset: Option<usize>,
    },
    /// Connect vertices: each face holding two or more of them split between them.
    Connect {
        #[arg(long)]
        vertices: String,
    },
    /// Triangulate faces (Beauty: the split with the roundest triangles).
    Triangulate {
        #[arg(long)]
        faces: String,
    },
    /// Poke faces: each a fan of triangles round its weighted centre.
    Poke {
        #[arg(long)]
        faces: String,
    },
    /// Subdivide faces: their edges cut N times, each triangle and quad so closed a grid.
    Subdivide {
        #[arg(long)]
        faces: String,
        #[arg(long, default_value_t = 1)]
        cuts: u32,
    },
    /// Knife (Bisect): cut the faces (all, or --faces) along the plane through --point square
    /// to --normal; each crossed edge takes a point on the plane and each crossed face splits.
    Knife {
        /// A point of the plane, as X,Y,Z.
        #[arg(long, allow_hyphen_values = true)]
        point: String,
        /// The plane's normal, as X,Y,Z.
        #[arg(long, allow_hyphen_values = true)]
        normal: String,
        /// Faces, e.g. 0,4,5 (default: every face).
        #[arg(long)]
        faces: Option<String>,
        /// Points nearer the plane than this lie on it (default: 1e-6 of the cage's size).
        #[arg(long)]
        threshold: Option<f64>,
    },
    /// Mirror the cage across the plane through the origin square to an axis, welding the
    /// points within the merge distance of the plane to their images.
    Mirror {
        #[arg(long, value_enum)]
        axis: MirrorAxis,
        #[arg(long, default_value_t = knotwork::kernel::subdiv::cage_edit::DEFAULT_MERGE_DISTANCE)]
        merge_distance: f64,
    },
}

/// The axis square to `mirror`'s plane.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MirrorAxis {
    X,
    Y,
    Z,
}

/// Where `merge` puts the merged vertex.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MergeAt {
    #[value(alias = "center")]
    Centre,
    First,
    Last,
}

/// Runs `knotwork cage`: exit code 0 with a summary, 1 with the error.
pub fn cage(input: &std::path::Path, output: &std::path::Path, tool: &CageTool) -> ExitCode {
    match cage_file(input, output, tool) {
        Ok(summary) => {
            println!("{summary}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("knotwork cage: {e}");
            ExitCode::FAILURE
        }
    }
}

fn indices(what: &str, text: &str) -> Result<Vec<u32>, String> {
    let list: Vec<u32> = text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<u32>()
                .map_err(|_| format!("--{what}: {s:?} is not an index (0, 1, 2, …)"))
        })
        .collect::<Result<_, _>>()?;
    if list.is_empty() {
        return Err(format!("--{what} names nothing"));
    }
    Ok(list)
}

fn edge_pairs(text: &str) -> Result<Vec<[u32; 2]>, String> {
    text.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|pair| {
            let parsed = pair
                .split_once('-')
                .and_then(|(a, b)| Some([a.trim().parse().ok()?, b.trim().parse().ok()?]));
            parsed.ok_or_else(|| format!("--edges: {pair:?} is not an edge A-B"))
        })
        .collect()
}

/// Three numbers X,Y,Z.
fn vector(what: &str, text: &str) -> Result<[f64; 3], String> {
    let numbers: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("--{what}: {text:?} is not three numbers X,Y,Z"))?;
    match numbers[..] {
        [x, y, z] => Ok([x, y, z]),
        _ => Err(format!("--{what}: {text:?} is not three numbers X,Y,Z")),
    }
}

fn face_list(text: &str) -> Result<Vec<usize>, String> {
    Ok(indices("faces", text)?
        .into_iter()
        .map(|f| f as usize)
        .collect())
}

/// The kernel's tool for the command line's.
pub fn tool_of(tool: &CageTool) -> Result<Tool, String> {
    Ok(match tool {
        CageTool::Extrude {
            faces: Some(faces),
            offset,
            individual,
            ..
        } => Tool::Extrude {
            faces: face_list(faces)?,
            offset: offset.unwrap_or_default(),
            individual: *individual,
        },
        CageTool::Extrude { edges, by, .. } => Tool::ExtrudeEdges {
            edges: edge_pairs(edges.as_deref().unwrap_or_default())?,
            by: vector("by", by.as_deref().unwrap_or_default())?,
        },
        CageTool::Spin {
            faces,
            edges,
            angle,
            steps,
            centre,
            axis,
            advance,
        } => Tool::Spin {
            faces: match faces {
                Some(list) => face_list(list)?,
                None => Vec::new(),
            },
            edges: match edges {
                Some(list) => edge_pairs(list)?,
                None => Vec::new(),
            },
            centre: vector("centre", centre)?,
            axis: vector("axis", axis)?,
            degrees: *angle,
            steps: *steps,
            advance: *advance,
        },
        CageTool::Inset {
            faces,
            thickness,
            depth,
            individual,
        } => Tool::Inset {
            faces: face_list(faces)?,
            thickness: *thickness,
            depth: *depth,
            individual: *individual,
        },
        CageTool::Loopcut { edge, cuts, slide } => match indices("edge", edge)?[..] {
            [a, b] => Tool::LoopCut {
                edge: [a, b],
                cuts: *cuts,
                slide: *slide,
            },
            _ => return Err("--edge names one edge by its two vertices, A,B".into()),
        },
        CageTool::Bevel {
            vertices: Some(vertices),
            width,
            segments,
            ..
        } => Tool::BevelVertices {
            vertices: indices("vertices", vertices)?,
            width: *width,
            segments: *segments,
        },
        CageTool::Bevel {
            edges,
            width,
            segments,
            ..
        } => Tool::Bevel {
            edges: edge_pairs(edges.as_deref().unwrap_or_default())?,
            width: *width,
            segments: *segments,
        },
        CageTool::Bridge { loop1, loop2 } => Tool::Bridge {
            loop1: indices("loop1", loop1)?,
            loop2: indices("loop2", loop2)?,
        },
        CageTool::Merge {
            vertices,
            distance: Some(distance),
            ..
        } => Tool::MergeByDistance {
            vertices: match vertices {
                Some(list) => indices("vertices", list)?,
                None => Vec::new(),
            },
            distance: *distance,
        },
        CageTool::Merge { vertices, at, .. } => {
            let mut vertices = indices("vertices", vertices.as_deref().unwrap_or_default())?;
            // At last: the last named vertex is kept, where it is.
            if *at == MergeAt::Last {
                vertices.reverse();
            }
            Tool::Merge {
                vertices,
                at_first: *at != MergeAt::Centre,
            }
        }
        CageTool::Dissolve {
            edges: Some(edges), ..
        } => Tool::Dissolve {
            edges: edge_pairs(edges)?,
        },
        CageTool::Dissolve {
            faces: Some(faces), ..
        } => Tool::DissolveFaces {
            faces: face_list(faces)?,
        },
        CageTool::Dissolve { vertices, .. } => Tool::DissolveVertices {
            vertices: indices("vertices", vertices.as_deref().unwrap_or_default())?,
        },
        CageTool::Delete {
            faces: Some(faces), ..
        } => Tool::Delete {
            faces: face_list(faces)?,
        },
        CageTool::Delete {
            edges: Some(edges), ..
        } => Tool::DeleteEdges {
            edges: edge_pairs(edges)?,
        },
        CageTool::Delete { vertices, .. } => Tool::DeleteVertices {
            vertices: indices("vertices", vertices.as_deref().unwrap_or_default())?,
        },
        CageTool::TrisToQuads {
            faces,
            face_angle,
            shape_angle,
        } => Tool::TrisToQuads {
            faces: face_list(faces)?,
            face_degrees: *face_angle,
            shape_degrees: *shape_angle,
        },
        CageTool::Fill { vertices } => Tool::Fill {
            r#loop: indices("loop", vertices)?,
        },
        CageTool::GridFill {
            loop1,
            loop2,
            rim,
            span,
            offset,
        } => {
            let list = |name: &str, list: &Option<String>| match list {
                Some(list) => indices(name, list),
                None => Ok(Vec::new()),
            };
            Tool::GridFill {
                loop1: list("loop1", loop1)?,
                loop2: list("loop2", loop2)?,
                rim: list("loop", rim)?,
                span: *span,
                offset: *offset,
            }
        }
        CageTool::Connect { vertices } => Tool::Connect {
            vertices: indices("vertices", vertices)?,
        },
        CageTool::Triangulate { faces } => Tool::Triangulate {
            faces: face_list(faces)?,
        },
        CageTool::Poke { faces } => Tool::Poke {
            faces: face_list(faces)?,
        },
        CageTool::Subdivide { faces, cuts } => Tool::Subdivide {
            faces: face_list(faces)?,
            cuts: *cuts,
        },
        CageTool::Knife {
            point,
            normal,
            faces,
            threshold,
        } => Tool::Knife {
            faces: match faces {
                Some(list) => face_list(list)?,
                None => Vec::new(),
            },
            point: vector("point", point)?,
            normal: vector("normal", normal)?,
            threshold: *threshold,
        },
        CageTool::Mirror {
            axis,
            merge_distance,
        } => Tool::Mirror {
            axis: *axis as u8,
            merge_distance: *merge_distance,
        },
    })
}

fn cage_file(
    input: &std::path::Path,
    output: &std::path::Path,
    tool: &CageTool,
) -> Result<String, String> {
    let text = std::fs::read_to_string(input).map_err(|e| format!("{}: {e}", input.display()))?;
    let parsed = knotwork::io::obj::parse(&text).map_err(|e| e.to_string())?;
    let cage = Cage {
        faces: parsed.all_faces(),
        points: parsed.vertices,
        creases: parsed.creases,
        corners: parsed.corners,
    };
    // Where Blender's tool leaves the mesh as it is (a ring that comes back across or
    // touches itself, border edges alone to bevel, a region with no border to inset), the
    // cage is written as it was, with the reason.
    let (edited, note) = match cage.apply(&tool_of(tool)?) {
        Ok(edited) => (edited, String::new()),
        Err(e) if e.leaves_cage_unchanged() => (cage, format!(", unchanged: {e}")),
        Err(e) => return Err(e.to_string()),
    };
    let obj = knotwork::io::obj::write_cage(&edited);
    std::fs::write(output, obj).map_err(|e| format!("{}: {e}", output.display()))?;
    Ok(format!(
        "wrote {} ({} vertices, {} faces){note}",
        output.display(),
        edited.points.len(),
        edited.faces.len()
    ))
}
