//! Joint-space trajectories with minimum-jerk time scaling: joint moves, straight-line Cartesian
//! moves of the pinch, and holds. All are sampled by time (seconds from their start) and hold
//! their end after [`Trajectory::duration`].
//!
//! Minimum-jerk scaling `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵`, `τ = t / T`, has zero velocity and
//! acceleration at both ends, peak speed `1.875 / T` and peak acceleration `(10/√3) / T²`
//! (times the distance); the durations below are the smallest `T` keeping every limit.

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::ik::{IkError, ik};
use super::kinematics::{fk_parts, rotation_vector};

/// Peak of `s'(τ)` for minimum jerk.
const MJ_PEAK_VEL: f64 = 1.875;
/// Peak of `|s''(τ)|` for minimum jerk (10/√3).
const MJ_PEAK_ACC: f64 = 5.773_502_691_896_258;

/// Minimum-jerk position, velocity and acceleration of the unit move at normalised time `tau`
/// (clamped to [0, 1]); derivatives with respect to `tau`.
pub fn min_jerk(tau: f64) -> (f64, f64, f64) {
    let t = tau.clamp(0.0, 1.0);
    let t2 = t * t;
    let t3 = t2 * t;
    (
        t3 * (10.0 - 15.0 * t + 6.0 * t2),
        30.0 * t2 * (1.0 - 2.0 * t + t2),
        60.0 * t * (1.0 - 3.0 * t + 2.0 * t2),
    )
}

/// Speed, acceleration and duration limits shared by every motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionLimits {
    /// Largest joint speed, rad/s. Default 3.0 rad/s: just under the UR5e's rated π rad/s (180°/s)
    /// for every joint, so the position servos can track it.
    pub max_joint_speed: f64,
    /// Largest joint acceleration, rad/s². Default 15 rad/s²: well inside what the Menagerie servos
    /// (kp 2000 / 500, force ±150 / ±28 N·m) follow without large tracking lag.
    pub max_joint_acc: f64,
    /// Largest linear speed of the pinch along a Cartesian line, m/s. Default 0.5 m/s: a brisk
    /// pick-and-place speed at which the cube stays in the unmodified 2F-85's grasp.
    pub tool_speed: f64,
    /// Shortest duration of any move, seconds. Default 0.2 s: keeps tiny corrections smooth
    /// instead of demanding an instantaneous jump.
    pub min_duration: f64,
}

impl Default for MotionLimits {
    /// 3.0 rad/s, 15 rad/s², 0.5 m/s, 0.2 s (see the field docs).
    fn default() -> Self {
        Self {
            max_joint_speed: 3.0,
            max_joint_acc: 15.0,
            tool_speed: 0.5,
            min_duration: 0.2,
        }
    }
}

/// Half the interval over which [`Trajectory::acceleration`] differentiates velocities by
/// default, seconds: half a physics step.
pub const ACC_DIFF_STEP: f64 = 1e-3;

/// A smooth motion in joint space that can be sampled at any time `t ≥ 0` (seconds since its
/// start); after [`duration`](Trajectory::duration) it holds [`end`](Trajectory::end).
pub trait Trajectory: Send {
    /// Joint positions (radians) and velocities (rad/s) at time `t` seconds; `t < 0` counts as 0.
    fn sample(&self, t: f64) -> ([f64; 6], [f64; 6]);
    /// Duration of the motion, seconds.
    fn duration(&self) -> f64;
    /// Joint accelerations at time `t` seconds, rad/s² (the servos' inertial feedforward). The
    /// default differentiates [`sample`](Self::sample)'s velocities over ±[`ACC_DIFF_STEP`]
    /// (one-sided at the ends, where the motion is at rest before and after); zero after the end.
    fn acceleration(&self, t: f64) -> [f64; 6] {
        let d = self.duration();
        if t.is_nan() || t >= d || d <= 0.0 {
            return [0.0; 6];
        }
        let (a, b) = ((t - ACC_DIFF_STEP).max(0.0), (t + ACC_DIFF_STEP).min(d));
        if b <= a {
            return [0.0; 6];
        }
        let (_, va) = self.sample(a);
        let (_, vb) = self.sample(b);
        std::array::from_fn(|j| (vb[j] - va[j]) / (b - a))
    }
    /// Final joint positions, radians (exactly what `sample(t)` returns for `t ≥ duration()`).
    fn end(&self) -> [f64; 6];
    /// What kind of motion this is, for logs ("joint move", "straight line", …).
    fn name(&self) -> &'static str {
        "motion"
    }
}

