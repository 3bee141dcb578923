//! Test geometry shared by the benchmarks.

use glam::Vec3A;
use tracelab::accel::TriangleInput;

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
            });
            triangles.push(TriangleInput {
                vertices: [a, c, d],
                material: 0,
            });
        }
    }
    triangles
}
