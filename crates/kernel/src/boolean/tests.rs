//! Booleans against closed forms and invariants, in general position.

use std::f64::consts::PI;

use glam::{DAffine3, DQuat, DVec3};

use super::*;
use crate::solids::{block, capped_cylinder, transformed};

use crate::test_support::{Xorshift, placement};

fn volume(faces: &[TrimmedSurface]) -> f64 {
    if faces.is_empty() {
        return 0.0;
    }
    signed_volume(faces).expect("volume")
}

fn moved(faces: Vec<TrimmedSurface>, motion: &DAffine3) -> Vec<TrimmedSurface> {
    transformed(&faces, motion).expect("moved")
}

fn run(op: BooleanOp, a: &[TrimmedSurface], b: &[TrimmedSurface], scale: f64) -> BooleanResult {
    boolean(op, a, b, 1e-6 * scale).unwrap_or_else(|e| panic!("{}: {e}", op.name()))
}

/// Every result is closed and consistently oriented, and its volume is the given one.
fn check(result: &BooleanResult, expected: f64, scale: f64, what: &str) {
    let faces = result.faces();
    let v = volume(&faces);
    let tolerance = 1e-6 * expected.abs().max(scale.powi(3));
    assert!(
        (v - expected).abs() <= tolerance,
        "{what}: volume {v}, expected {expected} (off by {:.3e})",
        v - expected
    );
    if !faces.is_empty() {
        let topology = find_topology(&faces, 1e-5 * scale).expect("topology");
        let valid = validity(faces.len(), &topology);
        assert!(valid.is_closed_shell(), "{what}: {valid:?}");
        assert!(valid.flipped.iter().all(|f| !f), "{what}: faces disagree");
    }
}

#[test]
fn two_overlapping_blocks_in_general_position() {
    for seed in 1..4 {
        let (motion, s) = placement(seed);
        let a = moved(
            block(DVec3::ZERO, DVec3::new(2.0, 1.5, 1.0)).unwrap(),
            &motion,
        );
        let b = moved(
            block(DVec3::new(1.2, 0.7, 0.4), DVec3::new(1.3, 1.7, 1.1)).unwrap(),
            &motion,
        );
        let (va, vb) = (3.0, 1.3 * 1.7 * 1.1);
        let common = 0.8 * 0.8 * 0.6;
        let s3 = s.powi(3);
        check(
            &run(BooleanOp::Union, &a, &b, s),
            (va + vb - common) * s3,
            s,
            "union",
        );
        check(
            &run(BooleanOp::Intersection, &a, &b, s),
            common * s3,
            s,
            "intersection",
        );
        check(
            &run(BooleanOp::Difference, &a, &b, s),
            (va - common) * s3,
            s,
            "difference",
        );
        check(
            &run(BooleanOp::Difference, &b, &a, s),
            (vb - common) * s3,
            s,
            "b - a",
        );
    }
}

#[test]
fn blocks_sharing_face_planes() {
    for seed in 4..6 {
        let (motion, s) = placement(seed);
        let s3 = s.powi(3);
        let a = moved(
            block(DVec3::ZERO, DVec3::new(2.0, 2.0, 1.0)).unwrap(),
            &motion,
        );
        // Flush with a's top, sticking out on one side.
        let b = moved(
            block(DVec3::new(0.5, 0.5, 0.5), DVec3::new(1.0, 2.0, 0.5)).unwrap(),
            &motion,
        );
        check(
            &run(BooleanOp::Union, &a, &b, s),
            (4.0 + 0.25) * s3,
            s,
            "flush union",
        );
        check(
            &run(BooleanOp::Difference, &a, &b, s),
            3.25 * s3,
            s,
            "flush cut",
        );
        check(
            &run(BooleanOp::Intersection, &a, &b, s),
            0.75 * s3,
            s,
            "flush common",
        );
        // Side by side, touching along a whole face: union is one block.
        let c = moved(
            block(DVec3::new(2.0, 0.0, 0.0), DVec3::new(1.0, 2.0, 1.0)).unwrap(),
            &motion,
        );
        let union = run(BooleanOp::Union, &a, &c, s);
        check(&union, 6.0 * s3, s, "side by side");
        assert_eq!(union.solids.len(), 1);
        // Standing on top, partly over the edge.
        let d = moved(
            block(DVec3::new(1.5, 0.5, 1.0), DVec3::new(1.0, 1.0, 1.0)).unwrap(),
            &motion,
        );
        let union = run(BooleanOp::Union, &a, &d, s);
        check(&union, 5.0 * s3, s, "standing on top");
        assert_eq!(union.solids.len(), 1);
        let common = run(BooleanOp::Intersection, &a, &d, s);
        assert!(
            common.solids.is_empty(),
            "touching blocks have no common volume"
        );
    }
}

