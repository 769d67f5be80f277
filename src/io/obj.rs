//! Wavefront OBJ import: `v` and `f` records become polygon meshes, one object per `o` (or `g`)
//! group that has faces. Face corners may be written `i`, `i/t`, `i//n` or `i/t/n`, with
//! negative indices counting back from the latest vertex. Texture coordinates, normals,
//! materials, smoothing groups, lines and points are ignored. OBJ is taken as Y-up (the common
//! convention, Blender's default) and turned into knotwork's Z-up: (x, y, z) ↦ (x, −z, y).
//!
//! Errors name the line. Limits: [`super::project::MAX_FILE_BYTES`],
//! [`super::gltf_import::MAX_IMPORT_VERTICES`] vertices and
//! [`super::gltf_import::MAX_IMPORT_TRIANGLES`] faces.

use glam::DVec3;

use super::gltf::from_gltf_axes;
use super::gltf_import::{MAX_IMPORT_TRIANGLES, MAX_IMPORT_VERTICES};
use super::project::{self, Project};
use crate::kernel::PolygonMesh;
use crate::kernel::mesh::MAX_FACE_CORNERS;
use crate::kernel::subdiv::{Corner, Crease, Options, SubdivisionSurface};
use crate::scene::json::FormatError;
use crate::scene::{ObjectGeometry, Scene, SceneObject};

fn at_line(line: usize, message: impl Into<String>) -> FormatError {
    FormatError::new(format!("line {line}"), message)
}

/// One group's faces, over the file's global vertex indices.
pub struct Group {
    pub name: String,
    pub faces: Vec<Vec<u32>>,
}

/// An OBJ file as written: vertices in the file's own axes, groups of faces over the file's
/// 0-based vertex indices, and OpenSubdiv's crease tags (`t crease 2/1/0 A B S`,
/// `t corner 1/1/0 V S`, 0-based indices).
pub struct ObjText {
    pub vertices: Vec<DVec3>,
    pub groups: Vec<Group>,
    pub creases: Vec<Crease>,
    pub corners: Vec<Corner>,
}

impl ObjText {
    /// Every face of the file, in order, over the file's vertex indices.
    pub fn all_faces(&self) -> Vec<Vec<u32>> {
        self.groups.iter().flat_map(|g| g.faces.clone()).collect()
    }
}

/// Reads a `t` (tag) record: `t NAME I/F/S ints... floats... strings...`.
fn read_tag(
    line: usize,
    mut fields: std::str::SplitWhitespace<'_>,
    creases: &mut Vec<Crease>,
    corners: &mut Vec<Corner>,
) -> Result<(), FormatError> {
    let Some(name) = fields.next() else {
        return Err(at_line(line, "a tag needs a name"));
    };
    if name != "crease" && name != "corner" {
        return Ok(());
    }
    let counts: Vec<usize> = fields
        .next()
        .unwrap_or("")
        .split('/')
        .map(|c| c.parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| at_line(line, "a tag's counts are written I/F/S"))?;
    let [ints, floats, ..] = counts[..] else {
        return Err(at_line(line, "a tag's counts are written I/F/S"));
    };
    let rest: Vec<&str> = fields.collect();
    if rest.len() < ints + floats || ints > MAX_IMPORT_VERTICES || floats == 0 {
        return Err(at_line(
            line,
            format!("the {name} tag needs {ints} indices and {floats} values"),
        ));
    }
    let indices: Vec<u32> = rest[..ints]
        .iter()
        .map(|x| x.parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| at_line(line, "a tag index is not a vertex number"))?;
    let values: Vec<f64> = rest[ints..ints + floats]
        .iter()
        .map(|x| x.parse::<f64>().ok().filter(|v| v.is_finite() && *v >= 0.0))
        .collect::<Option<_>>()
        .ok_or_else(|| at_line(line, "a sharpness must be a finite number ≥ 0"))?;
    let value = |k: usize| values.get(k).copied().unwrap_or(values[0]);
    if name == "crease" {
        if ints < 2 || ints % 2 != 0 {
            return Err(at_line(line, "a crease tag names pairs of vertices"));
        }
        for (k, pair) in indices.chunks(2).enumerate() {
            creases.push(Crease {
                a: pair[0],
                b: pair[1],
                sharpness: value(k),
            });
        }
    } else {
        for (k, &vertex) in indices.iter().enumerate() {
            corners.push(Corner {
                vertex,
                sharpness: value(k),
            });
        }
    }
    Ok(())
}

/// Reads OBJ text into a project of polygon meshes (no view); a file with crease tags opens as
/// one subdivision cage per group, level 0.
pub fn read(text: &str) -> Result<Project, FormatError> {
    let parsed = parse(text)?;
    let tagged = !parsed.creases.is_empty() || !parsed.corners.is_empty();
    objects(parsed, tagged)
}