/// Joint-space move with minimum-jerk time scaling: every joint follows `from + (to − from)·s(t/T)`.
#[derive(Debug, Clone, PartialEq)]
pub struct JointMove {
    from: [f64; 6],
    to: [f64; 6],
    duration: f64,
}

impl JointMove {
    /// A move from `from` to `to` (radians). Its duration is the shortest that keeps every joint
    /// within `limits.max_joint_speed` (rad/s) and `limits.max_joint_acc` (rad/s²), and at least
    /// `limits.min_duration` seconds — except a move of zero length, which takes no time.
    pub fn new(from: [f64; 6], to: [f64; 6], limits: &MotionLimits) -> Self {
        let span = (0..6).map(|j| (to[j] - from[j]).abs()).fold(0.0, f64::max);
        let duration = if span == 0.0 {
            0.0 // nothing to move: done at once
        } else {
            (MJ_PEAK_VEL * span / limits.max_joint_speed)
                .max((MJ_PEAK_ACC * span / limits.max_joint_acc).sqrt())
                .max(limits.min_duration)
        };
        Self { from, to, duration }
    }

    /// Start joints, radians.
    pub fn start(&self) -> [f64; 6] {
        self.from
    }
}

impl Trajectory for JointMove {
    fn name(&self) -> &'static str {
        "joint move"
    }

    fn sample(&self, t: f64) -> ([f64; 6], [f64; 6]) {
        if t >= self.duration {
            return (self.to, [0.0; 6]);
        }
        let (s, sd, _) = min_jerk(t / self.duration);
        let mut q = [0.0; 6];
        let mut qd = [0.0; 6];
        for j in 0..6 {
            let d = self.to[j] - self.from[j];
            q[j] = self.from[j] + d * s;
            qd[j] = d * sd / self.duration;
        }
        (q, qd)
    }

    fn duration(&self) -> f64 {
        self.duration
    }

    fn acceleration(&self, t: f64) -> [f64; 6] {
        if t.is_nan() || t >= self.duration {
            return [0.0; 6];
        }
        let (_, _, sdd) = min_jerk(t.max(0.0) / self.duration);
        let k = sdd / (self.duration * self.duration);
        std::array::from_fn(|j| (self.to[j] - self.from[j]) * k)
    }

    fn end(&self) -> [f64; 6] {
        self.to
    }
}

/// Holds one joint configuration for a given time (zero velocity).
#[derive(Debug, Clone, PartialEq)]
pub struct Hold {
    q: [f64; 6],
    duration: f64,
}

impl Hold {
    /// Hold `q` (radians) for `duration` seconds.
    pub fn new(q: [f64; 6], duration: f64) -> Self {
        Self {
            q,
            duration: duration.max(0.0),
        }
    }
}

impl Trajectory for Hold {
    fn name(&self) -> &'static str {
        "hold"
    }

    fn sample(&self, _t: f64) -> ([f64; 6], [f64; 6]) {
        (self.q, [0.0; 6])
    }
    fn duration(&self) -> f64 {
        self.duration
    }
    fn end(&self) -> [f64; 6] {
        self.q
    }
}