#[test]
fn a_block_minus_a_through_hole() {
    for seed in 6..8 {
        let (motion, s) = placement(seed);
        let s3 = s.powi(3);
        let r = 0.4;
        let a = moved(
            block(DVec3::ZERO, DVec3::new(2.0, 1.5, 1.0)).unwrap(),
            &motion,
        );
        let pin = moved(
            capped_cylinder(DVec3::new(0.9, 0.7, -0.5), DVec3::Z * 2.0, r).unwrap(),
            &motion,
        );
        let cut = run(BooleanOp::Difference, &a, &pin, s);
        check(&cut, (3.0 - PI * r * r) * s3, s, "through hole");
    }
}

/// A block minus three pins through it, done a step at a time: the progress never goes back
/// and ends at 1, the stage is named at every step, and the result has the closed-form volume
/// (the block less three cylinders). A job dropped half-way leaves nothing behind, and one
/// given a tolerance of 0 is refused before it starts.
#[test]
fn a_boolean_done_a_step_at_a_time() {
    let (motion, s) = placement(11);
    let r = 0.2;
    let a = moved(
        block(DVec3::ZERO, DVec3::new(2.0, 1.5, 1.0)).unwrap(),
        &motion,
    );
    let mut pins = Vec::new();
    for (k, x) in [0.4, 1.0, 1.6].into_iter().enumerate() {
        pins.extend(moved(
            capped_cylinder(DVec3::new(x, 0.3 + 0.4 * k as f64, -0.5), DVec3::Z * 2.0, r).unwrap(),
            &motion,
        ));
    }
    let mut job = BooleanJob::new(
        BooleanOp::Difference,
        (a.clone(), None),
        (pins.clone(), None),
        1e-6 * s,
    )
    .unwrap();
    let (mut last, mut steps, mut stages) = (job.progress(), 0, Vec::new());
    assert_eq!(last, 0.0);
    while !job.step().unwrap() {
        steps += 1;
        let now = job.progress();
        assert!(now >= last && now <= 1.0, "progress {last} then {now}");
        last = now;
        if stages.last() != Some(&job.stage()) {
            stages.push(job.stage());
        }
        assert!(steps < 10_000, "the job does not end");
    }
    assert_eq!(job.progress(), 1.0);
    assert!(steps > 10, "{steps} steps");
    assert!(stages.len() >= 4, "{stages:?}");
    let cut = job.finish().unwrap();
    check(&cut, (3.0 - 3.0 * PI * r * r) * s.powi(3), s, "three pins");
    assert_eq!(cut.split_faces, 2 + 3);
    let mut dropped =
        BooleanJob::new(BooleanOp::Union, (a.clone(), None), (pins, None), 1e-6 * s).unwrap();
    for _ in 0..5 {
        dropped.step().unwrap();
    }
    assert!(dropped.progress() > 0.0 && dropped.progress() < 1.0);
    assert!(dropped.finish().is_err());
    assert!(BooleanJob::new(BooleanOp::Union, (a.clone(), None), (a, None), 0.0).is_err());
}

/// Two equal cylinders crossing at right angles, each turned about its own axis (so their
/// seams lie anywhere), in general position: their common part is the Steinmetz solid,
/// 16 r³ / 3. Their surfaces touch at two points where the intersection curves cross; the
/// curves are ended there at one common point on both.
#[test]
fn crossing_cylinders_have_the_steinmetz_volume() {
    for (seed, turns) in [(6, (0.7, 1.9)), (7, (2.3, 0.4))] {
        let (motion, s) = placement(seed);
        let s3 = s.powi(3);
        let r = 0.4;
        let spin =
            |axis: DVec3, angle: f64| DAffine3::from_quat(DQuat::from_axis_angle(axis, angle));
        let c1 = moved(
            moved(
                capped_cylinder(DVec3::new(-2.0, 0.0, 0.0), DVec3::X * 4.0, r).unwrap(),
                &spin(DVec3::X, turns.0),
            ),
            &motion,
        );
        let c2 = moved(
            moved(
                capped_cylinder(DVec3::new(0.0, -2.0, 0.0), DVec3::Y * 4.0, r).unwrap(),
                &spin(DVec3::Y, turns.1),
            ),
            &motion,
        );
        check(
            &run(BooleanOp::Intersection, &c1, &c2, s),
            16.0 * r.powi(3) / 3.0 * s3,
            s,
            "Steinmetz",
        );
        // And the union and difference keep the invariants with the cylinders' volumes.
        let v = PI * r * r * 4.0 * s3;
        let common = 16.0 * r.powi(3) / 3.0 * s3;
        check(
            &run(BooleanOp::Union, &c1, &c2, s),
            2.0 * v - common,
            s,
            "Steinmetz union",
        );
        check(
            &run(BooleanOp::Difference, &c1, &c2, s),
            v - common,
            s,
            "Steinmetz difference",
        );
    }
}

