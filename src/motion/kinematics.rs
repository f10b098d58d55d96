//! Forward kinematics and the geometric Jacobian of the 2F-85 pinch point on the Menagerie UR5e,
//! in closed form (pure nalgebra, no MuJoCo).
//!
//! The arm's chain and dimensions are the UR5e's facts ([`ur5e`](super::ur5e)); the gripper is
//! read off `robotiq_2f85/2f85.xml` (unmodified, attached at `ur5e/attachment_site` through
//! MjSpec):
//!
//! | body | position in parent (m) | rotation in parent | joint axis |
//! |---|---|---|---|
//! | gripper `base_mount` | (0, 0, 0.007) | — | — |
//! | gripper `base` | (0, 0, 0.0038) | −90° about z (quat 1 0 0 −1) | — |
//! | site `pinch` | (0, 0, 0.145) | — | — |
//!
//! So the pinch lies on the wrist-3 axis, [`TOOL_LENGTH`] = 0.1 + 0.007 + 0.0038 + 0.145 =
//! 0.2558 m from the wrist-3 origin, and its z axis *is* the wrist-3 axis: the arm is a standard
//! UR geometry (see [`mod@crate::motion::ik`]).

use nalgebra::{Isometry3, Matrix3, Matrix6, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::ur5e::{FOREARM, SHOULDER_HEIGHT, UPPER_ARM, WRIST_1_TO_2, WRIST_2_TO_3};

/// Wrist-3 origin to the pinch site along the wrist-3 axis (attachment 0.1 + base_mount 0.007
/// + base 0.0038 + pinch 0.145), metres.
pub const TOOL_LENGTH: f64 = 0.1 + 0.007 + 0.0038 + 0.145;

#[inline]
fn rot_y(q: f64) -> Matrix3<f64> {
    let (s, c) = q.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

#[inline]
fn rot_z(q: f64) -> Matrix3<f64> {
    let (s, c) = q.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// +90° about y (the Menagerie `quat="1 0 1 0"`), exact.
#[inline]
fn rot_y90() -> Matrix3<f64> {
    Matrix3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0)
}

/// Orientation of the pinch frame in the wrist-3 frame (−90° about x, then −90° about z):
/// pinch x = wrist-3 z, pinch y = wrist-3 x, pinch z = wrist-3 y.
#[inline]
pub(crate) fn tool_rot_in_wrist3() -> Matrix3<f64> {
    Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0)
}

/// World-frame origins, axes and the final frame of the chain.
pub(crate) struct Chain {
    /// Joint origins (world), metres.
    pub origins: [Vector3<f64>; 6],
    /// Joint axes (world, unit).
    pub axes: [Vector3<f64>; 6],
    /// The upper arm's far end on its own axis, before the elbow's lateral offset (world),
    /// metres.
    pub upper_arm_end: Vector3<f64>,
    /// Pinch position (world), metres.
    pub pinch_pos: Vector3<f64>,
    /// Pinch rotation (world).
    pub pinch_rot: Matrix3<f64>,
}

/// Runs the chain once and keeps every joint's world origin and axis.
pub(crate) fn chain(q: &[f64; 6]) -> Chain {
    let ey = Vector3::y();
    let ez = Vector3::z();
    // base: 180° about z.
    let mut r = Matrix3::new(-1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0);
    let mut p = Vector3::zeros();
    let mut origins = [Vector3::zeros(); 6];
    let mut axes = [Vector3::zeros(); 6];
    // shoulder_link
    p += r * Vector3::new(0.0, 0.0, SHOULDER_HEIGHT);
    origins[0] = p;
    axes[0] = r * ez;
    r *= rot_z(q[0]);
    // upper_arm_link
    p += r * Vector3::new(0.0, 0.138, 0.0);
    r *= rot_y90();
    origins[1] = p;
    axes[1] = r * ey;
    r *= rot_y(q[1]);
    let upper_arm_end = p + r * Vector3::new(0.0, 0.0, UPPER_ARM);
    // forearm_link
    p += r * Vector3::new(0.0, -0.131, UPPER_ARM);
    origins[2] = p;
    axes[2] = r * ey;
    r *= rot_y(q[2]);
    // wrist_1_link
    p += r * Vector3::new(0.0, 0.0, FOREARM);
    r *= rot_y90();
    origins[3] = p;
    axes[3] = r * ey;
    r *= rot_y(q[3]);
    // wrist_2_link
    p += r * Vector3::new(0.0, WRIST_1_TO_2, 0.0);
    origins[4] = p;
    axes[4] = r * ez;
    r *= rot_z(q[4]);
    // wrist_3_link
    p += r * Vector3::new(0.0, 0.0, WRIST_2_TO_3);
    origins[5] = p;
    axes[5] = r * ey;
    r *= rot_y(q[5]);
    // attachment_site + base_mount + base + pinch: all along wrist-3 y.
    let pinch_pos = p + r * Vector3::new(0.0, TOOL_LENGTH, 0.0);
    let pinch_rot = r * tool_rot_in_wrist3();
    Chain {
        origins,
        axes,
        upper_arm_end,
        pinch_pos,
        pinch_rot,
    }
}

/// Pinch position (world, metres) and rotation (world) for arm joints `q` (radians).
pub fn fk_parts(q: &[f64; 6]) -> (Vector3<f64>, Matrix3<f64>) {
    let c = chain(q);
    (c.pinch_pos, c.pinch_rot)
}

/// FK of the pinch site in the world frame for arm joints `q` (radians, shoulder pan … wrist 3).
/// Exact for the Menagerie chain (analytic, no MuJoCo); translation in metres. Matches MuJoCo's
/// `site_xpos` / `site_xmat` of `gripper/pinch` to ~1e-15 m (see `tests/physics/motion_fk.rs`).
pub fn fk(q: &[f64; 6]) -> Isometry3<f64> {
    let (p, r) = fk_parts(q);
    Isometry3::from_parts(
        Translation3::from(p),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
    )
}

/// 6×6 geometric Jacobian of the pinch site at joints `q` (radians), world frame, rows
/// `[linear (m/rad); angular (rad/rad)]`, columns shoulder pan … wrist 3 — the same quantity as
/// MuJoCo's `mj_jacSite` restricted to the arm's dofs.
pub fn jacobian(q: &[f64; 6]) -> Matrix6<f64> {
    jacobian_of(&chain(q))
}

pub(crate) fn jacobian_of(c: &Chain) -> Matrix6<f64> {
    let mut j = Matrix6::zeros();
    for i in 0..6 {
        let lin = c.axes[i].cross(&(c.pinch_pos - c.origins[i]));
        j.fixed_view_mut::<3, 1>(0, i).copy_from(&lin);
        j.fixed_view_mut::<3, 1>(3, i).copy_from(&c.axes[i]);
    }
    j
}

/// Rotation vector (axis × angle, radians) of the rotation matrix `r`, accurate for tiny angles
/// (from the antisymmetric part, no `acos` of the trace) and well defined near π.
pub fn rotation_vector(r: &Matrix3<f64>) -> Vector3<f64> {
    let v = Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) * 0.5;
    let s = v.norm();
    let c = ((r[(0, 0)] + r[(1, 1)] + r[(2, 2)]) - 1.0) * 0.5;
    if s < 1e-300 && c > 0.0 {
        return Vector3::zeros();
    }
    if c > -0.9 {
        return v * (s.atan2(c) / s);
    }
    // Near π: k·kᵀ = (sym(R) − c·I) / (1 − c); its largest-diagonal column is the axis, sign from v.
    let b = (r + r.transpose()) * 0.5 - Matrix3::identity() * c;
    let k = (0..3)
        .max_by(|&a, &b2| b[(a, a)].total_cmp(&b[(b2, b2)]))
        .unwrap_or(0);
    let mut axis: Vector3<f64> = b.column(k).into();
    axis.normalize_mut();
    if axis.dot(&v) < 0.0 {
        axis = -axis;
    }
    axis * s.atan2(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    const HOME: [f64; 6] = [-FRAC_PI_2, -FRAC_PI_2, FRAC_PI_2, -FRAC_PI_2, -FRAC_PI_2, 0.0];

    #[test]
    fn home_pose_points_down_with_x_along_world_y() {
        let (p, r) = fk_parts(&HOME);
        assert!((p - Vector3::new(-0.134, 0.492, 0.3322)).norm() < 1e-12, "{p}");
        assert!((r.column(2) - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-12);
        assert!((r.column(0) - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let q = [0.3, -1.1, 1.4, -0.7, -1.2, 0.5];
        let j = jacobian(&q);
        let (p0, r0) = fk_parts(&q);
        let h = 1e-7;
        for i in 0..6 {
            let mut qh = q;
            qh[i] += h;
            let (p1, r1) = fk_parts(&qh);
            let dp = (p1 - p0) / h;
            let dr = rotation_vector(&(r1 * r0.transpose())) / h;
            for k in 0..3 {
                assert!((dp[k] - j[(k, i)]).abs() < 1e-6, "lin {i} {k}");
                assert!((dr[k] - j[(k + 3, i)]).abs() < 1e-6, "ang {i} {k}");
            }
        }
    }

    #[test]
    fn rotation_vector_is_accurate_small_and_near_pi() {
        for angle in [
            0.0,
            1e-12,
            1e-7,
            0.3,
            2.0,
            3.0,
            3.1,
            std::f64::consts::PI - 1e-9,
            std::f64::consts::PI,
        ] {
            let axis = Vector3::new(0.3, -0.5, 0.8).normalize();
            let r = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle);
            let v = rotation_vector(r.matrix());
            let back = Rotation3::from_scaled_axis(v);
            assert!((back.matrix() - r.matrix()).norm() < 1e-9, "{angle}: {v}");
            assert!((v.norm() - angle).abs() < 1e-9, "{angle}: {v}");
        }
    }

    #[test]
    fn fk_isometry_agrees_with_parts() {
        let q = [1.0, -0.5, 2.0, 0.1, 0.2, -3.0];
        let iso = fk(&q);
        let (p, r) = fk_parts(&q);
        assert!((iso.translation.vector - p).norm() < 1e-15);
        assert!((iso.rotation.to_rotation_matrix().matrix() - r).norm() < 1e-12);
    }
}
