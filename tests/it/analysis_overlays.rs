//! The analysis overlays' geometry against closed forms: the ground grid's steps and plane,
//! the curvature vector of a circle, combs on a cylinder (equal hair on the circles, none on
//! the straight lines) and its principal directions (along and around the axis).

use glam::DVec3;
use knotwork::kernel::construct;
use knotwork::render::guides::{
    curvature_combs, curvature_vector, grid_steps, ground_grid, principal_directions,
};
use knotwork::scene::{ObjectGeometry, SceneObject};
use knotwork::view::{AnalysisSettings, CombCurves, OrbitCamera};

#[test]
fn the_grid_steps_are_powers_of_ten_that_follow_the_zoom() {
    assert_eq!(grid_steps(10.0), (1.0, 10.0));
    assert_eq!(grid_steps(99.0), (1.0, 10.0));
    let (minor, major) = grid_steps(0.37);
    assert!((minor - 0.01).abs() < 1e-15 && (major - 0.1).abs() < 1e-15);
    let camera = OrbitCamera::default();
    let (lines, step) = ground_grid(&camera);
    assert!(step > 0.0 && !lines.depth_tested.is_empty() && lines.on_top.is_empty());
    let eye = camera.eye();
    let forward = -camera.axes().2;
    for v in &lines.depth_tested {
        let p = glam::Vec3::from_slice(&v.position[..3]);
        assert_eq!(p.z, 0.0, "the grid lies in the XY plane");
        assert!(
            (p - eye).dot(forward) > 0.0,
            "cut to the part in front of the eye: {p}"
        );
    }
}

#[test]
fn the_curvature_vector_of_a_circle_points_to_its_centre() {
    let r = 2.0;
    let t: f64 = 0.7;
    let c1 = DVec3::new(-r * t.sin(), r * t.cos(), 0.0);
    let c2 = DVec3::new(-r * t.cos(), -r * t.sin(), 0.0);
    let k = curvature_vector(c1, c2).unwrap();
    let toward_centre = -DVec3::new(t.cos(), t.sin(), 0.0);
    assert!((k - toward_centre / r).length() < 1e-12, "{k}");
    // A straight line has none.
    assert_eq!(curvature_vector(DVec3::X, DVec3::ZERO), Some(DVec3::ZERO));
}

#[test]
fn combs_on_a_cylinder_have_equal_hair_on_the_circles_and_none_on_the_lines() {
    let radius = 1.5;
    let cylinder = construct::cylinder(DVec3::ZERO, 4.0 * DVec3::Z, radius).unwrap();
    let object = SceneObject::new("cylinder", ObjectGeometry::new(cylinder));
    let size = 10.0;
    let settings = AnalysisSettings {
        combs: CombCurves::Both,
        comb_density: 3,
        comb_scale: 2.0,
        ..Default::default()
    };
    let lines = curvature_combs(&object, &settings, size);
    assert!(!lines.on_top.is_empty());
    // Hair and envelope come as vertex pairs; hair starts on the surface.
    let longest = settings.comb_scale * 0.1 * size;
    let mut hair = 0;
    for pair in lines.on_top.chunks_exact(2) {
        let a = glam::Vec3::from_slice(&pair[0].position[..3]).as_dvec3();
        let b = glam::Vec3::from_slice(&pair[1].position[..3]).as_dvec3();
        let on_surface = ((a.x * a.x + a.y * a.y).sqrt() - radius).abs() < 1e-5;
        if on_surface && pair[0].color == pair[1].color && pair[0].color[2] > 0.8 {
            hair += 1;
            let length = a.distance(b);
            // Every circle has curvature 1/r (the largest): full-length hair pointing outward;
            // the straight lines along the axis have none.
            assert!(length < 1e-5 || (length - longest).abs() < 1e-4, "{length}");
            if length > 1e-5 {
                let outward = DVec3::new(a.x, a.y, 0.0).normalize();
                assert!((b - a).normalize().dot(outward) > 0.9999);
            }
        }
    }
    assert!(hair > 100, "{hair}");
}

#[test]
fn principal_directions_on_a_cylinder_run_along_and_around_the_axis() {
    let cylinder = construct::cylinder(DVec3::ZERO, 3.0 * DVec3::Z, 1.0).unwrap();
    let cylinder = SceneObject::new("cylinder", ObjectGeometry::new(cylinder));
    let lines = principal_directions(&cylinder, 6);
    assert!(
        lines.on_top.len() >= 2 * 2 * 36 / 2,
        "{}",
        lines.on_top.len()
    );
    for pair in lines.on_top.chunks_exact(2) {
        let a = glam::Vec3::from_slice(&pair[0].position[..3]).as_dvec3();
        let b = glam::Vec3::from_slice(&pair[1].position[..3]).as_dvec3();
        let d = (b - a).normalize();
        let along = d.dot(DVec3::Z).abs();
        assert!(
            !(1e-6..=1.0 - 1e-6).contains(&along),
            "neither along nor around: {d}"
        );
        let m = 0.5 * (a + b);
        let radial = DVec3::new(m.x, m.y, 0.0).normalize();
        assert!(
            d.dot(radial).abs() < 1e-6,
            "tangent to the cylinder at its middle: {d}"
        );
    }
}
