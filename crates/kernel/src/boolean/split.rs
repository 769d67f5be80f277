//! A solid split by a surface into closed pieces (Rhino's BooleanSplit; a boolean with an
//! open operand, on the boolean's own steps):
//!
//! 1. The body's faces are oriented outward and the surface's faces (one or more, open or
//!    closed) are intersected with them as in a boolean ([`super::cut_faces`]).
//! 2. Every part of the body's faces is kept; of the surface, the parts inside the body (by
//!    the body's winding number), the caps.
//! 3. The body's parts fall into sides: the groups joined across their shared edges, which
//!    the cuts separate. A side with open edges is closed by the caps that meet it, turned to
//!    agree with it; one without (a shell the surface does not reach) is a lump of its own,
//!    or a void of the piece around it.
//!
//! Where the surface does not reach through the body (its cut leaves one side), lies along a
//! face, or a piece does not close, the split is refused and says so.

use std::collections::BTreeSet;

use super::*;

/// The closed pieces that `tool`'s faces (a surface or a polysurface reaching through the
/// body) divide the solid `body` into (its faces, with its shared edges where known), at
/// `tolerance` (model units), each with the voids it holds (see the module documentation).
pub fn split(
    (body, topology): (&[TrimmedSurface], Option<&Topology>),
    tool: &[TrimmedSurface],
    tolerance: f64,
) -> Result<Vec<ResultSolid>, GeometryError> {
    positive(tolerance)?;
    if tool.is_empty() {
        return Err(construction(WHAT, "the splitting surface has no faces"));
    }
    let oriented = match topology {
        Some(t) => outward_faces_joined(body, t, "the body")?,
        None => outward_faces(body, tolerance, "the body")?,
    };
    let a = Operand::new(oriented, tolerance)?;
    let t = Operand::new((tool.to_vec(), vec![(0..tool.len()).collect()]), tolerance)?;
    let cuts = cut_faces(&a, &t, tolerance)?;
    if let Some(&(i, j)) = cuts.coplanar.first() {
        return Err(construction(
            WHAT,
            format!(
                "face {} of the surface lies in the plane of face {} of the body: a split \
                 needs a surface that crosses the body",
                j + 1,
                i + 1
            ),
        ));
    }
    if cuts.branches == 0 {
        return Err(construction(WHAT, "the surface does not cross the body"));
    }
    let mut parts = Vec::new();
    // Where the cuts run: the middles of the parts' edges along them.
    let mut cut_middles: Vec<DVec3> = Vec::new();
    for (k, face) in a.faces.iter().enumerate() {
        if cuts.a[k].is_empty() {
            parts.push(face.clone());
            continue;
        }
        for part in split_face(face, &a.boundaries[k], &cuts.a[k], tolerance)? {
            parts.push(TrimmedSurface::new(face.surface().clone(), part.loops)?);
            cut_middles.extend(part.cut_middles);
        }
    }
    let inside = classifier(&a, cuts.size)?;
    let mut caps = Vec::new();
    for (k, face) in t.faces.iter().enumerate() {
        let pieces: Vec<(Option<Vec<TrimLoop>>, Vec<DVec2>)> = if cuts.b[k].is_empty() {
            vec![(None, whole_face_points(face, &t.boundaries[k], tolerance)?)]
        } else {
            split_face(face, &t.boundaries[k], &cuts.b[k], tolerance)?
                .into_iter()
                .map(|part| (Some(part.loops), part.inside))
                .collect()
        };
        for (loops, points) in pieces {
            if classify(face, &points, &a, &[], &inside, tolerance)? != Place::Inside {
                continue;
            }
            caps.push(match loops {
                Some(loops) => TrimmedSurface::new(face.surface().clone(), loops)?,
                None => face.clone(),
            });
        }
    }
    if caps.is_empty() {
        return Err(construction(
            WHAT,
            "no part of the surface lies inside the body",
        ));
    }
    let join = tolerance * JOIN_FACTOR;
    let joined = find_topology(&parts, join)?;
    // Every edge's middle and direction there, of the body's parts and of the caps.
    let part_edges = edge_middles(&parts)?;
    let cap_loops: Vec<Vec<TrimLoop>> = caps.iter().map(face_loops).collect::<Result<_, _>>()?;
    let on_cut = |middle: DVec3| cut_middles.iter().any(|m| m.distance(middle) <= join);
    // Parts joined across every edge but the cuts.
    let middles: std::collections::HashMap<crate::join::EdgeId, DVec3> =
        part_edges.iter().map(|e| (e.id, e.middle)).collect();
    let mut links: Vec<(usize, usize)> = joined
        .shared
        .iter()
        .filter(|s| !middles.get(&s.a).is_some_and(|&m| on_cut(m)))
        .map(|s| (s.a.face, s.b.face))
        .collect();
    // Across a cap: the parts whose edge runs against the cap's along it lie on its one side
    // (the cap as it is closes them), those whose edge runs with it on the other.
    let mut along_cuts = vec![false; parts.len()];
    let mut meets: Vec<(usize, usize)> = Vec::new();
    for c in 0..caps.len() {
        let mut sides: [Option<usize>; 2] = [None, None];
        for edge in part_edges.iter().filter(|e| on_cut(e.middle)) {
            // The cap's boundary where this edge's middle lies on it, and its way there.
            let mut way = None;
            for curve in cap_loops[c].iter().flatten() {
                let surface = caps[c].surface();
                let (t, d) = nearest_on_edge(surface, curve, edge.middle)?;
                if d <= join {
                    let (t0, t1) = curve.domain();
                    let step = 1e-3 * (t1 - t0);
                    let at = |x: f64| -> Result<DVec3, GeometryError> {
                        surface.point_at_clamped(curve.point_at(x.clamp(t0, t1))?)
                    };
                    way = Some(at(t + step)? - at(t - step)?);
                    break;
                }
            }
            let Some(way) = way else {
                continue;
            };
            let part = edge.id.face;
            along_cuts[part] = true;
            meets.push((c, part));
            let side = usize::from(edge.direction.dot(way) > 0.0);
            match sides[side] {
                Some(first) => links.push((first, part)),
                None => sides[side] = Some(part),
            }
        }
    }
    let components = crate::join::connected_groups(parts.len(), links);
    let (sides, shells): (Vec<Vec<usize>>, Vec<Vec<usize>>) = components
        .into_iter()
        .partition(|c| c.iter().any(|&k| along_cuts[k]));
    if sides.len() < 2 {
        return Err(construction(
            WHAT,
            "the surface does not divide the body: its cut does not run all the way round \
             (extend the surface through the body)",
        ));
    }
    // Each side closed by the caps that meet it.
    let mut pieces: Vec<Vec<TrimmedSurface>> = Vec::with_capacity(sides.len());
    for side in &sides {
        let mut faces: Vec<TrimmedSurface> = side.iter().map(|&k| parts[k].clone()).collect();
        let touching: BTreeSet<usize> = meets
            .iter()
            .filter(|(_, part)| side.contains(part))
            .map(|&(c, _)| c)
            .collect();
        faces.extend(touching.into_iter().map(|c| caps[c].clone()));
        let (faces, _) = outward_faces(&faces, join, "a piece of the split body")?;
        pieces.push(faces);
    }
    // Shells the surface does not reach: a void goes with the piece around it (the first
    // whose winding number holds a point of it), a lump stands alone. The pieces' classifiers
    // are made once, when there is a void.
    let mut voids = Vec::new();
    for shell in shells {
        let faces: Vec<TrimmedSurface> = shell.iter().map(|&k| parts[k].clone()).collect();
        if signed_volume(&faces)? > 0.0 {
            pieces.push(faces);
        } else {
            voids.push(faces);
        }
    }
    let mut holders: Option<Vec<Classifier>> = None;
    for faces in voids {
        let lines = boundary_polylines(&faces[0], tolerance)?;
        let inside_point = whole_face_points(&faces[0], &lines, tolerance)?[0];
        let probe = faces[0].surface().point_at_clamped(inside_point)?;
        if holders.is_none() {
            let mut made = Vec::with_capacity(pieces.len());
            for piece in &pieces {
                let all = vec![(0..piece.len()).collect()];
                made.push(classifier(
                    &Operand::new((piece.clone(), all), tolerance)?,
                    cuts.size,
                )?);
            }
            holders = Some(made);
        }
        let holder = holders
            .iter()
            .flatten()
            .position(|c| c.winding(probe).0.abs() > 0.5);
        match holder {
            Some(k) => pieces[k].extend(faces),
            None => pieces.push(faces),
        }
    }
    let mut solids = Vec::new();
    for piece in pieces {
        solids.extend(assemble(piece, tolerance)?);
    }
    Ok(solids)
}

/// One edge of a face: which it is, its middle in space and its direction there (along its
/// loop).
struct EdgeMiddle {
    id: crate::join::EdgeId,
    middle: DVec3,
    direction: DVec3,
}

/// Every edge of every face, at its middle.
fn edge_middles(faces: &[TrimmedSurface]) -> Result<Vec<EdgeMiddle>, GeometryError> {
    let mut out = Vec::new();
    for (f, face) in faces.iter().enumerate() {
        for (l, lp) in face_loops(face)?.iter().enumerate() {
            for (c, curve) in lp.iter().enumerate() {
                let (t0, t1) = curve.domain();
                let at = |x: f64| -> Result<DVec3, GeometryError> {
                    face.surface()
                        .point_at_clamped(curve.point_at(t0 + (t1 - t0) * x)?)
                };
                out.push(EdgeMiddle {
                    id: crate::join::EdgeId {
                        face: f,
                        loop_index: l,
                        curve: c,
                    },
                    middle: at(0.5)?,
                    direction: at(0.55)? - at(0.45)?,
                });
            }
        }
    }
    Ok(out)
}
