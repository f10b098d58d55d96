//! Inverse kinematics of the pinch point: closed-form UR solutions (up to 8 branches), joint
//! limits, nearest-to-seed selection, a damped-least-squares polish on the analytic Jacobian and a
//! verified residual — every failure is reported, never silently returned.
//!
//! ## The closed form (Hawkins-style, in the Menagerie frames)
//! Work in the robot base frame (world rotated 180° about z) with the shoulder at height
//! [`SHOULDER_HEIGHT`]. With tool axes `x_t, y_t, z_t` and pinch position `p`:
//! 1. wrist-3 origin `p5 = p − TOOL_LENGTH·z_t` (the pinch lies on the wrist-3 axis);
//! 2. shoulder pan: all of joints 2…6 lie in a plane at [`LATERAL_OFFSET`] along the shoulder-lift
//!    axis `y1(q1) = (−sin q1, cos q1, 0)`, so `p5·y1 = 0.134` → two solutions, none if `p5` is
//!    closer than 0.134 m to the pan axis;
//! 3. wrist 2: `cos q5 = z_t·y1` → ±;
//! 4. wrist 3: `y1` seen in the wrist-3 frame is `(sin q5 cos q6, cos q5, sin q5 sin q6)` → `q6`
//!    (free at the wrist singularity `sin q5 = 0`: the seed's value is kept);
//! 5. the wrist-2 frame follows, hence `q2 + q3 + q4` and the wrist-1 origin; a planar 2-link
//!    problem (0.425 m, 0.392 m) gives the elbow ± and the shoulder lift; `q4` closes the sum.
//!
//! Each branch's angles are then moved by multiples of 2π to the equivalent nearest the seed
//! within [`JOINT_LIMITS`]; the branch nearest the seed (Euclidean in joint space) wins.
//!
//! Cost: ≈ 1.6–2 µs per solve in release builds on the 2-core box (see [`ik_benchmark`]); the reference's DLS IK costs
//! ≈ 3.7 ms (220 iterations of a full `mj_forward`) and reports no failure.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::fmt;

use nalgebra::{Isometry3, Matrix3, Matrix6, Rotation3, Translation3, UnitQuaternion, Vector3, Vector6};

use super::kinematics::{TOOL_LENGTH, chain, jacobian_of, rotation_vector};
use super::ur5e::{
    ARM_JOINTS, FOREARM, JOINT_LIMITS, LATERAL_OFFSET, SHOULDER_HEIGHT, UPPER_ARM, WRIST_1_TO_2, WRIST_2_TO_3,
};

/// Largest accepted position residual of a solution, metres.
pub const POSITION_TOLERANCE: f64 = 1e-6;
/// Largest accepted orientation residual of a solution, radians.
pub const ROTATION_TOLERANCE: f64 = 1e-5;
/// `|sin q5|` below which the wrist counts as singular (wrist 3 then keeps the seed's angle).
const WRIST_SINGULAR: f64 = 1e-7;
/// Damping of the polishing least-squares steps (λ², in m² / rad²).
const POLISH_DAMPING: f64 = 1e-10;
/// Polishing steps at most.
const POLISH_STEPS: usize = 6;

/// Why an IK request has no answer.
#[derive(Debug, Clone, PartialEq)]
pub enum IkError {
    /// No arm configuration reaches the pose at all (too far, or too close to the base axis).
    Unreachable {
        /// Human-readable cause with the numbers, e.g. "wrist centre 0.93 m from the shoulder,
        /// beyond the 0.817 m reach".
        reason: String,
    },
    /// Configurations exist but none respects the joint limits.
    JointLimits {
        /// Human-readable cause naming the joint and angles.
        reason: String,
    },
    /// The best solution's pose residual stays above the tolerance (near-singular targets).
    NoConvergence {
        /// Position residual of the best solution, metres.
        residual_m: f64,
        /// Orientation residual of the best solution, radians.
        residual_rad: f64,
    },
}

