//! Opening glTF 2.0 files (`.glb`, or `.gltf` with its buffers as `data:` URIs or files beside
//! it) through the `gltf` crate. A file knotwork exported opens as the project embedded in it
//! (`scenes[n].extras.knotwork`, see [`super::gltf`]); any other file's triangle meshes open as
//! polygon meshes, one object per node with a mesh, with the node transforms applied and glTF's
//! Y-up turned into knotwork's Z-up.
//!
//! The crate parses the GLB container and the JSON into its typed document, checks every
//! reference and enumerated value, and reads the accessors. A truncated or hostile file gives a
//! [`FormatError`] naming the JSON path, and nothing panics. The crate leaves some checks to its
//! caller (its readers would panic or overflow without them), so this module keeps them:
//! - a GLB header length under 12 bytes (the crate subtracts 12 from it unchecked);
//! - a primitive's POSITION index past the accessors (the crate's own validation indexes the
//!   accessor list with it before reporting the bad index);
//! - every accessor that is read: element type and component type (the readers assume them),
//!   `count` ≥ 1, the byte ranges of the accessor in its bufferView and of the bufferView in its
//!   buffer, and the stride (a multiple of 4, no smaller than an element);
//! - buffer lengths against the data present, `uri`s that leave the folder of the `.gltf`;
//! - the asset version, node cycles (at most [`MAX_NODE_DEPTH`] deep), finite transforms,
//!   indices against the vertex count.
//!
//! Leniency, as other importers have: a POSITION accessor without `min`/`max` and a primitive
//! without POSITION are accepted (the latter is skipped), as are points and lines; triangle
//! strips and fans are converted. Sparse accessors are refused.
//!
//! Limits: the file size of [`super::project::MAX_FILE_BYTES`] (each external buffer too),
//! [`MAX_IMPORT_VERTICES`] vertices and [`MAX_IMPORT_TRIANGLES`] triangles in all.

use std::borrow::Cow;
use std::collections::HashMap;

use base64::Engine as _;
use glam::{DMat4, DQuat, DVec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::json::validation::Validate as _;
use gltf::mesh::Mode;
use gltf::scene::Transform;
use gltf::{Document, Semantic};

use super::gltf::from_gltf_axes;
use super::project::{self, MAX_FILE_BYTES, Project};
use crate::kernel::PolygonMesh;
use crate::scene::json::FormatError;
use crate::scene::{ObjectGeometry, Scene, SceneObject};

/// The most vertices a glTF or OBJ import may create, over all objects.
pub const MAX_IMPORT_VERTICES: usize = 4_000_000;
/// The most triangles (faces for OBJ) an import may create, over all objects.
pub const MAX_IMPORT_TRIANGLES: usize = 8_000_000;
/// The deepest node hierarchy accepted.
pub const MAX_NODE_DEPTH: usize = 64;

fn error(path: impl Into<String>, message: impl Into<String>) -> FormatError {
    FormatError::new(path, message)
}

/// Whether `bytes` start like a GLB file.
pub fn is_glb(bytes: &[u8]) -> bool {
    bytes.starts_with(b"glTF")
}

/// Reads a `.glb` file or `.gltf` text. `external(uri)` returns the bytes of a buffer that
/// lives in a file beside the `.gltf` (or an error saying why it cannot).
pub fn read(
    bytes: &[u8],
    external: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Project, FormatError> {
    project::check_size(bytes.len() as u64)?;
    let (json, bin) = if is_glb(bytes) {
        glb_chunks(bytes)?
    } else {
        (bytes, None)
    };
    let document = parse(json)?;
    if let Some(model) = embedded_model(&document) {
        return project::read_value(model)
            .map_err(|e| error(format!("(embedded knotwork model) {}", e.path), e.message));
    }
    let buffers = load_buffers(&document, bin, external)?;
    let objects = read_meshes(&document, &buffers)?;
    if objects.is_empty() {
        return Err(error("meshes", "the file has no triangle meshes to open"));
    }
    Ok(Project {
        scene: Scene {
            objects,
            unit: None,
        },
        view: None,
    })
}

/// The JSON chunk and the BIN chunk of a GLB file (glTF 2.0, section 4.4), split by the crate
/// once the header's length is known to be sane.
fn glb_chunks<'a>(bytes: &'a [u8]) -> Result<(&'a [u8], Option<&'a [u8]>), FormatError> {
    let Some(header) = bytes.get(..12) else {
        return Err(error("", "the GLB header is truncated (under 12 bytes)"));
    };
    let length = u32::from_le_bytes([header[8], header[9], header[10], header[11]]) as usize;
    if length < 12 {
        return Err(error(
            "",
            format!("the GLB header says the file is {length} bytes, less than the header"),
        ));
    }
    let whole = bytes.get(..length).unwrap_or(bytes);
    let glb = gltf::binary::Glb::from_slice(whole).map_err(|e| error("", glb_message(&e)))?;
    // Reading from a slice, the crate borrows both chunks from it.
    let borrowed = |chunk: Cow<'a, [u8]>| match chunk {
        Cow::Borrowed(b) => b,
        Cow::Owned(_) => &[],
    };
    Ok((borrowed(glb.json), glb.bin.map(borrowed)))
}

