//! An orbit camera around a target point. World units are bohr.

use glam::{Mat3, Mat4, Quat, Vec3};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    /// The point the camera orbits and looks at.
    pub target: Vec3,
    /// Rotation about the world Y axis, radians.
    pub yaw: f32,
    /// Elevation above the XZ plane, radians, kept inside (−π/2, π/2).
    pub pitch: f32,
    /// Distance from the target, bohr.
    pub distance: f32,
    /// Vertical field of view, radians.
    pub fov_y: f32,
    /// The frame yaw and pitch are measured in (world from orbit frame): its Y is the axis the
    /// camera orbits about and the screen's up at zero pitch. Identity: world Y up.
    #[serde(default)]
    pub orientation: Quat,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            target: Vec3::ZERO,
            yaw: 0.0,
            pitch: 0.0,
            distance: 20.0,
            fov_y: 30f32.to_radians(),
            orientation: Quat::IDENTITY,
        }
    }
}

/// How close to straight up or down the camera may look (radians from the horizon).
pub const PITCH_LIMIT: f32 = std::f32::consts::FRAC_PI_2 - 1e-3;

impl Camera {
    /// A camera looking at the centre of the box `lo..hi` from far enough to see all of it.
    pub fn framing(lo: Vec3, hi: Vec3) -> Self {
        let mut cam = Self::default();
        cam.frame(lo, hi);
        cam
    }

    /// Re-targets the camera on the box `lo..hi`, keeping its direction.
    pub fn frame(&mut self, lo: Vec3, hi: Vec3) {
        self.target = 0.5 * (lo + hi);
        // Three quarters of the half-diagonal: the bounding sphere of a box overestimates what
        // shows in any one direction, and cube files pad their grids generously.
        let radius = (0.375 * (hi - lo).length()).max(1.0);
        self.distance = radius / (0.5 * self.fov_y).sin();
    }

    /// Moves back (never closer) until every point of `points` lies at least `margin` inside a
    /// view of width/height `aspect`, keeping the direction and the target: a wide scene framed
    /// for a narrow view, where the bounding sphere fits only its height.
    pub fn fit_points(&mut self, points: impl IntoIterator<Item = Vec3>, aspect: f32, margin: f32) {
        let (right, up) = self.screen_axes();
        let back = self.backward();
        let tan_v = (0.5 * self.fov_y).tan();
        let tan_h = tan_v * aspect.max(1e-3);
        for p in points {
            let d = p - self.target;
            let (x, y, z) = (d.dot(right).abs() + margin, d.dot(up).abs() + margin, d.dot(back));
            self.distance = self.distance.max(z + x / tan_h).max(z + y / tan_v);
        }
    }

    /// Looks at the middle of `points` from as close as keeps them all `margin` inside a view
    /// of width/height `aspect`, in the direction it looks now (nothing changes for no points).
    pub fn fit_exactly(&mut self, points: &[Vec3], aspect: f32, margin: f32) {
        let Some(&first) = points.first() else { return };
        let (lo, hi) = points.iter().fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        self.target = 0.5 * (lo + hi);
        self.distance = 0.0;
        self.fit_points(points.iter().copied(), aspect, margin);
    }

    /// Moves what the view frames into the part of a view `size` pixels (width, height) that a
    /// bar `room` pixels wide at its right edge leaves free: centred there, and stood back by
    /// how much narrower that part is (`fitted`: the framing already fits that part; only the
    /// centre moves).
    pub fn leave_room_right(&mut self, room: f32, size: [f32; 2], fitted: bool) {
        let [width, height] = size.map(|s| s.max(1.0));
        let free = ((width - room) / width).clamp(0.3, 1.0);
        if !fitted {
            self.distance /= free;
        }
        let (right, _) = self.screen_axes();
        let world_per_pixel = 2.0 * self.distance * (0.5 * self.fov_y).tan() / height;
        self.target += right * (0.5 * room * world_per_pixel);
    }