/// Path knot spacing along the line, metres.
const KNOT_STEP_M: f64 = 0.002;
/// Path knot spacing in rotation, radians.
const KNOT_STEP_RAD: f64 = 0.01;
/// Largest joint change between neighbouring knots before the path counts as a branch flip
/// (or a crossing so close to a singularity that the servos could not follow), radians.
pub const MAX_KNOT_JUMP: f64 = 0.25;
/// Safety factor on the numerically found joint-limited duration.
const DURATION_MARGIN: f64 = 1.01;

/// Straight-line Cartesian move of the pinch: position interpolated linearly, orientation by
/// slerp (geodesic), both with minimum-jerk time scaling.
///
/// Joint targets are solved by [`ik`] at construction on a fine path grid (every 2 mm and every
/// 0.01 rad of rotation), each seeded from the previous solution, and interpolated between knots
/// by a C¹ cubic Hermite spline in the path parameter (deviation from the line ≪ 0.1 mm). The
/// duration is the shortest keeping the pinch within `tool_speed` and every joint within
/// `max_joint_speed` / `max_joint_acc` (checked on a fine time grid), at least `min_duration`.
#[derive(Debug, Clone, PartialEq)]
pub struct CartesianMove {
    /// Joint knots at path parameter `k / (n − 1)`.
    knots: Vec<[f64; 6]>,
    /// dq/ds at each knot (per unit path parameter).
    tangents: Vec<[f64; 6]>,
    duration: f64,
    start_pose: Isometry3<f64>,
    end_pose: Isometry3<f64>,
}

/// Pose on the line at path parameter `s` ∈ [0, 1].
fn interpolate_pose(
    p0: &Vector3<f64>,
    r0: &Matrix3<f64>,
    dp: &Vector3<f64>,
    w: &Vector3<f64>,
    s: f64,
) -> Isometry3<f64> {
    let r = r0 * Rotation3::from_scaled_axis(w * s).matrix();
    Isometry3::from_parts(
        Translation3::from(p0 + dp * s),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
    )
}