/// The crate's GLB errors in words.
fn glb_message(e: &gltf::Error) -> String {
    use gltf::binary::Error as Glb;
    match e {
        gltf::Error::Binary(Glb::Version(v)) => {
            format!("GLB version {v}; knotwork reads version 2")
        }
        gltf::Error::Binary(Glb::Length {
            length,
            length_read,
        }) => format!(
            "the GLB is truncated: its header says {} bytes, the file has {}",
            *length as usize + 12,
            length_read + 12
        ),
        gltf::Error::Binary(Glb::ChunkLength {
            ty,
            length,
            length_read,
        }) => format!(
            "the GLB's {ty:?} chunk claims {length} bytes, past the end of the file \
             ({length_read} bytes are left)"
        ),
        gltf::Error::Binary(Glb::ChunkType(ty)) => {
            format!("the GLB has a {ty:?} chunk where another was expected (JSON comes first)")
        }
        gltf::Error::Binary(Glb::UnknownChunkType(ty)) => {
            format!("the GLB has a chunk of unknown type {ty:?}")
        }
        gltf::Error::Binary(Glb::Io(e)) => format!("the GLB is truncated: {e}"),
        other => format!("the GLB is not valid: {other}"),
    }
}

/// The glTF JSON as the crate's document: deserialized (a type error names its JSON path),
/// the version checked, and the crate's validation run.
fn parse(json: &[u8]) -> Result<Document, FormatError> {
    let mut deserializer = serde_json::Deserializer::from_slice(json);
    let root: gltf::json::Root =
        serde_path_to_error::deserialize(&mut deserializer).map_err(|e| {
            let path = e.path().to_string();
            let path = if path == "." { String::new() } else { path };
            error(path, format!("the glTF JSON is not valid: {}", e.inner()))
        })?;
    if !root.asset.version.starts_with("2.") {
        return Err(error(
            "asset.version",
            format!(
                "knotwork reads glTF 2.x, this file says {:?}",
                root.asset.version
            ),
        ));
    }
    check_position_indices(&root)?;
    let mut first = None;
    root.validate(&root, gltf::json::Path::new, &mut |path, e| {
        let path = path().to_string();
        if first.is_none() && !tolerated(&path, e) {
            first = Some(error(path, validation_message(e)));
        }
    });
    match first {
        Some(e) => Err(e),
        None => Ok(Document::from_json_without_validation(root)),
    }
}

/// Validation findings accepted anyway: POSITION's `min`/`max` (knotwork measures its own
/// bounds) and a missing POSITION (that primitive is skipped).
fn tolerated(path: &str, e: gltf::json::validation::Error) -> bool {
    let position = path.contains("attributes[\"POSITION\"]");
    position
        && (path.ends_with(".min")
            || path.ends_with(".max")
            || (path.ends_with("[\"POSITION\"]") && e == gltf::json::validation::Error::Missing))
}

fn validation_message(e: gltf::json::validation::Error) -> &'static str {
    use gltf::json::validation::Error as V;
    match e {
        V::IndexOutOfBounds => "refers to an item that does not exist",
        V::Invalid => "is not a valid value here",
        V::Missing => "is required but missing",
        V::Oversize => "is larger than this machine can address",
        V::Unsupported => "needs an extension knotwork does not support",
    }
}

