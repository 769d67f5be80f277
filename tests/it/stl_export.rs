//! STL for printing: `knotwork export … -o OUT.stl` writes binary STL whose closed bodies are
//! watertight (every directed edge met once each way, after nothing but reading the f32
//! coordinates back: shared edges share their vertices) and turned outward (positive signed
//! volume), and whose volume is the bodies' exact volume within the tolerance times the area.

use std::collections::HashMap;
use std::f64::consts::PI;

use glam::{DAffine3, DQuat, DVec3};
use knotwork::io::project::{self, Project};
use knotwork::kernel::construct;
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};

/// The facets of a binary STL: (normal, [a, b, c]) in f32.
fn read_stl(bytes: &[u8]) -> Vec<([f32; 3], [[f32; 3]; 3])> {
    assert!(bytes.len() >= 84);
    let count = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert_eq!(bytes.len(), 84 + 50 * count, "50 bytes a facet");
    let f = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    let v = |at: usize| [f(at), f(at + 4), f(at + 8)];
    (0..count)
        .map(|k| {
            let at = 84 + 50 * k;
            (v(at), [v(at + 12), v(at + 24), v(at + 36)])
        })
        .collect()
}

/// A project of a block (three unit cubes in a row) and a ball of radius 0.8, scaled by 12,
/// turned and moved into general position, in millimetres, the ball coloured; and their
/// exact volume.
fn bodies_project(name: &str) -> (std::path::PathBuf, f64) {
    let motion = DAffine3::from_scale_rotation_translation(
        DVec3::splat(12.0),
        DQuat::from_axis_angle(DVec3::new(-0.4, 0.7, 0.2).normalize(), 0.9),
        DVec3::new(-30.0, 55.0, 12.0),
    );
    let block = crate::common::box_of_planes(&motion);
    let ball = construct::sphere(DVec3::new(-2.0, 1.0, 0.5), 0.8)
        .unwrap()
        .transformed(&motion)
        .unwrap();
    let mut ball = SceneObject::new("ball & <co>", ObjectGeometry::new(ball));
    ball.color = Some([1.0, 0.5, 0.0]);
    let scene = Scene {
        objects: vec![SceneObject::new("block", ObjectGeometry::new(block)), ball],
        unit: Some(knotwork::kernel::LengthUnit::Millimetre),
    };
    let input = crate::common::artifact_path(name);
    std::fs::write(&input, project::write(&Project { scene, view: None })).unwrap();
    let s = 12.0_f64;
    (input, 3.0 * s.powi(3) + 4.0 / 3.0 * PI * (0.8 * s).powi(3))
}

/// Runs `knotwork export INPUT -o OUTPUT --tolerance T` and returns the file's bytes.
fn exported(input: &std::path::Path, output: &str, tolerance: f64) -> Vec<u8> {
    let output = crate::common::artifact_path(output);
    crate::common::knotwork_ok(&[
        "export".as_ref(),
        input.as_os_str(),
        "-o".as_ref(),
        output.as_os_str(),
        "--tolerance".as_ref(),
        tolerance.to_string().as_ref(),
    ]);
    std::fs::read(&output).unwrap()
}

#[test]
fn an_stl_of_closed_bodies_is_watertight_outward_and_holds_their_volume() {
    let (input, exact) = bodies_project("stl-bodies.json");
    let tolerance = 0.01;
    let bytes = exported(&input, "stl-bodies.stl", tolerance);
    assert!(bytes.starts_with(b"knotwork binary STL, mm"));
    let facets = read_stl(&bytes);
    assert!(facets.len() > 100, "{}", facets.len());

    // Watertight and consistently turned: each directed edge once, its reverse once.
    let key = |p: [f32; 3]| p.map(f32::to_bits);
    let mut edges: HashMap<([u32; 3], [u32; 3]), i32> = HashMap::new();
    let mut volume = 0.0;
    let mut area = 0.0;
    for (normal, [a, b, c]) in &facets {
        let [pa, pb, pc] = [a, b, c].map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
        let cross = (pb - pa).cross(pc - pa);
        area += 0.5 * cross.length();
        volume += pa.dot(pb.cross(pc)) / 6.0;
        if cross.length() > 0.0 {
            let n = DVec3::new(normal[0] as f64, normal[1] as f64, normal[2] as f64);
            assert!(
                n.dot(cross.normalize()) > 0.999,
                "the normal follows the winding"
            );
        }
        let [ka, kb, kc] = [key(*a), key(*b), key(*c)];
        if ka == kb || kb == kc || ka == kc {
            continue;
        }
        for (p, q) in [(ka, kb), (kb, kc), (kc, ka)] {
            *edges.entry((p, q)).or_default() += 1;
            *edges.entry((q, p)).or_default() -= 1;
        }
    }
    let open: Vec<_> = edges.values().filter(|&&n| n != 0).collect();
    assert!(open.is_empty(), "{} directed edges unmatched", open.len());

    assert!(volume > 0.0, "outward: {volume}");
    assert!(
        (volume - exact).abs() < tolerance * area,
        "volume {volume}, exact {exact}, bound {}",
        tolerance * area
    );
}