impl fmt::Display for IkError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IkError::Unreachable { reason } => write!(f, "IK: pose unreachable: {reason}"),
            IkError::JointLimits { reason } => write!(f, "IK: joint limits: {reason}"),
            IkError::NoConvergence {
                residual_m,
                residual_rad,
            } => write!(
                f,
                "IK: no converged solution (residual {:.3} mm, {:.4} mrad; tolerance {} mm, {} mrad)",
                residual_m * 1e3,
                residual_rad * 1e3,
                POSITION_TOLERANCE * 1e3,
                ROTATION_TOLERANCE * 1e3
            ),
        }
    }
}

impl std::error::Error for IkError {}

/// Wraps `a` into (−π, π].
#[inline]
fn wrap_pi(a: f64) -> f64 {
    let mut x = a.rem_euclid(TAU);
    if x > PI {
        x -= TAU;
    }
    x
}

/// The equivalent of `q` modulo `period` nearest to `seed` inside `[lo, hi]`.
#[inline]
fn nearest_equivalent(q: f64, seed: f64, period: f64, (lo, hi): (f64, f64)) -> Option<f64> {
    let k = ((seed - q) / period).round();
    let mut best: Option<f64> = None;
    for c in [q + k * period, q + (k - 1.0) * period, q + (k + 1.0) * period] {
        if c >= lo && c <= hi && best.is_none_or(|b| (c - seed).abs() < (b - seed).abs()) {
            best = Some(c);
        }
    }
    best
}

/// Rotation vector (world frame) taking `from` onto `to`, radians.
#[inline]
fn rotation_error(to: &Matrix3<f64>, from: &Matrix3<f64>) -> Vector3<f64> {
    rotation_vector(&(to * from.transpose()))
}

/// Outcome of the closed form for one pose.
struct Raw {
    /// Up to 8 branch solutions, angles in (−π, π] (wrist 3 possibly the seed's when singular).
    sols: [[f64; 6]; 8],
    n: usize,
    /// Why branches were lost, for the error message when none is left.
    why: Option<String>,
}

