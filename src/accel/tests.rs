//! Unit tests of the ray queries.

use super::*;
use glam::Affine3A;

fn quad_mesh() -> Vec<TriangleInput> {
    // Two triangles sharing the diagonal of the unit square at z = 1.
    let p = [
        Vec3A::new(0.0, 0.0, 1.0),
        Vec3A::new(1.0, 0.0, 1.0),
        Vec3A::new(1.0, 1.0, 1.0),
        Vec3A::new(0.0, 1.0, 1.0),
    ];
    vec![
        TriangleInput {
            vertices: [p[0], p[1], p[2]],
            material: 0,
            uvs: None,
            normals: None,
        },
        TriangleInput {
            vertices: [p[0], p[2], p[3]],
            material: 1,
            uvs: None,
            normals: None,
        },
    ]
}

#[test]
fn rays_through_a_shared_edge_never_slip_through() {
    let g = Geometry::build(&quad_mesh(), vec![]);
    // Rays aimed exactly at the shared diagonal x = y.
    for i in 1..100 {
        let s = i as f32 / 100.0;
        let ray = Ray::new(Vec3A::new(s, s, 0.0), Vec3A::Z);
        let hit = g.intersect(&ray).expect("ray through the diagonal missed");
        assert!((hit.t - 1.0).abs() < 1e-6);
        assert!(g.occluded(&Ray { t_max: 2.0, ..ray }));
        assert!(!g.occluded(&Ray { t_max: 0.5, ..ray }));
    }
}

#[test]
fn closest_of_sphere_and_triangle_wins() {
    let sphere = Sphere {
        center: Vec3A::new(0.5, 0.5, 3.0),
        radius: 0.5,
        material: 7,
        light: NO_LIGHT,
    };
    let g = Geometry::build(&quad_mesh(), vec![sphere]);
    let hit = g
        .intersect(&Ray::new(Vec3A::new(0.5, 0.5, 5.0), -Vec3A::Z))
        .unwrap();
    assert_eq!(hit.material, 7);
    assert!((hit.t - 1.5).abs() < 1e-5);
    assert!((hit.normal - Vec3A::Z).length() < 1e-5);
    // From inside the sphere the far side is hit.
    let hit = g
        .intersect(&Ray::new(Vec3A::new(0.5, 0.5, 3.0), Vec3A::Z))
        .unwrap();
    assert!((hit.t - 0.5).abs() < 1e-5);
    let hit = g
        .intersect(&Ray::new(Vec3A::new(0.25, 0.5, 0.0), Vec3A::Z))
        .unwrap();
    assert!(hit.material <= 1);
    assert!((hit.normal - Vec3A::Z).length() < 1e-6);
}

#[test]
fn negative_zero_direction_components_still_hit() {
    let sphere = Sphere {
        center: Vec3A::new(0.5, 0.5, 3.0),
        radius: 0.5,
        material: 0,
        light: NO_LIGHT,
    };
    let g = Geometry::build(&[], vec![sphere]);
    for d in [
        Vec3A::new(-0.0, -0.0, -1.0),
        Vec3A::new(-0.0, 0.0, -1.0),
        Vec3A::new(1e-3, -0.0, -1.0),
    ] {
        let hit = g.intersect(&Ray::new(Vec3A::new(0.5, 0.5, 5.0), d.normalize()));
        assert!(hit.is_some(), "{d:?}");
        assert!(g.occluded(&Ray::new(Vec3A::new(0.5, 0.5, 5.0), d.normalize())));
    }
}

#[test]
fn moving_sphere_is_where_the_ray_time_puts_it() {
    let mut g = Geometry::build(&quad_mesh(), vec![]);
    let ball = Sphere {
        center: Vec3A::new(-3.0, 0.5, 0.5),
        radius: 0.25,
        material: 9,
        light: NO_LIGHT,
    };
    g.add_moving(Geometry::build(&[], vec![ball]), Vec3A::new(4.0, 0.0, 0.0));
    let ray = |time| Ray::new(Vec3A::new(0.5, 0.5, -1.0), Vec3A::Z).at_time(time);
    // At time 0 the ball is far to the side: the quad at z = 1 is hit.
    assert!(g.intersect(&ray(0.0)).unwrap().material <= 1);
    // At 0.875 the centre is at x = 0.5, on the ray: hit at z = 0.25.
    let hit = g.intersect(&ray(0.875)).unwrap();
    assert_eq!(hit.material, 9);
    assert!((hit.t - 1.25).abs() < 1e-5, "{}", hit.t);
    assert!((hit.point - Vec3A::new(0.5, 0.5, 0.25)).length() < 1e-5);
    assert_eq!(hit.time, 0.875);
    assert_eq!(hit.spawn_ray(Vec3A::X).time, 0.875);
    // Shadow rays that stop before the quad see the ball only when it is there.
    let short = |time| Ray {
        t_max: 1.5,
        ..ray(time)
    };
    assert!(!g.occluded(&short(0.0)));
    assert!(g.occluded(&short(0.875)));
    // The bounds cover the whole sweep.
    assert!(g.bounds().max.x >= 1.25 && g.bounds().min.x <= -3.25);
}

