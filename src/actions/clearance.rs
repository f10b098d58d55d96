//! The set-down clearance check that `carry` and `place` share: the held block and the Robotiq
//! 2F-85's fingers, opened to the block's width plus a release gap, as oriented boxes in the
//! table plane (the closing axis at the tool's yaw), tested against the footprints of the
//! objects beside the place and against the walls of the container it goes into.
//!
//! The finger dimensions are measured on the unmodified Menagerie model (`robotiq_2f85/2f85.xml`,
//! its collision geoms at openings 0 … 85 mm; docs/nodes/place.md gives the table). Beyond
//! the pad's face, along the closing axis, the finger reaches 8 mm (the pad) plus up to 8.5 mm
//! (the follower's knuckle behind it) within 40 mm of the fingertip, and up to 33 mm (the
//! follower and coupler) from 40 to 60 mm; across the closing axis the pads are 22 mm wide and
//! the links above them up to 27 mm (39 mm higher up).

use nalgebra::{UnitQuaternion, Vector2, Vector3};

use crate::failure::{Failure, FailureKind};
use crate::scene::{ObjectKind, Shape};
use crate::world::World;

/// Height above the fingertips of the pads' band, metres: within it the finger reaches
/// [`PAD_OUTSIDE`] beyond the pad's face and [`PAD_HALF_WIDTH`] across.
pub const PAD_BAND: f64 = 0.040;
/// How far the finger reaches beyond its pad's face, along the closing axis, within
/// [`PAD_BAND`] of the fingertip, metres (8 mm pad + 8.5 mm follower knuckle).
pub const PAD_OUTSIDE: f64 = 0.0165;
/// Half the finger's width across the closing axis within [`PAD_BAND`] of the fingertip, metres
/// (the pads are 22 mm wide; the follower 15 mm; 12 mm at the band's top).
pub const PAD_HALF_WIDTH: f64 = 0.012;
/// Top of the knuckle band above the fingertips, metres: from [`PAD_BAND`] up to here the finger
/// reaches [`KNUCKLE_OUTSIDE`] beyond the pad's face and [`KNUCKLE_HALF_WIDTH`] across.
pub const KNUCKLE_BAND: f64 = 0.060;
/// How far the finger reaches beyond its pad's face along the closing axis from [`PAD_BAND`] to
/// [`KNUCKLE_BAND`] above the fingertip, metres (follower and coupler, any opening ≥ 39 mm).
pub const KNUCKLE_OUTSIDE: f64 = 0.033;
/// Half the finger's width across the closing axis from [`PAD_BAND`] to [`KNUCKLE_BAND`], metres.
pub const KNUCKLE_HALF_WIDTH: f64 = 0.0135;
/// How far the hand reaches beyond a pad's face along the closing axis higher than
/// [`KNUCKLE_BAND`] above the fingertips (up to 80 mm: couplers and drivers), metres.
pub const LINK_OUTSIDE: f64 = 0.043;
/// Half the hand's width across the closing axis higher than [`KNUCKLE_BAND`] (the spring
/// links), metres.
pub const LINK_HALF_WIDTH: f64 = 0.0195;
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
        let (outside, across) = if h <= PAD_BAND {
            (PAD_OUTSIDE, PAD_HALF_WIDTH)
        } else if h <= KNUCKLE_BAND {
            (KNUCKLE_OUTSIDE, KNUCKLE_HALF_WIDTH)
        } else {
            (LINK_OUTSIDE, LINK_HALF_WIDTH)
        };
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
        let yaw = crate::world::snapshot::yaw_of(&o.quat);
        let r = Rect {
            centre: o.pos.xy(),
            axis: Vector2::new(yaw.cos(), yaw.sin()),
            half: w.spec(j).shape.footprint_half(),
        };
        Some(
            self.envelope(h)
                .iter()
                .map(|e| gap(e, &r))
                .fold(f64::INFINITY, f64::min),
        )
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
        // 54 mm opening: 27 mm to each pad face, 16.5 mm of finger beyond it.
        assert!((fingers.half[0] - 0.0435).abs() < 1e-12);
        assert!((fingers.half[1] - PAD_HALF_WIDTH).abs() < 1e-12);
    }
}
