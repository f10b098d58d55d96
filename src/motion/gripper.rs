//! Calibration of the simulated Robotiq 2F-85 (Menagerie, unmodified): actuator command
//! (0 … 255) ↔ pad-face opening (metres).
//!
//! ## How the table was measured
//! `tests/physics/motion_gripper.rs::calibration_table_matches_the_simulator` (which re-measures and
//! checks this table): in the task scene (arm holding home, nothing between the fingers), starting
//! from open, the command is raised through the table's commands (0, 15, …, 240, 246, 255) and each command is held for
//! 2 s (1000 physics steps of 2 ms); the opening is then read as `World::gripper_width` =
//! distance between the left and right pad centres minus 2 × 0.004 m (the pad boxes'
//! half-thickness). The finger linkage is not linear (the opening shrinks faster as it closes),
//! so the map is piecewise linear between the measured points, monotone decreasing in the command.

/// Command that opens the gripper fully (≈ 85 mm between the pad faces).
pub const OPEN_CTRL: f64 = 0.0;
/// Command that closes the gripper fully (pads ≈ touching).
pub const CLOSED_CTRL: f64 = 255.0;

/// Measured (command, opening in metres), command ascending, opening strictly descending: every
/// 15 units, plus 246 where the pads meet (below ≈ 1.2 mm the fingertips touch and the opening
/// barely changes).
pub const CALIBRATION: [(f64, f64); 19] = [
    (0.0, 0.08513),
    (15.0, 0.08082),
    (30.0, 0.07636),
    (45.0, 0.07175),
    (60.0, 0.06701),
    (75.0, 0.06214),
    (90.0, 0.05716),
    (105.0, 0.05208),
    (120.0, 0.04690),
    (135.0, 0.04164),
    (150.0, 0.03631),
    (165.0, 0.03092),
    (180.0, 0.02547),
    (195.0, 0.01999),
    (210.0, 0.01448),
    (225.0, 0.00895),
    (240.0, 0.00342),
    (246.0, 0.00121),
    (255.0, 0.00083),
];

/// Pad-face opening (metres) the gripper settles at for command `ctrl` (clamped to 0 … 255),
/// piecewise linear in [`CALIBRATION`].
pub fn width_for_ctrl(ctrl: f64) -> f64 {
    let u = ctrl.clamp(OPEN_CTRL, CLOSED_CTRL);
    for w in CALIBRATION.windows(2) {
        let ((c0, w0), (c1, w1)) = (w[0], w[1]);
        if u <= c1 {
            return w0 + (w1 - w0) * (u - c0) / (c1 - c0);
        }
    }
    CALIBRATION[CALIBRATION.len() - 1].1
}

/// Command (0 … 255) that makes the gripper settle at pad-face opening `width_m` (metres),
/// the inverse of [`width_for_ctrl`]. Wider than fully open gives [`OPEN_CTRL`]; narrower than
/// fully closed gives [`CLOSED_CTRL`]. To squeeze an object of width `w`, command a width a few
/// millimetres below `w`: the commanded-minus-actual gap sets the grip force.
pub fn ctrl_for_width(width_m: f64) -> f64 {
    let first = CALIBRATION[0];
    let last = CALIBRATION[CALIBRATION.len() - 1];
    if width_m >= first.1 {
        return OPEN_CTRL;
    }
    if width_m <= last.1 {
        return CLOSED_CTRL;
    }
    for w in CALIBRATION.windows(2) {
        let ((c0, w0), (c1, w1)) = (w[0], w[1]);
        if width_m >= w1 {
            return c0 + (c1 - c0) * (w0 - width_m) / (w0 - w1);
        }
    }
    CLOSED_CTRL
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_strictly_monotone() {
        for w in CALIBRATION.windows(2) {
            assert!(w[1].0 > w[0].0 && w[1].1 < w[0].1, "{w:?}");
        }
        assert_eq!(CALIBRATION[0].0, OPEN_CTRL);
        assert_eq!(CALIBRATION[CALIBRATION.len() - 1].0, CLOSED_CTRL);
    }

    #[test]
    fn maps_are_inverse() {
        for i in 0..=255 {
            let c = i as f64;
            assert!((ctrl_for_width(width_for_ctrl(c)) - c).abs() < 1e-9, "{c}");
        }
        for i in 1..85 {
            let w = i as f64 * 1e-3;
            if w > CALIBRATION[CALIBRATION.len() - 1].1 && w < CALIBRATION[0].1 {
                assert!((width_for_ctrl(ctrl_for_width(w)) - w).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn clamps_outside_the_range() {
        assert_eq!(ctrl_for_width(0.2), OPEN_CTRL);
        assert_eq!(ctrl_for_width(0.0), CLOSED_CTRL);
        assert_eq!(width_for_ctrl(-5.0), CALIBRATION[0].1);
        assert_eq!(width_for_ctrl(300.0), CALIBRATION[CALIBRATION.len() - 1].1);
    }
}