#[test]
fn queries_take_the_inlined_path_only_where_nothing_else_takes_part() {
    let mut g = Geometry::build(&quad_mesh(), vec![]);
    assert!(g.is_plain());
    assert!(g.flattened().is_plain());
    g.set_offset(OffsetMode::Fixed(1e-3));
    assert!(!g.is_plain(), "a fixed offset widens every hit's error");
    g.set_offset(OffsetMode::Robust);
    assert!(g.is_plain());
    let ball = Sphere {
        center: Vec3A::new(-3.0, 0.5, 0.5),
        radius: 0.25,
        material: 9,
        light: NO_LIGHT,
    };
    let mut moving = g.clone();
    moving.add_moving(Geometry::build(&[], vec![ball]), Vec3A::X);
    assert!(!moving.is_plain() && !moving.flattened().is_plain());
    let mut placed = g.clone();
    placed.add_instances(
        vec![Geometry::build(&quad_mesh(), vec![])],
        &[(0, Affine3A::from_translation(glam::Vec3::Z))],
    );
    assert!(!placed.is_plain());
    // A geometry nobody settled takes the general path, which is always right.
    assert!(!Geometry::default().is_plain());
}

#[test]
fn pathologically_deep_bvh_falls_back_to_testing_every_triangle() {
    // Hundreds of copies of one quad (the shape of a fuzzer's find).
    let mut triangles = Vec::new();
    for _ in 0..300 {
        triangles.extend(quad_mesh());
    }
    let g = Geometry::build(&triangles, vec![]);
    // Either way every ray must still find the quad.
    for i in 1..20 {
        let s = i as f32 / 20.0;
        let hit = g.intersect(&Ray::new(Vec3A::new(s, 0.3, 0.0), Vec3A::Z));
        assert!(hit.is_some_and(|h| (h.t - 1.0).abs() < 1e-6));
    }
    let normal = Geometry::build(&quad_mesh().repeat(40), vec![]);
    assert!(g.bvh_too_deep());
    assert!(!normal.bvh_too_deep());
}

#[test]
fn tiny_far_sphere_is_hit() {
    let c = Vec3A::new(1e4, 0.0, 0.0);
    let ray = Ray::new(Vec3A::ZERO, Vec3A::X);
    let t = intersect_sphere(ray.origin, ray.direction, c, 1e-3, f32::INFINITY).unwrap();
    assert!((t - (1e4 - 1e-3)).abs() < 1e-2);
}

/// A bumpy 12 × 12 grid over the unit square (288 triangles: a BVH), with
/// vertex normals and uvs.
fn bumpy_grid() -> Vec<TriangleInput> {
    let n = 12;
    let at = |i: usize, j: usize| {
        let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
        let z = 0.1 * (6.0 * u).sin() * (5.0 * v).cos();
        let dzdu = 0.6 * (6.0 * u).cos() * (5.0 * v).cos();
        let dzdv = -0.5 * (6.0 * u).sin() * (5.0 * v).sin();
        let normal = Vec3A::new(-dzdu, -dzdv, 1.0).normalize();
        (Vec3A::new(u, v, z), normal, Vec2::new(u, v))
    };
    let mut out = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let corners = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            for [a, b, c] in [[0, 1, 2], [0, 2, 3]] {
                let pick = [corners[a], corners[b], corners[c]];
                out.push(TriangleInput {
                    vertices: pick.map(|p| p.0),
                    material: (i + j) as u32 % 3,
                    uvs: Some(pick.map(|p| p.2)),
                    normals: Some(pick.map(|p| p.1)),
                });
            }
        }
    }
    out
}

