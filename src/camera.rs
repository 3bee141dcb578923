//! Perspective camera: pinhole, or thin lens with an aperture and focus distance.

use crate::filter::PixelFilter;
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
    /// Shutter interval: the film integrates over times in [open, close).
    /// Equal ends give an instantaneous exposure (no motion blur).
    pub shutter_open: f32,
    pub shutter_close: f32,
    /// How samples are spread over pixels (Mitsuba's `rfilter`).
    pub filter: PixelFilter,
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
            shutter_open: 0.0,
            shutter_close: 0.0,
            filter: PixelFilter::Box,
        }
    }

    /// The same camera with pixel filter `filter`.
    pub fn with_filter(mut self, filter: PixelFilter) -> Self {
        self.filter = filter;
        self
    }

    /// The same camera with the shutter open over [open, close).
    pub fn with_shutter(mut self, open: f32, close: f32) -> Self {
        self.shutter_open = open;
        self.shutter_close = close;
        self
    }

    /// True when the exposure spans an interval of time.
    pub fn has_shutter_interval(&self) -> bool {
        self.shutter_close > self.shutter_open
    }

    /// The time for `u` in [0, 1): uniform over the shutter interval (a box
    /// shutter, as Mitsuba's and pbrt's default).
    #[inline]
    pub fn time(&self, u: f32) -> f32 {
        self.shutter_open + u * (self.shutter_close - self.shutter_open)
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

/// A connection from a scene point to the camera, for light tracing.
#[derive(Clone, Copy, Debug)]
pub struct CameraConnection {
    /// Film position (pixels) the connection lands on.
    pub film: Vec2,
    /// Point on the lens (the eye for a pinhole).
    pub lens_point: Vec3A,
    /// Unit direction from the scene point to `lens_point`.
    pub wi: Vec3A,
    /// We / p: importance of the ray through one pixel divided by the density
    /// of the connection wrt. solid angle at the scene point.
    pub weight: f32,
}

impl Camera {
    /// Density wrt. solid angle with which camera rays over the whole film
    /// take the direction `w` (unit): the film at unit distance has area
    /// A, so p = 1 / (A cos^3) inside the field of view (for a thin lens,
    /// given the lens point). Bidirectional estimators weigh strategies
    /// with it; one sample per pixel over W x H pixels is one sample of
    /// this density.
    #[inline]
    pub fn pdf_direction(&self, w: Vec3A) -> f32 {
        let cos = w.dot(self.forward);
        if cos <= 0.0 {
            return 0.0;
        }
        let aspect = self.width as f32 / self.height as f32;
        let film_area = 4.0 * self.tan_half_fov_y * self.tan_half_fov_y * aspect;
        1.0 / (film_area * cos * cos * cos)
    }

    /// Connects `point` to a point on the lens chosen with `u_lens` (pbrt-v4's
    /// `PerspectiveCamera::SampleWi`). A box-filtered pixel of area A (on the
    /// image plane at unit distance) has importance We = 1 / (A A_lens cos^4),
    /// and the lens point has density d^2 / (cos A_lens) wrt. solid angle, so
    /// We / p = 1 / (A cos^3 d^2) for both pinhole and thin lens.
    /// `None` when the point is behind the camera or maps outside the film.
    #[inline]
    pub fn connect(&self, point: Vec3A, u_lens: Vec2) -> Option<CameraConnection> {
        let lens_local = if self.aperture_radius > 0.0 {
            square_to_concentric_disk(u_lens) * self.aperture_radius
        } else {
            Vec2::ZERO
        };
        let lens_point = self.eye + self.right * lens_local.x + self.up * lens_local.y;
        let to_lens = lens_point - point;
        let dist2 = to_lens.length_squared();
        let distance = dist2.sqrt();
        let wi = to_lens / distance;
        let outgoing = -wi;
        let cos = outgoing.dot(self.forward);
        if cos <= 0.0 || !distance.is_finite() || distance == 0.0 {
            return None;
        }
        // The ray from the lens point crosses the focus plane where a pinhole
        // ray through the lens centre would; that point fixes the pixel.
        let in_focus = if self.aperture_radius > 0.0 {
            lens_point + outgoing * (self.focus_distance / cos) - self.eye
        } else {
            outgoing
        };
        let depth = in_focus.dot(self.forward);
        let aspect = self.width as f32 / self.height as f32;
        let ndc_x = in_focus.dot(self.right) / (depth * self.tan_half_fov_y * aspect);
        let ndc_y = in_focus.dot(self.up) / (depth * self.tan_half_fov_y);
        let film = Vec2::new(
            (ndc_x + 1.0) * 0.5 * self.width as f32,
            (1.0 - ndc_y) * 0.5 * self.height as f32,
        );
        if !(film.x >= 0.0
            && film.y >= 0.0
            && film.x < self.width as f32
            && film.y < self.height as f32)
        {
            return None;
        }
        let pixel_side = 2.0 * self.tan_half_fov_y / self.height as f32;
        let pixel_area = pixel_side * pixel_side;
        let weight = 1.0 / (pixel_area * cos * cos * cos * dist2);
        Some(CameraConnection {
            film,
            lens_point,
            wi,
            weight,
        })
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

    #[test]
    fn connections_land_on_the_pixel_whose_ray_passes_through_the_point() {
        for aperture in [0.0, 20.0] {
            let mut cam = cornell_camera();
            cam.aperture_radius = aperture;
            let (film, lens) = (Vec2::new(37.3, 201.6), Vec2::new(0.3, 0.8));
            let ray = cam.generate_ray(film, lens);
            let point = ray.at(1234.0);
            let c = cam.connect(point, lens).expect("point is in view");
            assert!((c.film - film).length() < 1e-2, "{:?} vs {film:?}", c.film);
            assert!((c.wi + ray.direction).length() < 1e-5);
            assert!((c.lens_point - ray.origin).length() < 1e-3);
        }
        let cam = cornell_camera();
        assert!(
            cam.connect(Vec3A::new(278.0, 273.0, -900.0), Vec2::ZERO)
                .is_none()
        );
    }
}
