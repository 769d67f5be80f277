//! `knotwork fillet-edges`, `chamfer-edges` and `shell`: edge and face features of a file's
//! solids ([`knotwork::kernel::features`]), written as STEP solids.

use std::process::ExitCode;

use glam::DVec3;
use knotwork::kernel::features::{
    EdgeFeature, EdgePick, FeatureResult, Polyhedron, draft_faces, offset_faces, round_edges,
    round_edges_varying, shell as shell_solid,
};

use knotwork::kernel::features::polyhedron::segment_distance;

use super::boolean::{diagonal, named_solids_of, write_solids};
use super::*;

/// A point given as "X,Y,Z".
pub fn parse_point(text: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [x, y, z] = parts[..] else {
        return Err(format!("{text:?} is not a point X,Y,Z"));
    };
    let number = |s: &str| -> Result<f64, String> {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{text:?}: {s:?} is not a finite number"))
    };
    Ok(DVec3::new(number(x)?, number(y)?, number(z)?))
}

/// A radius at a point, given as "X,Y,Z,R".
pub fn parse_point_radius(text: &str) -> Result<(DVec3, f64), String> {
    let Some((at, r)) = text.rsplit_once(',') else {
        return Err(format!("{text:?} is not a point and a radius X,Y,Z,R"));
    };
    let point =
        parse_point(at).map_err(|_| format!("{text:?} is not a point and a radius X,Y,Z,R"))?;
    let r = r
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|r| r.is_finite())
        .ok_or_else(|| format!("{text:?}: {r:?} is not a finite number"))?;
    Ok((point, r))
}

/// What one of the three commands makes.
pub enum Feature {
    Fillet {
        radius: f64,
        /// Radii at the picked edges' ends nearest points, "X,Y,Z,R" each.
        radius_at: Vec<String>,
    },
    Chamfer {
        distance: f64,
    },
    Shell {
        thickness: f64,
    },
    OffsetFace {
        distance: f64,
    },
    Draft {
        /// Radians.
        angle: f64,
        neutral: DVec3,
        pull: DVec3,
    },
}

impl Feature {
    fn command(&self) -> &'static str {
        match self {
            Feature::Fillet { .. } => "fillet-edges",
            Feature::Chamfer { .. } => "chamfer-edges",
            Feature::Shell { .. } => "shell",
            Feature::OffsetFace { .. } => "offset-face",
            Feature::Draft { .. } => "draft-face",
        }
    }
}

