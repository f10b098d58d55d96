//! The screen's bounding shapes contain what they bound.

use nalgebra::{Matrix3, Vector3};

use super::link_capsule::link_capsule;
use super::local::Local;
use super::shapes::{Shape, Sphere, segment_segment_dist2, separation};
use super::sphere::link_sphere;

#[test]
fn a_link_sphere_contains_every_shape_of_the_link() {
    let shapes = [
        Local::Capsule {
            a: Vector3::new(0.0, 0.0, -0.1),
            b: Vector3::new(0.0, 0.0, 0.3),
            radius: 0.05,
        },
        Local::Box {
            center: Vector3::new(0.2, -0.1, 0.0),
            axes: Matrix3::identity(),
            half: Vector3::new(0.02, 0.03, 0.04),
        },
    ];
    let Some(Sphere { centre, radius: r }) = link_sphere(shapes.iter()) else {
        panic!("a sphere");
    };
    let c = Vector3::from(centre);
    for l in &shapes {
        assert!(
            (l.centre() - c).norm() + l.reach() <= r + 1e-12,
            "{l:?} outside ({c}, {r})"
        );
    }
    // No shape: no sphere.
    assert!(link_sphere(std::iter::empty()).is_none());
}

#[test]
fn a_link_capsule_contains_every_shape_of_the_link() {
    let shapes = [
        Local::Capsule {
            a: Vector3::new(0.0, 0.0, -0.1),
            b: Vector3::new(0.02, 0.0, 0.3),
            radius: 0.05,
        },
        Local::Box {
            center: Vector3::new(0.05, -0.04, 0.2),
            axes: Matrix3::new(0.8, -0.6, 0.0, 0.6, 0.8, 0.0, 0.0, 0.0, 1.0),
            half: Vector3::new(0.02, 0.03, 0.04),
        },
    ];
    let Some(Local::Capsule { a, b, radius }) = link_capsule(shapes.iter()) else {
        panic!("a capsule");
    };
    // Every shape's extreme points, and the capsule's surface points around its ends.
    let to_axis = |p: &Vector3<f64>| segment_segment_dist2(&a, &b, p, p).sqrt();
    let mut points: Vec<(Vector3<f64>, f64)> = Vec::new();
    if let Local::Capsule { a, b, radius } = &shapes[0] {
        for k in 0..=20 {
            points.push((a + (b - a) * (k as f64 / 20.0), *radius));
        }
    }
    if let Local::Box { center, axes, half } = &shapes[1] {
        for k in 0..8 {
            let s = |i: usize| if k >> i & 1 == 0 { -half[i] } else { half[i] };
            points.push((center + axes * Vector3::new(s(0), s(1), s(2)), 0.0));
        }
    }
    for (p, r) in &points {
        assert!(to_axis(p) + r <= radius + 1e-12, "{p} ({r}) outside the capsule");
    }
    // Tighter than the sphere around the same shapes, and none for no shape.
    assert!(link_sphere(shapes.iter()).is_some_and(|s| radius < s.radius));
    assert!(link_capsule(std::iter::empty()).is_none());
}

#[test]
fn a_sphere_kept_from_a_box_is_not_near_it() {
    let b = Shape::Box {
        center: Vector3::new(0.5, 0.0, 0.2),
        axes: [
            Vector3::new(0.8, 0.6, 0.0),
            Vector3::new(-0.6, 0.8, 0.0),
            Vector3::new(0.0, 0.0, 1.0),
        ],
        half: Vector3::new(0.1, 0.05, 0.2),
    };
    let gap = 0.0055;
    let mut apart = 0;
    // Seeded points on a grid around the box: whenever the sphere test says apart, the
    // (conservative) nearness test of the sphere as a capsule says not near either.
    for i in 0..20 {
        for j in 0..20 {
            for k in 0..10 {
                let c = Vector3::new(
                    0.2 + 0.03 * i as f64,
                    -0.3 + 0.03 * j as f64,
                    0.05 * k as f64 - 0.1,
                );
                let r = 0.02;
                let s = Shape::Capsule {
                    a: c,
                    b: c,
                    radius: r,
                };
                if (Sphere { centre: c, radius: r }).keeps_from_box(&b, gap) {
                    apart += 1;
                    assert!(!separation(&s, &b).near(gap), "{c:?}");
                }
            }
        }
    }
    assert!(apart > 1000, "{apart}");
    // Not a box: never apart by this test.
    let h = Shape::HalfSpace {
        normal: Vector3::new(0.0, 0.0, 1.0),
        offset: 0.0,
    };
    assert!(
        !Sphere {
            centre: Vector3::new(0.0, 0.0, 5.0),
            radius: 0.1
        }
        .keeps_from_box(&h, gap)
    );
}
