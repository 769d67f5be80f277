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

#[test]
fn an_stl_of_closed_bodies_is_watertight_outward_and_holds_their_volume() {
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
    let scene = Scene {
        objects: vec![
            SceneObject::new("block", ObjectGeometry::new(block)),
            SceneObject::new("ball", ObjectGeometry::new(ball)),
        ],
        unit: Some(knotwork::kernel::LengthUnit::Millimetre),
    };
    let input = crate::common::artifact_path("stl-bodies.json");
    let output = crate::common::artifact_path("stl-bodies.stl");
    std::fs::write(&input, project::write(&Project { scene, view: None })).unwrap();
    let tolerance = 0.01;
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .args([
            "export".as_ref(),
            input.as_os_str(),
            "-o".as_ref(),
            output.as_os_str(),
        ])
        .args(["--tolerance", &tolerance.to_string()])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let bytes = std::fs::read(&output).unwrap();
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

    let s = 12.0_f64;
    let exact = 3.0 * s.powi(3) + 4.0 / 3.0 * PI * (0.8 * s).powi(3);
    assert!(volume > 0.0, "outward: {volume}");
    assert!(
        (volume - exact).abs() < tolerance * area,
        "volume {volume}, exact {exact}, bound {}",
        tolerance * area
    );
}
