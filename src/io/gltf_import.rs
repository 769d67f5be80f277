//! Opening glTF 2.0 files (`.glb`, or `.gltf` with its buffers as `data:` URIs or files beside
//! it). A file knotwork exported opens as the project embedded in it
//! (`scenes[n].extras.knotwork`, see [`super::gltf`]); any other file's triangle meshes open as
//! polygon meshes, one object per node with a mesh, with the node transforms applied and glTF's
//! Y-up turned into knotwork's Z-up.
//!
//! Everything is checked before it is used, so a truncated or hostile file gives a
//! [`FormatError`] naming the JSON path and nothing panics:
//! - the GLB header, chunk lengths and types; buffer lengths against the data present;
//! - bufferView ranges, strides (4-byte multiples, 4 to 252) and accessor ranges; component
//!   types and element types; sparse accessors are refused;
//! - indices against the vertex count; node hierarchies (no cycles, at most
//!   [`MAX_NODE_DEPTH`] deep); transforms finite.
//!
//! Limits: the file size of [`super::project::MAX_FILE_BYTES`] (each external buffer too),
//! [`MAX_IMPORT_VERTICES`] vertices and [`MAX_IMPORT_TRIANGLES`] triangles in all. Points,
//! lines and primitives without POSITION are skipped; triangle strips and fans are converted.

use std::collections::HashMap;

use glam::{DMat4, DQuat, DVec3};
use serde_json::Value;

use super::gltf::from_gltf_axes;
use super::json::FormatError;
use super::project::{self, MAX_FILE_BYTES, Project};
use crate::kernel::PolygonMesh;
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
        split_glb(bytes)?
    } else {
        (bytes, None)
    };
    let root: Value = serde_json::from_slice(json)
        .map_err(|e| error("", format!("the glTF JSON is not valid: {e}")))?;
    if !root.is_object() {
        return Err(error("", "the glTF JSON is not an object"));
    }
    let version = root["asset"]["version"].as_str().unwrap_or("");
    if !version.starts_with("2.") {
        return Err(error(
            "asset.version",
            format!(
                "knotwork reads glTF 2.x, this file says {:?}",
                root["asset"]["version"]
            ),
        ));
    }
    if let Some(model) = embedded_model(&root) {
        return project::read_value(model.clone())
            .map_err(|e| error(format!("(embedded knotwork model) {}", e.path), e.message));
    }
    let buffers = load_buffers(&root, bin, external)?;
    let objects = read_meshes(&root, &buffers)?;
    if objects.is_empty() {
        return Err(error("meshes", "the file has no triangle meshes to open"));
    }
    Ok(Project {
        scene: Scene { objects },
        view: None,
    })
}

/// The knotwork project in the default scene's (or any scene's) extras.
fn embedded_model(root: &Value) -> Option<&Value> {
    let scenes = root["scenes"].as_array()?;
    let first = root["scene"].as_u64().unwrap_or(0) as usize;
    scenes
        .get(first)
        .into_iter()
        .chain(scenes)
        .find_map(|s| s["extras"].get("knotwork"))
}

/// The JSON chunk and the BIN chunk of a GLB file (glTF 2.0, section 4.4).
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), FormatError> {
    let word = |at: usize| -> Option<u32> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(error("", "the GLB header is truncated (under 12 bytes)"));
    };
    if version != 2 {
        return Err(error(
            "",
            format!("GLB version {version}; knotwork reads version 2"),
        ));
    }
    let length = length as usize;
    if length > bytes.len() {
        return Err(error(
            "",
            format!(
                "the GLB is truncated: its header says {length} bytes, the file has {}",
                bytes.len()
            ),
        ));
    }
    let mut chunks = Vec::new();
    let mut at = 12;
    while at < length {
        let (Some(size), Some(kind)) = (word(at), word(at + 4)) else {
            return Err(error(
                "",
                format!("GLB chunk header at byte {at} is truncated"),
            ));
        };
        let start = at + 8;
        let end = start.checked_add(size as usize).filter(|&e| e <= length);
        let Some(end) = end else {
            return Err(error(
                "",
                format!("GLB chunk at byte {at} claims {size} bytes, past the end of the file"),
            ));
        };
        chunks.push((kind, &bytes[start..end]));
        at = end.next_multiple_of(4);
    }
    const JSON: u32 = 0x4E4F_534A;
    const BIN: u32 = 0x004E_4942;
    match chunks.first() {
        Some(&(JSON, json)) => {
            let bin = chunks.get(1).filter(|c| c.0 == BIN).map(|c| c.1);
            Ok((json, bin))
        }
        _ => Err(error("", "the GLB's first chunk is not JSON")),
    }
}