impl CartesianMove {
    /// A straight-line move of the pinch from its pose at `from_q` (radians) to `to` (world frame,
    /// metres). `Err` if a waypoint has no IK solution ([`IkError`] of that waypoint, its reason
    /// prefixed with the waypoint) or if staying on the line needs a joint jump larger than
    /// [`MAX_KNOT_JUMP`] between neighbouring waypoints (a branch flip or a singularity crossing:
    /// `IkError::Unreachable` saying which joint).
    pub fn new(from_q: [f64; 6], to: Isometry3<f64>, limits: &MotionLimits) -> Result<Self, IkError> {
        let (p0, r0) = fk_parts(&from_q);
        let r1 = *to.rotation.to_rotation_matrix().matrix();
        let dp = to.translation.vector - p0;
        // Rotation vector in the start (body) frame: R(s) = R0 · exp(s·w).
        let w = rotation_vector(&(r0.transpose() * r1));
        let length = dp.norm();
        let angle = w.norm();
        let segments = ((length / KNOT_STEP_M).max(angle / KNOT_STEP_RAD).ceil() as usize).max(2);
        let mut knots = Vec::with_capacity(segments + 1);
        knots.push(from_q);
        for k in 1..=segments {
            let s = k as f64 / segments as f64;
            let pose = if k == segments {
                to
            } else {
                interpolate_pose(&p0, &r0, &dp, &w, s)
            };
            let prev = knots[k - 1];
            let q = ik(&pose, &prev).map_err(|e| match e {
                IkError::Unreachable { reason } => IkError::Unreachable {
                    reason: format!(
                        "waypoint {k}/{segments} of the line at {:.3?}: {reason}",
                        pose.translation.vector.as_slice()
                    ),
                },
                IkError::JointLimits { reason } => IkError::JointLimits {
                    reason: format!("waypoint {k}/{segments} of the line: {reason}"),
                },
                e => e,
            })?;
            for j in 0..6 {
                let jump = (q[j] - prev[j]).abs();
                if jump > MAX_KNOT_JUMP {
                    return Err(IkError::Unreachable {
                        reason: format!(
                            "staying on the line needs joint {} to jump {jump:.2} rad between waypoints \
                             {}/{segments} and {k}/{segments} at {:.3?} (branch flip or wrist \
                             singularity on the path); use a joint move",
                            j + 1,
                            k - 1,
                            pose.translation.vector.as_slice()
                        ),
                    });
                }
            }
            knots.push(q);
        }
        let n = knots.len();
        let h = 1.0 / (n - 1) as f64;
        let tangents: Vec<[f64; 6]> = (0..n)
            .map(|k| {
                let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
                let span = (b - a) as f64 * h;
                let mut m = [0.0; 6];
                for j in 0..6 {
                    m[j] = (knots[b][j] - knots[a][j]) / span;
                }
                m
            })
            .collect();
        let mut mv = Self {
            knots,
            tangents,
            duration: 1.0,
            start_pose: interpolate_pose(&p0, &r0, &dp, &w, 0.0),
            end_pose: to,
        };
        // Joint speed / acceleration of the unit-duration move, scanned on a fine time grid.
        let samples = (8 * n).max(400);
        let (mut vmax, mut amax) = (0.0f64, 0.0f64);
        for i in 0..=samples {
            let tau = i as f64 / samples as f64;
            let (s, sd, sdd) = min_jerk(tau);
            let (_, d1, d2) = mv.spline(s);
            for j in 0..6 {
                vmax = vmax.max((d1[j] * sd).abs());
                amax = amax.max((d2[j] * sd * sd + d1[j] * sdd).abs());
            }
        }
        mv.duration = if length < 1e-9 && vmax < 1e-6 {
            0.0 // nothing to move: done at once
        } else {
            (MJ_PEAK_VEL * length / limits.tool_speed)
                .max(DURATION_MARGIN * vmax / limits.max_joint_speed)
                .max(DURATION_MARGIN * (amax / limits.max_joint_acc).sqrt())
                .max(limits.min_duration)
        };
        Ok(mv)
    }

    /// Joints, dq/ds and d²q/ds² of the path at parameter `s` ∈ [0, 1].
    fn spline(&self, s: f64) -> ([f64; 6], [f64; 6], [f64; 6]) {
        let segs = self.knots.len() - 1;
        let x = s.clamp(0.0, 1.0) * segs as f64;
        let i = (x.floor() as usize).min(segs - 1);
        let u = x - i as f64;
        let h = 1.0 / segs as f64;
        let (u2, u3) = (u * u, u * u * u);
        let (h00, h10, h01, h11) = (
            2.0 * u3 - 3.0 * u2 + 1.0,
            u3 - 2.0 * u2 + u,
            -2.0 * u3 + 3.0 * u2,
            u3 - u2,
        );
        let (d00, d10, d01, d11) = (
            6.0 * u2 - 6.0 * u,
            3.0 * u2 - 4.0 * u + 1.0,
            -6.0 * u2 + 6.0 * u,
            3.0 * u2 - 2.0 * u,
        );
        let (e00, e10, e01, e11) = (12.0 * u - 6.0, 6.0 * u - 4.0, -12.0 * u + 6.0, 6.0 * u - 2.0);
        let (p0, p1, m0, m1) = (
            &self.knots[i],
            &self.knots[i + 1],
            &self.tangents[i],
            &self.tangents[i + 1],
        );
        let mut q = [0.0; 6];
        let mut dq = [0.0; 6];
        let mut ddq = [0.0; 6];
        for j in 0..6 {
            let (a, b, c, d) = (p0[j], h * m0[j], p1[j], h * m1[j]);
            q[j] = h00 * a + h10 * b + h01 * c + h11 * d;
            dq[j] = (d00 * a + d10 * b + d01 * c + d11 * d) / h;
            ddq[j] = (e00 * a + e10 * b + e01 * c + e11 * d) / (h * h);
        }
        (q, dq, ddq)
    }

