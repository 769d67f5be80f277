//! An orbit camera around a target point, Z up, as in Blender and Rhino.

use glam::{Mat4, Vec3};

/// Orbits `target` at `distance`; `yaw` turns about +Z, `pitch` lifts above the XY plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitCamera {
    pub target: Vec3,
    pub distance: f32,
    /// Radians about +Z; at 0 the camera sits on the +X side of the target.
    pub yaw: f32,
    /// Radians above the XY plane: within ±(π/2 − 0.01) while orbiting, exactly ±π/2 in the
    /// top and bottom views.
    pub pitch: f32,
    /// Vertical field of view in radians. An orthographic view shows the same height at the
    /// target: 2 · distance · tan(fov_y / 2).
    pub fov_y: f32,
    /// Parallel projection (the standard views' default) instead of perspective.
    pub orthographic: bool,
}

/// The steepest pitch, just short of straight up or down (where the view would flip).
pub const PITCH_LIMIT: f32 = std::f32::consts::FRAC_PI_2 - 0.01;
/// Radians of orbit per pixel of drag.
const ORBIT_SPEED: f32 = 0.008;
const MIN_DISTANCE: f32 = 1e-4;
const MAX_DISTANCE: f32 = 1e7;

impl Default for OrbitCamera {
    fn default() -> Self {
        Self {
            target: Vec3::ZERO,
            distance: 10.0,
            yaw: -0.9,
            pitch: 0.45,
            fov_y: 35f32.to_radians(),
            orthographic: false,
        }
    }
}

