//! Opening glTF and OBJ files: malformed and hostile input is refused with a clear error and
//! nothing panics; good files of other tools open as polygon meshes.

use glam::DVec3;
use knotwork::io::gltf::{self as export, ExportOptions};
use knotwork::io::project::Project;
use knotwork::kernel::PolygonMesh;
use knotwork::kernel::tess::Tessellation;
use knotwork::scene::json::FormatError;
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};
use serde_json::{Value, json};

fn no_files(name: &str) -> Result<Vec<u8>, String> {
    Err(format!("no file {name} here"))
}

/// A plain (non-knotwork) glTF of one quad: its JSON and its binary buffer.
fn foreign() -> (Value, Vec<u8>) {
    let mesh = PolygonMesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.2), DVec3::Y],
        &[vec![0, 1, 2, 3]],
    )
    .unwrap();
    let project = Project {
        scene: Scene {
            objects: vec![SceneObject::new("quad", ObjectGeometry::new(mesh))],
            unit: None,
        },
        view: None,
    };
    let options = ExportOptions {
        tessellation: Tessellation::Segments(1),
        curvature: false,
        colors: None,
    };
    let mut e = export::export(&project, &options).unwrap();
    e.root.scenes[0].extras = None;
    (serde_json::to_value(&e.root).unwrap(), e.bin)
}

fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    export::glb_bytes(&serde_json::to_vec(json).unwrap(), bin)
}

fn open(bytes: &[u8]) -> Result<Project, FormatError> {
    knotwork::io::open("test.glb", bytes, &no_files)
}

fn refused(bytes: &[u8], expected: &str) {
    match open(bytes) {
        Ok(p) => panic!(
            "opened ({} objects), expected {expected:?}",
            p.scene.objects.len()
        ),
        Err(e) => {
            let text = e.to_string();
            assert!(
                text.contains(expected),
                "{text:?} does not mention {expected:?}"
            );
        }
    }
}