    /// Pinch pose at the start (FK of `from_q`), world frame.
    pub fn start_pose(&self) -> Isometry3<f64> {
        self.start_pose
    }

    /// Pinch pose at the end (the requested target), world frame.
    pub fn end_pose(&self) -> Isometry3<f64> {
        self.end_pose
    }

    /// Pinch pose on the straight line at time `t` seconds (what the joints of `sample(t)`
    /// approximate to well under 0.1 mm).
    pub fn pose_at(&self, t: f64) -> Isometry3<f64> {
        let (s, _, _) = min_jerk(t.max(0.0) / self.duration);
        let p0 = self.start_pose.translation.vector;
        let dp = self.end_pose.translation.vector - p0;
        let r0 = self.start_pose.rotation.to_rotation_matrix();
        let w = rotation_vector((r0.inverse() * self.end_pose.rotation.to_rotation_matrix()).matrix());
        interpolate_pose(&p0, r0.matrix(), &dp, &w, s)
    }

    /// The IK waypoints (joint knots, radians), evenly spaced along the path.
    pub fn knots(&self) -> &[[f64; 6]] {
        &self.knots
    }
}

impl Trajectory for CartesianMove {
    fn name(&self) -> &'static str {
        "straight line"
    }

    fn sample(&self, t: f64) -> ([f64; 6], [f64; 6]) {
        if t >= self.duration {
            return (self.end(), [0.0; 6]);
        }
        let (s, sd, _) = min_jerk(t / self.duration);
        let (q, dq, _) = self.spline(s);
        let mut qd = [0.0; 6];
        for j in 0..6 {
            qd[j] = dq[j] * sd / self.duration;
        }
        (q, qd)
    }

    fn duration(&self) -> f64 {
        self.duration
    }

    fn end(&self) -> [f64; 6] {
        self.knots[self.knots.len() - 1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::HOME_Q;
    use crate::motion::ik::down_pose;
    use crate::motion::kinematics::fk;

    #[test]
    fn min_jerk_endpoints_and_peaks() {
        assert_eq!(min_jerk(0.0), (0.0, 0.0, 0.0));
        let (s, sd, sdd) = min_jerk(1.0);
        assert!((s - 1.0).abs() < 1e-15 && sd.abs() < 1e-12 && sdd.abs() < 1e-12);
        assert!((min_jerk(0.5).1 - MJ_PEAK_VEL).abs() < 1e-12);
        let tau = 0.5 - 3f64.sqrt() / 6.0;
        assert!((min_jerk(tau).2 - MJ_PEAK_ACC).abs() < 1e-9);
    }

    #[test]
    fn hold_holds() {
        let h = Hold::new(HOME_Q, 0.5);
        assert_eq!(h.sample(0.3), (HOME_Q, [0.0; 6]));
        assert_eq!(h.end(), HOME_Q);
        assert_eq!(h.duration(), 0.5);
    }

    #[test]
    fn zero_length_cartesian_move_takes_no_time() {
        let lim = MotionLimits::default();
        let m = CartesianMove::new(HOME_Q, fk(&HOME_Q), &lim).unwrap();
        assert_eq!(m.duration(), 0.0);
        let (q, _) = m.sample(0.1);
        for j in 0..6 {
            assert!((q[j] - HOME_Q[j]).abs() < 1e-9);
        }
    }

    #[test]
    fn cartesian_down_move_ends_on_target() {
        let lim = MotionLimits::default();
        let to = down_pose(&Vector3::new(0.45, -0.18, 0.1), 0.0);
        let m = CartesianMove::new(HOME_Q, to, &lim).unwrap();
        let end = fk(&m.sample(m.duration() + 1.0).0);
        assert!((end.translation.vector - to.translation.vector).norm() < 1e-6);
        assert!(end.rotation.angle_to(&to.rotation) < 1e-5);
    }
}