/// Parses OBJ text without changing axes ([`ObjText`]).
pub fn parse(text: &str) -> Result<ObjText, FormatError> {
    project::check_size(text.len() as u64)?;
    let mut parsed = ObjText {
        vertices: Vec::new(),
        groups: vec![Group {
            name: String::new(),
            faces: Vec::new(),
        }],
        creases: Vec::new(),
        corners: Vec::new(),
    };
    let (mut creases, mut corners) = (Vec::new(), Vec::new());
    let vertices = &mut parsed.vertices;
    let groups = &mut parsed.groups;
    let mut face_total = 0usize;
    for (number, raw) in text.lines().enumerate() {
        let line = number + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        let mut fields = content.split_whitespace();
        let Some(keyword) = fields.next() else {
            continue;
        };
        match keyword {
            "v" => {
                let mut xyz = [0.0; 3];
                for slot in &mut xyz {
                    let field = fields
                        .next()
                        .ok_or_else(|| at_line(line, "a vertex needs x, y and z"))?;
                    *slot = field
                        .parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| {
                            at_line(line, format!("{field:?} is not a finite number"))
                        })?;
                }
                if vertices.len() >= MAX_IMPORT_VERTICES {
                    return Err(at_line(
                        line,
                        format!("more than {MAX_IMPORT_VERTICES} vertices"),
                    ));
                }
                vertices.push(DVec3::from_array(xyz));
            }
            "f" => {
                let mut face = Vec::new();
                for corner in fields {
                    if face.len() >= MAX_FACE_CORNERS {
                        return Err(at_line(
                            line,
                            format!("a face has more than {MAX_FACE_CORNERS} corners"),
                        ));
                    }
                    let first = corner.split('/').next().unwrap_or("");
                    let index: i64 = first
                        .parse()
                        .map_err(|_| at_line(line, format!("{corner:?} is not a vertex index")))?;
                    let count = vertices.len() as i64;
                    let resolved = if index > 0 { index - 1 } else { count + index };
                    if index == 0 || !(0..count).contains(&resolved) {
                        return Err(at_line(
                            line,
                            format!(
                                "vertex index {index} is out of range ({count} vertices so far)"
                            ),
                        ));
                    }
                    face.push(resolved as u32);
                }
                // A corner repeated at once (a zero-length edge) is dropped; what is left must
                // still be a polygon.
                face.dedup();
                while face.len() > 1 && face.first() == face.last() {
                    face.pop();
                }
                if face.len() < 3 {
                    return Err(at_line(line, "a face needs at least 3 distinct corners"));
                }
                face_total += 1;
                if face_total > MAX_IMPORT_TRIANGLES {
                    return Err(at_line(
                        line,
                        format!("more than {MAX_IMPORT_TRIANGLES} faces"),
                    ));
                }
                if let Some(group) = groups.last_mut() {
                    group.faces.push(face);
                }
            }
            "o" | "g" => {
                let name = fields.collect::<Vec<_>>().join(" ");
                match groups.last_mut() {
                    Some(group) if group.faces.is_empty() => group.name = name,
                    _ => groups.push(Group {
                        name,
                        faces: Vec::new(),
                    }),
                }
            }
            "t" => {
                read_tag(line, fields, &mut creases, &mut corners)?;
            }
            // Texture coordinates, normals, parameter-space vertices, materials, smoothing
            // groups, lines, points and free-form records: not part of a polygon cage.
            _ => {}
        }
    }
    parsed.creases = creases;
    parsed.corners = corners;
    Ok(parsed)
}

/// OBJ text of a mesh: `v` lines, one `vn` per `v` when `normals` is not empty, and `f` lines
/// (1-based, `i//i` when there are normals).
pub fn write(positions: &[DVec3], normals: &[DVec3], faces: &[&[u32]]) -> String {
    use std::fmt::Write;
    let mut out = String::with_capacity(positions.len() * 60 + faces.len() * 24);
    for p in positions {
        let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
    }
    for n in normals {
        let _ = writeln!(out, "vn {} {} {}", n.x, n.y, n.z);
    }
    for face in faces {
        out.push('f');
        for &v in *face {
            if normals.is_empty() {
                let _ = write!(out, " {}", v + 1);
            } else {
                let _ = write!(out, " {}//{}", v + 1, v + 1);
            }
        }
        out.push('\n');
    }
    out
}

