//! The set-down clearance check that `carry` and `place` share: the held block and the Robotiq
//! 2F-85's fingers, opened to the block's width plus a release gap, as oriented boxes in the
//! table plane (the closing axis at the tool's yaw), tested against the footprints of the
//! objects beside the place and against the walls of the container it goes into.
//!
//! The finger dimensions are measured on the unmodified Menagerie model (`robotiq_2f85/2f85.xml`)
//! as MuJoCo collides it: a mesh geom collides as its convex hull, and the follower's hull
//! reaches well beyond the curved finger itself (docs/nodes/place.md gives the table). How far
//! the finger reaches beyond the pad's face along the closing axis grows with the height above
//! the fingertips — 8 mm (the pad) at the tip, 18 mm at 20 mm, 28 mm at 40 mm, 31–38 mm at
//! 60 mm — and, above 50 mm, with the fingers closing (the couplers and drivers stay where they
//! are while the pads move in); across the closing axis the finger is 11 mm each side up to
//! 35 mm, 17 mm at 60 mm, and the hand wider above.

use nalgebra::{UnitQuaternion, Vector2, Vector3};

use crate::failure::{Failure, FailureKind};
use crate::scene::{ObjectKind, Shape};
use crate::world::World;

/// Heights above the fingertips at which the finger envelope is tabulated, metres.
const HEIGHTS: [f64; 19] = [
    0.0, 0.005, 0.010, 0.015, 0.020, 0.025, 0.030, 0.035, 0.040, 0.045, 0.050, 0.055, 0.060, 0.070, 0.080,
    0.090, 0.100, 0.110, 0.120,
];
/// Pad-face distances (openings) at which the envelope is tabulated, metres.
const OPENINGS: [f64; 6] = [0.0265, 0.032, 0.0428, 0.0533, 0.0668, 0.0852];
/// How far the finger (the convex hulls of its collision geoms) reaches beyond its pad's face
/// along the closing axis, anywhere from the fingertip up to `HEIGHTS[i]`, at opening
/// `OPENINGS[j]`, millimetres (measured on the Menagerie model, gravity off, fingers at rest).
const OUTSIDE_MM: [[f64; 6]; 19] = [
    [8.0, 8.0, 8.0, 8.0, 8.0, 8.0],
    [8.1, 8.1, 8.1, 8.1, 8.0, 8.0],
    [13.5, 13.5, 13.4, 13.4, 13.3, 13.2],
    [15.9, 15.9, 15.8, 15.7, 15.7, 15.5],
    [18.3, 18.3, 18.2, 18.1, 18.0, 17.8],
    [20.8, 20.7, 20.6, 20.5, 20.3, 20.1],
    [23.2, 23.2, 23.0, 22.9, 22.7, 22.4],
    [25.7, 25.6, 25.4, 25.3, 25.0, 24.7],
    [28.1, 28.0, 27.8, 27.6, 27.4, 27.0],
    [30.5, 30.4, 30.2, 30.0, 29.7, 29.3],
    [33.0, 32.8, 32.4, 32.2, 31.8, 31.4],
    [35.2, 34.8, 33.9, 33.1, 32.2, 31.5],
    [37.5, 36.7, 35.3, 34.1, 32.5, 31.5],
    [42.0, 40.7, 38.2, 36.0, 33.2, 31.5],
    [46.5, 44.6, 41.1, 37.9, 33.8, 31.5],
    [51.0, 48.5, 44.0, 39.7, 34.4, 31.5],
    [52.3, 50.2, 45.7, 41.1, 34.9, 31.5],
    [52.3, 50.2, 45.7, 41.1, 34.9, 31.5],
    [52.3, 50.2, 45.7, 41.1, 34.9, 31.5],
];
/// Half the hand's width across the closing axis, anywhere from the fingertip up to
/// `HEIGHTS[i]`, at any opening, millimetres (the pads are 22 mm wide; the base mount above
/// 90 mm).
const ACROSS_MM: [f64; 19] = [
    11.0, 11.0, 11.0, 11.0, 11.0, 11.0, 11.0, 11.0, 12.5, 14.1, 15.2, 16.3, 17.2, 18.4, 19.6, 24.3, 29.0,
    33.7, 37.5,
];

/// Where `x` falls in the increasing `xs`: the index of the segment and the fraction along it
/// (clamped to the ends).
fn locate(xs: &[f64], x: f64) -> (usize, f64) {
    let last = xs.len() - 1;
    if x <= xs[0] {
        return (0, 0.0);
    }
    if x >= xs[last] {
        return (last - 1, 1.0);
    }
    let i = xs.windows(2).position(|w| x <= w[1]).unwrap_or(last - 1);
    (i, (x - xs[i]) / (xs[i + 1] - xs[i]))
}

