//! Bounding spheres: the screen's cheapest tests, and a link's sphere around its shapes.

use nalgebra::Vector3;

use super::local::Local;
use super::posed::Posed;
use super::shapes::{Shape, Sphere, V3};

impl Sphere {
    /// True when the two spheres keep at least `gap` metres between them.
    #[inline]
    pub(super) fn keeps(&self, other: &Sphere, gap: f64) -> bool {
        self.keeps_at(self.centre_dist2(other), other, gap)
    }

    /// [`Sphere::keeps`] with the squared distance between the centres given (`d2`, metres²:
    /// [`Sphere::centre_dist2`]), for several gaps of one pair.
    #[inline]
    pub(super) fn keeps_at(&self, d2: f64, other: &Sphere, gap: f64) -> bool {
        let t = self.radius + other.radius + gap;
        d2 >= t * t
    }

    /// The squared distance between the two centres, metres².
    #[inline]
    pub(super) fn centre_dist2(&self, other: &Sphere) -> f64 {
        let (c1, c2) = (&self.centre, &other.centre);
        let d = [c1[0] - c2[0], c1[1] - c2[1], c1[2] - c2[2]];
        d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    }

    /// True when `shape` is a box and the sphere keeps at least `gap` metres from it (the
    /// distance from the centre to the box, less the radius); false otherwise.
    #[inline]
    pub(super) fn keeps_from_box(&self, shape: &Shape, gap: f64) -> bool {
        let Some(out2) = box_dist2(&self.centre, shape) else {
            return false;
        };
        let t = self.radius + gap;
        out2 >= t * t
    }

    /// The height of the sphere's lowest point above the plane `normal · p = offset`, metres
    /// (negative below it).
    #[inline]
    pub(super) fn above(&self, normal: &V3, offset: f64) -> f64 {
        let c = &self.centre;
        normal[0] * c[0] + normal[1] * c[1] + normal[2] * c[2] - offset - self.radius
    }

    /// A lower bound on the distance between the two spheres, metres.
    #[inline]
    fn gap(&self, other: &Sphere) -> f64 {
        let (c1, c2) = (&self.centre, &other.centre);
        let d = [c1[0] - c2[0], c1[1] - c2[1], c1[2] - c2[2]];
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - self.radius - other.radius
    }

    /// A lower bound on the distance between the sphere and a posed shape, metres: the larger
    /// of the bounds through the shape's bounding sphere and, for a box or a half-space, through
    /// the shape itself.
    pub(super) fn gap_to(&self, posed: &Posed) -> f64 {
        let through_sphere = posed.sphere.map_or(f64::NEG_INFINITY, |s| self.gap(&s));
        let through_shape = match &posed.shape {
            Shape::HalfSpace { normal, offset } => self.above(normal, *offset),
            Shape::Box { .. } => {
                box_dist2(&self.centre, &posed.shape).map_or(f64::NEG_INFINITY, |d2| d2.sqrt() - self.radius)
            }
            Shape::Capsule { .. } => f64::NEG_INFINITY,
        };
        through_sphere.max(through_shape)
    }
}

/// The squared distance from the point `c` to `shape` if it is a box, metres².
#[inline]
fn box_dist2(c: &V3, shape: &Shape) -> Option<f64> {
    let Shape::Box { center, axes, half } = shape else {
        return None;
    };
    let d = [c[0] - center[0], c[1] - center[1], c[2] - center[2]];
    let mut out2 = 0.0;
    for i in 0..3 {
        let u = (d[0] * axes[i][0] + d[1] * axes[i][1] + d[2] * axes[i][2]).abs() - half[i];
        if u > 0.0 {
            out2 += u * u;
        }
    }
    Some(out2)
}

/// A sphere (in the link's frame) containing every one of `shapes` (each within its
/// [`Local::reach`] of its centre); `None` when there are none.
pub(super) fn link_sphere<'a>(shapes: impl Iterator<Item = &'a Local> + Clone) -> Option<Sphere> {
    let (mut lo, mut hi) = (Vector3::repeat(f64::INFINITY), Vector3::repeat(f64::NEG_INFINITY));
    for l in shapes.clone() {
        let (c, r) = (l.centre(), l.reach());
        lo = lo.inf(&(c - Vector3::repeat(r)));
        hi = hi.sup(&(c + Vector3::repeat(r)));
    }
    if !lo.x.is_finite() {
        return None;
    }
    let mid = (lo + hi) / 2.0;
    let radius = shapes
        .map(|l| (l.centre() - mid).norm() + l.reach())
        .fold(0.0, f64::max);
    Some(Sphere { centre: mid, radius })
}