/// All closed-form solutions for pinch position `p_w` and rotation `r_w` (world frame).
fn closed_form(p_w: &Vector3<f64>, r_w: &Matrix3<f64>, seed: &[f64; 6]) -> Raw {
    let mut out = Raw {
        sols: [[0.0; 6]; 8],
        n: 0,
        why: None,
    };
    // World → base frame (180° about z).
    let p = Vector3::new(-p_w.x, -p_w.y, p_w.z);
    let mut r = *r_w;
    for c in 0..3 {
        r[(0, c)] = -r[(0, c)];
        r[(1, c)] = -r[(1, c)];
    }
    let x_t: Vector3<f64> = r.column(0).into();
    let y_t: Vector3<f64> = r.column(1).into();
    let z_t: Vector3<f64> = r.column(2).into();
    // Wrist-3 frame: x_w3 = y_t, y_w3 = z_t, z_w3 = x_t.
    let r_w3 = Matrix3::from_columns(&[y_t, z_t, x_t]);
    let p5 = p - TOOL_LENGTH * z_t;
    let rxy = p5.x.hypot(p5.y);
    if rxy < LATERAL_OFFSET {
        out.why = Some(format!(
            "the wrist centre (pinch − {TOOL_LENGTH:.4} m along the tool axis) is {:.3} m from the \
             shoulder-pan axis, inside the {LATERAL_OFFSET} m shoulder offset (too close to the base)",
            rxy
        ));
        return out;
    }
    let phi = p5.y.atan2(p5.x);
    let alpha = (LATERAL_OFFSET / rxy).asin();
    let a2 = UPPER_ARM;
    let a3 = FOREARM;
    let mut worst_far: Option<f64> = None;
    let mut worst_near: Option<f64> = None;
    for q1 in [phi - alpha, phi - PI + alpha] {
        let (s1, c1) = q1.sin_cos();
        let x1 = Vector3::new(c1, s1, 0.0);
        let y1 = Vector3::new(-s1, c1, 0.0);
        let c5 = z_t.dot(&y1).clamp(-1.0, 1.0);
        let q5a = c5.acos();
        for q5 in [q5a, -q5a] {
            let s5 = q5.sin();
            let q6 = if s5.abs() < WRIST_SINGULAR {
                seed[5]
            } else {
                (x_t.dot(&y1) / s5).atan2(y_t.dot(&y1) / s5)
            };
            // Wrist-2 frame = wrist-3 frame · Ry(−q6) · Rz(−q5).
            let (s6, c6) = q6.sin_cos();
            let (s5, c5) = q5.sin_cos();
            let ry = Matrix3::new(c6, 0.0, -s6, 0.0, 1.0, 0.0, s6, 0.0, c6);
            let rz = Matrix3::new(c5, s5, 0.0, -s5, c5, 0.0, 0.0, 0.0, 1.0);
            let r_w2 = r_w3 * ry * rz;
            let x_w2: Vector3<f64> = r_w2.column(0).into();
            let z_w2: Vector3<f64> = r_w2.column(2).into();
            let q234 = x_w2.z.atan2(-x_w2.dot(&x1));
            let p_w1 = p5 - WRIST_2_TO_3 * z_w2 - WRIST_1_TO_2 * y1;
            let d = p_w1 - Vector3::new(0.0, 0.0, SHOULDER_HEIGHT);
            let x = d.dot(&x1);
            let z = -d.z;
            let dist2 = x * x + z * z;
            let c3 = (dist2 - a2 * a2 - a3 * a3) / (2.0 * a2 * a3);
            if c3 > 1.0 + 1e-12 {
                let dist = dist2.sqrt();
                worst_far = Some(worst_far.map_or(dist, |w: f64| w.min(dist)));
                continue;
            }
            if c3 < -1.0 - 1e-12 {
                let dist = dist2.sqrt();
                worst_near = Some(worst_near.map_or(dist, |w: f64| w.max(dist)));
                continue;
            }
            let q3a = c3.clamp(-1.0, 1.0).acos();
            for q3 in [q3a, -q3a] {
                let (s3, c3) = q3.sin_cos();
                let q2 = z.atan2(x) - (a3 * s3).atan2(a2 + a3 * c3);
                let q4 = q234 - q2 - q3;
                out.sols[out.n] = [
                    wrap_pi(q1),
                    wrap_pi(q2),
                    q3,
                    wrap_pi(q4),
                    wrap_pi(q5),
                    wrap_pi(q6),
                ];
                out.n += 1;
            }
        }
    }
    if out.n == 0 {
        let shoulder = Vector3::new(0.0, 0.0, SHOULDER_HEIGHT);
        let target_dist = (p - shoulder).norm();
        out.why = Some(if let Some(dist) = worst_far {
            format!(
                "target {target_dist:.3} m from the shoulder: with this tool orientation the wrist \
                 centre would be {dist:.3} m from the shoulder in the arm plane, beyond the {:.3} m \
                 reach (upper arm {a2} + forearm {a3})",
                a2 + a3
            )
        } else {
            format!(
                "the wrist centre would be {:.3} m from the shoulder in the arm plane, closer than the \
                 {:.3} m the folded arm can reach",
                worst_near.unwrap_or(0.0),
                a2 - a3
            )
        });
    }
    out
}

/// A solution after limits and polishing, with its residuals.
struct Solved {
    q: [f64; 6],
    res_m: f64,
    res_rad: f64,
}

/// Damped-least-squares steps on the analytic Jacobian towards (`p`, `r`).
fn polish(q: &mut [f64; 6], p: &Vector3<f64>, r: &Matrix3<f64>) -> (f64, f64) {
    let mut res = (f64::INFINITY, f64::INFINITY);
    for step in 0..=POLISH_STEPS {
        let c = chain(q);
        let ep = p - c.pinch_pos;
        let er = rotation_error(r, &c.pinch_rot);
        res = (ep.norm(), er.norm());
        if (res.0 < POSITION_TOLERANCE * 1e-3 && res.1 < ROTATION_TOLERANCE * 1e-3) || step == POLISH_STEPS {
            break;
        }
        let j = jacobian_of(&c);
        let e = Vector6::new(ep.x, ep.y, ep.z, er.x, er.y, er.z);
        let jjt = j * j.transpose() + Matrix6::identity() * POLISH_DAMPING;
        let Some(y) = jjt.cholesky().map(|ch| ch.solve(&e)) else {
            break;
        };
        let dq = j.transpose() * y;
        for i in 0..6 {
            q[i] += dq[i];
        }
    }
    res
}