/// How far a finger opened to `opening` (pad faces apart, metres) reaches beyond its pad's face
/// along the closing axis, from the fingertip up to `h` metres above it, metres: interpolated in
/// the measured table (an opening below 26.5 mm reads as 26.5 mm, a height above 120 mm as
/// 120 mm).
pub fn finger_outside(h: f64, opening: f64) -> f64 {
    let (i, a) = locate(&HEIGHTS, h);
    let (j, b) = locate(&OPENINGS, opening);
    let at = |i: usize| OUTSIDE_MM[i][j] + (OUTSIDE_MM[i][j + 1] - OUTSIDE_MM[i][j]) * b;
    (at(i) + (at(i + 1) - at(i)) * a) * 1e-3
}

/// Half the hand's width across the closing axis from the fingertip up to `h` metres above it,
/// metres (interpolated in the measured table).
pub fn finger_half_width(h: f64) -> f64 {
    let (i, a) = locate(&HEIGHTS, h);
    (ACROSS_MM[i] + (ACROSS_MM[i + 1] - ACROSS_MM[i]) * a) * 1e-3
}
/// Half the height of a pad (two 18.75 mm silicone boxes stacked), metres: the fingertips are
/// this far below the pads' centre.
pub const PAD_HALF_HEIGHT: f64 = 0.01875;
/// Gap each pad opens to beyond the held block's face to let it go, metres: the fingers are
/// checked opened to the block's width plus twice this.
pub const RELEASE_GAP: f64 = 0.005;
/// Least gap kept between the envelope and anything beside it (or a container's inner wall),
/// metres.
pub const MARGIN: f64 = 0.003;

/// The pad faces' distance when the fingers open to let a block of half-edge `half` go, metres:
/// its width plus [`RELEASE_GAP`] a side.
pub fn release_opening(half: f64) -> f64 {
    2.0 * (half + RELEASE_GAP)
}

/// A set-down as the clearance check sees it: where the held block's centre ends up, which way
/// the fingers close, and how wide they open to let go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SetDown {
    /// The held block's centre at the end of the set-down, world frame, metres.
    pub centre: Vector3<f64>,
    /// Unit vector along the fingers' closing axis, world table plane.
    pub closing: Vector2<f64>,
    /// Half the held block's edge, metres.
    pub half: f64,
    /// Height of the fingertips above the block's centre (negative: below it), metres.
    pub tip: f64,
    /// Distance between the pad faces the fingers open to, metres (normally
    /// [`release_opening`]).
    pub opening: f64,
}

/// The fingers' closing axis in the pinch frame, from the pad centres of a snapshot (unit; the
/// pinch frame's y axis for the 2F-85 mounted as the cell has it).
pub fn closing_axis_in_pinch(w: &World) -> Vector3<f64> {
    let d = w.pinch_rot.transpose() * (w.right_pad_pos - w.left_pad_pos);
    if d.norm() < 1e-9 {
        Vector3::y()
    } else {
        d.normalize()
    }
}

/// Height of the fingertips above the centre of the block they hold, from a snapshot, metres
/// (the pads' centres less [`PAD_HALF_HEIGHT`], the tool pointing down).
pub fn tip_above_block(w: &World, block: usize) -> f64 {
    w.left_pad_pos.z.min(w.right_pad_pos.z) - PAD_HALF_HEIGHT - w.objects[block].pos.z
}

/// The closing axis in the world table plane for the tool orientation `rotation`, given the
/// axis in the pinch frame ([`closing_axis_in_pinch`]); unit.
pub fn closing_in_world(rotation: &UnitQuaternion<f64>, in_pinch: &Vector3<f64>) -> Vector2<f64> {
    let d = (rotation * in_pinch).xy();
    if d.norm() < 1e-9 {
        Vector2::x()
    } else {
        d.normalize()
    }
}

/// An oriented rectangle in the table plane: centre, unit x axis, half extents, metres.
#[derive(Clone, Copy, Debug)]
struct Rect {
    centre: Vector2<f64>,
    axis: Vector2<f64>,
    half: [f64; 2],
}

impl Rect {
    fn axes(&self) -> [Vector2<f64>; 2] {
        [self.axis, Vector2::new(-self.axis.y, self.axis.x)]
    }
    fn radius_along(&self, n: &Vector2<f64>) -> f64 {
        let [a, b] = self.axes();
        self.half[0] * a.dot(n).abs() + self.half[1] * b.dot(n).abs()
    }
    fn corners(&self) -> [Vector2<f64>; 4] {
        let [a, b] = self.axes();
        let (u, v) = (a * self.half[0], b * self.half[1]);
        [
            self.centre + u + v,
            self.centre + u - v,
            self.centre - u + v,
            self.centre - u - v,
        ]
    }
}

