//! Yaw angles about world z: of an object's orientation, of the tool, and folded for a square
//! seen from above.

use nalgebra::{UnitQuaternion, Vector3};

/// Rotation about world z of a quaternion (the yaw of its x axis), radians in (-π, π].
pub fn yaw_of(q: &UnitQuaternion<f64>) -> f64 {
    let x = q * Vector3::x();
    x.y.atan2(x.x)
}

/// Yaw of the tool about world z, in the convention of `motion::ik_down` (0 at home, where the
/// pinch x axis points along world +y), radians in (-π, π].
pub fn tool_yaw(pinch_rot: &nalgebra::Matrix3<f64>) -> f64 {
    let x = pinch_rot.column(0);
    (-x[0]).atan2(x[1])
}

/// Folds an angle into [-π/4, π/4): the yaw of a square seen from above.
pub fn fold_quarter_turn(a: f64) -> f64 {
    let q = std::f64::consts::FRAC_PI_2;
    (a + q / 2.0).rem_euclid(q) - q / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_turn_folding_stays_in_range() {
        for i in -100..100 {
            let a = i as f64 * 0.07;
            let f = fold_quarter_turn(a);
            assert!(
                (-std::f64::consts::FRAC_PI_4..std::f64::consts::FRAC_PI_4).contains(&f),
                "{a} -> {f}"
            );
            let k = ((a - f) / std::f64::consts::FRAC_PI_2).round();
            assert!((a - f - k * std::f64::consts::FRAC_PI_2).abs() < 1e-9);
        }
    }
}
