//! The points that follow a drag besides the dragged ones, as in Blender's edit mode.
//!
//! - Mirror editing (X / Y / Z mirror): the points at the dragged points' mirror images across
//!   the planes x = 0, y = 0, z = 0 of the enabled axes move by the mirrored offset, and a
//!   point on such a plane stays on it.
//! - Proportional editing: every point within the radius of a dragged point moves by that
//!   point's offset times the smooth falloff of its distance.

use glam::DVec3;

/// A point that follows a dragged one across the mirror planes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Partner {
    /// The point that follows.
    pub point: usize,
    /// The dragged point it mirrors.
    pub source: usize,
    /// The axes it is mirrored across.
    pub flip: [bool; 3],
}

/// `v` with the components of the axes in `flip` negated.
pub fn flipped(v: DVec3, flip: [bool; 3]) -> DVec3 {
    let mut out = v;
    for a in 0..3 {
        if flip[a] {
            out[a] = -out[a];
        }
    }
    out
}

/// The points that follow the `dragged` ones under mirror editing on `axes`: for every
/// non-empty set of the enabled axes, the point within `tolerance` of a dragged point's image
/// across them (not a dragged point itself, each point following one source).
pub fn partners(
    points: &[DVec3],
    dragged: &[usize],
    axes: [bool; 3],
    tolerance: f64,
) -> Vec<Partner> {
    let flips: Vec<[bool; 3]> = (1..8u8)
        .map(|m| [m & 1 != 0, m & 2 != 0, m & 4 != 0])
        .filter(|f| (0..3).all(|a| !f[a] || axes[a]))
        .collect();
    let mut out: Vec<Partner> = Vec::new();
    for &source in dragged {
        let Some(&p) = points.get(source) else {
            continue;
        };
        for &flip in &flips {
            let image = flipped(p, flip);
            let nearest = (0..points.len())
                .map(|j| (j, points[j].distance(image)))
                .filter(|&(_, d)| d <= tolerance)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((point, _)) = nearest
                && !dragged.contains(&point)
                && !out.iter().any(|q| q.point == point)
            {
                out.push(Partner {
                    point,
                    source,
                    flip,
                });
            }
        }
    }
    out
}

/// The offset a dragged point at `start` moves by for the cursor's `delta`: the components of
/// the enabled axes whose plane it lies on (within `tolerance`) are dropped, so it stays there.
pub fn kept_on_planes(start: DVec3, delta: DVec3, axes: [bool; 3], tolerance: f64) -> DVec3 {
    let mut out = delta;
    for a in 0..3 {
        if axes[a] && start[a].abs() <= tolerance {
            out[a] = 0.0;
        }
    }
    out
}

/// Blender's Smooth falloff at `distance` of a radius `radius`: 3s² − 2s³ with
/// s = 1 − distance / radius, 1 at the dragged point and 0 from the radius out.
pub fn smooth_falloff(distance: f64, radius: f64) -> f64 {
    if !(radius > 0.0) || distance >= radius {
        return 0.0;
    }
    let s = 1.0 - distance / radius;
    s * s * (3.0 - 2.0 * s)
}

/// A point that proportional editing moves with a dragged one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Falloff {
    pub point: usize,
    /// The nearest dragged point, whose offset it takes a share of.
    pub source: usize,
    pub weight: f64,
}

/// The points within `radius` of a `dragged` point (not dragged themselves), each with its
/// nearest dragged point and the smooth falloff of the distance to it.
pub fn falloff(points: &[DVec3], dragged: &[usize], radius: f64) -> Vec<Falloff> {
    let sources: Vec<(usize, DVec3)> = dragged
        .iter()
        .filter_map(|&k| Some((k, *points.get(k)?)))
        .collect();
    (0..points.len())
        .filter(|j| !dragged.contains(j))
        .filter_map(|point| {
            let (source, distance) = sources
                .iter()
                .map(|&(k, p)| (k, p.distance(points[point])))
                .min_by(|a, b| a.1.total_cmp(&b.1))?;
            let weight = smooth_falloff(distance, radius);
            (weight > 0.0).then_some(Falloff {
                point,
                source,
                weight,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_falloff_is_smooth_from_one_to_zero_at_the_radius() {
        use super::*;
        assert_eq!(smooth_falloff(0.0, 2.0), 1.0);
        assert_eq!(smooth_falloff(1.0, 2.0), 0.5);
        assert_eq!(smooth_falloff(2.0, 2.0), 0.0);
        assert_eq!(smooth_falloff(0.5, 0.0), 0.0);
        let points: Vec<DVec3> = (0..5).map(|k| DVec3::new(f64::from(k), 0.0, 0.0)).collect();
        // Dragging 0 and 4 with radius 2: 1 and 3 follow by half, 2 by nothing.
        let found = falloff(&points, &[0, 4], 2.0);
        assert_eq!(
            found,
            [
                Falloff {
                    point: 1,
                    source: 0,
                    weight: 0.5
                },
                Falloff {
                    point: 3,
                    source: 4,
                    weight: 0.5
                }
            ]
        );
    }

    use super::*;

    #[test]
    fn mirror_images_follow_and_points_on_the_plane_stay_on_it() {
        let points = vec![
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(-1.0, 2.0, 3.0),
            DVec3::new(1.0, -2.0, 3.0),
            DVec3::new(-1.0, -2.0, 3.0),
            DVec3::new(0.0, 5.0, 1.0),
            DVec3::new(-1.0 + 1e-9, 7.0, 0.0),
        ];
        // X only: point 0's partner is 1.
        assert_eq!(
            partners(&points, &[0], [true, false, false], 1e-6),
            [Partner {
                point: 1,
                source: 0,
                flip: [true, false, false]
            }]
        );
        // X and Y: 1 across x, 2 across y, 3 across both.
        let both = partners(&points, &[0], [true, true, false], 1e-6);
        let mut found: Vec<usize> = both.iter().map(|p| p.point).collect();
        found.sort_unstable();
        assert_eq!(found, [1, 2, 3]);
        // A dragged point is nobody's partner; a point on the plane is its own image.
        assert!(partners(&points, &[0, 1], [true, false, false], 1e-6).is_empty());
        assert!(partners(&points, &[4], [true, false, false], 1e-6).is_empty());
        let delta = DVec3::new(0.5, -0.25, 1.0);
        assert_eq!(
            kept_on_planes(points[4], delta, [true, false, false], 1e-6),
            DVec3::new(0.0, -0.25, 1.0)
        );
        assert_eq!(
            flipped(delta, [true, false, true]),
            DVec3::new(-0.5, -0.25, -1.0)
        );
    }
}