#[test]
fn instances_answer_as_their_copies_do() {
    let grid = bumpy_grid();
    // 4 × 4 placements, rotated, scaled (unevenly on some) and spread out:
    // more than the list holds, so the top-level BVH is searched.
    let mut placements = Vec::new();
    for k in 0..16 {
        let angle = k as f32 * 0.7;
        let scale = glam::Vec3::new(1.0 + 0.1 * k as f32, 1.0, 1.0 + 0.05 * (k % 3) as f32);
        let rotation =
            glam::Quat::from_axis_angle(glam::Vec3::new(1.0, 2.0, 0.5).normalize(), angle);
        let offset = glam::Vec3::new((k % 4) as f32 * 2.5, (k / 4) as f32 * 2.5, 0.3 * k as f32);
        placements.push((
            0,
            Affine3A::from_scale_rotation_translation(scale, rotation, offset),
        ));
    }
    let copies: Vec<TriangleInput> = placements
        .iter()
        .flat_map(|(_, m)| crate::scene::InstancesInput::copy(&grid, *m))
        .collect();
    let flat = Geometry::build_full(copies.clone(), vec![], AccelChoice::Auto, true);
    let mut shared = Geometry::default();
    let prototype = Geometry::build_full(grid.clone(), vec![], AccelChoice::Auto, true);
    shared.add_instances(vec![prototype], &placements);
    assert_eq!(shared.triangles_drawn(), flat.triangle_count());
    assert!(shared.memory_bytes() * 8 < flat.memory_bytes());
    assert!((shared.triangle_area() - flat.triangle_area()).abs() < 1e-4 * flat.triangle_area());
    let (a, b) = (shared.bounds(), flat.bounds());
    // Conservative: each instance's box is its prototype's box moved.
    assert!(Vec3A::from(a.min).cmple(Vec3A::from(b.min) + 1e-5).all());
    assert!(Vec3A::from(a.max).cmpge(Vec3A::from(b.max) - 1e-5).all());

    // Rays from around the field towards random points in it.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let (mut hits, mut disagreements) = (0, 0);
    let rays = 4000;
    for _ in 0..rays {
        let origin = Vec3A::new(
            random() * 16.0 - 4.0,
            random() * 16.0 - 4.0,
            8.0 * random() - 4.0,
        );
        let target = Vec3A::new(random() * 9.0, random() * 9.0, random() * 5.0);
        let ray = Ray::new(origin, (target - origin).normalize());
        let (s, f) = (shared.intersect(&ray), flat.intersect(&ray));
        assert_eq!(shared.occluded(&ray), flat.occluded(&ray));
        let (Some(s), Some(f)) = (s, f) else {
            // Grazing rays may fall on either side of an edge or silhouette.
            disagreements += usize::from(s.is_some() != f.is_some());
            continue;
        };
        hits += 1;
        if (s.t - f.t).abs() > 1e-4 * f.t {
            // A ray through a shared edge meets the other triangle.
            disagreements += 1;
            continue;
        }
        assert_ne!(s.instance, NO_INSTANCE);
        assert!((s.point - f.point).length() < 1e-4 * (1.0 + f.point.length()));
        // The moved point's rounding bound keeps a ray spawned there off
        // its own triangle.
        let back = s.spawn_ray(-ray.direction);
        let again = shared.intersect(&back);
        assert!(!again.is_some_and(|h| h.primitive == s.primitive && h.instance == s.instance));
        if s.material == f.material {
            assert!(
                (s.normal - f.normal).length() < 1e-4,
                "{:?} {:?}",
                s.normal,
                f.normal
            );
            assert!((shared.uv(&s) - flat.uv(&f)).length() < 1e-4);
            // Vertex normals: interpolated before the transform rather than
            // after, which differs slightly under uneven scales.
            let (ns, nf) = (shared.shading_normal(&s), flat.shading_normal(&f));
            assert!((ns - nf).length() < 2e-2, "{ns:?} {nf:?}");
            let (ds, df) = (
                shared.uv_derivatives(&s).unwrap(),
                flat.uv_derivatives(&f).unwrap(),
            );
            assert!((ds.0 - df.0).length() < 1e-3 * df.0.length());
            assert!((ds.1 - df.1).length() < 1e-3 * df.1.length());
        }
    }
    assert!(hits > rays / 8, "{hits} hits");
    assert!(disagreements * 200 < rays, "{disagreements} disagreements");
    // Flattening gives the copies back.
    assert_eq!(shared.flattened().triangle_count(), flat.triangle_count());
}