/// Separation of two oriented rectangles along the best of their four axes (separating-axis
/// test), metres: positive when apart (exact for parallel sides, a lower bound otherwise),
/// negative when they overlap.
fn gap(a: &Rect, b: &Rect) -> f64 {
    let d = b.centre - a.centre;
    a.axes()
        .into_iter()
        .chain(b.axes())
        .map(|n| d.dot(&n).abs() - a.radius_along(&n) - b.radius_along(&n))
        .fold(f64::NEG_INFINITY, f64::max)
}

impl SetDown {
    /// The fingertips' height, or the block's bottom if lower, metres.
    fn bottom(&self) -> f64 {
        self.centre.z + self.tip.max(-self.half)
    }

    /// The rectangles the block and the opened fingers cover for something whose top stands
    /// `h` metres above the fingertips: the block's footprint (its faces square to the closing
    /// axis) and the fingers' band at that height.
    fn envelope(&self, h: f64) -> [Rect; 2] {
        let (outside, across) = (finger_outside(h, self.opening), finger_half_width(h));
        let centre = self.centre.xy();
        [
            Rect {
                centre,
                axis: self.closing,
                half: [self.half, self.half],
            },
            Rect {
                centre,
                axis: self.closing,
                half: [self.opening / 2.0 + outside, across],
            },
        ]
    }

    /// The smallest gap between the envelope and object `j`'s footprint, metres (negative:
    /// they overlap), or `None` when `j` does not reach above the fingertips.
    fn gap_to(&self, w: &World, j: usize) -> Option<f64> {
        let h = w.top(j) - self.bottom();
        if h <= 0.0 {
            return None;
        }
        let o = &w.objects[j];
        let yaw = crate::world::angles::yaw_of(&o.quat);
        let r = Rect {
            centre: o.pos.xy(),
            axis: Vector2::new(yaw.cos(), yaw.sin()),
            half: w.spec(j).shape.footprint_half(),
        };
        Some(self.gap_to_rect(&r, h))
    }

    /// The smallest gap between the envelope and a footprint `r` whose top stands `h` metres
    /// above the fingertips, metres.
    fn gap_to_rect(&self, r: &Rect, h: f64) -> f64 {
        self.envelope(h)
            .iter()
            .map(|e| gap(e, r))
            .fold(f64::INFINITY, f64::min)
    }

    /// The smallest gap between the envelope and a block that is not in the world yet: a cube of
    /// half-edge `half` standing at `centre` (table plane) with a side along the unit `axis`, its
    /// top at `top` (all metres); `None` when its top is below the fingertips. The packing
    /// look-ahead sees the blocks it plans to set down so.
    pub fn gap_to_cube(&self, centre: Vector2<f64>, axis: Vector2<f64>, half: f64, top: f64) -> Option<f64> {
        let h = top - self.bottom();
        (h > 0.0).then(|| {
            self.gap_to_rect(
                &Rect {
                    centre,
                    axis,
                    half: [half, half],
                },
                h,
            )
        })
    }

    /// How far the envelope stays inside container `c`'s inner walls, metres (negative: it
    /// crosses a wall), or `None` for an object that is not a container or a rim below the
    /// fingertips.
    pub fn wall_gap(&self, w: &World, c: usize) -> Option<f64> {
        let Shape::Container { inner_half, .. } = w.spec(c).shape else {
            return None;
        };
        let h = w.top(c) - self.bottom();
        if h <= 0.0 {
            return None;
        }
        let mut least = f64::INFINITY;
        for e in self.envelope(h) {
            for p in e.corners() {
                let d = w.local_xy(c, &Vector3::new(p.x, p.y, 0.0));
                least = least
                    .min(inner_half[0] - d.x.abs())
                    .min(inner_half[1] - d.y.abs());
            }
        }
        Some(least)
    }

    /// The first thing the envelope would hit, with the gap (negative or under [`MARGIN`]),
    /// metres: any object but the held block and the destination `dest`, or `dest`'s own walls
    /// when it is a container.
    pub fn obstruction(&self, w: &World, held: usize, dest: Option<usize>) -> Option<(usize, f64, bool)> {
        if let Some(c) = dest
            && let Some(g) = self.wall_gap(w, c)
            && g < MARGIN
        {
            return Some((c, g, true));
        }
        (0..w.objects.len())
            .filter(|&j| j != held && Some(j) != dest)
            .filter_map(|j| self.gap_to(w, j).map(|g| (j, g, false)))
            .find(|&(_, g, _)| g < MARGIN)
    }

    /// The smallest gap between the envelope and the blocks `others`, metres (∞ when none
    /// reaches above the fingertips): how roomy a candidate spot is.
    pub fn room(&self, w: &World, others: &[usize]) -> f64 {
        others
            .iter()
            .filter_map(|&j| self.gap_to(w, j))
            .fold(f64::INFINITY, f64::min)
    }