    /// Unit vector from the target towards the eye.
    pub fn backward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.orientation * Vec3::new(sy * cp, sp, cy * cp)
    }

    /// The orbit axis (the screen's up at zero pitch).
    pub fn up(&self) -> Vec3 {
        self.orientation * Vec3::Y
    }

    /// The screen's right and up directions in world space.
    pub fn screen_axes(&self) -> (Vec3, Vec3) {
        let back = self.backward();
        let right = self.up().cross(back).normalize_or(self.orientation * Vec3::X);
        (right, back.cross(right))
    }

    pub fn eye(&self) -> Vec3 {
        self.target + self.backward() * self.distance
    }

    pub fn view_from_world(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye(), self.target, self.up())
    }

    /// Looks along `direction` (from the eye towards the target) with `up` as the screen's up
    /// (made perpendicular to `direction`); target and distance stay.
    pub fn look_along(&mut self, direction: Vec3, up: Vec3) {
        let back = -direction.normalize_or(Vec3::NEG_Z);
        let up = (up - up.dot(back) * back).try_normalize().unwrap_or_else(|| back.any_orthonormal_vector());
        let right = up.cross(back);
        self.orientation = Quat::from_mat3(&Mat3::from_cols(right, up, back)).normalize();
        self.yaw = 0.0;
        self.pitch = 0.0;
    }

    /// Near and far planes that bracket everything within `scene_radius` of the target.
    fn depth_range(&self, scene_radius: f32) -> (f32, f32) {
        let near = (self.distance - scene_radius).max(self.distance * 1e-3).max(1e-3);
        let far = self.distance + scene_radius.max(1.0);
        (near, far)
    }

    /// wgpu clip space (depth 0..1, y up) from world.
    pub fn clip_from_world(&self, aspect: f32, scene_radius: f32) -> Mat4 {
        let (near, far) = self.depth_range(scene_radius);
        let proj = glam::camera::rh::proj::directx::perspective(self.fov_y, aspect.max(1e-3), near, far);
        proj * self.view_from_world()
    }

    /// Orbits by the given angles (radians).
    pub fn orbit(&mut self, d_yaw: f32, d_pitch: f32) {
        self.yaw = (self.yaw + d_yaw).rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch + d_pitch).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Zooms by a factor (> 1 moves away).
    pub fn zoom(&mut self, factor: f32) {
        self.distance = (self.distance * factor).clamp(0.5, 1e5);
    }

    /// Moves the target in the view plane; `dx`, `dy` are fractions of the view height.
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let (right, up) = self.screen_axes();
        let height = 2.0 * self.distance * (0.5 * self.fov_y).tan();
        self.target += (-dx * right + dy * up) * height;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn target_projects_to_centre_and_eye_sees_it_in_front() {
        let mut cam = Camera::framing(Vec3::splat(-3.0), Vec3::new(5.0, 3.0, 3.0));
        cam.orbit(0.7, -0.4);
        let m = cam.clip_from_world(4.0 / 3.0, 10.0);
        let c = m * cam.target.extend(1.0);
        let ndc = c.truncate() / c.w;
        assert!(ndc.x.abs() < 1e-5 && ndc.y.abs() < 1e-5);
        assert!(ndc.z > 0.0 && ndc.z < 1.0);
        assert!((cam.eye() - cam.target).length() - cam.distance < 1e-4);
    }

    #[test]
    fn looking_along_a_direction_puts_up_on_top() {
        let mut cam = Camera::framing(Vec3::splat(-2.0), Vec3::splat(2.0));
        let (dir, up) = (Vec3::new(1.0, -2.0, 0.5).normalize(), Vec3::new(0.0, 0.0, 1.0));
        cam.look_along(dir, up);
        assert!((cam.backward() + dir).length() < 1e-5, "the eye looks along the direction");
        let m = cam.clip_from_world(1.0, 5.0);
        let project = |p: Vec3| {
            let c = m * p.extend(1.0);
            c.truncate() / c.w
        };
        let above = project(cam.target + up);
        assert!(above.y > 0.1 && above.x.abs() < 1e-4, "up projects straight up: {above}");
        // Orbiting turns about the new up axis, as the default camera turns about world Y.
        let before = cam.backward();
        cam.orbit(0.3, 0.0);
        assert!((cam.backward().dot(cam.up()) - before.dot(cam.up())).abs() < 1e-5);
        let (right, screen_up) = cam.screen_axes();
        assert!(right.dot(cam.backward()).abs() < 1e-5 && screen_up.dot(cam.backward()).abs() < 1e-5);
    }

    #[test]
    fn pitch_is_clamped_and_pan_moves_target() {
        let mut cam = Camera::default();
        cam.orbit(0.0, 10.0);
        assert!(cam.pitch < std::f32::consts::FRAC_PI_2);
        let before = cam.target;
        cam.pan(0.1, 0.0);
        assert!((cam.target - before).length() > 0.0);
        assert!((cam.target - before).dot(cam.backward()).abs() < 1e-5);
    }
}
