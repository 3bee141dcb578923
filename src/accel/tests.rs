//! Unit tests of the ray queries.

use super::*;

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