/// The entries (name, bytes) of a ZIP archive of stored entries, read from its central
/// directory (PKWARE APPNOTE 4.3.12, 4.3.16), each checked against its CRC-32.
fn zip_entries(bytes: &[u8]) -> Vec<(String, Vec<u8>)> {
    let u16_at = |at: usize| u16::from_le_bytes([bytes[at], bytes[at + 1]]) as usize;
    let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let end = bytes.len() - 22;
    assert_eq!(
        u32_at(end),
        0x0605_4b50,
        "the end of central directory record"
    );
    let count = u16_at(end + 10);
    let mut at = u32_at(end + 16);
    let mut entries = Vec::new();
    for _ in 0..count {
        assert_eq!(u32_at(at), 0x0201_4b50, "a central directory header");
        assert_eq!(u16_at(at + 10), 0, "stored");
        let crc = u32_at(at + 16) as u32;
        let size = u32_at(at + 20);
        assert_eq!(
            size,
            u32_at(at + 24),
            "stored: the same size packed and unpacked"
        );
        let name_len = u16_at(at + 28);
        let skip = name_len + u16_at(at + 30) + u16_at(at + 32);
        let name = String::from_utf8(bytes[at + 46..at + 46 + name_len].to_vec()).unwrap();
        let local = u32_at(at + 42);
        assert_eq!(u32_at(local), 0x0403_4b50, "{name}: a local header");
        let data = local + 30 + u16_at(local + 26) + u16_at(local + 28);
        let data = bytes[data..data + size].to_vec();
        assert_eq!(crc32fast::hash(&data), crc, "{name}: CRC-32");
        entries.push((name, data));
        at += 46 + skip;
    }
    entries
}

/// The value of attribute `name` in the XML element text `element`.
fn attribute<'a>(element: &'a str, name: &str) -> &'a str {
    let key = format!(" {name}=\"");
    let start = element
        .find(&key)
        .unwrap_or_else(|| panic!("{name} in {element}"))
        + key.len();
    &element[start..start + element[start..].find('"').unwrap()]
}

/// A 3MF mesh object: its attributes' text, vertices and triangles.
struct MeshObject {
    element: String,
    vertices: Vec<DVec3>,
    triangles: Vec<[usize; 3]>,
}

/// The mesh objects of a 3MF model part.
fn mesh_objects(model: &str) -> Vec<MeshObject> {
    model
        .split("<object ")
        .skip(1)
        .map(|text| {
            let text = &text[..text.find("</object>").unwrap()];
            // Each element's attributes, after a space as `attribute` looks for them.
            let elements = |tag: &str| -> Vec<String> {
                text.split(&format!("<{tag} "))
                    .skip(1)
                    .map(|e| format!(" {}", &e[..e.find("/>").unwrap()]))
                    .collect()
            };
            let number = |e: &str, n: &str| attribute(e, n).parse::<f64>().unwrap();
            MeshObject {
                element: format!(" {}", &text[..text.find('>').unwrap()]),
                vertices: elements("vertex")
                    .iter()
                    .map(|e| DVec3::new(number(e, "x"), number(e, "y"), number(e, "z")))
                    .collect(),
                triangles: elements("triangle")
                    .iter()
                    .map(|e| ["v1", "v2", "v3"].map(|n| attribute(e, n).parse().unwrap()))
                    .collect(),
            }
        })
        .collect()
}

