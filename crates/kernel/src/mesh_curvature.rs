//! Curvature estimated on a triangle mesh that carries surface normals, for the tessellations
//! that have no exact second derivatives at their vertices: subdivision surfaces (around
//! extraordinary vertices and at creases the limit curvature is not defined by the stencils),
//! displaced surfaces and lattice-deformed ones.
//!
//! The estimate is Rusinkiewicz's ("Estimating curvatures and their derivatives on triangle
//! meshes", 3DPVT 2004): on every triangle, the second fundamental form II that best maps its
//! three edges e to the change of the normal along them, II(e) ≈ Δn, in the least-squares
//! sense; then, at every vertex, the forms of its triangles rotated into the vertex's tangent
//! plane and averaged, weighted by the vertex's mixed Voronoi share of each triangle (Meyer,
//! Desbrun, Schröder & Barr, "Discrete differential-geometry operators for triangulated
//! 2-manifolds", 2003). The eigenvalues of the averaged form are the principal curvatures.
//!
//! Sign: the kernel's II is L = S_uu · n, which is −S_u · n_u, so the estimate is the negated
//! normal change: a sphere with outward normals has k1 = k2 = −1/r, as
//! [`crate::diffgeo::CurvatureValues`] has it.

use glam::{DMat3, DQuat, DVec3};

use crate::diffgeo::CurvatureValues;

/// The curvatures (K, H, k1 ≥ k2) at every vertex of the mesh `triangles` over `positions`
/// with unit `normals` (one per position), by the estimate described in the module
/// documentation. A vertex of no usable triangle, or with a normal that is not finite, gets
/// zeros.
pub fn estimate_vertex_curvatures(
    positions: &[DVec3],
    normals: &[DVec3],
    triangles: &[[u32; 3]],
) -> Vec<CurvatureValues> {
    let count = positions.len();
    // Per vertex: the accumulated form as a symmetric tensor in space, and the total weight.
    let mut tensors = vec![DMat3::ZERO; count];
    let mut weights = vec![0.0; count];
    let normal_at = |k: usize| normals.get(k).copied().filter(|n| n.is_finite());
    for triangle in triangles {
        let [a, b, c] = triangle.map(|k| k as usize);
        if a.max(b).max(c) >= count {
            continue;
        }
        let (Some(na), Some(nb), Some(nc)) = (normal_at(a), normal_at(b), normal_at(c)) else {
            continue;
        };
        let corners = [positions[a], positions[b], positions[c]];
        let Some((form, face_normal)) = face_form(corners, [na, nb, nc]) else {
            continue;
        };
        let shares = voronoi_shares(corners);
        for (i, &v) in [a, b, c].iter().enumerate() {
            let vertex_normal = [na, nb, nc][i];
            // The face's form turned with the smallest rotation that takes its plane to the
            // vertex's tangent plane.
            let turn = DMat3::from_quat(DQuat::from_rotation_arc(
                face_normal,
                vertex_normal.normalize_or_zero(),
            ));
            tensors[v] += shares[i] * (turn * form * turn.transpose());
            weights[v] += shares[i];
        }
    }
    (0..count)
        .map(|v| {
            let n = normals
                .get(v)
                .copied()
                .unwrap_or(DVec3::ZERO)
                .normalize_or_zero();
            if !(weights[v] > 0.0) || n == DVec3::ZERO {
                return CurvatureValues::default();
            }
            principal_values(tensors[v] * (1.0 / weights[v]), n)
        })
        .collect()
}

/// The least-squares second fundamental form of one triangle as a symmetric tensor in space
/// (zero along the face normal), with the kernel's sign, and the face's unit normal, turned to
/// the side of the vertex normals. `None` for a triangle of no area or a singular fit.
fn face_form(corners: [DVec3; 3], normals: [DVec3; 3]) -> Option<(DMat3, DVec3)> {
    let [p0, p1, p2] = corners;
    let cross = (p1 - p0).cross(p2 - p0);
    let mut w = cross.normalize_or_zero();
    if w == DVec3::ZERO || !w.is_finite() {
        return None;
    }
    if w.dot(normals[0] + normals[1] + normals[2]) < 0.0 {
        w = -w;
    }
    let u = (p1 - p0).normalize_or_zero();
    let v = w.cross(u);
    // Normal equations of  [a b 0; 0 a b] (e f g)ᵀ = (Δn·u, Δn·v)  over the three edges.
    let mut ata = DMat3::ZERO;
    let mut atb = DVec3::ZERO;
    for (from, to) in [(0, 1), (1, 2), (2, 0)] {
        let edge = corners[to] - corners[from];
        let dn = normals[to] - normals[from];
        let (a, b) = (edge.dot(u), edge.dot(v));
        let rows = [
            (DVec3::new(a, b, 0.0), dn.dot(u)),
            (DVec3::new(0.0, a, b), dn.dot(v)),
        ];
        for (row, rhs) in rows {
            ata += outer(row, row);
            atb += row * rhs;
        }
    }
    if !(ata.determinant().abs() > 1e-300) {
        return None;
    }
    let [e, f, g] = (ata.inverse() * atb).to_array();
    // The normal's change is −II: the kernel's form is the negated fit.
    let form = -(e * outer(u, u) + f * (outer(u, v) + outer(v, u)) + g * outer(v, v));
    form.is_finite().then_some((form, w))
}

