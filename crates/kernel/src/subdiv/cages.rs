//! Cage primitives for subdivision surfaces: cube, open cylinder, torus, grid and the
//! icosahedron (triangles), every face counter-clockwise seen from outside.

use std::f64::consts::TAU;

use glam::DVec3;

use crate::{GeometryError, PolygonMesh};

/// A cube of edge `size` centred at `center`: 8 points, 6 quads.
pub fn cube(center: DVec3, size: f64) -> Result<PolygonMesh, GeometryError> {
    let h = 0.5 * size;
    let points = (0..8)
        .map(|k| {
            center
                + DVec3::new(
                    if k & 1 == 0 { -h } else { h },
                    if k & 2 == 0 { -h } else { h },
                    if k & 4 == 0 { -h } else { h },
                )
        })
        .collect();
    let faces = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 6, 7, 3],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
    ];
    PolygonMesh::new(points, &faces)
}

/// A torus about the z axis through `center`: `around` × `across` quads on radii `major` and
/// `minor` (the cage's points lie on the torus).
pub fn torus(
    center: DVec3,
    major: f64,
    minor: f64,
    around: usize,
    across: usize,
) -> Result<PolygonMesh, GeometryError> {
    let (n, m) = (around.max(3), across.max(3));
    let mut points = Vec::with_capacity(n * m);
    for i in 0..n {
        let a = TAU * i as f64 / n as f64;
        for j in 0..m {
            let b = TAU * j as f64 / m as f64;
            let r = major + minor * b.cos();
            points.push(center + DVec3::new(r * a.cos(), r * a.sin(), minor * b.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let faces: Vec<Vec<u32>> = (0..n)
        .flat_map(|i| {
            (0..m).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    PolygonMesh::new(points, &faces)
}

/// An open cylinder about the z axis: `around` quads around, `rows` rows up to `height`.
pub fn cylinder(
    center: DVec3,
    radius: f64,
    height: f64,
    around: usize,
    rows: usize,
) -> Result<PolygonMesh, GeometryError> {
    let (n, m) = (around.max(3), rows.max(1) + 1);
    let mut points = Vec::with_capacity(n * m);
    for i in 0..n {
        let a = TAU * i as f64 / n as f64;
        for j in 0..m {
            let z = height * j as f64 / (m - 1) as f64;
            points.push(center + DVec3::new(radius * a.cos(), radius * a.sin(), z));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + j) as u32;
    let faces: Vec<Vec<u32>> = (0..n)
        .flat_map(|i| {
            (0..m - 1).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    PolygonMesh::new(points, &faces)
}

/// A flat `cells` × `cells` grid of quads of side `size` in the xy plane, facing +z.
pub fn grid(center: DVec3, size: f64, cells: usize) -> Result<PolygonMesh, GeometryError> {
    let n = cells.max(1) + 1;
    let points = (0..n * n)
        .map(|k| {
            let (i, j) = (k / n, k % n);
            let step = size / (n - 1) as f64;
            center
                + DVec3::new(
                    i as f64 * step - 0.5 * size,
                    j as f64 * step - 0.5 * size,
                    0.0,
                )
        })
        .collect();
    let id = |i: usize, j: usize| (i * n + j) as u32;
    let faces: Vec<Vec<u32>> = (0..n - 1)
        .flat_map(|i| {
            (0..n - 1).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    PolygonMesh::new(points, &faces)
}

/// A regular icosahedron with its points on the sphere of `radius` about `center`: 12 points,
/// 20 triangles. The points are the cyclic permutations of (0, ±1, ±φ); the faces are the
/// triples at mutual distance 2 (the edge length), turned to face outwards.
pub fn icosahedron(center: DVec3, radius: f64) -> Result<PolygonMesh, GeometryError> {
    let phi = 0.5 * (1.0 + 5f64.sqrt());
    let mut unit = Vec::with_capacity(12);
    for (a, b) in [(1.0, phi), (1.0, -phi), (-1.0, phi), (-1.0, -phi)] {
        unit.push(DVec3::new(0.0, a, b));
        unit.push(DVec3::new(a, b, 0.0));
        unit.push(DVec3::new(b, 0.0, a));
    }
    let edge = |i: usize, j: usize| ((unit[i] - unit[j]).length() - 2.0).abs() < 1e-9;
    let mut faces = Vec::with_capacity(20);
    for i in 0..12 {
        for j in i + 1..12 {
            for k in j + 1..12 {
                if edge(i, j) && edge(j, k) && edge(i, k) {
                    let normal = (unit[j] - unit[i]).cross(unit[k] - unit[i]);
                    let outward = normal.dot(unit[i] + unit[j] + unit[k]) > 0.0;
                    let (i, j, k) = (i as u32, j as u32, k as u32);
                    faces.push(if outward {
                        vec![i, j, k]
                    } else {
                        vec![i, k, j]
                    });
                }
            }
        }
    }
    let scale = radius / unit[0].length();
    let points = unit.into_iter().map(|p| center + p * scale).collect();
    PolygonMesh::new(points, &faces)
}
