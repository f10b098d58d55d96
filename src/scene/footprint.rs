//! Oriented footprints: an object's outline on the table as a rectangle turned by its yaw, and
//! the exact questions placement asks of two of them (the gap between them, whether one lies
//! inside the other). Metres and radians.

/// A rectangle in the table plane: centre, half extents along its own axes, and yaw.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Rect {
    /// Centre x, y, metres.
    pub centre: [f64; 2],
    /// Half extents along the rectangle's own x and y, metres.
    pub half: [f64; 2],
    /// Yaw of the rectangle's x axis about world z, radians.
    pub yaw: f64,
}

impl Rect {
    /// The rectangle's unit axes in the world frame.
    fn axes(&self) -> [[f64; 2]; 2] {
        let (s, c) = self.yaw.sin_cos();
        [[c, s], [-s, c]]
    }

    /// The four corners, counter-clockwise, world frame, metres.
    pub fn corners(&self) -> [[f64; 2]; 4] {
        let [ax, ay] = self.axes();
        let [hx, hy] = self.half;
        let [cx, cy] = self.centre;
        let at = |sx: f64, sy: f64| {
            [
                cx + sx * hx * ax[0] + sy * hy * ay[0],
                cy + sx * hx * ax[1] + sy * hy * ay[1],
            ]
        };
        [at(1.0, 1.0), at(-1.0, 1.0), at(-1.0, -1.0), at(1.0, -1.0)]
    }

    /// `p` in the rectangle's own frame (relative to its centre, turned by its yaw), metres.
    pub fn local(&self, p: [f64; 2]) -> [f64; 2] {
        let d = [p[0] - self.centre[0], p[1] - self.centre[1]];
        let [ax, ay] = self.axes();
        [d[0] * ax[0] + d[1] * ax[1], d[0] * ay[0] + d[1] * ay[1]]
    }

    /// Distance from `p` to the rectangle (0 inside it), metres.
    pub fn distance_to_point(&self, p: [f64; 2]) -> f64 {
        let [u, v] = self.local(p);
        let dx = (u.abs() - self.half[0]).max(0.0);
        let dy = (v.abs() - self.half[1]).max(0.0);
        dx.hypot(dy)
    }

    /// Half the extent of the rectangle along the world-frame unit direction `n`, metres.
    fn extent_along(&self, n: [f64; 2]) -> f64 {
        let [ax, ay] = self.axes();
        self.half[0] * (ax[0] * n[0] + ax[1] * n[1]).abs()
            + self.half[1] * (ay[0] * n[0] + ay[1] * n[1]).abs()
    }

    /// The two rectangles' interiors overlap (separating-axis test on the four edge normals;
    /// touching edges do not overlap).
    pub fn overlaps(&self, other: &Rect) -> bool {
        let d = [other.centre[0] - self.centre[0], other.centre[1] - self.centre[1]];
        self.axes().iter().chain(other.axes().iter()).all(|n| {
            let centre_gap = (d[0] * n[0] + d[1] * n[1]).abs();
            centre_gap < self.extent_along(*n) + other.extent_along(*n)
        })
    }

    /// The smallest distance between the two rectangles, metres: 0 when they touch or
    /// overlap. (Between two convex polygons that do not overlap it is reached between a corner
    /// of one and an edge of the other.)
    pub fn gap(&self, other: &Rect) -> f64 {
        if self.overlaps(other) {
            return 0.0;
        }
        let a = self.corners().map(|p| other.distance_to_point(p));
        let b = other.corners().map(|p| self.distance_to_point(p));
        a.into_iter().chain(b).fold(f64::INFINITY, f64::min)
    }

    /// How far `inner` lies inside this rectangle: the smallest distance from a corner of
    /// `inner` to this rectangle's edges, metres; negative when a corner sticks out (by that
    /// much, along this rectangle's axes).
    pub fn margin_inside(&self, inner: &Rect) -> f64 {
        inner
            .corners()
            .iter()
            .map(|&p| {
                let [u, v] = self.local(p);
                (self.half[0] - u.abs()).min(self.half[1] - v.abs())
            })
            .fold(f64::INFINITY, f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_4;

    fn rect(x: f64, y: f64, hx: f64, hy: f64, yaw: f64) -> Rect {
        Rect {
            centre: [x, y],
            half: [hx, hy],
            yaw,
        }
    }

    #[test]
    fn axis_aligned_gaps_are_the_distance_between_edges() {
        let a = rect(0.0, 0.0, 0.1, 0.1, 0.0);
        assert!((a.gap(&rect(0.25, 0.0, 0.05, 0.05, 0.0)) - 0.1).abs() < 1e-12);
        // Diagonal: corner to corner.
        let g = a.gap(&rect(0.3, 0.3, 0.1, 0.1, 0.0));
        assert!((g - (0.1f64).hypot(0.1)).abs() < 1e-12, "{g}");
        assert_eq!(a.gap(&rect(0.15, 0.0, 0.1, 0.1, 0.0)), 0.0);
        assert!(a.overlaps(&rect(0.15, 0.0, 0.1, 0.1, 0.0)));
        assert!(
            !a.overlaps(&rect(0.2, 0.0, 0.1, 0.1, 0.0)),
            "touching is not overlapping"
        );
    }

    #[test]
    fn a_thin_wall_is_a_rectangle_not_a_disc() {
        // A 0.30 × 0.02 m wall along y; a 0.04 m block 0.05 m beside it: 0.04 m gap, though the
        // block's centre is inside the wall's 0.15 m circle.
        let wall = rect(0.5, 0.0, 0.01, 0.15, 0.0);
        let block = rect(0.57, 0.0, 0.02, 0.02, 0.0);
        assert!((wall.gap(&block) - 0.04).abs() < 1e-12);
        // Turned 90°, the wall runs along x through the block.
        let turned = rect(0.5, 0.0, 0.01, 0.15, std::f64::consts::FRAC_PI_2);
        assert!(turned.overlaps(&block));
    }

    #[test]
    fn a_turned_square_pokes_out_by_its_corner() {
        let bin = rect(0.0, 0.0, 0.1, 0.1, 0.0);
        let inside = rect(0.0, 0.0, 0.05, 0.05, FRAC_PI_4);
        let m = bin.margin_inside(&inside);
        assert!((m - (0.1 - 0.05 * 2f64.sqrt())).abs() < 1e-12, "{m}");
        let out = rect(0.08, 0.0, 0.05, 0.05, 0.0);
        assert!((bin.margin_inside(&out) + 0.03).abs() < 1e-12);
    }

    #[test]
    fn gaps_are_symmetric_for_turned_rectangles() {
        for k in 0..50 {
            let t = k as f64 * 0.37;
            let a = rect(0.0, 0.0, 0.15, 0.01, t);
            let b = rect(0.2 * t.cos(), 0.2 * t.sin() + 0.05, 0.03, 0.02, -t);
            assert!((a.gap(&b) - b.gap(&a)).abs() < 1e-12);
            assert_eq!(a.overlaps(&b), b.overlaps(&a));
        }
    }
}
