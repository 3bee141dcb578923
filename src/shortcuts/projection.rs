//! Triangles projected onto a pinhole camera's film, and their overlap with
//! pixel squares: shared by the camera rays' candidate lists and the
//! integration of emitters seen directly.

use crate::camera::Camera;
use glam::{DVec2, DVec3, Vec3A};

/// The triangle's vertices in pixel coordinates (x right, y down, as
/// [`Camera::generate_ray`] reads its film position), or None when a vertex
/// lies on or behind the eye's image plane.
pub fn project_triangle(camera: &Camera, triangle: &[Vec3A; 3]) -> Option<[DVec2; 3]> {
    let aspect = f64::from(camera.width) / f64::from(camera.height);
    let tan_y = f64::from(camera.tan_half_fov_y);
    let (right, up, forward) = (
        camera.right.as_dvec3(),
        camera.up.as_dvec3(),
        camera.forward.as_dvec3(),
    );
    let eye = camera.eye.as_dvec3();
    let mut out = [DVec2::ZERO; 3];
    for (p, v) in out.iter_mut().zip(triangle) {
        let d: DVec3 = v.as_dvec3() - eye;
        let z = d.dot(forward);
        // Far enough in front that the division stays well conditioned.
        if z <= 1e-6 * d.length() {
            return None;
        }
        let ndc_x = d.dot(right) / z / (tan_y * aspect);
        let ndc_y = d.dot(up) / z / tan_y;
        *p = DVec2::new(
            (ndc_x + 1.0) * 0.5 * f64::from(camera.width),
            (1.0 - ndc_y) * 0.5 * f64::from(camera.height),
        );
    }
    Some(out)
}

/// The projected triangle's edge lines, oriented so that its inside is on
/// their positive side.
pub struct EdgeTests {
    /// (normal, offset): a point p is on the inner side when normal . p >= offset.
    pub edges: [(DVec2, f64); 3],
    /// A triangle seen edge-on has no inside to test: its bounding box decides.
    pub degenerate: bool,
}

impl EdgeTests {
    pub fn new(p: &[DVec2; 3]) -> Self {
        let area2 = (p[1] - p[0]).perp_dot(p[2] - p[0]);
        let orientation = area2.signum();
        let edges = [0, 1, 2].map(|i| {
            let (a, b) = (p[i], p[(i + 1) % 3]);
            // Left normal of a -> b, flipped for clockwise triangles.
            let normal = DVec2::new(a.y - b.y, b.x - a.x) * orientation;
            (normal, normal.dot(a))
        });
        let scale = (p[1] - p[0]).length() * (p[2] - p[0]).length();
        EdgeTests {
            edges,
            degenerate: area2.abs() <= 1e-9 * scale,
        }
    }

    /// True unless an edge line separates the square [lo, hi] from the
    /// triangle (the bounding boxes are known to overlap).
    pub fn overlaps(&self, lo: DVec2, hi: DVec2) -> bool {
        self.degenerate
            || self.edges.iter().all(|&(normal, offset)| {
                // The square's corner furthest along the normal.
                let corner = DVec2::new(
                    if normal.x >= 0.0 { hi.x } else { lo.x },
                    if normal.y >= 0.0 { hi.y } else { lo.y },
                );
                normal.dot(corner) >= offset
            })
    }
}