/// OBJ text of a cage as written (no change of axes): `v` and `f` lines, then OpenSubdiv's tags
/// for its creases (`t crease 2/1/0 A B S`) and corners (`t corner 1/1/0 V S`), 0-based as
/// [`parse`] reads them.
pub fn write_cage(cage: &crate::kernel::subdiv::cage_edit::Cage) -> String {
    use std::fmt::Write;
    let faces: Vec<&[u32]> = cage.faces.iter().map(Vec::as_slice).collect();
    let mut out = write(&cage.points, &[], &faces);
    for c in &cage.creases {
        let _ = writeln!(out, "t crease 2/1/0 {} {} {}", c.a, c.b, c.sharpness);
    }
    for c in &cage.corners {
        let _ = writeln!(out, "t corner 1/1/0 {} {}", c.vertex, c.sharpness);
    }
    out
}

/// The scene objects of a parsed file, turned from OBJ's Y-up into knotwork's Z-up.
fn objects(parsed: ObjText, cages: bool) -> Result<Project, FormatError> {
    let vertices: Vec<DVec3> = parsed.vertices.iter().map(|&p| from_gltf_axes(p)).collect();
    let mut objects = Vec::new();
    for group in parsed.groups.into_iter().filter(|g| !g.faces.is_empty()) {
        // Each object keeps only the vertices its faces use, renumbered in first-use order.
        let mut map = std::collections::HashMap::new();
        let mut points = Vec::new();
        let faces: Vec<Vec<u32>> = group
            .faces
            .iter()
            .map(|face| {
                face.iter()
                    .map(|&i| {
                        *map.entry(i).or_insert_with(|| {
                            points.push(vertices[i as usize]);
                            (points.len() - 1) as u32
                        })
                    })
                    .collect()
            })
            .collect();
        let name = if crate::scene::valid_name(&group.name) {
            group.name.clone()
        } else {
            format!("OBJ mesh {}", objects.len() + 1)
        };
        let mesh = PolygonMesh::new(points, &faces)
            .map_err(|e| FormatError::new(format!("object {name:?}"), e.to_string()))?;
        let geometry = if cages {
            let local = |v: u32| map.get(&v).copied();
            let creases = parsed
                .creases
                .iter()
                .filter_map(|c| {
                    Some(Crease {
                        a: local(c.a)?,
                        b: local(c.b)?,
                        ..*c
                    })
                })
                .collect();
            let corners = parsed
                .corners
                .iter()
                .filter_map(|c| {
                    Some(Corner {
                        vertex: local(c.vertex)?,
                        ..*c
                    })
                })
                .collect();
            let surface = SubdivisionSurface::new(mesh, creases, corners, Options::default(), 0)
                .map_err(|e| FormatError::new(format!("object {name:?}"), e.to_string()))?;
            ObjectGeometry::new(crate::scene::SubdivObject::from(surface))
        } else {
            ObjectGeometry::new(mesh)
        };
        let mut object = SceneObject::new(name, geometry);
        object.segments = 1;
        objects.push(object);
    }
    if objects.is_empty() {
        return Err(FormatError::new("", "the OBJ file has no faces"));
    }
    Ok(Project {
        scene: Scene {
            objects,
            unit: None,
        },
        view: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_with_slashes_negative_indices_and_two_objects_opens() {
        let text = "# a cube and a triangle\nmtllib x.mtl\no cube\n\
            v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
            vt 0 0\nvn 0 0 1\nusemtl red\ns off\n\
            f 1/1/1 4/1/1 3/1/1 2/1/1\nf 5//1 6//1 7//1 8//1\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf -4 -8 -5 -1\n\
            o tri\nv 5 5 5\nv 6 5 5\nv 5 6 5\nf -3 -2 -1\n";
        let project = read(text).unwrap();
        assert_eq!(project.scene.objects.len(), 2);
        let Some(cube) = project.scene.objects[0].kind().cage() else {
            panic!()
        };
        assert_eq!(project.scene.objects[0].name, "cube");
        assert_eq!((cube.points().len(), cube.face_count()), (8, 6));
        // Y-up to Z-up: OBJ (0, 1, 0) is knotwork's +z.
        assert!(cube.points().contains(&DVec3::new(0.0, 0.0, 1.0)));
        assert!(cube.points().contains(&DVec3::new(0.0, -1.0, 0.0)));
        let Some(tri) = project.scene.objects[1].kind().cage() else {
            panic!()
        };
        assert_eq!((tri.points().len(), tri.face_count()), (3, 1));
    }

    #[test]
    fn malformed_obj_files_name_the_line() {
        for (text, line) in [
            ("v 0 0 0\nv 1 0 0\nf 1 2 3\n", "line 3"),
            ("v 0 0\n", "line 1"),
            ("v 0 nan 0\n", "line 1"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "line 4"),
            ("v 0 0 0\nv 1 0 0\nf 1 2 2\n", "line 3"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "line 4"),
        ] {
            let e = read(text).unwrap_err();
            assert_eq!(e.path, line, "{text:?}: {e}");
        }
        assert!(read("v 0 0 0\n").is_err());
        assert!(read("").is_err());
    }
}