/// The same with both seams through the touching points (where the curves end on the seam,
/// not where the surfaces touch): closed since the cut curves are fitted through some of the
/// marched points (a regression kept from when it was refused).
#[test]
fn crossing_cylinders_with_their_seams_through_the_touching_points() {
    let r = 0.4;
    let c1 = capped_cylinder(DVec3::new(-2.0, 0.0, 0.0), DVec3::X * 4.0, r).unwrap();
    let c2 = capped_cylinder(DVec3::new(0.0, -2.0, 0.0), DVec3::Y * 4.0, r).unwrap();
    check(
        &run(BooleanOp::Intersection, &c1, &c2, 1.0),
        16.0 * r.powi(3) / 3.0,
        1.0,
        "Steinmetz with seams at the touching points",
    );
}

#[test]
fn a_body_inside_another_leaves_a_void_and_disjoint_bodies_stay_apart() {
    let (motion, s) = placement(9);
    let s3 = s.powi(3);
    let a = moved(block(DVec3::ZERO, DVec3::splat(2.0)).unwrap(), &motion);
    let inner = moved(
        block(DVec3::splat(0.5), DVec3::splat(1.0)).unwrap(),
        &motion,
    );
    let hollow = run(BooleanOp::Difference, &a, &inner, s);
    check(&hollow, 7.0 * s3, s, "void");
    assert_eq!(hollow.solids.len(), 1);
    assert_eq!(hollow.solids[0].shells.len(), 2);
    let far = moved(
        block(DVec3::splat(5.0), DVec3::splat(1.0)).unwrap(),
        &motion,
    );
    let both = run(BooleanOp::Union, &a, &far, s);
    check(&both, 9.0 * s3, s, "disjoint union");
    assert_eq!(both.solids.len(), 2);
    assert!(run(BooleanOp::Intersection, &a, &far, s).solids.is_empty());
}

#[test]
fn an_open_body_is_refused() {
    let mut a = block(DVec3::ZERO, DVec3::ONE).unwrap();
    a.pop();
    let b = block(DVec3::splat(0.5), DVec3::ONE).unwrap();
    let e = boolean(BooleanOp::Union, &a, &b, 1e-6).unwrap_err();
    assert!(e.to_string().contains("not a closed solid"), "{e}");
}

/// Two boxes along the axes, each face planed in its own direction and half of them facing
/// in: the difference is 3 − 1 × 0.5 × 1.
#[test]
fn aligned_blocks_with_faces_facing_either_way() {
    let mixed = |shift: DVec3| {
        let plane = |o: DVec3, u: DVec3, v: DVec3| {
            TrimmedSurface::untrimmed(crate::construct::plane(o + shift, u, v).unwrap())
        };
        let (x, y, z) = (DVec3::X * 2.0, DVec3::Y, DVec3::Z * 1.5);
        vec![
            plane(DVec3::ZERO, y, x),
            plane(z, y, x),
            plane(DVec3::ZERO, x, z),
            plane(y, x, z),
            plane(DVec3::ZERO, z, y),
            plane(x, y, z),
        ]
    };
    let a = mixed(DVec3::ZERO);
    let b = mixed(DVec3::new(1.0, 0.5, 0.5));
    // Every cut lies on a grid line of the faces' domains: a part's inner point is not
    // taken on one (the regression: a scan line along a cut put it on B's edge).
    check(
        &run(BooleanOp::Difference, &a, &b, 1.0),
        2.5,
        1.0,
        "aligned difference",
    );
    check(
        &run(BooleanOp::Union, &a, &b, 1.0),
        5.5,
        1.0,
        "aligned union",
    );
    check(
        &run(BooleanOp::Intersection, &a, &b, 1.0),
        0.5,
        1.0,
        "aligned intersection",
    );
}

