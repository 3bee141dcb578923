//! Perspective camera: pinhole, or thin lens with an aperture and focus distance.

use crate::math::Ray;
use crate::sampling::warp::square_to_concentric_disk;
use glam::{Vec2, Vec3A};

/// A perspective camera looking from `eye` along `forward`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3A,
    /// Unit vectors of the camera frame: image right, image up, view direction.
    pub right: Vec3A,
    pub up: Vec3A,
    pub forward: Vec3A,
    /// tan(vertical fov / 2).
    pub tan_half_fov_y: f32,
    pub width: u32,
    pub height: u32,
    /// Radius of the thin lens; zero for a pinhole.
    pub aperture_radius: f32,
    /// Distance along the view direction of the plane in focus.
    pub focus_distance: f32,
}

impl Camera {
    /// Builds the frame from eye, target and up vector. Right-handed: with
    /// +y up and looking along +z, image right is -x (Mitsuba's `lookat`).
    pub fn look_at(
        eye: Vec3A,
        target: Vec3A,
        up: Vec3A,
        fov_y_degrees: f32,
        width: u32,
        height: u32,
        aperture_radius: f32,
        focus_distance: f32,
    ) -> Self {
        let forward = (target - eye).normalize();
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        Camera {
            eye,
            right,
            up,
            forward,
            tan_half_fov_y: (fov_y_degrees.to_radians() * 0.5).tan(),
            width,
            height,
            aperture_radius,
            focus_distance,
        }
    }

    /// Primary ray through the film position `film` (in pixels, origin at the
    /// top-left corner, y down) using `lens` in [0, 1)² for the aperture.
    #[inline]
    pub fn generate_ray(&self, film: Vec2, lens: Vec2) -> Ray {
        let aspect = self.width as f32 / self.height as f32;
        let ndc_x = 2.0 * film.x / self.width as f32 - 1.0;
        let ndc_y = 1.0 - 2.0 * film.y / self.height as f32;
        // Direction to the point on the image plane at unit distance.
        let local = Vec3A::new(
            ndc_x * self.tan_half_fov_y * aspect,
            ndc_y * self.tan_half_fov_y,
            1.0,
        );
        if self.aperture_radius <= 0.0 {
            let direction = (self.right * local.x + self.up * local.y + self.forward).normalize();
            return Ray::new(self.eye, direction);
        }
        // Thin lens: all rays through the lens meet at the focus plane point.
        let focus = local * self.focus_distance;
        let lens_point = square_to_concentric_disk(lens) * self.aperture_radius;
        let origin_local = Vec3A::new(lens_point.x, lens_point.y, 0.0);
        let d = focus - origin_local;
        let origin = self.eye + self.right * origin_local.x + self.up * origin_local.y;
        let direction = (self.right * d.x + self.up * d.y + self.forward * d.z).normalize();
        Ray::new(origin, direction)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cornell_camera() -> Camera {
        Camera::look_at(
            Vec3A::new(278.0, 273.0, -800.0),
            Vec3A::new(278.0, 273.0, 0.0),
            Vec3A::Y,
            39.307648,
            256,
            256,
            0.0,
            800.0,
        )
    }

    #[test]
    fn centre_pixel_looks_at_the_target_and_red_wall_is_left() {
        let cam = cornell_camera();
        let centre = cam.generate_ray(Vec2::new(128.0, 128.0), Vec2::ZERO);
        assert!((centre.direction - Vec3A::Z).length() < 1e-6);
        // The left edge of the image looks towards +x (the red wall at x ~ 550).
        let left = cam.generate_ray(Vec2::new(0.0, 128.0), Vec2::ZERO);
        assert!(left.direction.x > 0.3);
        let top = cam.generate_ray(Vec2::new(128.0, 0.0), Vec2::ZERO);
        assert!(top.direction.y > 0.3);
        // Half of the vertical fov at the top edge.
        let angle = top.direction.dot(Vec3A::Z).acos().to_degrees();
        assert!((angle - 39.307648 / 2.0).abs() < 1e-3);
    }

    #[test]
    fn thin_lens_rays_meet_on_the_focus_plane() {
        let mut cam = cornell_camera();
        cam.aperture_radius = 20.0;
        let film = Vec2::new(40.0, 200.0);
        let a = cam.generate_ray(film, Vec2::new(0.1, 0.2));
        let b = cam.generate_ray(film, Vec2::new(0.9, 0.7));
        let pa = a.at((800.0) / a.direction.z);
        let pb = b.at((800.0) / b.direction.z);
        assert!((pa - pb).length() < 1e-2, "{pa:?} {pb:?}");
        assert!((a.origin - b.origin).length() > 1.0);
    }
}