/// Every primitive's POSITION index is an accessor (checked before the crate's validation,
/// which looks the accessor up without this check).
fn check_position_indices(root: &gltf::json::Root) -> Result<(), FormatError> {
    let positions = gltf::json::validation::Checked::Valid(Semantic::Positions);
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive.attributes.get(&positions)
                && index.value() >= root.accessors.len()
            {
                return Err(error(
                    format!("meshes[{m}].primitives[{p}].attributes.POSITION"),
                    format!(
                        "accessor {index} does not exist (there are {})",
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The knotwork project in the default scene's (or any scene's) extras.
fn embedded_model(document: &Document) -> Option<serde_json::Value> {
    let model = |scene: gltf::Scene| -> Option<serde_json::Value> {
        let raw = scene.extras().as_ref()?;
        let mut extras: serde_json::Value = serde_json::from_str(raw.get()).ok()?;
        extras.get_mut("knotwork").map(serde_json::Value::take)
    };
    document
        .default_scene()
        .into_iter()
        .chain(document.scenes())
        .find_map(model)
}

/// Every buffer's bytes: the GLB's BIN chunk, a `data:` URI, or a file through `external`.
fn load_buffers(
    document: &Document,
    bin: Option<&[u8]>,
    external: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Vec<Vec<u8>>, FormatError> {
    let mut out = Vec::new();
    for buffer in document.buffers() {
        let k = buffer.index();
        let path = format!("buffers[{k}]");
        let data = match buffer.source() {
            gltf::buffer::Source::Bin if k == 0 => bin
                .ok_or_else(|| error(&path, "no uri and no GLB BIN chunk to hold it"))?
                .to_vec(),
            gltf::buffer::Source::Bin => {
                return Err(error(
                    &path,
                    "no uri (only buffer 0 may use the GLB BIN chunk)",
                ));
            }
            gltf::buffer::Source::Uri(uri) => read_uri(&path, uri, external)?,
        };
        if data.len() < buffer.length() {
            return Err(error(
                format!("{path}.byteLength"),
                format!(
                    "says {} bytes but only {} are there",
                    buffer.length(),
                    data.len()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

fn read_uri(
    path: &str,
    uri: &str,
    external: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Vec<u8>, FormatError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, data)) = rest.split_once(";base64,") else {
            return Err(error(
                format!("{path}.uri"),
                "only base64 data URIs are supported",
            ));
        };
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| {
                error(
                    format!("{path}.uri"),
                    format!("the base64 data is malformed: {e}"),
                )
            });
    }
    if uri.contains("://") || uri.starts_with('/') || uri.split(['/', '\\']).any(|s| s == "..") {
        return Err(error(
            format!("{path}.uri"),
            format!("{uri:?}: only files beside the .gltf are read"),
        ));
    }
    let name = super::gltf::uri_decode(uri)
        .ok_or_else(|| error(format!("{path}.uri"), format!("{uri:?} is not a valid URI")))?;
    let bytes =
        external(&name).map_err(|e| error(format!("{path}.uri"), format!("{name}: {e}")))?;
    if bytes.len() > MAX_FILE_BYTES {
        return Err(error(
            format!("{path}.uri"),
            format!("{name} is over the size limit"),
        ));
    }
    Ok(bytes)
}

/// Checks what the crate's accessor readers take for granted: `dimensions` and one of
/// `types`, at most `limit` and at least one element, no sparse storage, and every byte of
/// every element inside its bufferView and the bufferView inside its buffer's `data`.
fn check_accessor(
    accessor: &gltf::Accessor,
    dimensions: Dimensions,
    types: &[DataType],
    limit: usize,
    buffers: &[Vec<u8>],
) -> Result<(), FormatError> {
    let path = format!("accessors[{}]", accessor.index());
    let count = accessor.count();
    if count > limit {
        return Err(error(
            format!("{path}.count"),
            format!("{count} elements; knotwork imports at most {limit}"),
        ));
    }
    if count == 0 {
        return Err(error(format!("{path}.count"), "must be at least 1"));
    }
    if accessor.sparse().is_some() {
        return Err(error(
            format!("{path}.sparse"),
            "sparse accessors are not supported",
        ));
    }
    if accessor.dimensions() != dimensions {
        return Err(error(
            format!("{path}.type"),
            format!("expected {dimensions:?}, found {:?}", accessor.dimensions()),
        ));
    }
    if !types.contains(&accessor.data_type()) || accessor.normalized() {
        return Err(error(
            format!("{path}.componentType"),
            format!(
                "{:?}{} is not supported here (positions are floats, indices unsigned integers)",
                accessor.data_type(),
                if accessor.normalized() {
                    ", normalized,"
                } else {
                    ""
                }
            ),
        ));
    }
    let Some(view) = accessor.view() else {
        return Err(error(format!("{path}.bufferView"), "is missing"));
    };
    let vpath = format!("bufferViews[{}]", view.index());
    let data = buffers.get(view.buffer().index()).map_or(0, Vec::len);
    let view_end = view.offset().checked_add(view.length());
    if view_end.is_none_or(|end| end > data) {
        return Err(error(&vpath, "its byte range lies outside its buffer"));
    }
    let element = accessor.size();
    let stride = match view.stride() {
        None => element,
        Some(s) if s.is_multiple_of(4) && s >= element => s,
        Some(s) => {
            return Err(error(
                format!("{vpath}.byteStride"),
                format!("{s} is not a multiple of 4 in {element}..=252"),
            ));
        }
    };
    let needed = stride
        .checked_mul(count - 1)
        .and_then(|x| x.checked_add(accessor.offset()))
        .and_then(|x| x.checked_add(element));
    if needed.is_none_or(|n| n > view.length()) {
        return Err(error(
            &path,
            format!(
                "{count} elements do not fit in {vpath} ({} bytes)",
                view.length()
            ),
        ));
    }
    Ok(())
}

/// A node's local transform in f64: `matrix` (column-major) or translation, rotation
/// (normalized here) and scale; every number finite.
fn node_transform(node: &gltf::Node, path: &str) -> Result<DMat4, FormatError> {
    let finite = |key: &str, values: &[f32]| {
        if values.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(error(format!("{path}.{key}"), "expected finite numbers"))
        }
    };
    let vector = |v: [f32; 3]| DVec3::from_array(v.map(f64::from));
    match node.transform() {
        Transform::Matrix { matrix } => {
            finite("matrix", matrix.as_flattened())?;
            Ok(DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from))))
        }
        Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            finite("translation", &translation)?;
            finite("rotation", &rotation)?;
            finite("scale", &scale)?;
            let [x, y, z, w] = rotation.map(f64::from);
            let rotation = DQuat::from_xyzw(x, y, z, w);
            let rotation = if rotation.length() > 0.0 {
                rotation.normalize()
            } else {
                DQuat::IDENTITY
            };
            Ok(DMat4::from_scale_rotation_translation(
                vector(scale),
                rotation,
                vector(translation),
            ))
        }
    }
}

/// Every node with a mesh, reached from the default scene (or the first; without scenes,
/// every node nobody lists as a child), as a polygon mesh in knotwork's axes.
fn read_meshes(document: &Document, buffers: &[Vec<u8>]) -> Result<Vec<SceneObject>, FormatError> {
    let roots: Vec<gltf::Node> = match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => scene.nodes().collect(),
        None => {
            let children: std::collections::HashSet<usize> = document
                .nodes()
                .flat_map(|n| n.children().map(|c| c.index()).collect::<Vec<_>>())
                .collect();
            document
                .nodes()
                .filter(|n| !children.contains(&n.index()))
                .collect()
        }
    };
    let mut objects = Vec::new();
    let mut budget = (MAX_IMPORT_VERTICES, MAX_IMPORT_TRIANGLES);
    let mut visited = vec![false; document.nodes().len()];
    let mut stack: Vec<(gltf::Node, DMat4, usize)> = roots
        .into_iter()
        .rev()
        .map(|r| (r, DMat4::IDENTITY, 0))
        .collect();
    while let Some((node, parent, depth)) = stack.pop() {
        let path = format!("nodes[{}]", node.index());
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(error(
                path,
                "is reached twice: the node hierarchy has a cycle or a shared node",
            ));
        }
        if depth > MAX_NODE_DEPTH {
            return Err(error(
                path,
                format!("the node hierarchy is deeper than {MAX_NODE_DEPTH}"),
            ));
        }
        let transform = parent * node_transform(&node, &path)?;
        if let Some(mesh) = node.mesh()
            && let Some(polygons) = read_mesh(&mesh, buffers, transform, &mut budget)?
        {
            let name = node
                .name()
                .or(mesh.name())
                .filter(|n| crate::scene::valid_name(n))
                .map_or_else(|| format!("glTF mesh {}", objects.len() + 1), str::to_owned);
            let mut object = SceneObject::new(name, ObjectGeometry::new(polygons));
            object.segments = 1;
            objects.push(object);
        }
        let children: Vec<gltf::Node> = node.children().collect();
        for child in children.into_iter().rev() {
            stack.push((child, transform, depth + 1));
        }
    }
    Ok(objects)
}