/// Random pairs of blocks with corners on a quarter grid (so they often share face planes,
/// touch along faces, edges or corners, or lie apart), moved into general position: every
/// boolean either refuses or returns closed, consistently oriented solids whose volumes
/// keep vol(A ∪ B) + vol(A ∩ B) = vol(A) + vol(B) and vol(A − B) + vol(A ∩ B) = vol(A).
#[test]
fn random_blocks_on_a_grid_keep_the_volume_invariants() {
    let mut random = Xorshift::from_state(0x5EED);
    let mut next = |n: u64| random.below(n);
    let mut refused = Vec::new();
    let cases = 40;
    for case in 0..cases {
        let corner = |next: &mut dyn FnMut(u64) -> u64| {
            DVec3::new(next(9) as f64, next(9) as f64, next(9) as f64) * 0.25
        };
        let size = |next: &mut dyn FnMut(u64) -> u64| {
            DVec3::new(
                1.0 + next(8) as f64,
                1.0 + next(8) as f64,
                1.0 + next(8) as f64,
            ) * 0.25
        };
        let (ca, sa) = (corner(&mut next), size(&mut next));
        let (cb, sb) = (corner(&mut next), size(&mut next));
        let (motion, s) = placement(100 + case);
        let a = moved(block(ca, sa).unwrap(), &motion);
        let b = moved(block(cb, sb).unwrap(), &motion);
        let s3 = s.powi(3);
        let (va, vb) = (sa.x * sa.y * sa.z * s3, sb.x * sb.y * sb.z * s3);
        let overlap = (ca + sa).min(cb + sb) - ca.max(cb);
        let common = overlap.max(DVec3::ZERO).x
            * overlap.max(DVec3::ZERO).y
            * overlap.max(DVec3::ZERO).z
            * s3;
        let expected = [
            (BooleanOp::Union, va + vb - common),
            (BooleanOp::Difference, va - common),
            (BooleanOp::Intersection, common),
        ];
        for (op, want) in expected {
            match boolean(op, &a, &b, 1e-6 * s) {
                Ok(result) => check(&result, want, s, &format!("case {case} {}", op.name())),
                Err(e) => refused.push(format!("case {case} {}: {e}", op.name())),
            }
        }
    }
    eprintln!("{} of {} refused", refused.len(), cases * 3);
    assert!(refused.is_empty(), "{refused:#?}");
}

/// Random blocks against random upright cylinders (radius and axis on a quarter grid, so the
/// cylinder often touches a side of the block, stands on its top or shares its bottom plane),
/// in general position: each result closed and oriented, and the volume invariants hold. A
/// cylinder tangent to a side plane of the block (touching it along a line: seeds 0 and 9)
/// may be refused, never answered with an open body.
#[test]
fn random_cylinders_against_blocks_keep_the_volume_invariants() {
    let mut random = Xorshift::from_state(0xC1);
    let mut next = |n: u64| random.below(n);
    let mut refused = Vec::new();
    let cases = 16;
    for case in 0..cases {
        let corner = DVec3::new(next(5) as f64, next(5) as f64, next(5) as f64) * 0.25;
        let size = DVec3::new(
            2.0 + next(6) as f64,
            2.0 + next(6) as f64,
            1.0 + next(6) as f64,
        ) * 0.25;
        let r = 0.25 * (1.0 + next(3) as f64);
        let base = DVec3::new(next(9) as f64, next(9) as f64, next(5) as f64) * 0.25;
        let height = 0.25 * (1.0 + next(8) as f64);
        let (motion, s) = placement(200 + case);
        let a = moved(block(corner, size).unwrap(), &motion);
        let b = moved(
            capped_cylinder(base, DVec3::Z * height, r).unwrap(),
            &motion,
        );
        let s3 = s.powi(3);
        let (va, vb) = (size.x * size.y * size.z * s3, PI * r * r * height * s3);
        let tangent = [0, 1].iter().any(|&i| {
            [corner[i], corner[i] + size[i]].iter().any(|&side| {
                (base[i] + r - side).abs() < 1e-12 || (base[i] - r - side).abs() < 1e-12
            })
        });
        let mut volumes = std::collections::BTreeMap::new();
        for op in BooleanOp::ALL {
            match boolean(op, &a, &b, 1e-6 * s) {
                Ok(result) => {
                    let v = volume(&result.faces());
                    check(&result, v, s, &format!("case {case} {}", op.name()));
                    volumes.insert(op.name(), v);
                }
                Err(e) if tangent => eprintln!("case {case} {} (tangent) refused: {e}", op.name()),
                Err(e) => refused.push(format!("case {case} {} (block {corner} {size}, cylinder r {r} at {base} up {height}): {e}", op.name())),
            }
        }
        if volumes.len() == 3 {
            let tolerance = 1e-6 * (va + vb);
            assert!(
                (volumes["union"] + volumes["intersection"] - va - vb).abs() < tolerance,
                "case {case}: {volumes:?} against {va} + {vb}"
            );
            assert!(
                (volumes["difference"] + volumes["intersection"] - va).abs() < tolerance,
                "case {case}: {volumes:?} against {va}"
            );
        }
    }
    eprintln!("{} of {} refused", refused.len(), cases * 3);
    assert!(refused.is_empty(), "{refused:#?}");
}