/// A mesh's Euler characteristic V − E + F and signed volume, after checking that it is
/// closed and oriented as 3MF asks: every directed edge once and its reverse once.
fn closed_oriented(mesh: &MeshObject) -> (i64, f64) {
    let mut edges: HashMap<(usize, usize), i32> = HashMap::new();
    let mut volume = 0.0;
    for &[a, b, c] in &mesh.triangles {
        assert!(
            a != b && b != c && c != a,
            "a triangle with a repeated vertex"
        );
        for (p, q) in [(a, b), (b, c), (c, a)] {
            *edges.entry((p, q)).or_default() += 1;
        }
        let [pa, pb, pc] = [a, b, c].map(|k| mesh.vertices[k]);
        volume += pa.dot(pb.cross(pc)) / 6.0;
    }
    for (&(p, q), &n) in &edges {
        assert_eq!(n, 1, "edge {p}-{q} directed {n} times");
        assert_eq!(
            edges.get(&(q, p)),
            Some(&1),
            "edge {p}-{q} without its twin"
        );
    }
    let euler = mesh.vertices.len() as i64 - (edges.len() / 2) as i64 + mesh.triangles.len() as i64;
    (euler, volume)
}

#[test]
fn a_3mf_package_holds_each_body_closed_and_outward_with_its_unit_and_colour() {
    let (input, exact) = bodies_project("3mf-bodies.json");
    let tolerance = 0.01;
    let entries = zip_entries(&exported(&input, "3mf-bodies.3mf", tolerance));
    let names: Vec<&str> = entries.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        ["[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model"]
    );
    let text = |k: usize| String::from_utf8(entries[k].1.clone()).unwrap();
    assert!(text(0).contains(
        "Extension=\"model\" ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\""
    ));
    assert!(text(1).contains("Target=\"/3D/3dmodel.model\""));
    assert!(
        text(1).contains("Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"")
    );
    let model = text(2);
    assert!(
        model.contains("<model unit=\"millimeter\""),
        "{}",
        &model[..200]
    );
    assert!(model.contains("<base name=\"ball &amp; &lt;co&gt;\" displaycolor=\"#FF8000FF\"/>"));

    let objects = mesh_objects(&model);
    assert_eq!(objects.len(), 2);
    let mut total = 0.0;
    for object in &objects {
        assert_eq!(attribute(&object.element, "type"), "model");
        let (euler, volume) = closed_oriented(object);
        assert_eq!(euler, 2, "a block and a ball are spheres topologically");
        assert!(volume > 0.0, "outward: {volume}");
        total += volume;
    }
    assert_eq!(attribute(&objects[1].element, "pindex"), "1");
    let area: f64 = objects
        .iter()
        .flat_map(|o| {
            o.triangles.iter().map(|&[a, b, c]| {
                0.5 * (o.vertices[b] - o.vertices[a])
                    .cross(o.vertices[c] - o.vertices[a])
                    .length()
            })
        })
        .sum();
    assert!(
        (total - exact).abs() < tolerance * area,
        "volume {total}, exact {exact}, bound {}",
        tolerance * area
    );
}

#[test]
fn a_boolean_with_a_through_hole_prints_as_one_closed_mesh_of_genus_one() {
    let reference =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/boolean");
    let solid = crate::common::artifact_path("3mf-hole.step");
    crate::common::knotwork_json(&[
        "boolean".as_ref(),
        "difference".as_ref(),
        reference.join("hole-a.step").as_os_str(),
        reference.join("hole-b.step").as_os_str(),
        "-o".as_ref(),
        solid.as_os_str(),
    ]);
    let entries = zip_entries(&exported(&solid, "3mf-hole.3mf", 0.01));
    let objects = mesh_objects(std::str::from_utf8(&entries[2].1).unwrap());
    assert_eq!(objects.len(), 1);
    let (euler, volume) = closed_oriented(&objects[0]);
    assert_eq!(euler, 0, "a body with one hole through it");
    assert!(volume > 0.0, "outward: {volume}");
}