/// Rotation of the tool about its own z axis by `a` radians (right-multiplied).
#[inline]
fn rot_tool_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// The core solver: target (`p`, `r`), wrist 3 equivalent modulo `q6_period` (2π for a full pose,
/// π or π/2 when the gripper's symmetry makes those yaws equivalent).
fn solve(
    p: &Vector3<f64>,
    r: &Matrix3<f64>,
    seed: &[f64; 6],
    q6_period: f64,
) -> Result<([f64; 6], Matrix3<f64>), IkError> {
    if !(p.iter().chain(r.iter()).chain(seed.iter()).all(|v| v.is_finite())) {
        return Err(IkError::Unreachable {
            reason: format!("non-finite target {:?} or seed {seed:?}", p.as_slice()),
        });
    }
    let raw = closed_form(p, r, seed);
    if raw.n == 0 {
        return Err(IkError::Unreachable {
            reason: raw.why.unwrap_or_else(|| "no closed-form branch".into()),
        });
    }
    // Best candidate inside the limits: (distance², joints, wrist-3 shift).
    let mut best: Option<(f64, [f64; 6], f64)> = None;
    let mut limit_note: Option<String> = None;
    'branches: for sol in &raw.sols[..raw.n] {
        let mut q = [0.0; 6];
        for j in 0..6 {
            let period = if j == 5 { q6_period } else { TAU };
            match nearest_equivalent(sol[j], seed[j], period, JOINT_LIMITS[j]) {
                Some(v) => q[j] = v,
                None => {
                    limit_note.get_or_insert_with(|| {
                        format!(
                            "{} would need {:.4} rad, outside its range [{}, {}]",
                            ARM_JOINTS[j], sol[j], JOINT_LIMITS[j].0, JOINT_LIMITS[j].1
                        )
                    });
                    continue 'branches;
                }
            }
        }
        let d2: f64 = q.iter().zip(seed).map(|(a, b)| (a - b) * (a - b)).sum();
        if best.as_ref().is_none_or(|b| d2 < b.0) {
            best = Some((d2, q, q[5] - sol[5]));
        }
    }
    let Some((_, q, shift)) = best else {
        return Err(IkError::JointLimits {
            reason: limit_note.unwrap_or_else(|| "no branch within the joint limits".into()),
        });
    };
    // The pose actually aimed at: the target turned about its z by the wrist-3 shift (a multiple
    // of q6_period, exactly 0 or ±2πk for a full pose).
    let shift_mod = shift - (shift / TAU).round() * TAU;
    let r_eff = if shift_mod.abs() < 1e-12 {
        *r
    } else {
        r * rot_tool_z(shift)
    };
    let mut sol = Solved {
        q,
        res_m: 0.0,
        res_rad: 0.0,
    };
    (sol.res_m, sol.res_rad) = polish(&mut sol.q, p, &r_eff);
    for (j, v) in sol.q.iter().enumerate() {
        if *v < JOINT_LIMITS[j].0 || *v > JOINT_LIMITS[j].1 {
            return Err(IkError::JointLimits {
                reason: format!(
                    "{} at {:.4} rad after polishing, outside its range [{}, {}]",
                    ARM_JOINTS[j], v, JOINT_LIMITS[j].0, JOINT_LIMITS[j].1
                ),
            });
        }
    }
    if !(sol.res_m <= POSITION_TOLERANCE && sol.res_rad <= ROTATION_TOLERANCE) {
        return Err(IkError::NoConvergence {
            residual_m: sol.res_m,
            residual_rad: sol.res_rad,
        });
    }
    Ok((sol.q, r_eff))
}

/// Full-pose IK of the pinch site: closed-form UR solutions (Hawkins-style, up to 8 branches),
/// keep those within [`JOINT_LIMITS`], return the one nearest `seed` (radians; each joint moved
/// by ±2π to the equivalent nearest the seed within its limits), polished by a few
/// damped-least-squares steps on the analytic Jacobian and verified (residual ≤
/// [`POSITION_TOLERANCE`] = 1e-6 m and ≤ [`ROTATION_TOLERANCE`] = 1e-5 rad), else `Err`.
///
/// `target` is the pinch pose in the world frame (metres). Result in radians.
pub fn ik(target: &Isometry3<f64>, seed: &[f64; 6]) -> Result<[f64; 6], IkError> {
    let p = target.translation.vector;
    let r = *target.rotation.to_rotation_matrix().matrix();
    solve(&p, &r, seed, TAU).map(|(q, _)| q)
}