/// Found by a random run: a cylinder whose axis is a vertical edge of the block and whose top
/// cap lies in the block's top plane (the cap's disc centred on the block's corner). Not yet
/// closed: refused, never answered open.
#[test]
fn a_cylinder_capped_in_a_block_face_around_its_corner() {
    let (motion, s) = placement(203);
    let a = moved(
        block(DVec3::new(1.0, 0.0, 0.5), DVec3::new(0.75, 0.75, 1.0)).unwrap(),
        &motion,
    );
    let b = moved(
        capped_cylinder(DVec3::new(1.75, 0.0, 0.25), DVec3::Z * 1.25, 0.5).unwrap(),
        &motion,
    );
    let s3 = s.powi(3);
    // A quarter of the cylinder's disc over the block's height 1: π r² / 4.
    let common = PI * 0.25 / 4.0 * s3;
    check(
        &run(BooleanOp::Intersection, &a, &b, s),
        common,
        s,
        "quarter cylinder",
    );
    check(
        &run(BooleanOp::Union, &a, &b, s),
        0.5625 * s3 + PI * 0.25 * 1.25 * s3 - common,
        s,
        "union",
    );
}

/// A body combined with its copy: the union and the intersection are the body, the difference
/// is empty (its faces lie on one another everywhere and are not intersected); two equal
/// cylinders on one axis, one shifted along it, share a curved face over an area: refused,
/// saying so, in a bounded time (the intersection stops after its most cell pairs).
#[test]
fn a_body_and_its_copy_and_cylinders_sharing_their_side() {
    let (motion, s) = placement(31);
    let s3 = s.powi(3);
    let r = 0.4;
    let pin = moved(
        capped_cylinder(DVec3::ZERO, DVec3::Z * 2.0, r).unwrap(),
        &motion,
    );
    let copy = pin.clone();
    let exact = std::f64::consts::PI * r * r * 2.0 * s3;
    check(
        &run(BooleanOp::Union, &pin, &copy, s),
        exact,
        s,
        "union with a copy",
    );
    check(
        &run(BooleanOp::Intersection, &pin, &copy, s),
        exact,
        s,
        "intersection with a copy",
    );
    assert!(run(BooleanOp::Difference, &pin, &copy, s).solids.is_empty());
    let shifted = moved(
        capped_cylinder(DVec3::Z, DVec3::Z * 2.0, r).unwrap(),
        &motion,
    );
    let started = std::time::Instant::now();
    match boolean(BooleanOp::Union, &pin, &shifted, 1e-6 * s) {
        Ok(made) => check(&made, exact * 1.5, s, "cylinders sharing their side"),
        Err(e) => assert!(e.to_string().contains("lie on one another"), "{e}"),
    }
    eprintln!("cylinders sharing their side: {:?}", started.elapsed());
}

/// Blocks and capped cylinders the boolean census (random placements on a quarter grid)
/// found refused: a cylinder halved by a block's face through its axis (one cut runs along
/// the cylinder's seam), cylinders touching a block along a line (through a face's sample
/// point, and along the seam), a cap touching a block's face with the block's edge across it
/// and another edge tangent to it, and a cylinder crossing a face whose edge its circle
/// touches. Each in its own place and moved into general position; volumes from closed forms.
#[test]
fn cylinders_touching_blocks_along_lines_and_seams() {
    let cylinder = |base: [f64; 3], height: f64, r: f64| {
        let faces =
            capped_cylinder(DVec3::from(base), DVec3::new(0.0, 0.0, height), r).expect("cylinder");
        (faces, PI * r * r * height)
    };
    let cuboid = |corner: [f64; 3], size: [f64; 3]| {
        let faces = block(DVec3::from(corner), DVec3::from(size)).expect("block");
        (faces, size[0] * size[1] * size[2])
    };
    // (first body, second body, the volume they share)
    let cases = [
        (
            cuboid([0.75, -0.75, -0.5], [2.75, 2.75, 1.0]),
            cylinder([0.75, 0.5, -2.0], 3.0, 0.375),
            0.5 * PI * 0.375 * 0.375,
        ),
        (
            cylinder([-1.75, 0.0, -0.25], 0.5, 1.5),
            cuboid([-0.25, -0.25, -0.25], [0.25, 2.0, 2.0]),
            0.0,
        ),
        (
            cylinder([-0.25, 0.25, -1.5], 1.25, 0.25),
            cuboid([-1.75, -1.0, -1.0], [2.0, 1.0, 0.5]),
            0.0,
        ),
        (
            cylinder([1.75, -0.5, -1.25], 1.0, 0.25),
            cuboid([-0.5, -1.25, -0.25], [2.25, 1.0, 0.5]),
            0.0,
        ),
        (
            cuboid([-1.5, 1.0, 2.0], [2.0, 1.75, 3.0]),
            cylinder([0.0, 1.25, 1.75], 1.0, 0.25),
            PI * 0.25 * 0.25 * 0.75,
        ),
    ];
    for (n, ((a, va), (b, vb), common)) in cases.into_iter().enumerate() {
        // Seeds 1, 4 and 9 put case 4's circle a rounding past the face's edge it touches.
        for seed in [0, 1, 4, 7, 9] {
            let (motion, s) = if seed == 0 {
                (DAffine3::IDENTITY, 1.0)
            } else {
                placement(seed + n as u64)
            };
            let (a, b) = (moved(a.clone(), &motion), moved(b.clone(), &motion));
            let s3 = s.powi(3);
            let what = |op: &str| format!("case {n}, seed {seed}: {op}");
            check(
                &run(BooleanOp::Union, &a, &b, s),
                (va + vb - common) * s3,
                s,
                &what("union"),
            );
            check(
                &run(BooleanOp::Intersection, &a, &b, s),
                common * s3,
                s,
                &what("intersection"),
            );
            check(
                &run(BooleanOp::Difference, &a, &b, s),
                (va - common) * s3,
                s,
                &what("difference"),
            );
        }
    }
}

