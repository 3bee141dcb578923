//! Test geometry shared by the benchmarks.
// Each benchmark uses part of this module.
#![allow(dead_code)]

use glam::{Vec2, Vec3A};
use tracelab::accel::TriangleInput;
use tracelab::math::Ray;
use tracelab::sampling::hash::{hash_combine, to_unit_float};
use tracelab::sampling::warp::square_to_uniform_sphere;

/// UV sphere of radius 1 with about `2 * n * n` triangles.
pub fn uv_sphere(n: usize) -> Vec<TriangleInput> {
    let point = |i: usize, j: usize| {
        let theta = std::f32::consts::PI * i as f32 / n as f32;
        let phi = 2.0 * std::f32::consts::PI * j as f32 / n as f32;
        Vec3A::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        )
    };
    let mut triangles = Vec::with_capacity(2 * n * n);
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            triangles.push(TriangleInput {
                vertices: [a, b, c],
                material: 0,
                uvs: None,
                normals: None,
            });
            triangles.push(TriangleInput {
                vertices: [a, c, d],
                material: 0,
                uvs: None,
                normals: None,
            });
        }
    }
    triangles
}

/// Two uniform numbers from a hash of (i, salt).
pub fn unit(i: u64, salt: u64) -> Vec2 {
    let h = hash_combine(i, salt);
    Vec2::new(to_unit_float(h), to_unit_float(h << 24))
}

/// Rays from a sphere of radius 2 towards random points in the unit ball.
pub fn incoherent_rays(count: usize) -> Vec<Ray> {
    (0..count as u64)
        .map(|i| {
            let origin = 2.0 * square_to_uniform_sphere(unit(i, 1));
            let target =
                0.9 * square_to_uniform_sphere(unit(i, 2)) * to_unit_float(hash_combine(i, 3));
            Ray::new(origin, (target - origin).normalize())
        })
        .collect()
}

/// A scanline grid of directions from one origin.
pub fn coherent_rays(side: usize) -> Vec<Ray> {
    let origin = Vec3A::new(0.0, 0.0, 3.0);
    (0..side * side)
        .map(|k| {
            let (x, y) = (
                (k % side) as f32 / side as f32,
                (k / side) as f32 / side as f32,
            );
            let target = Vec3A::new(2.0 * x - 1.0, 2.0 * y - 1.0, 0.0);
            Ray::new(origin, (target - origin).normalize())
        })
        .collect()
}