/// a bᵀ.
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Each corner's mixed Voronoi area of the triangle (Meyer et al. 2003, section 3.3): the
/// Voronoi region (|PR|² cot Q + |PQ|² cot R)/8 in a triangle without an obtuse angle; else
/// half the area at the obtuse corner and a quarter at each other one.
fn voronoi_shares(corners: [DVec3; 3]) -> [f64; 3] {
    let area = 0.5
        * (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .length();
    let cot = |k: usize| {
        let (p, q, r) = (corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3]);
        let (a, b) = (q - p, r - p);
        a.dot(b) / a.cross(b).length().max(f64::MIN_POSITIVE)
    };
    let obtuse = (0..3).find(|&k| {
        let (p, q, r) = (corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3]);
        (q - p).dot(r - p) < 0.0
    });
    match obtuse {
        Some(o) => std::array::from_fn(|k| if k == o { 0.5 * area } else { 0.25 * area }),
        None => std::array::from_fn(|k| {
            let (q, r) = ((k + 1) % 3, (k + 2) % 3);
            let (to_q, to_r) = (corners[q] - corners[k], corners[r] - corners[k]);
            (to_r.length_squared() * cot(q) + to_q.length_squared() * cot(r)) / 8.0
        }),
    }
}

/// The principal curvatures of the symmetric `tensor` in the plane normal to `n`: the
/// eigenvalues of its 2 × 2 restriction, k1 = H + √(H² − K) and k2 = H − √(H² − K).
fn principal_values(tensor: DMat3, n: DVec3) -> CurvatureValues {
    let (t1, t2) = n.any_orthonormal_pair();
    let (a, b, c) = (
        t1.dot(tensor * t1),
        0.5 * (t1.dot(tensor * t2) + t2.dot(tensor * t1)),
        t2.dot(tensor * t2),
    );
    let mean = 0.5 * (a + c);
    let disc = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let (k1, k2) = (mean + disc, mean - disc);
    CurvatureValues {
        gaussian: k1 * k2,
        mean,
        k1,
        k2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;
    use crate::tess::{Tessellation, TriangleMesh, grid_for, triangulate};

    fn mesh_of(surface: &crate::NurbsSurface, tolerance: f64) -> TriangleMesh {
        let grid = grid_for(surface, Tessellation::Tolerance(tolerance)).unwrap();
        triangulate(surface, &grid, true).unwrap()
    }

    /// The estimate on a tessellated surface, and the kernel's exact values at the same
    /// vertices: the largest difference of K, H, k1, k2 over all vertices, each relative to
    /// `scale`.
    fn worst_relative_error(surface: &crate::NurbsSurface, tolerance: f64, scale: f64) -> f64 {
        let mesh = mesh_of(surface, tolerance);
        let estimated = estimate_vertex_curvatures(&mesh.positions, &mesh.normals, &mesh.triangles);
        mesh.curvatures
            .iter()
            .zip(&estimated)
            .flat_map(|(exact, guess)| {
                [
                    (exact.gaussian - guess.gaussian) / (scale * scale),
                    (exact.mean - guess.mean) / scale,
                    (exact.k1 - guess.k1) / scale,
                    (exact.k2 - guess.k2) / scale,
                ]
            })
            .fold(0.0, |worst: f64, e| worst.max(e.abs()))
    }

    #[test]
    fn a_sphere_has_both_principal_curvatures_minus_one_over_the_radius() {
        let r = 2.5;
        let sphere = construct::sphere(DVec3::new(1.0, -2.0, 0.5), r).unwrap();
        let mesh = mesh_of(&sphere, 1e-3);
        let estimated = estimate_vertex_curvatures(&mesh.positions, &mesh.normals, &mesh.triangles);
        let mut used = vec![false; mesh.positions.len()];
        for t in &mesh.triangles {
            for &k in t {
                used[k as usize] = true;
            }
        }
        for (c, _) in estimated.iter().zip(&used).filter(|(_, u)| **u) {
            // Analytic: k1 = k2 = −1/r with outward normals, K = 1/r², H = −1/r.
            assert!((c.k1 + 1.0 / r).abs() < 0.02 / r, "{c:?}");
            assert!((c.k2 + 1.0 / r).abs() < 0.02 / r, "{c:?}");
            assert!((c.gaussian - 1.0 / (r * r)).abs() < 0.04 / (r * r), "{c:?}");
        }
    }

    #[test]
    fn a_torus_and_a_cylinder_agree_with_the_exact_curvatures_of_the_kernel() {
        let torus = construct::torus(DVec3::ZERO, DVec3::Z, 3.0, 1.0).unwrap();
        let error = worst_relative_error(&torus, 1e-3, 1.0);
        assert!(error < 0.02, "torus: worst error {error}");
        let cylinder = construct::cylinder(DVec3::ZERO, DVec3::Z, 0.5).unwrap();
        let error = worst_relative_error(&cylinder, 1e-4, 2.0);
        assert!(error < 1e-6, "cylinder: worst error {error}");
    }

    #[test]
    fn a_plane_is_flat_and_bad_input_gives_zeros_rather_than_a_panic() {
        let positions = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::ONE];
        let normals = [DVec3::Z; 4];
        let estimated = estimate_vertex_curvatures(&positions, &normals, &[[0, 1, 2], [1, 3, 2]]);
        assert!(estimated.iter().all(|c| *c == CurvatureValues::default()));
        let odd = estimate_vertex_curvatures(
            &positions,
            &[DVec3::NAN, DVec3::Z, DVec3::ZERO, DVec3::Z],
            &[[0, 1, 2], [1, 3, 2], [0, 0, 0], [7, 1, 2]],
        );
        assert_eq!(odd.len(), 4);
        assert!(odd.iter().all(|c| c.k1.is_finite() && c.k2.is_finite()));
    }
}