/// Two blocks turned about different axes, one grazing the other's edge at a shallow angle
/// (the census found the crossing point on the edge placed 1e-4 apart on its two faces when
/// marched; the planes' line puts it at the three planes' point): the union and the
/// intersection add up to the two blocks, the difference and the intersection to the first.
#[test]
fn blocks_turned_apart_meet_at_the_three_planes_point() {
    let turn = |faces: Vec<TrimmedSurface>, axis: [f64; 3], angle: f64| {
        let rotation = DQuat::from_axis_angle(DVec3::from(axis).normalize(), angle);
        moved(faces, &DAffine3::from_quat(rotation))
    };
    let a = turn(
        block(DVec3::new(0.0, -1.0, -0.25), DVec3::new(2.0, 1.5, 1.25)).unwrap(),
        [-0.5457823368931042, 0.0699720944734749, -0.8350003273834671],
        3.381,
    );
    let b = turn(
        block(DVec3::new(-1.0, -0.25, 0.0), DVec3::new(0.75, 0.75, 2.5)).unwrap(),
        [-0.542589986033689, -0.8385481602338831, 0.049326362366699],
        4.9,
    );
    let (va, vb) = (2.0 * 1.5 * 1.25, 0.75 * 0.75 * 2.5);
    // The census's tolerance.
    let run =
        |op: BooleanOp| boolean(op, &a, &b, 8e-6).unwrap_or_else(|e| panic!("{}: {e}", op.name()));
    let union = run(BooleanOp::Union);
    let common = run(BooleanOp::Intersection);
    let difference = run(BooleanOp::Difference);
    let vc = volume(&common.faces());
    assert!(vc > 1e-3, "they overlap: {vc}");
    check(&union, va + vb - vc, 1.0, "union");
    check(&difference, va - vc, 1.0, "difference");
    check(&common, vc, 1.0, "intersection");
}

/// A flat sheet through `point` with unit normal `normal`, `half` wide each way.
fn sheet(point: DVec3, normal: DVec3, half: f64) -> TrimmedSurface {
    let normal = normal.normalize();
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let origin = point - (u + v) * half;
    TrimmedSurface::untrimmed(
        crate::construct::plane(origin, u * 2.0 * half, v * 2.0 * half).unwrap(),
    )
}

/// The volumes of a split's pieces, smallest first; each piece closed and consistently
/// oriented.
fn split_volumes(body: &[TrimmedSurface], tool: &[TrimmedSurface], scale: f64) -> Vec<f64> {
    let pieces = split((body, None), tool, 1e-6 * scale).unwrap_or_else(|e| panic!("split: {e}"));
    let mut volumes: Vec<f64> = pieces
        .iter()
        .map(|p| {
            let result = BooleanResult {
                solids: vec![p.clone()],
                split_faces: 0,
                branches: 0,
            };
            let v = p.volume().expect("volume");
            check(&result, v, scale, "piece");
            v
        })
        .collect();
    volumes.sort_by(f64::total_cmp);
    volumes
}