impl OrbitCamera {
    /// The camera position.
    pub fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * Vec3::new(cp * cy, cp * sy, sp)
    }

    /// The screen's up direction: the eye direction's derivative with respect to the pitch,
    /// (−sin p cos y, −sin p sin y, cos p). Z-ish at every pitch short of the poles, and still
    /// defined at ±π/2, where the top and bottom views look straight down and up.
    fn up(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(-sp * cy, -sp * sy, cp)
    }

    /// World → view (right-handed, looking at the target, Z up).
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye(), self.target, self.up())
    }

    /// The camera's right, up and back (toward the viewer) unit axes in world space.
    pub fn axes(&self) -> (Vec3, Vec3, Vec3) {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let back = Vec3::new(cp * cy, cp * sy, sp);
        let up = self.up();
        (up.cross(back), up, back)
    }

    /// View → clip in WebGPU's convention (NDC z in 0..1, y up: glam's "directx" one); near and
    /// far planes follow the distance. Orthographic: the height 2 · distance · tan(fov_y / 2)
    /// and a depth range that reaches as far behind the eye as in front, so that nothing of the
    /// model is cut off.
    pub fn projection(&self, aspect: f32) -> Mat4 {
        let aspect = aspect.max(1e-3);
        if self.orthographic {
            let half_h = self.distance * (self.fov_y * 0.5).tan();
            let half_w = half_h * aspect;
            return glam::camera::rh::proj::directx::orthographic(
                -half_w,
                half_w,
                -half_h,
                half_h,
                -self.distance * 100.0,
                self.distance * 100.0,
            );
        }
        glam::camera::rh::proj::directx::perspective(
            self.fov_y,
            aspect,
            self.near(),
            self.distance * 100.0,
        )
    }

    /// The perspective view's near plane distance (it follows the orbit distance).
    pub fn near(&self) -> f32 {
        (self.distance * 0.01).max(MIN_DISTANCE * 0.1)
    }

    /// World → clip.
    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        self.projection(aspect) * self.view()
    }

    /// Turns the camera by a drag of (dx, dy) pixels: right drag turns the model to the right,
    /// down drag tips it toward the viewer.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        if dx == 0.0 && dy == 0.0 {
            return;
        }
        self.yaw -= dx * ORBIT_SPEED;
        self.pitch = (self.pitch + dy * ORBIT_SPEED).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Moves the target so that the point under the cursor follows a drag of (dx, dy) pixels in a
    /// viewport `viewport_height` pixels tall.
    pub fn pan(&mut self, dx: f32, dy: f32, viewport_height: f32) {
        let world_per_pixel =
            2.0 * self.distance * (self.fov_y * 0.5).tan() / viewport_height.max(1.0);
        let (right, up, _) = self.axes();
        self.target += (-dx * right + dy * up) * world_per_pixel;
    }

    /// Moves toward the target for positive `steps` (one wheel notch ≈ 1 step), away for negative.
    pub fn zoom(&mut self, steps: f32) {
        self.distance = (self.distance * (-0.15 * steps).exp()).clamp(MIN_DISTANCE, MAX_DISTANCE);
    }

    /// Aims at the centre of the box [lo, hi] and moves to the nearest distance (plus a 5% margin)
    /// at which all eight corners lie inside both the vertical and horizontal field of view.
    pub fn frame(&mut self, lo: Vec3, hi: Vec3, aspect: f32) {
        self.target = 0.5 * (lo + hi);
        let tan_v = (self.fov_y * 0.5).tan();
        let tan_h = tan_v * aspect.max(1e-3);
        // Camera axes (independent of the distance).
        let (right, up, back) = self.axes();
        // A corner at offset c from the target is in view at distance d when
        // |c·right| ≤ (d − c·back) tan_h and |c·up| ≤ (d − c·back) tan_v.
        let mut distance = 0.0f32;
        for corner in 0..8 {
            let c = Vec3::new(
                if corner & 1 == 0 { lo.x } else { hi.x },
                if corner & 2 == 0 { lo.y } else { hi.y },
                if corner & 4 == 0 { lo.z } else { hi.z },
            ) - self.target;
            let depth = c.dot(back);
            distance = distance
                .max(depth + c.dot(right).abs() / tan_h)
                .max(depth + c.dot(up).abs() / tan_v);
        }
        self.distance = (distance * 1.05).clamp(MIN_DISTANCE, MAX_DISTANCE);
    }

    /// The camera `t` ∈ [0, 1] of the way from `self` to `to`: target linearly, distance
    /// geometrically, yaw the short way round and pitch linearly; the projection switches at
    /// the start.
    pub fn interpolate(&self, to: &OrbitCamera, t: f32) -> OrbitCamera {
        let t = t.clamp(0.0, 1.0);
        let tau = std::f32::consts::TAU;
        let turn =
            (to.yaw - self.yaw + std::f32::consts::PI).rem_euclid(tau) - std::f32::consts::PI;
        OrbitCamera {
            target: self.target.lerp(to.target, t),
            distance: self.distance * (to.distance / self.distance).powf(t),
            yaw: self.yaw + turn * t,
            pitch: self.pitch + (to.pitch - self.pitch) * t,
            fov_y: self.fov_y + (to.fov_y - self.fov_y) * t,
            orthographic: to.orthographic,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn framed_box_projects_inside_the_view() {
        let mut camera = OrbitCamera::default();
        let (lo, hi) = (Vec3::new(-3.0, -2.0, 0.0), Vec3::new(3.5, 2.0, 3.2));
        for aspect in [0.5, 1.0, 2.0] {
            camera.frame(lo, hi, aspect);
            let m = camera.view_projection(aspect);
            for corner in 0..8 {
                let p = Vec3::new(
                    if corner & 1 == 0 { lo.x } else { hi.x },
                    if corner & 2 == 0 { lo.y } else { hi.y },
                    if corner & 4 == 0 { lo.z } else { hi.z },
                );
                let ndc = m.project_point3(p);
                assert!(ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0, "{aspect} {ndc}");
                assert!((0.0..=1.0).contains(&ndc.z), "{aspect} {ndc}");
            }
        }
    }

    #[test]
    fn pitch_stays_clear_of_the_poles() {
        let mut camera = OrbitCamera::default();
        camera.orbit(0.0, 1e6);
        assert!(camera.pitch < std::f32::consts::FRAC_PI_2);
        assert!(camera.view().is_finite());
        camera.orbit(0.0, -1e6);
        assert!(camera.pitch > -std::f32::consts::FRAC_PI_2);
    }

    #[test]
    fn pan_moves_target_across_the_view() {
        let mut camera = OrbitCamera::default();
        let before = camera.view_projection(1.0).project_point3(Vec3::ZERO);
        camera.pan(100.0, 0.0, 800.0);
        let after = camera.view_projection(1.0).project_point3(Vec3::ZERO);
        // Dragging right moves the scene right: 100 px of 800 is 0.25 in NDC.
        assert!((after.x - before.x - 0.25).abs() < 1e-3, "{before} {after}");
    }
}
