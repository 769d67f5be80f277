//! Mass properties: `knotwork info` gives each body's area and, closed, its volume and centroid,
//! exactly (the divergence theorem over the faces, not a mesh), checked against closed forms
//! on bodies in general position: a box of planes with mixed orientations joined into a
//! polysurface, a NURBS sphere, an open cup (area only), and a STEP sphere cut by two planes
//! whose area and volume the script that made it computed in closed form.

use glam::{DAffine3, DQuat, DVec3};
use knotwork::io::project::{self, Project};
use knotwork::kernel::construct;
use knotwork::kernel::trim::TrimmedSurface;
use knotwork::scene::polysurface::Polysurface;
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};
use serde_json::Value;
use std::f64::consts::PI;

fn info(path: &std::path::Path) -> Value {
    crate::common::knotwork_json(&[std::ffi::OsStr::new("info"), path.as_os_str()])
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn point(value: &Value) -> DVec3 {
    let a: Vec<f64> = serde_json::from_value(value.clone()).unwrap();
    DVec3::new(a[0], a[1], a[2])
}

#[test]
fn knotwork_info_gives_each_bodys_exact_area_volume_and_centroid() {
    let motion = DAffine3::from_scale_rotation_translation(
        DVec3::splat(1.7),
        DQuat::from_axis_angle(DVec3::new(0.3, -0.8, 0.5).normalize(), 2.1),
        DVec3::new(41.0, -13.0, 7.5),
    );
    let block = crate::common::box_of_planes(&motion);
    let r = 0.9;
    let centre = DVec3::new(-3.0, 2.0, 1.0);
    let sphere = construct::sphere(centre, r)
        .unwrap()
        .transformed(&motion)
        .unwrap();
    let side = construct::cylinder(DVec3::ZERO, DVec3::Z, 0.8).unwrap();
    let circle = construct::circle(DVec3::ZERO, DVec3::Z, DVec3::X, 0.8).unwrap();
    let cap = knotwork::kernel::planar::planar_face(&[circle]).unwrap();
    let cup = Polysurface::new(vec![TrimmedSurface::untrimmed(side), cap], 1e-7).unwrap();
    let scene = Scene {
        objects: vec![
            SceneObject::new("block", ObjectGeometry::new(block)),
            SceneObject::new("ball", ObjectGeometry::new(sphere)),
            SceneObject::new("cup", ObjectGeometry::new(cup)),
        ],
        unit: None,
    };
    let path = crate::common::artifact_path("mass-bodies.json");
    std::fs::write(&path, project::write(&Project { scene, view: None })).unwrap();
    let out = info(&path);
    let bodies = out["bodies"].as_array().unwrap();
    let s = 1.7_f64;

    let block = &bodies[0];
    assert_eq!(block["closed"], true, "{block}");
    let volume = block["volume"].as_f64().unwrap();
    assert!(relative(volume, 3.0 * s.powi(3)) < 1e-12, "{volume}");
    let area = block["area"].as_f64().unwrap();
    assert!(relative(area, 13.0 * s * s) < 1e-12, "{area}");
    let middle = motion.transform_point3(DVec3::new(1.0, 0.5, 0.75));
    assert!(point(&block["centroid"]).distance(middle) < 1e-9, "{block}");

    let ball = &bodies[1];
    assert_eq!(ball["closed"], true, "{ball}");
    let rs = r * s;
    let volume = ball["volume"].as_f64().unwrap();
    assert!(
        relative(volume, 4.0 / 3.0 * PI * rs.powi(3)) < 1e-9,
        "{volume}"
    );
    assert!(relative(ball["area"].as_f64().unwrap(), 4.0 * PI * rs * rs) < 1e-9);
    assert!(point(&ball["centroid"]).distance(motion.transform_point3(centre)) < 1e-9);

    assert_eq!(block["validity"]["closed_shell"], true, "{block}");
    let cup = &bodies[2];
    assert_eq!(cup["closed"], false, "{cup}");
    // The cup's open rim is its naked edge, found at the rim's height (z = 1, radius 0.8).
    let validity = &cup["validity"];
    assert_eq!(validity["closed_shell"], false, "{validity}");
    assert_eq!(validity["naked_edges"], 1, "{validity}");
    let rim = point(&validity["places"]["naked"][0]["at"]);
    assert!(
        (rim.z - 1.0).abs() < 1e-9 && (rim.truncate().length() - 0.8).abs() < 1e-3,
        "{rim}"
    );
    assert!(cup.get("volume").is_none(), "{cup}");
    let area = 2.0 * PI * 0.8 + PI * 0.64;
    assert!(
        relative(cup["area"].as_f64().unwrap(), area) < 1e-9,
        "{cup}"
    );
}

#[test]
fn knotwork_info_measures_a_step_body_to_its_closed_form() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/reference/occ/step");
    let reference: Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{dir}/step.json")).unwrap())
            .unwrap();
    let out = info(std::path::Path::new(&format!("{dir}/sphere-cut.step")));
    let body = &out["bodies"][0];
    let expected = &reference["sphere-cut.step"];
    let area = body["area"].as_f64().unwrap();
    let volume = body["volume"].as_f64().unwrap();
    let exact_area = expected["analytic_area"].as_f64().unwrap();
    let exact_volume = expected["analytic_volume"].as_f64().unwrap();
    assert!(relative(area, exact_area) < 1e-9, "{area} {exact_area}");
    assert!(
        relative(volume, exact_volume) < 1e-9,
        "{volume} {exact_volume}"
    );
}