fn close(got: &[f64], expected: &[f64], scale: f64, what: &str) {
    assert_eq!(
        got.len(),
        expected.len(),
        "{what}: {got:?} for {expected:?}"
    );
    for (g, e) in got.iter().zip(expected) {
        assert!(
            (g - e).abs() <= 1e-6 * scale.powi(3),
            "{what}: {got:?} for {expected:?}"
        );
    }
}

/// A block split by a sheet across it, a cylinder by one through its axis, a ball by a
/// slanted one and a block by an open cylinder's side through it, each in general
/// position: the pieces' volumes are the closed forms (a prism's, half a cylinder, a
/// spherical cap's πh²(3r − h)/3, a cylinder's).
#[test]
fn a_solid_split_by_a_surface_into_closed_pieces() {
    for seed in [3, 11] {
        let (motion, s) = placement(seed);
        let s3 = s.powi(3);
        let to = |faces: Vec<TrimmedSurface>| moved(faces, &motion);
        // A 2 × 1 × 1 block cut at x = 0.7 by a sheet turned about z so that it meets the
        // bottom at x = 0.7 - 0.25 t and the top alike: a prism split in the ratio of its
        // trapezoids.
        let body = to(block(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0)).unwrap());
        let normal = DVec3::new(1.0, 0.25, 0.0);
        let tool = to(vec![sheet(DVec3::new(0.7, 0.5, 0.5), normal, 3.0)]);
        // x on the sheet at y: 0.7 - 0.25 (y - 0.5); the part below x has area 0.7 (a
        // trapezoid whose mean width is 0.7).
        close(
            &split_volumes(&body, &tool, s),
            &[0.7 * s3, 1.3 * s3],
            s,
            "block",
        );
        // A cylinder of radius 0.6 and height 1.5, split through its axis.
        let body = to(capped_cylinder(DVec3::ZERO, DVec3::new(0.0, 0.0, 1.5), 0.6).unwrap());
        let tool = to(vec![sheet(
            DVec3::new(0.0, 0.0, 0.75),
            DVec3::new(0.3, 1.0, 0.0),
            3.0,
        )]);
        let half = 0.5 * PI * 0.36 * 1.5 * s3;
        close(
            &split_volumes(&body, &tool, s),
            &[half, half],
            s,
            "cylinder",
        );
        // A ball of radius 1 cut by a slanted plane 0.4 from its centre: caps of heights 0.6
        // and 1.4.
        let body = to(crate::solids::ball(DVec3::ZERO, 1.0).unwrap());
        let normal = DVec3::new(0.3, -0.5, 0.8).normalize();
        let tool = to(vec![sheet(normal * 0.4, normal, 3.0)]);
        let cap = |h: f64| PI * h * h * (3.0 - h) / 3.0 * s3;
        close(
            &split_volumes(&body, &tool, s),
            &[cap(0.6), cap(1.4)],
            s,
            "ball",
        );
        // A 2 × 2 × 1 block split by the side of a cylinder of radius 0.5 standing through
        // it (its caps left off): the core and the block around it.
        let body = to(block(DVec3::ZERO, DVec3::new(2.0, 2.0, 1.0)).unwrap());
        let side: Vec<TrimmedSurface> =
            capped_cylinder(DVec3::new(1.0, 0.9, -1.0), DVec3::new(0.0, 0.0, 3.0), 0.5)
                .unwrap()
                .into_iter()
                .filter(|f| !f.is_trimmed())
                .collect();
        assert_eq!(side.len(), 1, "the cylinder's side");
        let core = PI * 0.25 * s3;
        close(
            &split_volumes(&body, &to(side), s),
            &[core, 4.0 * s3 - core],
            s,
            "core",
        );
    }
}

/// A surface that misses the body, one that stops inside it and one lying in a face's plane
/// are refused with what is wrong.
#[test]
fn a_split_that_cannot_divide_the_body_is_refused() {
    let body = block(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0)).unwrap();
    let refusal = |tool: TrimmedSurface| match split((&body, None), &[tool], 1e-6) {
        Ok(pieces) => panic!("{} pieces", pieces.len()),
        Err(e) => e.to_string(),
    };
    let missing = refusal(sheet(DVec3::new(5.0, 0.5, 0.5), DVec3::X, 1.0));
    assert!(missing.contains("does not cross"), "{missing}");
    let inside = refusal(sheet(DVec3::new(1.0, 0.5, 0.8), DVec3::X, 0.3));
    assert!(inside.contains("does not divide"), "{inside}");
    let on_face = refusal(sheet(DVec3::new(1.0, 0.5, 1.0), DVec3::Z, 3.0));
    assert!(on_face.contains("lies in the plane"), "{on_face}");
}