/// A primitive's corners (its indices, or 0..vertices) as triangles: lists as they are,
/// strips with every other triangle turned to keep the winding, fans around the first corner
/// (glTF 2.0, section 3.7.2.1). None for points and lines.
fn triangles(mode: Mode, corners: &[usize]) -> Vec<[usize; 3]> {
    match mode {
        Mode::Triangles => corners
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
        Mode::TriangleStrip => (2..corners.len())
            .map(|k| {
                if k % 2 == 0 {
                    [corners[k - 2], corners[k - 1], corners[k]]
                } else {
                    [corners[k - 1], corners[k - 2], corners[k]]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..corners.len())
            .map(|k| [corners[0], corners[k - 1], corners[k]])
            .collect(),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => Vec::new(),
    }
}

/// A mesh's triangles (all primitives) as one polygon mesh: positions transformed, turned to
/// knotwork's axes, and welded where they coincide exactly; triangles that collapse are dropped.
/// `None` when it has no triangles.
fn read_mesh(
    mesh: &gltf::Mesh,
    buffers: &[Vec<u8>],
    transform: DMat4,
    budget: &mut (usize, usize),
) -> Result<Option<PolygonMesh>, FormatError> {
    let mut points = Vec::new();
    let mut welded: HashMap<[u64; 3], u32> = HashMap::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for primitive in mesh.primitives() {
        let path = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
        let Some(position) = primitive.get(&Semantic::Positions) else {
            continue;
        };
        if matches!(
            primitive.mode(),
            Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip
        ) {
            continue;
        }
        check_accessor(
            &position,
            Dimensions::Vec3,
            &[DataType::F32],
            budget.0,
            buffers,
        )?;
        let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
        let positions: Vec<[f32; 3]> = reader
            .read_positions()
            .ok_or_else(|| error(&path, "its positions cannot be read"))?
            .collect();
        let corners: Vec<usize> = match primitive.indices() {
            Some(indices) => {
                let unsigned = [DataType::U8, DataType::U16, DataType::U32];
                check_accessor(
                    &indices,
                    Dimensions::Scalar,
                    &unsigned,
                    budget.1.saturating_mul(3),
                    buffers,
                )?;
                let list = reader
                    .read_indices()
                    .ok_or_else(|| error(&path, "its indices cannot be read"))?
                    .into_u32();
                let mut out = Vec::with_capacity(indices.count());
                for (e, x) in list.enumerate() {
                    let x = x as usize;
                    if x >= positions.len() {
                        return Err(error(
                            format!("accessors[{}]", indices.index()),
                            format!(
                                "index {x} at element {e} is past the {} vertices",
                                positions.len()
                            ),
                        ));
                    }
                    out.push(x);
                }
                out
            }
            None => (0..positions.len()).collect(),
        };
        let triangles = triangles(primitive.mode(), &corners);
        let mut map = vec![u32::MAX; positions.len()];
        for t in triangles {
            let mut face = [0u32; 3];
            for (slot, &c) in face.iter_mut().zip(&t) {
                if map[c] == u32::MAX {
                    let local = DVec3::from_array(positions[c].map(f64::from));
                    let q = from_gltf_axes(transform.transform_point3(local));
                    if !q.is_finite() {
                        return Err(error(
                            format!("accessors[{}]", position.index()),
                            format!("vertex {c} is not finite"),
                        ));
                    }
                    let key = q.to_array().map(f64::to_bits);
                    map[c] = *welded.entry(key).or_insert_with(|| {
                        points.push(q);
                        (points.len() - 1) as u32
                    });
                }
                *slot = map[c];
            }
            if face[0] != face[1] && face[1] != face[2] && face[0] != face[2] {
                faces.push(face.to_vec());
            }
        }
        if points.len() > budget.0 || faces.len() > budget.1 {
            return Err(error(
                &path,
                format!(
                    "the file has more than {MAX_IMPORT_VERTICES} vertices or {MAX_IMPORT_TRIANGLES} triangles"
                ),
            ));
        }
    }
    if faces.is_empty() {
        return Ok(None);
    }
    budget.0 -= points.len();
    budget.1 -= faces.len();
    PolygonMesh::new(points, &faces)
        .map(Some)
        .map_err(|e| error(format!("meshes[{}]", mesh.index()), e.to_string()))
}