/// Runs the feature on every solid of `input` (with `points`, each point goes to the solid
/// with the edge or face nearest it, and solids without one are written unchanged) and
/// writes the solids to `output`; prints the solids, faces, volume and timings as JSON.
pub fn feature(
    feature: Feature,
    input: &std::path::Path,
    points: &[String],
    output: &std::path::Path,
) -> ExitCode {
    let command = feature.command();
    let run = || -> Result<serde_json::Value, String> {
        let points = points
            .iter()
            .map(|p| parse_point(p))
            .collect::<Result<Vec<_>, _>>()?;
        let radii = match &feature {
            Feature::Fillet { radius_at, .. } => radius_at
                .iter()
                .map(|p| parse_point_radius(p))
                .collect::<Result<Vec<_>, _>>()?,
            _ => Vec::new(),
        };
        let started = std::time::Instant::now();
        let (scene, named) = named_solids_of(input)?;
        let (names, bodies): (Vec<String>, Vec<_>) = named.into_iter().unzip();
        let read_ms = started.elapsed().as_secs_f64() * 1e3;
        let tolerance = 1e-6 * diagonal(&bodies);
        // Each point to the body nearest it.
        let mut mine: Vec<Vec<DVec3>> = vec![Vec::new(); bodies.len()];
        let mut mine_radii: Vec<Vec<(DVec3, f64)>> = vec![Vec::new(); bodies.len()];
        if bodies.len() == 1 {
            mine[0] = points.clone();
            mine_radii[0] = radii.clone();
        } else {
            // Edges as polylines, any body's (a curved one's rims too); faces by the
            // polyhedron where the body is one, else by its edges.
            let solids: Vec<Option<Polyhedron>> = bodies
                .iter()
                .map(|b| Polyhedron::from_faces(&b.faces, tolerance).ok())
                .collect();
            let lines: Vec<Vec<Vec<DVec3>>> = bodies
                .iter()
                .map(|b| {
                    b.topology.as_ref().map_or_else(Vec::new, |t| {
                        t.shared
                            .iter()
                            .filter_map(|s| {
                                knotwork::kernel::join::edge_polyline(
                                    &b.faces,
                                    s.a,
                                    1e3 * tolerance,
                                )
                                .ok()
                            })
                            .collect()
                    })
                })
                .collect();
            let owner = |p: DVec3| {
                let edge_gap = |k: usize| {
                    lines[k]
                        .iter()
                        .flat_map(|line| line.windows(2))
                        .map(|pair| segment_distance(pair[0], pair[1], p))
                        .fold(f64::INFINITY, f64::min)
                };
                let distance = |k: usize| match (&solids[k], &feature) {
                    (Some(s), Feature::Shell { .. }) => s
                        .nearest_face(p)
                        .map_or(f64::INFINITY, |f| s.face_distance(f, p)),
                    _ => edge_gap(k),
                };
                (0..bodies.len())
                    .min_by(|&i, &j| distance(i).total_cmp(&distance(j)))
                    .unwrap_or(0)
            };
            for &p in &points {
                mine[owner(p)].push(p);
            }
            for &(p, r) in &radii {
                mine_radii[owner(p)].push((p, r));
            }
        }
        let at = std::time::Instant::now();
        let mut solids = Vec::new();
        let (mut volume, mut faces, mut picked) = (0.0, 0, 0);
        for (k, ((body, mine), radii)) in bodies.into_iter().zip(mine).zip(mine_radii).enumerate() {
            let name = format!("{command} {}", k + 1);
            let skip = !points.is_empty() && mine.is_empty();
            let result = if skip {
                let topology = body.topology.clone().unwrap_or_default();
                FeatureResult {
                    faces: body.faces,
                    topology,
                    picked: 0,
                }
            } else {
                let pick = if mine.is_empty() {
                    EdgePick::All
                } else {
                    EdgePick::Near(mine.clone())
                };
                match feature {
                    Feature::Fillet { radius, .. } => round_edges_varying(
                        &body.faces,
                        &pick,
                        EdgeFeature::Fillet { radius },
                        &radii,
                        tolerance,
                    ),
                    Feature::Chamfer { distance } => round_edges(
                        &body.faces,
                        &pick,
                        EdgeFeature::Chamfer {
                            distance,
                            other: distance,
                        },
                        tolerance,
                    ),
                    Feature::Shell { thickness } => {
                        shell_solid(&body.faces, thickness, &mine, tolerance)
                    }
                    Feature::OffsetFace { distance } => {
                        offset_faces(&body.faces, &mine, distance, tolerance)
                    }
                    Feature::Draft {
                        angle,
                        neutral,
                        pull,
                    } => draft_faces(&body.faces, &mine, angle, (neutral, pull), tolerance),
                }
                .map_err(|e| {
                    if names.len() > 1 {
                        format!("{}: {e}", names[k])
                    } else {
                        e.to_string()
                    }
                })?
            };
            volume += result.volume().map_err(|e| e.to_string())?;
            faces += result.faces.len();
            picked += result.picked;
            solids.push((name, result.faces, result.topology));
        }
        let feature_ms = at.elapsed().as_secs_f64() * 1e3;
        let count = solids.len();
        let at = std::time::Instant::now();
        let left_out = write_solids(scene.unit, solids, tolerance, output)?;
        let write_ms = at.elapsed().as_secs_f64() * 1e3;
        Ok(serde_json::json!({
            "operation": command,
            "solids": count,
            "faces": faces,
            "picked": picked,
            "volume": volume,
            "tolerance": tolerance,
            "read_ms": read_ms,
            "feature_ms": feature_ms,
            "write_ms": write_ms,
            "left_out": left_out,
        }))
    };
    finish(command, run())
}