/// Closed bodies that do not pass through themselves (a block, a capped cylinder, a ball, a
/// boolean's result with a hole through it) have no self-intersection; two overlapping
/// blocks' faces taken as one body cross where the blocks' faces do (four segments on the
/// top and bottom of the first, four on the second's sides, ...), each reported once, on the
/// crossing.
#[test]
fn self_intersections_are_where_a_body_passes_through_itself() {
    let (motion, s) = placement(5);
    let a = moved(
        block(DVec3::ZERO, DVec3::new(2.0, 1.5, 1.0)).unwrap(),
        &motion,
    );
    let tolerance = 1e-6 * s;
    let pin = moved(
        capped_cylinder(DVec3::new(1.0, 0.75, -1.0), DVec3::new(0.0, 0.0, 3.0), 0.3).unwrap(),
        &motion,
    );
    let holed = boolean(BooleanOp::Difference, &a, &pin, tolerance)
        .expect("a hole")
        .faces();
    for (what, body) in [
        ("block", a.clone()),
        ("cylinder", pin.clone()),
        (
            "ball",
            moved(crate::solids::ball(DVec3::ZERO, 1.0).unwrap(), &motion),
        ),
        ("block with a hole", holed),
    ] {
        let found = self_intersections(&body, tolerance).expect("checked");
        assert!(found.is_empty(), "{what}: {found:?}");
    }
    // The block and a second one through its top: the second's four sides cross the first's
    // top, and the first's four sides... (x from 1.5 to 2.5 passes the right face at x = 2).
    let b = moved(
        block(DVec3::new(1.5, 0.5, 0.5), DVec3::new(1.0, 0.5, 1.0)).unwrap(),
        &motion,
    );
    let mut both = a.clone();
    both.extend(b);
    let found = self_intersections(&both, tolerance).expect("checked");
    assert!(!found.is_empty(), "overlapping blocks cross");
    let inverse = motion.inverse();
    for crossing in &found {
        let (i, j) = crossing.faces;
        assert!(i < 6 && j >= 6, "a face of each block: {crossing:?}");
        // Back in the blocks' frame the point lies on both blocks' boundaries.
        let p = inverse.transform_point3(crossing.at);
        let on = |lo: DVec3, hi: DVec3| {
            let inside = (p - lo).min_element() >= -1e-6 && (hi - p).min_element() >= -1e-6;
            let on_face = [p - lo, hi - p]
                .iter()
                .any(|d| d.min_element().abs() <= 1e-6);
            inside && on_face
        };
        assert!(
            on(DVec3::ZERO, DVec3::new(2.0, 1.5, 1.0))
                && on(DVec3::new(1.5, 0.5, 0.5), DVec3::new(2.5, 1.0, 1.5)),
            "{p} on both blocks"
        );
    }
}

/// A ball cut by a plane whose circle passes close by the ball's pole, enclosing it or not:
/// there the sphere's u sweeps most of its range within a short way, and the cut's (u, v)
/// curve must still follow the circle in space. The cap's volume is π h² (3r − h) / 3 for
/// its height h.
#[test]
fn a_ball_cut_by_a_plane_passing_by_its_pole() {
    use crate::solids::ball;
    let r = 0.8;
    let tilt: f64 = 0.3;
    let mut seed = 60;
    for miss in [-0.02, -0.004, 0.003, 0.012, 0.05] {
        seed += 1;
        let (motion, s) = placement(seed);
        // The plane's normal is turned `tilt` from the pole's axis; its circle keeps
        // `tilt + miss` from the normal, so it passes `miss` (in angle) beyond the pole.
        let circle = tilt + miss;
        let d = r * circle.cos();
        let turn = DAffine3::from_quat(DQuat::from_rotation_x(tilt));
        let a = moved(ball(DVec3::ZERO, r).unwrap(), &motion);
        let b = moved(
            block(
                DVec3::new(-1.5 * r, -1.5 * r, d),
                DVec3::new(3.0 * r, 3.0 * r, 3.0 * r),
            )
            .unwrap(),
            &(motion * turn),
        );
        let h = r - d;
        let cap = PI * h * h * (3.0 * r - h) / 3.0;
        let s3 = s.powi(3);
        let what = format!("the plane passing {miss} rad by the pole");
        check(
            &run(BooleanOp::Intersection, &a, &b, s),
            cap * s3,
            s,
            &format!("cap, {what}"),
        );
        check(
            &run(BooleanOp::Difference, &a, &b, s),
            (4.0 / 3.0 * PI * r.powi(3) - cap) * s3,
            s,
            &format!("ball less the cap, {what}"),
        );
    }
}
