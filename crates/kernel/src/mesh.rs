//! Polygon meshes: imported OBJ files and other glTF files' meshes, kept as points and faces
//! (each face a loop of point indices, counter-clockwise seen from its front). Until
//! subdivision surfaces land they are shown and edited as bilinear Bézier patches
//! ([`PolygonMesh::to_bezier_patch_set`]), so the same compute shaders draw them.

use std::collections::BTreeSet;

use glam::{DAffine3, DVec3};

use super::{BezierPatch, BezierPatchSet, GeometryError, Location};

/// The most corners one face may have.
pub const MAX_FACE_CORNERS: usize = 256;

/// Points and polygonal faces. Faces are stored flat: face `k` is
/// `corners[starts[k]..starts[k + 1]]`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PolygonMesh {
    points: Vec<DVec3>,
    starts: Vec<u32>,
    corners: Vec<u32>,
}

fn invalid(message: String) -> GeometryError {
    GeometryError::Construction {
        what: "polygon mesh",
        message,
    }
}

impl PolygonMesh {
    /// A mesh from points and faces, checking that coordinates are finite, that every face has
    /// 3 to [`MAX_FACE_CORNERS`] corners, that indices are in range and that no face uses a
    /// point twice in a row (a zero-length edge).
    pub fn new(points: Vec<DVec3>, faces: &[Vec<u32>]) -> Result<Self, GeometryError> {
        let mut starts = Vec::with_capacity(faces.len() + 1);
        let mut corners = Vec::with_capacity(faces.iter().map(Vec::len).sum());
        starts.push(0);
        for face in faces {
            corners.extend_from_slice(face);
            starts.push(corners.len() as u32);
        }
        let mesh = Self {
            points,
            starts,
            corners,
        };
        mesh.validate()?;
        Ok(mesh)
    }

    fn validate(&self) -> Result<(), GeometryError> {
        for (index, p) in self.points.iter().enumerate() {
            if let Some(coordinate) = p.to_array().iter().position(|c| !c.is_finite()) {
                return Err(GeometryError::NonFinitePoint {
                    at: Location::point(index),
                    coordinate,
                });
            }
        }
        if self.starts.len() < 2 {
            return Err(invalid("it has no faces".into()));
        }
        for (k, face) in self.faces().enumerate() {
            if !(3..=MAX_FACE_CORNERS).contains(&face.len()) {
                return Err(invalid(format!(
                    "face {k} has {} corners (3 to {MAX_FACE_CORNERS} allowed)",
                    face.len()
                )));
            }
            if let Some(&index) = face.iter().find(|&&i| i as usize >= self.points.len()) {
                return Err(invalid(format!(
                    "face {k} uses point {index}, but there are {} points",
                    self.points.len()
                )));
            }
            if (0..face.len()).any(|c| face[c] == face[(c + 1) % face.len()]) {
                return Err(invalid(format!(
                    "face {k} repeats a point on consecutive corners"
                )));
            }
        }
        Ok(())
    }

    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    /// How many faces the mesh has.
    pub fn face_count(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    /// Face `k`'s corner indices.
    pub fn face(&self, k: usize) -> &[u32] {
        &self.corners[self.starts[k] as usize..self.starts[k + 1] as usize]
    }

    /// Every face's corner indices, in order.
    pub fn faces(&self) -> impl Iterator<Item = &[u32]> + '_ {
        self.starts
            .windows(2)
            .map(|w| &self.corners[w[0] as usize..w[1] as usize])
    }

    /// How many bilinear patches face `face` becomes: 1 for a triangle or quad, n − 2 (a fan
    /// of triangles) for an n-gon.
    pub fn patches_of_face(face: &[u32]) -> usize {
        if face.len() <= 4 { 1 } else { face.len() - 2 }
    }

    /// Moves point `index`. A bad index or a non-finite position is refused.
    pub fn set_point(&mut self, index: usize, position: DVec3) -> Result<(), GeometryError> {
        super::bezier::set_point_checked(&mut self.points, index, position)
    }

    /// The mesh with `transform` applied to every point. A transform that sends a point to a
    /// non-finite position is refused.
    pub fn transformed(&self, transform: &DAffine3) -> Result<Self, GeometryError> {
        let mut mesh = self.clone();
        for p in &mut mesh.points {
            *p = transform.transform_point3(*p);
        }
        mesh.validate()?;
        Ok(mesh)
    }