/// Every admissible IK solution of `target` (the pinch pose in the world frame, metres): each
/// closed-form branch (up to 8) with its joints moved by multiples of 2π to the equivalent nearest
/// `seed` (radians) within [`JOINT_LIMITS`], polished and verified like [`ik`]; nearest to the
/// seed first, duplicates (branches that coincide, e.g. at a singularity) dropped. This is the
/// goal set a planner chooses from, instead of the single branch [`ik`] picks.
///
/// # Errors
/// As [`ik`]: unreachable (no branch), joint limits (no branch within them), or no converged
/// solution — the error of the branch nearest to success.
pub fn ik_all(target: &Isometry3<f64>, seed: &[f64; 6]) -> Result<Vec<[f64; 6]>, IkError> {
    let p = target.translation.vector;
    let r = *target.rotation.to_rotation_matrix().matrix();
    if !(p.iter().chain(r.iter()).chain(seed.iter()).all(|v| v.is_finite())) {
        return Err(IkError::Unreachable {
            reason: format!("non-finite target {:?} or seed {seed:?}", p.as_slice()),
        });
    }
    let raw = closed_form(&p, &r, seed);
    if raw.n == 0 {
        return Err(IkError::Unreachable {
            reason: raw.why.unwrap_or_else(|| "no closed-form branch".into()),
        });
    }
    let mut out: Vec<(f64, [f64; 6])> = Vec::with_capacity(raw.n);
    let mut last_err: Option<IkError> = None;
    'branches: for sol in &raw.sols[..raw.n] {
        let mut q = [0.0; 6];
        for j in 0..6 {
            match nearest_equivalent(sol[j], seed[j], TAU, JOINT_LIMITS[j]) {
                Some(v) => q[j] = v,
                None => {
                    if !matches!(last_err, Some(IkError::NoConvergence { .. })) {
                        last_err = Some(IkError::JointLimits {
                            reason: format!(
                                "{} would need {:.4} rad, outside its range [{}, {}]",
                                ARM_JOINTS[j], sol[j], JOINT_LIMITS[j].0, JOINT_LIMITS[j].1
                            ),
                        });
                    }
                    continue 'branches;
                }
            }
        }
        let (res_m, res_rad) = polish(&mut q, &p, &r);
        if let Some((j, v)) = q
            .iter()
            .enumerate()
            .find(|(j, v)| **v < JOINT_LIMITS[*j].0 || **v > JOINT_LIMITS[*j].1)
        {
            last_err = Some(IkError::JointLimits {
                reason: format!(
                    "{} at {:.4} rad after polishing, outside its range [{}, {}]",
                    ARM_JOINTS[j], v, JOINT_LIMITS[j].0, JOINT_LIMITS[j].1
                ),
            });
            continue;
        }
        if !(res_m <= POSITION_TOLERANCE && res_rad <= ROTATION_TOLERANCE) {
            last_err = Some(IkError::NoConvergence {
                residual_m: res_m,
                residual_rad: res_rad,
            });
            continue;
        }
        if out
            .iter()
            .any(|(_, o)| o.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-9))
        {
            continue;
        }
        let d2: f64 = q.iter().zip(seed).map(|(a, b)| (a - b) * (a - b)).sum();
        out.push((d2, q));
    }
    if out.is_empty() {
        return Err(last_err.unwrap_or_else(|| IkError::JointLimits {
            reason: "no branch within the joint limits".into(),
        }));
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(out.into_iter().map(|(_, q)| q).collect())
}

/// Every closed-form solution of `target` (up to 8, angles in (−π, π], not wrapped to a seed,
/// not filtered by limits), for diagnostics and tests. Empty when unreachable.
pub fn ik_branches(target: &Isometry3<f64>) -> Vec<[f64; 6]> {
    let p = target.translation.vector;
    let r = *target.rotation.to_rotation_matrix().matrix();
    let raw = closed_form(&p, &r, &[0.0; 6]);
    raw.sols[..raw.n].to_vec()
}

