//! Goal sets: every joint configuration that counts as arriving, so the planner chooses the IK
//! branch (and the equivalent grasp yaw) instead of taking the first.

use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use crate::motion::ik::{IkError, ik_all};

/// The configurations a motion may end in (radians), and, when there are none, why.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct GoalSet {
    /// Candidate end configurations, in the caller's order of preference (the planner tries a
    /// direct motion to each in this order first).
    pub configs: Vec<[f64; 6]>,
    /// Why IK gave no configuration for a pose (its reason), when [`configs`](Self::configs) is
    /// empty because of IK.
    pub ik_failure: Option<String>,
}

impl GoalSet {
    /// Exactly these configurations (radians).
    pub fn configs(configs: Vec<[f64; 6]>) -> Self {
        Self {
            configs,
            ik_failure: None,
        }
    }

    /// Every IK branch of the pinch pose `target` (world frame, metres), each joint on the
    /// equivalent nearest `seed` (radians), nearest first ([`ik_all`]). When IK has no answer the
    /// set is empty and [`ik_failure`](Self::ik_failure) says why.
    pub fn pose(target: &Isometry3<f64>, seed: &[f64; 6]) -> Self {
        Self::poses(std::slice::from_ref(target), seed)
    }

    /// Every IK branch of each of `targets` (poses that are equally good, e.g. the grasp yaws a
    /// block's symmetry makes equivalent), all sorted nearest to `seed` first, duplicates dropped.
    pub fn poses(targets: &[Isometry3<f64>], seed: &[f64; 6]) -> Self {
        let mut found: Vec<(f64, [f64; 6])> = Vec::new();
        let mut reasons: Vec<String> = Vec::new();
        for t in targets {
            match ik_all(t, seed) {
                Ok(qs) => {
                    for q in qs {
                        if found
                            .iter()
                            .any(|(_, o)| o.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-9))
                        {
                            continue;
                        }
                        let d2: f64 = q.iter().zip(seed).map(|(a, b)| (a - b) * (a - b)).sum();
                        found.push((d2, q));
                    }
                }
                Err(e) => {
                    let text = match e {
                        IkError::Unreachable { reason } => format!("no IK solution: {reason}"),
                        IkError::JointLimits { reason } => format!("outside the joint limits: {reason}"),
                        e => e.to_string(),
                    };
                    if !reasons.contains(&text) {
                        reasons.push(text);
                    }
                }
            }
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0));
        let ik_failure = (found.is_empty()).then(|| {
            if reasons.is_empty() {
                "no target pose given".to_string()
            } else {
                reasons.join("; ")
            }
        });
        Self {
            configs: found.into_iter().map(|(_, q)| q).collect(),
            ik_failure,
        }
    }

    /// The tool pointing down at `position` (world, metres) with its finger axis at `yaw`
    /// (radians, as [`crate::motion::down_pose`]) and every yaw the gripper's symmetry makes
    /// equivalent: `yaw + kπ`, or `yaw + kπ/2` with `quarter` (a square block); every IK branch
    /// of each ([`GoalSet::poses`]).
    pub fn down(position: &Vector3<f64>, yaw: f64, quarter: bool, seed: &[f64; 6]) -> Self {
        let (step, n) = if quarter {
            (std::f64::consts::FRAC_PI_2, 4)
        } else {
            (std::f64::consts::PI, 2)
        };
        let poses: Vec<Isometry3<f64>> = (0..n)
            .map(|k| {
                let base = crate::motion::ik::down_pose(position, yaw);
                let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), k as f64 * step);
                Isometry3::from_parts(base.translation, base.rotation * turn)
            })
            .collect();
        Self::poses(&poses, seed)
    }

    /// Number of candidate configurations.
    pub fn len(&self) -> usize {
        self.configs.len()
    }

    /// True when there is no candidate.
    pub fn is_empty(&self) -> bool {
        self.configs.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::{HOME_Q, fk};

    #[test]
    fn a_down_pose_gives_several_branches_over_both_yaws() {
        let p = Vector3::new(0.45, 0.1, 0.12);
        let g = GoalSet::down(&p, 0.3, false, &HOME_Q);
        assert!(g.len() >= 8, "{} goals", g.len());
        assert!(g.ik_failure.is_none());
        for q in &g.configs {
            assert!((fk(q).translation.vector - p).norm() < 1e-6);
        }
        let quarter = GoalSet::down(&p, 0.3, true, &HOME_Q);
        assert!(quarter.len() > g.len());
    }

    #[test]
    fn an_unreachable_pose_says_why() {
        let g = GoalSet::down(&Vector3::new(1.5, 0.0, 0.1), 0.0, false, &HOME_Q);
        assert!(g.is_empty());
        let why = g.ik_failure.unwrap();
        assert!(why.contains("no IK solution") && why.contains("beyond"), "{why}");
    }
}