#[test]
fn the_create_dialogs_solids_are_closed_bodies_with_their_closed_form_volumes() {
    use knotwork::doc::create::{Primitive, PrimitiveParams};
    let (s, h, r) = (1.3, 2.1, 0.4);
    let cases = [
        (Primitive::SolidBox, s * s * h, 2.0 * s * s + 4.0 * s * h),
        (
            Primitive::SolidCylinder,
            PI * s * s * h,
            2.0 * PI * s * s + 2.0 * PI * s * h,
        ),
        (
            // A frustum of radii s and r·s: πh(R² + Rr + r²)/3; its side π(R + r)·slant.
            Primitive::SolidCone,
            PI * h * (s * s + s * (r * s) + (r * s) * (r * s)) / 3.0,
            PI * s * s
                + PI * (r * s) * (r * s)
                + PI * (s + r * s) * (h * h + (s - r * s) * (s - r * s)).sqrt(),
        ),
    ];
    for (kind, volume, area) in cases {
        let object = PrimitiveParams {
            kind,
            center: DVec3::new(0.7, -2.0, 5.0),
            size: s,
            height: h,
            ratio: r,
            degree: [3, 3],
        }
        .build()
        .unwrap();
        let body = object.body().expect("a body");
        assert!(body.closed(), "{kind:?} is closed");
        let (measured_area, mass) = body.measure().unwrap();
        let m = mass.expect("a closed body's mass properties");
        assert!(
            relative(m.volume, volume) < 1e-9,
            "{kind:?}: {} for {volume}",
            m.volume
        );
        assert!(
            relative(measured_area, area) < 1e-9,
            "{kind:?}: {measured_area} for {area}"
        );
    }
}

/// `knotwork info --self-intersections` finds none on a closed box, and where two overlapping
/// boxes joined into one polysurface cross (each crossing on both boxes' boundaries, between a
/// face of each); without the flag it is not looked for.
#[test]
fn knotwork_info_finds_where_a_body_passes_through_itself() {
    let motion = DAffine3::from_scale_rotation_translation(
        DVec3::splat(1.3),
        DQuat::from_axis_angle(DVec3::new(-0.4, 0.7, 0.2).normalize(), 0.9),
        DVec3::new(-6.0, 3.0, 12.0),
    );
    let block = crate::common::box_of_planes(&motion);
    let shifted = motion * DAffine3::from_translation(DVec3::new(1.0, 0.5, 0.5));
    let other = crate::common::box_of_planes(&shifted);
    let mut faces = block.faces().to_vec();
    faces.extend(other.faces().iter().cloned());
    let crossing = Polysurface::new(faces, 1e-7).unwrap();
    let scene = Scene {
        objects: vec![
            SceneObject::new("block", ObjectGeometry::new(block)),
            SceneObject::new("crossing", ObjectGeometry::new(crossing)),
        ],
        unit: None,
    };
    let path = crate::common::artifact_path("self-intersecting-bodies.json");
    std::fs::write(&path, project::write(&Project { scene, view: None })).unwrap();
    let plain = info(&path);
    assert!(plain["bodies"][0]["validity"]["self_intersections"].is_null());
    let out = crate::common::knotwork_json(&[
        std::ffi::OsStr::new("info"),
        path.as_os_str(),
        std::ffi::OsStr::new("--self-intersections"),
    ]);
    let bodies = out["bodies"].as_array().unwrap();
    assert_eq!(
        bodies[0]["validity"]["self_intersections"], 0,
        "{:#}",
        bodies[0]
    );
    let found = bodies[1]["validity"]["self_intersections"]
        .as_u64()
        .unwrap();
    assert!(found >= 4, "{:#}", bodies[1]["validity"]);
    let inverse = motion.inverse();
    for place in bodies[1]["validity"]["places"]["self_intersections"]
        .as_array()
        .unwrap()
    {
        let faces: Vec<usize> = serde_json::from_value(place["faces"].clone()).unwrap();
        assert!(faces[0] < 6 && faces[1] >= 6, "a face of each box: {place}");
        let p = inverse.transform_point3(point(&place["at"]));
        let on_box = |lo: DVec3, hi: DVec3| {
            (p - lo).min_element() >= -1e-6
                && (hi - p).min_element() >= -1e-6
                && ((p - lo).min_element().abs() <= 1e-6 || (hi - p).min_element().abs() <= 1e-6)
        };
        assert!(
            on_box(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.5))
                && on_box(DVec3::new(1.0, 0.5, 0.5), DVec3::new(3.0, 1.5, 2.0)),
            "{p} on both boxes"
        );
    }
}