/// Rotation matrix of a downward tool yawed by `yaw` radians about world z: pinch z = −world z,
/// pinch x = (−sin yaw, cos yaw, 0) (yaw 0: world +y, as at home).
fn down_rot(yaw: f64) -> Matrix3<f64> {
    let (s, c) = yaw.sin_cos();
    Matrix3::new(-s, c, 0.0, c, s, 0.0, 0.0, 0.0, -1.0)
}

/// The pose [`ik_down`] aims at: pinch at `position` (world, metres), pointing straight down
/// (pinch z = −world z) with its x (finger-opening) axis yawed by `yaw` radians about world z from
/// world +y (yaw 0 = the home orientation).
pub fn down_pose(position: &Vector3<f64>, yaw: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(*position),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(down_rot(yaw))),
    )
}

/// IK for the tool pointing straight down at `position` (world, metres), finger axis yawed by
/// `yaw` radians about world z (see [`down_pose`]).
///
/// The two-finger gripper is symmetric under a half turn, so the yaw is taken modulo π (and
/// modulo π/2 when `symmetric_quarter` is set, e.g. for a cube): the equivalent that puts wrist 3
/// nearest the seed's wrist 3 is chosen, so the wrist never spins more than needed (at most π/2,
/// resp. π/4, for that symmetry; plus whatever the rest of the arm needs). The returned joints
/// realise `down_pose(position, yaw + k·π)` (resp. `k·π/2`) for some integer k.
pub fn ik_down(
    position: &Vector3<f64>,
    yaw: f64,
    symmetric_quarter: bool,
    seed: &[f64; 6],
) -> Result<[f64; 6], IkError> {
    ik_down_with_pose(position, yaw, symmetric_quarter, seed).map(|(q, _)| q)
}

/// [`ik_down`], also returning the pose it actually reached: `down_pose(position, yaw')` with
/// `yaw'` the equivalent of `yaw` (modulo π, or π/2 with `symmetric_quarter`) that was chosen.
/// Use that pose as the target of a [`crate::motion::CartesianMove`] so a straight-line move
/// ends on the same wrist turn.
pub fn ik_down_with_pose(
    position: &Vector3<f64>,
    yaw: f64,
    symmetric_quarter: bool,
    seed: &[f64; 6],
) -> Result<([f64; 6], Isometry3<f64>), IkError> {
    let period = if symmetric_quarter { FRAC_PI_2 } else { PI };
    let (q, r) = solve(position, &down_rot(yaw), seed, period)?;
    let pose = Isometry3::from_parts(
        Translation3::from(*position),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
    );
    Ok((q, pose))
}

/// The task region used by the IK benchmark and the coverage tests: x ∈ [0.25, 0.65] m,
/// y ∈ [−0.35, 0.35] m, z ∈ [0.02, 0.45] m (pinch position, world frame).
pub const TASK_REGION: [(f64, f64); 3] = [(0.25, 0.65), (-0.35, 0.35), (0.02, 0.45)];