/// Every buffer's bytes: the GLB's BIN chunk, a `data:` URI, or a file through `external`.
fn load_buffers(
    root: &Value,
    bin: Option<&[u8]>,
    external: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Vec<Vec<u8>>, FormatError> {
    let Some(buffers) = root.get("buffers") else {
        return Ok(Vec::new());
    };
    let buffers = buffers
        .as_array()
        .ok_or_else(|| error("buffers", "expected an array"))?;
    let mut out = Vec::with_capacity(buffers.len());
    for (k, buffer) in buffers.iter().enumerate() {
        let path = format!("buffers[{k}]");
        let length = buffer["byteLength"].as_u64().ok_or_else(|| {
            error(
                format!("{path}.byteLength"),
                "missing or not a whole number",
            )
        })? as usize;
        let data = match buffer.get("uri") {
            None if k == 0 => bin
                .ok_or_else(|| error(&path, "no uri and no GLB BIN chunk to hold it"))?
                .to_vec(),
            None => {
                return Err(error(
                    &path,
                    "no uri (only buffer 0 may use the GLB BIN chunk)",
                ));
            }
            Some(Value::String(uri)) => read_uri(&path, uri, external)?,
            Some(other) => {
                return Err(error(
                    format!("{path}.uri"),
                    format!("expected a string, found {other}"),
                ));
            }
        };
        if data.len() < length {
            return Err(error(
                format!("{path}.byteLength"),
                format!("says {length} bytes but only {} are there", data.len()),
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
        return base64_decode(data)
            .ok_or_else(|| error(format!("{path}.uri"), "the base64 data is malformed"));
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

/// Standard base64 (RFC 4648, section 4) with optional padding; `None` on any other character.
fn base64_decode(text: &str) -> Option<Vec<u8>> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    };
    let text = text.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(text.len() * 3 / 4);
    for chunk in text.chunks(4) {
        if chunk.len() == 1 {
            return None;
        }
        let mut acc = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            acc |= value(c)? << (18 - 6 * k);
        }
        let bytes = acc.to_be_bytes();
        out.extend_from_slice(&bytes[1..chunk.len()]);
    }
    Some(out)
}

/// The index at `value[key]`, checked against `count` items of `what`.
fn index(
    value: &Value,
    key: &str,
    path: &str,
    what: &str,
    count: usize,
) -> Result<usize, FormatError> {
    let i = value[key]
        .as_u64()
        .ok_or_else(|| error(format!("{path}.{key}"), "missing or not a whole number"))?
        as usize;
    if i >= count {
        return Err(error(
            format!("{path}.{key}"),
            format!("{what} {i} does not exist (there are {count})"),
        ));
    }
    Ok(i)
}

fn array<'a>(root: &'a Value, key: &str) -> &'a [Value] {
    root[key].as_array().map_or(&[], Vec::as_slice)
}

/// Reads accessor `k` as `N`-component f64 tuples (floats, or integer indices for SCALAR).
fn accessor<const N: usize>(
    root: &Value,
    buffers: &[Vec<u8>],
    k: usize,
    limit: usize,
) -> Result<Vec<[f64; N]>, FormatError> {
    let path = format!("accessors[{k}]");
    let a = &array(root, "accessors")[k];
    let count = a["count"]
        .as_u64()
        .ok_or_else(|| error(format!("{path}.count"), "missing or not a whole number"))?
        as usize;
    if count > limit {
        return Err(error(
            format!("{path}.count"),
            format!("{count} elements; knotwork imports at most {limit}"),
        ));
    }
    if a.get("sparse").is_some() {
        return Err(error(
            format!("{path}.sparse"),
            "sparse accessors are not supported",
        ));
    }
    let kind = a["type"].as_str().unwrap_or("");
    let components = match kind {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        _ => 0,
    };
    if components != N {
        return Err(error(
            format!("{path}.type"),
            format!("expected {} components, found {kind:?}", N),
        ));
    }
    let component = a["componentType"].as_u64().unwrap_or(0);
    let size = match component {
        5121 => 1, // UNSIGNED_BYTE
        5123 => 2, // UNSIGNED_SHORT
        5125 => 4, // UNSIGNED_INT
        5126 => 4, // FLOAT
        _ => {
            return Err(error(
                format!("{path}.componentType"),
                format!("{component} is not supported (float, or unsigned integers for indices)"),
            ));
        }
    };
    if (component == 5126) != (N > 1) {
        return Err(error(
            format!("{path}.componentType"),
            "positions must be floats and indices unsigned integers",
        ));
    }
    let element = size * N;
    let Some(view_index) = a.get("bufferView") else {
        // No bufferView: all zeros (glTF 2.0, 3.6.2.1).
        return Ok(vec![[0.0; N]; count]);
    };
    let views = array(root, "bufferViews");
    let view_index = view_index
        .as_u64()
        .map(|v| v as usize)
        .filter(|&v| v < views.len())
        .ok_or_else(|| error(format!("{path}.bufferView"), "does not exist"))?;
    let vpath = format!("bufferViews[{view_index}]");
    let view = &views[view_index];
    let buffer = index(view, "buffer", &vpath, "buffer", buffers.len())?;
    let data = &buffers[buffer];
    let view_offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let view_length = view["byteLength"]
        .as_u64()
        .ok_or_else(|| error(format!("{vpath}.byteLength"), "missing"))?
        as usize;
    let view_end = view_offset
        .checked_add(view_length)
        .filter(|&e| e <= data.len())
        .ok_or_else(|| error(&vpath, "its byte range lies outside its buffer"))?;
    let stride = match view["byteStride"].as_u64() {
        None => element,
        Some(s) if (4..=252).contains(&s) && s % 4 == 0 && s as usize >= element => s as usize,
        Some(s) => {
            return Err(error(
                format!("{vpath}.byteStride"),
                format!("{s} is not a multiple of 4 in {element}..=252"),
            ));
        }
    };
    let offset = a["byteOffset"].as_u64().unwrap_or(0) as usize;
    if count > 0 {
        let needed = offset
            .checked_add(stride.saturating_mul(count - 1))
            .and_then(|x| x.checked_add(element));
        if needed.is_none_or(|n| n > view_length) {
            return Err(error(
                &path,
                format!("{count} elements do not fit in {vpath} ({view_length} bytes)"),
            ));
        }
    }
    let bytes = &data[view_offset..view_end];
    let mut out = Vec::with_capacity(count);
    for e in 0..count {
        let start = offset + e * stride;
        let mut tuple = [0.0; N];
        for (c, slot) in tuple.iter_mut().enumerate() {
            let at = start + c * size;
            let b = &bytes[at..at + size];
            *slot = match component {
                5121 => f64::from(b[0]),
                5123 => f64::from(u16::from_le_bytes([b[0], b[1]])),
                5125 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                _ => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            };
        }
        out.push(tuple);
    }
    Ok(out)
}

/// A node's local transform: `matrix` (column-major) or translation, rotation, scale.
fn node_transform(node: &Value, path: &str) -> Result<DMat4, FormatError> {
    let numbers = |key: &str, n: usize| -> Result<Option<Vec<f64>>, FormatError> {
        match node.get(key) {
            None => Ok(None),
            Some(Value::Array(values)) if values.len() == n => {
                let v: Option<Vec<f64>> = values.iter().map(Value::as_f64).collect();
                match v {
                    Some(v) if v.iter().all(|x| x.is_finite()) => Ok(Some(v)),
                    _ => Err(error(format!("{path}.{key}"), "expected finite numbers")),
                }
            }
            Some(_) => Err(error(
                format!("{path}.{key}"),
                format!("expected {n} numbers"),
            )),
        }
    };
    if let Some(m) = numbers("matrix", 16)? {
        let mut cols = [0.0; 16];
        cols.copy_from_slice(&m);
        return Ok(DMat4::from_cols_array(&cols));
    }
    let t = numbers("translation", 3)?.map_or(DVec3::ZERO, |v| DVec3::new(v[0], v[1], v[2]));
    let r = numbers("rotation", 4)?.map_or(DQuat::IDENTITY, |v| {
        DQuat::from_xyzw(v[0], v[1], v[2], v[3]).normalize()
    });
    let s = numbers("scale", 3)?.map_or(DVec3::ONE, |v| DVec3::new(v[0], v[1], v[2]));
    Ok(DMat4::from_scale_rotation_translation(s, r, t))
}

/// Every node with a mesh, reached from the default scene (or, without scenes, every node),
/// as a polygon mesh in knotwork's axes.
fn read_meshes(root: &Value, buffers: &[Vec<u8>]) -> Result<Vec<SceneObject>, FormatError> {
    let nodes = array(root, "nodes");
    let scenes = array(root, "scenes");
    let roots: Vec<usize> = if scenes.is_empty() {
        // Nodes nobody lists as a child.
        let children: std::collections::HashSet<u64> = nodes
            .iter()
            .flat_map(|n| array(n, "children").iter().filter_map(Value::as_u64))
            .collect();
        (0..nodes.len())
            .filter(|&k| !children.contains(&(k as u64)))
            .collect()
    } else {
        let s = root["scene"].as_u64().unwrap_or(0) as usize;
        let scene = scenes
            .get(s)
            .ok_or_else(|| error("scene", format!("scene {s} does not exist")))?;
        array(scene, "nodes")
            .iter()
            .enumerate()
            .map(|(k, v)| {
                v.as_u64()
                    .map(|v| v as usize)
                    .filter(|&v| v < nodes.len())
                    .ok_or_else(|| error(format!("scenes[{s}].nodes[{k}]"), "no such node"))
            })
            .collect::<Result<_, _>>()?
    };
    let mut objects = Vec::new();
    let mut budget = (MAX_IMPORT_VERTICES, MAX_IMPORT_TRIANGLES);
    let mut visited = vec![false; nodes.len()];
    let mut stack: Vec<(usize, DMat4, usize)> = roots
        .into_iter()
        .rev()
        .map(|r| (r, DMat4::IDENTITY, 0))
        .collect();
    while let Some((k, parent, depth)) = stack.pop() {
        let path = format!("nodes[{k}]");
        if visited[k] {
            return Err(error(
                path,
                "is reached twice: the node hierarchy has a cycle or a shared node",
            ));
        }
        visited[k] = true;
        if depth > MAX_NODE_DEPTH {
            return Err(error(
                path,
                format!("the node hierarchy is deeper than {MAX_NODE_DEPTH}"),
            ));
        }
        let node = &nodes[k];
        let transform = parent * node_transform(node, &path)?;
        if node.get("mesh").is_some() {
            let mesh = index(node, "mesh", &path, "mesh", array(root, "meshes").len())?;
            if let Some(object) = read_mesh(root, buffers, mesh, transform, &mut budget)? {
                let name = node["name"]
                    .as_str()
                    .or(array(root, "meshes")[mesh]["name"].as_str())
                    .filter(|n| crate::scene::valid_name(n))
                    .map_or_else(|| format!("glTF mesh {}", objects.len() + 1), str::to_owned);
                let mut object = SceneObject::new(name, ObjectGeometry::Mesh(object));
                object.segments = 1;
                objects.push(object);
            }
        }
        for (c, child) in array(node, "children").iter().enumerate().rev() {
            let child = child
                .as_u64()
                .map(|v| v as usize)
                .filter(|&v| v < nodes.len())
                .ok_or_else(|| error(format!("{path}.children[{c}]"), "no such node"))?;
            stack.push((child, transform, depth + 1));
        }
    }
    Ok(objects)
}

/// Mesh `m`'s triangles (all primitives) as one polygon mesh: positions transformed, turned to
/// knotwork's axes, and welded where they coincide exactly; triangles that collapse are dropped.
/// `None` when it has no triangles.
fn read_mesh(
    root: &Value,
    buffers: &[Vec<u8>],
    m: usize,
    transform: DMat4,
    budget: &mut (usize, usize),
) -> Result<Option<PolygonMesh>, FormatError> {
    let mesh = &array(root, "meshes")[m];
    let accessors = array(root, "accessors").len();
    let mut points = Vec::new();
    let mut welded: HashMap<[u64; 3], u32> = HashMap::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for (p, primitive) in array(mesh, "primitives").iter().enumerate() {
        let path = format!("meshes[{m}].primitives[{p}]");
        let mode = primitive["mode"].as_u64().unwrap_or(4);
        if !(4..=6).contains(&mode) || primitive["attributes"].get("POSITION").is_none() {
            continue;
        }
        let position = index(
            &primitive["attributes"],
            "POSITION",
            &format!("{path}.attributes"),
            "accessor",
            accessors,
        )?;
        let positions = accessor::<3>(root, buffers, position, budget.0)?;
        let corners: Vec<usize> = if primitive.get("indices").is_some() {
            let i = index(primitive, "indices", &path, "accessor", accessors)?;
            let list = accessor::<1>(root, buffers, i, 3 * budget.1)?;
            let mut out = Vec::with_capacity(list.len());
            for (e, [x]) in list.into_iter().enumerate() {
                let x = x as usize;
                if x >= positions.len() {
                    return Err(error(
                        format!("accessors[{i}]"),
                        format!(
                            "index {x} at element {e} is past the {} vertices",
                            positions.len()
                        ),
                    ));
                }
                out.push(x);
            }
            out
        } else {
            (0..positions.len()).collect()
        };
        let triangles: Vec<[usize; 3]> = match mode {
            4 => corners
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
            5 => (2..corners.len())
                .map(|k| {
                    if k % 2 == 0 {
                        [corners[k - 2], corners[k - 1], corners[k]]
                    } else {
                        [corners[k - 1], corners[k - 2], corners[k]]
                    }
                })
                .collect(),
            _ => (2..corners.len())
                .map(|k| [corners[0], corners[k - 1], corners[k]])
                .collect(),
        };
        let mut map = vec![u32::MAX; positions.len()];
        for t in triangles {
            let mut face = [0u32; 3];
            for (slot, &c) in face.iter_mut().zip(&t) {
                if map[c] == u32::MAX {
                    let q =
                        from_gltf_axes(transform.transform_point3(DVec3::from_array(positions[c])));
                    if !q.is_finite() {
                        return Err(error(
                            format!("accessors[{position}]"),
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
        .map_err(|e| error(format!("meshes[{m}]"), e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_the_rfc_4648_examples() {
        for (text, plain) in [
            ("", ""),
            ("Zg==", "f"),
            ("Zm8=", "fo"),
            ("Zm9v", "foo"),
            ("Zm9vYg==", "foob"),
            ("Zm9vYmE=", "fooba"),
            ("Zm9vYmFy", "foobar"),
        ] {
            assert_eq!(base64_decode(text).unwrap(), plain.as_bytes(), "{text}");
        }
        assert_eq!(base64_decode("Zm9v!"), None);
        assert_eq!(base64_decode("Z"), None);
    }
}