    /// Checks that the block and the fingers, opened to [`opening`](Self::opening) along the
    /// closing axis, can come down here: a failure of kind `blocked` naming what they would hit.
    pub fn check(&self, w: &World, held: usize, dest: Option<usize>) -> Result<(), Failure> {
        let Some((j, g, wall)) = self.obstruction(w, held, dest) else {
            return Ok(());
        };
        let what = if wall {
            format!("the walls of {}", w.name(j))
        } else {
            w.name(j).to_string()
        };
        Err(Failure::new(
            FailureKind::Blocked,
            format!(
                "no clear way down to ({:.3}, {:.3}): the fingers (opened to {:.0} mm along their closing axis at {:.0}°) would hit {what} ({:.0} mm clearance, {:.0} mm needed; its top at {:.3} m)",
                self.centre.x,
                self.centre.y,
                self.opening * 1e3,
                self.closing.y.atan2(self.closing.x).to_degrees(),
                g * 1e3,
                MARGIN * 1e3,
                w.top(j)
            ),
        ))
    }
}

/// Blocks (other than `held`) resting inside container `c`.
pub fn blocks_inside(w: &World, c: usize, held: usize) -> Vec<usize> {
    (0..w.objects.len())
        .filter(|&j| j != held && w.spec(j).kind() == ObjectKind::Block && w.inside(j, c))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(x: f64, y: f64, yaw: f64, hx: f64, hy: f64) -> Rect {
        Rect {
            centre: Vector2::new(x, y),
            axis: Vector2::new(yaw.cos(), yaw.sin()),
            half: [hx, hy],
        }
    }

    #[test]
    fn parallel_rectangles_gap_exactly() {
        let a = rect(0.0, 0.0, 0.0, 0.05, 0.01);
        let b = rect(0.1, 0.0, 0.0, 0.02, 0.02);
        assert!((gap(&a, &b) - 0.03).abs() < 1e-12);
        let c = rect(0.0, 0.05, 0.0, 0.02, 0.02);
        assert!((gap(&a, &c) - 0.02).abs() < 1e-12);
        assert!(gap(&a, &rect(0.06, 0.0, 0.0, 0.02, 0.02)) < 0.0);
    }

    #[test]
    fn a_turned_rectangle_is_tested_on_its_own_axes() {
        // A square turned 45° whose corner points at the other: the corner is 0.02·√2 out.
        let a = rect(0.0, 0.0, 0.0, 0.02, 0.02);
        let b = rect(0.06, 0.0, std::f64::consts::FRAC_PI_4, 0.02, 0.02);
        let g = gap(&a, &b);
        assert!(
            (g - (0.06 - 0.02 - 0.02 * std::f64::consts::SQRT_2)).abs() < 1e-12,
            "{g}"
        );
    }

    #[test]
    fn the_envelope_is_wider_along_the_closing_axis() {
        let s = SetDown {
            centre: Vector3::new(0.5, 0.0, 0.022),
            closing: Vector2::x(),
            half: 0.022,
            tip: -0.019,
            opening: release_opening(0.022),
        };
        let [block, fingers] = s.envelope(0.04);
        assert_eq!(block.half, [0.022, 0.022]);
        // 54 mm opening: 27 mm to each pad face, 27.6 mm of finger (hull) beyond it at 40 mm.
        let outside = finger_outside(0.04, 0.054);
        assert!((outside - 0.0276).abs() < 2e-4, "{outside}");
        assert!((fingers.half[0] - (0.027 + outside)).abs() < 1e-12);
        assert!((fingers.half[1] - 0.0125).abs() < 1e-12);
    }

    /// Regression: the bands were measured on the finger's mesh, not on the convex hull MuJoCo
    /// collides, so 35 mm above the fingertips the follower reached 25 mm beyond the pad's face
    /// where the check allowed 16.5 mm, and a release in the bin put it on the wall's top edge
    /// (`clear_table` scenario 267 of seed 1).
    #[test]
    fn follower_hull_reached_past_the_pad_band() {
        assert!(finger_outside(0.035, 0.053) >= 0.0253);
        assert!(finger_outside(0.0, 0.053) >= 0.008);
        // Monotone in height, and wider beyond the pad as the fingers close, high up.
        let mut last = 0.0;
        for k in 0..=130 {
            let h = k as f64 * 1e-3;
            let o = finger_outside(h, 0.046);
            assert!(o >= last - 1e-12, "{h}: {o} < {last}");
            last = o;
        }
        assert!(finger_outside(0.08, 0.03) > finger_outside(0.08, 0.08));
        assert!((finger_outside(0.5, 0.01) - 0.0523).abs() < 1e-12);
        assert!((finger_half_width(0.02) - 0.011).abs() < 1e-12);
    }
}
