//! Where the cube and the bowl start.

use std::f64::consts::PI;

/// A task layout: cube centre and yaw on the table, bowl centre on the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// Cube centre x, y on the table, metres.
    pub cube_xy: [f64; 2],
    /// Cube yaw about world z, radians.
    pub cube_yaw: f64,
    /// Bowl centre x, y on the table, metres.
    pub bowl_xy: [f64; 2],
}

impl Default for Layout {
    /// The reference tutorial's default: cube at (0.45, −0.18), bowl target at (0.45, 0.08).
    fn default() -> Self {
        Self {
            cube_xy: [0.45, -0.18],
            cube_yaw: 0.0,
            bowl_xy: [0.45, 0.08],
        }
    }
}

impl Layout {
    /// A layout from cube (x, y, yaw in degrees) and bowl (x, y).
    pub fn new(cube_x: f64, cube_y: f64, cube_yaw_deg: f64, bowl_x: f64, bowl_y: f64) -> Self {
        Self {
            cube_xy: [cube_x, cube_y],
            cube_yaw: cube_yaw_deg * PI / 180.0,
            bowl_xy: [bowl_x, bowl_y],
        }
    }

    /// The reference tutorial's five layouts: its default and its four `workspace_layouts`.
    pub fn reference_layouts() -> [Layout; 5] {
        [
            Layout::default(),
            Layout::new(0.44, -0.21, 0.0, 0.48, 0.10),
            Layout::new(0.51, -0.18, 0.0, 0.39, 0.04),
            Layout::new(0.45, -0.20, 0.0, 0.38, 0.02),
            Layout::new(0.52, -0.18, 0.0, 0.45, 0.02),
        ]
    }

    /// Distance between cube and bowl centres on the table, metres.
    pub fn separation(&self) -> f64 {
        (self.cube_xy[0] - self.bowl_xy[0]).hypot(self.cube_xy[1] - self.bowl_xy[1])
    }
}
