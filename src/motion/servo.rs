//! Feed-forward for the Menagerie UR5e position servos, so a sampled trajectory is actually
//! followed.
//!
//! Each arm actuator is `force = kp·(ctrl − q) − kv·q̇` with kp/kv = 2000/400 (shoulder, elbow)
//! and 500/100 (wrists). Commanding the bare trajectory `ctrl = q_d(t)` therefore (a) lags by
//! kv/kp = 0.2 s × joint speed — 0.6 rad at 3 rad/s, tens of centimetres at the pinch — and (b)
//! sags under gravity by τ_g/kp (≈ 11 mm at the pinch at home). With
//! `ctrl = q_d + (kv/kp)·q̇_d + τ_g(q_d)/kp` ([`servo_command`]) the servo becomes a PD tracker
//! around the trajectory with gravity compensated: `force = kp·(q_d − q) + kv·(q̇_d − q̇) + τ_g`.
//! `tests/motion_tracking.rs` measures both in the simulator.

use nalgebra::Vector3;

use super::kinematics::{Chain, JOINT_LIMITS, chain};

/// Position gain of each arm servo (Menagerie `gainprm`), N·m/rad.
pub const SERVO_KP: [f64; 6] = [2000.0, 2000.0, 2000.0, 500.0, 500.0, 500.0];
/// Velocity damping of each arm servo (Menagerie `biasprm[2]`, negated), N·m·s/rad.
pub const SERVO_KV: [f64; 6] = [400.0, 400.0, 400.0, 100.0, 100.0, 100.0];
/// Largest servo force of each arm actuator (Menagerie `forcerange`), N·m.
pub const SERVO_FORCE_LIMIT: [f64; 6] = [150.0, 150.0, 150.0, 28.0, 28.0, 28.0];
/// Standard gravity used by the scene, m/s².
pub const GRAVITY: f64 = 9.81;

/// Mass (kg) and centre of mass (body frame, metres) of each moving link, from the compiled
/// scene (`tests/motion_servo.rs` checks them against MuJoCo). The last entry lumps wrist 3 with
/// the whole 2F-85 (fingers open; closing moves its centre of mass by < 1 mm).
const LINKS: [(usize, f64, [f64; 3]); 5] = [
    (1, 8.393, [0.0, 0.0, 0.2125]),
    (2, 2.275, [0.0, 0.0, 0.196]),
    (3, 1.219, [0.0, 0.127, 0.0]),
    (4, 1.219, [0.0, 0.0, 0.1]),
    (5, 1.241_508_339, [-0.000_060_499, 0.136_098_314, -0.000_010_314]),
];

/// Joint torques (N·m) that hold the arm still at `q` (radians) against gravity, with an extra
/// point mass of `payload_kg` (kg, e.g. a grasped cube) at the pinch — MuJoCo's `qfrc_bias` at
/// rest for the arm's dofs.
pub fn gravity_torque(q: &[f64; 6], payload_kg: f64) -> [f64; 6] {
    gravity_torque_of(&chain(q), payload_kg)
}

fn gravity_torque_of(c: &Chain, payload_kg: f64) -> [f64; 6] {
    let weight = |m: f64| Vector3::new(0.0, 0.0, -m * GRAVITY);
    let mut tau = [0.0; 6];
    let mut add = |body: usize, com: Vector3<f64>, m: f64| {
        // Force −m·g·ez at `com` acts on every joint upstream of (and including) `body`.
        for (j, t) in tau.iter_mut().enumerate().take(body + 1) {
            *t -= c.axes[j].cross(&(com - c.origins[j])).dot(&weight(m));
        }
    };
    for (body, m, ipos) in LINKS {
        let com = c.origins[body] + c.frames[body] * Vector3::from(ipos);
        add(body, com, m);
    }
    if payload_kg != 0.0 {
        add(5, c.pinch_pos, payload_kg);
    }
    tau
}

/// The actuator commands (radians) that make the position servos follow a trajectory sample
/// (`q` radians, `qd` rad/s): `q + (kv/kp)·qd + τ_g(q)/kp` per joint, gravity including a
/// `payload_kg` point mass at the pinch, clamped to the servos' command range ([`JOINT_LIMITS`]).
/// For holding a pose pass `qd = 0`.
pub fn servo_command(q: &[f64; 6], qd: &[f64; 6], payload_kg: f64) -> [f64; 6] {
    let g = gravity_torque(q, payload_kg);
    std::array::from_fn(|j| {
        let u = q[j] + SERVO_KV[j] / SERVO_KP[j] * qd[j] + g[j] / SERVO_KP[j];
        u.clamp(JOINT_LIMITS[j].0, JOINT_LIMITS[j].1)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::HOME_Q;
    use crate::motion::kinematics::jacobian;

    #[test]
    fn gravity_torque_matches_virtual_work_of_a_payload() {
        let q = [0.2, -1.0, 1.2, -1.5, -1.4, 0.3];
        let a = gravity_torque(&q, 0.0);
        let b = gravity_torque(&q, 0.5);
        let j = jacobian(&q);
        for i in 0..6 {
            // Holding torque for a weight at the pinch = Jᵀ·(m·g·ez).
            let expect = j[(2, i)] * 0.5 * GRAVITY;
            assert!((b[i] - a[i] - expect).abs() < 1e-9, "joint {i}");
        }
        assert!(a[0].abs() < 1e-12, "pan axis is vertical");
    }

    #[test]
    fn servo_command_at_rest_is_position_plus_sag_correction() {
        let u = servo_command(&HOME_Q, &[0.0; 6], 0.0);
        let g = gravity_torque(&HOME_Q, 0.0);
        for j in 0..6 {
            assert!((u[j] - HOME_Q[j] - g[j] / SERVO_KP[j]).abs() < 1e-15);
        }
        let v = servo_command(&HOME_Q, &[1.0; 6], 0.0);
        assert!((v[0] - u[0] - 0.2).abs() < 1e-12);
    }
}