    /// The box of the points.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        self.points
            .iter()
            .map(|&p| (p, p))
            .reduce(|(lo, hi), (a, b)| (lo.min(a), hi.max(b)))
    }

    /// Index pairs of the mesh's edges, each once.
    pub fn edge_indices(&self) -> Vec<u32> {
        let mut edges = BTreeSet::new();
        for face in self.faces() {
            for c in 0..face.len() {
                let (a, b) = (face[c], face[(c + 1) % face.len()]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        edges.into_iter().flat_map(|(a, b)| [a, b]).collect()
    }

    /// The faces as bilinear Bézier patches over the mesh's own points (shared, weight 1), in
    /// face order: a quad (a, b, c, d) is the patch with corners S(0,0) = a, S(1,0) = b,
    /// S(1,1) = c, S(0,1) = d, so Su × Sv points to the face's front; a triangle (a, b, c) is
    /// the same with d = c (the edge v = 1 collapsed); an n-gon is fanned into the triangles
    /// (f0, f_k, f_k+1).
    pub fn to_bezier_patch_set(&self) -> Result<BezierPatchSet, GeometryError> {
        let bilinear = |a: u32, b: u32, c: u32, d: u32| BezierPatch::new(1, 1, vec![a, d, b, c]);
        let mut patches = Vec::with_capacity(self.face_count());
        for face in self.faces() {
            match *face {
                [a, b, c] => patches.push(bilinear(a, b, c, c)),
                [a, b, c, d] => patches.push(bilinear(a, b, c, d)),
                _ => patches.extend(
                    face[1..]
                        .windows(2)
                        .map(|w| bilinear(face[0], w[0], w[1], w[1])),
                ),
            }
        }
        BezierPatchSet::new(self.points.clone(), None, patches)
    }

    /// The patches of [`Self::to_bezier_patch_set`] that use point `index`.
    pub fn patches_using(&self, index: u32) -> Vec<usize> {
        let mut out = Vec::new();
        let mut first = 0;
        for face in self.faces() {
            let count = Self::patches_of_face(face);
            if face.contains(&index) {
                if count == 1 || face[0] == index {
                    out.extend(first..first + count);
                } else {
                    // In a fan, corner c (≥ 1) is in triangles c − 2 and c − 1 (where they exist).
                    let mut fan = BTreeSet::new();
                    for (c, _) in face.iter().enumerate().filter(|&(_, &i)| i == index) {
                        fan.extend(c.saturating_sub(2)..=(c - 1).min(count - 1));
                    }
                    out.extend(fan.into_iter().map(|t| first + t));
                }
            }
            first += count;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pentagon_and_friends() -> PolygonMesh {
        let points = (0..8)
            .map(|k| {
                let t = k as f64;
                DVec3::new(t.cos(), t.sin(), 0.1 * t)
            })
            .collect();
        PolygonMesh::new(
            points,
            &[vec![0, 1, 2], vec![2, 3, 4, 5], vec![1, 3, 5, 6, 7]],
        )
        .unwrap()
    }

    #[test]
    fn faces_become_bilinear_patches_through_their_corners() {
        let mesh = pentagon_and_friends();
        let set = mesh.to_bezier_patch_set().unwrap();
        assert_eq!(set.patches().len(), 1 + 1 + 3);
        let corner = |k: usize, u: f64, v: f64| set.evaluate(k, u, v).unwrap().point;
        let p = mesh.points();
        // The quad's corners in order, and the triangle's collapsed edge.
        for (u, v, i) in [(0.0, 0.0, 2), (1.0, 0.0, 3), (1.0, 1.0, 4), (0.0, 1.0, 5)] {
            assert!(corner(1, u, v).distance(p[i]) < 1e-15);
        }
        assert!(corner(0, 0.3, 1.0).distance(p[2]) < 1e-15);
        // The pentagon's fan: (1, 3, 5), (1, 5, 6), (1, 6, 7).
        assert!(corner(4, 1.0, 0.0).distance(p[6]) < 1e-15);
        assert!(corner(4, 0.5, 1.0).distance(p[7]) < 1e-15);
    }

    #[test]
    fn the_patches_using_a_point_are_exactly_those_that_reference_it() {
        let mesh = pentagon_and_friends();
        let set = mesh.to_bezier_patch_set().unwrap();
        for index in 0..mesh.points().len() as u32 {
            let expected: Vec<usize> = set
                .patches()
                .iter()
                .enumerate()
                .filter(|(_, p)| p.indices().contains(&index))
                .map(|(k, _)| k)
                .collect();
            assert_eq!(mesh.patches_using(index), expected, "point {index}");
        }
    }

    #[test]
    fn bad_meshes_are_refused() {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
        assert!(PolygonMesh::new(p.clone(), &[vec![0, 1]]).is_err());
        assert!(PolygonMesh::new(p.clone(), &[vec![0, 1, 3]]).is_err());
        assert!(PolygonMesh::new(p.clone(), &[vec![0, 1, 1]]).is_err());
        assert!(PolygonMesh::new(p.clone(), &[]).is_err());
        assert!(PolygonMesh::new(vec![DVec3::NAN, DVec3::X, DVec3::Y], &[vec![0, 1, 2]]).is_err());
        assert!(PolygonMesh::new(p, &[vec![0, 1, 2]]).is_ok());
    }
}
