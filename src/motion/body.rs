//! The UR5e's and the 2F-85's bodies as capsules along the kinematic chain, for checks that need
//! no MuJoCo: the scene loader refuses an obstacle the arm at home stands in. Each radius is the
//! link's inner radius, smaller than its mesh, so a capsule that meets an object means the real
//! link does (the physics' own collision check stays the judge of near misses).

use nalgebra::Vector3;

use super::kinematics::chain;

/// One link's body: the points within `radius` of the segment `from`–`to` (world, metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capsule {
    /// The link, for messages (`forearm`, `gripper`).
    pub link: &'static str,
    /// One end of the axis (world), metres.
    pub from: Vector3<f64>,
    /// The other end (world), metres.
    pub to: Vector3<f64>,
    /// Radius, metres.
    pub radius: f64,
}

/// Inner radius of the upper arm's tube, metres (its mesh: about 0.06).
const UPPER_ARM_RADIUS: f64 = 0.045;
/// Inner radius of the forearm's tube and of the wrists, metres (their meshes: about 0.045).
const FOREARM_RADIUS: f64 = 0.035;
/// Inner half-width of the 2F-85's body, metres (its housing: about 0.04; open fingers reach
/// 0.0425 either side).
const GRIPPER_RADIUS: f64 = 0.03;

/// The arm's and the gripper's capsules at joints `q` (radians): the upper arm, the elbow's
/// offset, the forearm, the two wrist links, and the gripper down to its pinch point. The
/// shoulder above the base is left out (objects keep clear of the base anyway).
pub fn arm_capsules(q: &[f64; 6]) -> [Capsule; 6] {
    let c = chain(q);
    let o = c.origins;
    let capsule = |link, from, to, radius| Capsule {
        link,
        from,
        to,
        radius,
    };
    [
        capsule("upper arm", o[1], c.upper_arm_end, UPPER_ARM_RADIUS),
        capsule("elbow", c.upper_arm_end, o[2], UPPER_ARM_RADIUS),
        capsule("forearm", o[2], o[3], FOREARM_RADIUS),
        capsule("wrist 1", o[3], o[4], FOREARM_RADIUS),
        capsule("wrist 2", o[4], o[5], FOREARM_RADIUS),
        capsule("gripper", o[5], c.pinch_pos, GRIPPER_RADIUS),
    ]
}

impl Capsule {
    /// Points along the axis at most `step` metres apart, both ends included.
    pub fn axis_points(&self, step: f64) -> impl Iterator<Item = Vector3<f64>> + '_ {
        let n = ((self.to - self.from).norm() / step).ceil().max(1.0) as usize;
        (0..=n).map(move |k| self.from + (self.to - self.from) * (k as f64 / n as f64))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn at_home_the_arm_rises_over_its_base_and_the_gripper_hangs_down_to_the_pinch() {
        let caps = arm_capsules(&crate::motion::HOME_Q);
        let top = caps.iter().map(|c| c.from.z.max(c.to.z)).fold(0.0, f64::max);
        assert!(
            (top - (0.163 + 0.425)).abs() < 1e-9,
            "the elbow at shoulder + upper arm: {top}"
        );
        let pinch = crate::motion::fk(&crate::motion::HOME_Q).translation.vector;
        let gripper = caps[5];
        assert_eq!(gripper.link, "gripper");
        assert!((gripper.to - pinch).norm() < 1e-12);
        assert!(gripper.from.z > gripper.to.z, "the tool points down at home");
        // Consecutive capsules join: one body.
        for w in caps.windows(2) {
            assert!(
                (w[0].to - w[1].from).norm() < 1e-12,
                "{} → {}",
                w[0].link,
                w[1].link
            );
        }
    }
}