/// Mean wall time of one [`ik_down`] solve, microseconds, over `n` random task-region targets
/// (seeded RNG, any yaw, half-turn symmetry, seed = home). Failed solves count too (there are
/// none in the task region). For `macrotree bench`; build with `--release` for meaningful numbers.
pub fn ik_benchmark(n: usize) -> f64 {
    use rand::{Rng, SeedableRng};
    let n = n.max(1);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x005E_ED1C);
    let targets: Vec<(Vector3<f64>, f64)> = (0..n)
        .map(|_| {
            let p = Vector3::new(
                rng.random_range(TASK_REGION[0].0..=TASK_REGION[0].1),
                rng.random_range(TASK_REGION[1].0..=TASK_REGION[1].1),
                rng.random_range(TASK_REGION[2].0..=TASK_REGION[2].1),
            );
            (p, rng.random_range(-PI..PI))
        })
        .collect();
    let home = crate::motion::HOME_Q;
    let t0 = std::time::Instant::now();
    for (p, yaw) in &targets {
        let _ = std::hint::black_box(ik_down(std::hint::black_box(p), *yaw, false, &home));
    }
    t0.elapsed().as_secs_f64() * 1e6 / n as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::HOME_Q;
    use crate::motion::kinematics::fk;

    #[test]
    fn home_round_trip_returns_home() {
        let q = ik(&fk(&HOME_Q), &HOME_Q).unwrap();
        for j in 0..6 {
            assert!((q[j] - HOME_Q[j]).abs() < 1e-9, "{q:?}");
        }
    }

    #[test]
    fn down_pose_at_yaw_zero_is_the_home_orientation() {
        let home = fk(&HOME_Q);
        let d = down_pose(&home.translation.vector, 0.0);
        assert!(home.rotation.angle_to(&d.rotation) < 1e-12);
    }

    #[test]
    fn nearest_equivalent_respects_limits() {
        assert_eq!(nearest_equivalent(3.0, -3.0, TAU, (-TAU, TAU)), Some(3.0 - TAU));
        assert_eq!(nearest_equivalent(PI - 1e-6, 3.0, TAU, JOINT_LIMITS[2]), None);
        // 0.1 + 2π is past the +6.28319 limit: 0.1 itself is the nearest admissible equivalent.
        assert_eq!(nearest_equivalent(0.1, 6.2, TAU, JOINT_LIMITS[0]), Some(0.1));
        assert!((nearest_equivalent(0.1, -6.0, TAU, JOINT_LIMITS[0]).unwrap() - (0.1 - TAU)).abs() < 1e-12);
    }

    #[test]
    fn non_finite_inputs_are_rejected() {
        let mut seed = HOME_Q;
        seed[3] = f64::NAN;
        assert!(matches!(
            ik(&fk(&HOME_Q), &seed),
            Err(IkError::Unreachable { .. })
        ));
        let p = Vector3::new(f64::INFINITY, 0.0, 0.3);
        assert!(matches!(
            ik_down(&p, 0.0, false, &HOME_Q),
            Err(IkError::Unreachable { .. })
        ));
    }

    #[test]
    fn ik_down_with_pose_reports_the_reached_yaw() {
        let p = Vector3::new(0.4, 0.2, 0.1);
        for yaw in [0.3, 1.2, -2.5, 3.0] {
            for quarter in [false, true] {
                let (q, pose) = ik_down_with_pose(&p, yaw, quarter, &HOME_Q).unwrap();
                let reached = fk(&q);
                assert!((reached.translation.vector - p).norm() < 1e-9);
                assert!(reached.rotation.angle_to(&pose.rotation) < 1e-9);
                assert!((pose.rotation * Vector3::z() + Vector3::z()).norm() < 1e-12);
            }
        }
    }

    #[test]
    fn ik_all_gives_every_branch_nearest_first_and_the_single_ik_is_the_first() {
        let target = down_pose(&Vector3::new(0.4, -0.2, 0.15), 0.7);
        let all = ik_all(&target, &HOME_Q).unwrap();
        assert!(all.len() >= 4, "{} branches", all.len());
        for q in &all {
            let reached = fk(q);
            assert!((reached.translation.vector - target.translation.vector).norm() < 1e-6);
            assert!(reached.rotation.angle_to(&target.rotation) < 1e-5);
        }
        let single = ik(&target, &HOME_Q).unwrap();
        for j in 0..6 {
            assert!((all[0][j] - single[j]).abs() < 1e-9, "{:?} vs {single:?}", all[0]);
        }
        assert!(ik_all(&down_pose(&Vector3::new(1.3, 0.0, 0.2), 0.0), &HOME_Q).is_err());
    }

    #[test]
    fn too_far_is_unreachable_with_a_reason() {
        let err = ik_down(&Vector3::new(1.2, 0.0, 0.3), 0.0, false, &HOME_Q).unwrap_err();
        match &err {
            IkError::Unreachable { reason } => assert!(reason.contains("beyond"), "{reason}"),
            e => panic!("{e}"),
        }
        assert!(err.to_string().contains("unreachable"));
    }

    #[test]
    fn inside_the_base_is_unreachable_with_a_reason() {
        let err = ik_down(&Vector3::new(0.02, 0.03, 0.3), 0.0, false, &HOME_Q).unwrap_err();
        match &err {
            IkError::Unreachable { reason } => assert!(reason.contains("too close"), "{reason}"),
            e => panic!("{e}"),
        }
    }
}
