//! Mirror editing (Blender's X / Y / Z mirror in edit mode): while points are dragged, the
//! points at their mirror images across the planes x = 0, y = 0, z = 0 of the enabled axes
//! move by the mirrored offset, and a point on such a plane stays on it.

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

#[cfg(test)]
mod tests {
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