#[test]
fn the_reference_file_opens() {
    let (json, bin) = foreign();
    let project = open(&glb(&json, &bin)).unwrap();
    assert_eq!(project.scene.objects.len(), 1);
    // As .gltf text with the buffer as a data: URI.
    let mut text = json.clone();
    text["buffers"][0]["uri"] = Value::String(format!(
        "data:application/octet-stream;base64,{}",
        base64(&bin)
    ));
    let project = knotwork::io::open("quad.gltf", text.to_string().as_bytes(), &no_files).unwrap();
    assert_eq!(project.scene.objects.len(), 1);
}

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[test]
fn truncated_and_corrupted_glb_files_are_refused_without_panicking() {
    let (json, bin) = foreign();
    let good = glb(&json, &bin);
    refused(&good[..8], "truncated");
    refused(&good[..good.len() - 4], "truncated");
    for cut in (0..good.len()).step_by(7) {
        assert!(open(&good[..cut]).is_err(), "a file cut at {cut} opened");
    }
    // Every single-byte corruption either opens or is refused; none panics.
    for at in 0..good.len() {
        for value in [0x00, 0xFF, b'9', b'"'] {
            let mut bad = good.clone();
            bad[at] = value;
            let _ = open(&bad);
        }
    }
    let mut chunk = good.clone();
    chunk[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    refused(&chunk, "past the end");
    let mut version = good.clone();
    version[4] = 1;
    refused(&version, "version 1");
}

#[test]
fn hostile_json_is_refused_with_its_path() {
    let (json, bin) = foreign();
    type Mutation = Box<dyn Fn(&mut Value)>;
    let cases: Vec<(&str, Mutation, &str)> = vec![
        (
            "glTF 1",
            Box::new(|j| j["asset"]["version"] = json!("1.0")),
            "asset.version",
        ),
        (
            "short buffer",
            Box::new(|j| j["buffers"][0]["byteLength"] = json!(1_000_000)),
            "buffers[0].byteLength",
        ),
        (
            "view past buffer",
            Box::new(|j| j["bufferViews"][0]["byteOffset"] = json!(1_000_000)),
            "bufferViews[0]",
        ),
        (
            "huge count",
            Box::new(|j| j["accessors"][0]["count"] = json!(1_000_000_000_000u64)),
            "accessors[0].count",
        ),
        (
            "count past view",
            Box::new(|j| j["accessors"][0]["count"] = json!(1000)),
            "do not fit",
        ),
        (
            "bad stride",
            Box::new(|j| j["bufferViews"][0]["byteStride"] = json!(3)),
            "byteStride",
        ),
        (
            "sparse",
            Box::new(|j| j["accessors"][0]["sparse"] = json!({"count": 1})),
            "sparse",
        ),
        (
            "positions as VEC2",
            Box::new(|j| j["accessors"][0]["type"] = json!("VEC2")),
            "accessors[0].type",
        ),
        (
            "bad component",
            Box::new(|j| j["accessors"][0]["componentType"] = json!(5130)),
            "componentType",
        ),
        (
            "no such view",
            Box::new(|j| j["accessors"][0]["bufferView"] = json!(99)),
            "bufferView",
        ),
        (
            "no such mesh",
            Box::new(|j| j["nodes"][0]["mesh"] = json!(7)),
            "nodes[0].mesh",
        ),
        (
            "cycle",
            Box::new(|j| j["nodes"][0]["children"] = json!([0])),
            "cycle",
        ),
        (
            "no such child",
            Box::new(|j| j["nodes"][0]["children"] = json!([5])),
            "children[0]",
        ),
        (
            "NaN-free matrix",
            Box::new(|j| j["nodes"][0]["matrix"] = json!([1, 0, 0])),
            "matrix",
        ),
        (
            "escape",
            Box::new(|j| j["buffers"][0]["uri"] = json!("../../etc/passwd")),
            "beside",
        ),
        (
            "bad base64",
            Box::new(|j| {
                j["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,!!!!")
            }),
            "base64",
        ),
        (
            "broken model",
            Box::new(
                |j| j["scenes"][0]["extras"] = json!({"knotwork": {"format": "knotwork", "version": 2, "objects": [{"type": "polygon_mesh", "points": [[0, 0, 0]], "faces": [[0, 0, 0]]}]}}),
            ),
            "embedded knotwork model",
        ),
        // What the gltf crate leaves to its caller: each of these would panic, overflow or
        // hit an `unreachable!` inside the crate if it were not checked first.
        (
            "no such POSITION accessor",
            Box::new(|j| j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(99)),
            "attributes.POSITION",
        ),
        (
            "zero count",
            Box::new(|j| j["accessors"][0]["count"] = json!(0)),
            "accessors[0].count",
        ),
        (
            "float indices",
            Box::new(|j| j["accessors"][2]["componentType"] = json!(5126)),
            "accessors[2].componentType",
        ),
        (
            "byte positions",
            Box::new(|j| j["accessors"][0]["componentType"] = json!(5121)),
            "accessors[0].componentType",
        ),
        (
            "stride not a multiple of 4",
            Box::new(|j| j["bufferViews"][0]["byteStride"] = json!(13)),
            "byteStride",
        ),
        (
            "accessor offset overflows",
            Box::new(|j| j["accessors"][0]["byteOffset"] = json!(u64::MAX - 8)),
            "accessors[0]",
        ),
        (
            "view length overflows",
            Box::new(|j| j["bufferViews"][0]["byteLength"] = json!(u64::MAX - 8)),
            "bufferViews[0]",
        ),
        (
            "unknown mode",
            Box::new(|j| j["meshes"][0]["primitives"][0]["mode"] = json!(99)),
            "mode",
        ),
        (
            "required extension",
            Box::new(|j| j["extensionsRequired"] = json!(["KHR_draco_mesh_compression"])),
            "extensionsRequired",
        ),
        (
            "wrong JSON type",
            Box::new(|j| j["nodes"] = json!(5)),
            "nodes",
        ),
        (
            "no meshes",
            Box::new(|j| {
                j["nodes"][0]
                    .as_object_mut()
                    .unwrap()
                    .remove("mesh")
                    .map(|_| ())
                    .unwrap_or(())
            }),
            "no triangle meshes",
        ),
    ];
    for (name, mutate, expected) in cases {
        let mut bad = json.clone();
        mutate(&mut bad);
        match open(&glb(&bad, &bin)) {
            Ok(_) => panic!("{name}: opened"),
            Err(e) => assert!(
                e.to_string().contains(expected),
                "{name}: {e} does not mention {expected:?}"
            ),
        }
    }
    // An index past the vertices.
    let mut bad_bin = bin.clone();
    let indices = json["accessors"][2]["bufferView"].as_u64().unwrap() as usize;
    let offset = json["bufferViews"][indices]["byteOffset"].as_u64().unwrap() as usize;
    bad_bin[offset..offset + 2].copy_from_slice(&500u16.to_le_bytes());
    refused(&glb(&json, &bad_bin), "past the 4 vertices");
    // A GLB header whose length is under its own 12 bytes.
    let mut short = glb(&json, &bin);
    short[8..12].copy_from_slice(&5u32.to_le_bytes());
    refused(&short, "less than the header");
    // Tolerated as other importers do: POSITION without min/max, and a primitive without
    // POSITION (skipped) beside one with it.
    let mut lenient = json.clone();
    let accessor = &mut lenient["accessors"][0];
    accessor.as_object_mut().unwrap().remove("min");
    accessor.as_object_mut().unwrap().remove("max");
    let mut headless = lenient["meshes"][0]["primitives"][0].clone();
    headless["attributes"]
        .as_object_mut()
        .unwrap()
        .remove("POSITION");
    lenient["meshes"][0]["primitives"]
        .as_array_mut()
        .unwrap()
        .push(headless);
    let project = open(&glb(&lenient, &bin)).unwrap();
    assert_eq!(project.scene.objects.len(), 1);
    // Not glTF, not JSON.
    assert!(knotwork::io::open("x.gltf", b"\x00\x01garbage", &no_files).is_err());
    assert!(knotwork::io::open("x.glb", b"glTF", &no_files).is_err());
}
