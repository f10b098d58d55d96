//! [`JointSpare`]: how much clearance a free configuration has to spare, by joint range, and
//! how far the joints may move from it before the spare is used up.

/// Widest spare clearance the planner asks a checker for, metres
/// ([`FastChecks::exact_spare`](super::FastChecks::exact_spare),
/// [`FastChecks::screen_spare`](super::FastChecks::screen_spare)): a configuration
/// measured with this much to spare vouches for those up to this far (in the lever-arm
/// displacement bound) along a segment.
pub const SPARE_CAP: f64 = 0.15;

/// Spare clearance by joint range, metres: for each range of arm joints `lo..=hi` (0 = base …
/// 5 = wrist 3), a lower bound on how much farther than the clearance margin every pair of
/// parts that only those joints move relative to each other is. The fixed cell and a part of
/// link `k` (moved by joints `0..=k`) form a pair of range `0..=k`; parts of links `a < b`, a pair
/// of range `a+1..=b`. A point of a part moves relative to its partner at most
/// `Σ_{j in range} r_j |Δq_j|` (lever arms `r_j`), so a configuration whose joint changes keep
/// every range's sum within its spare keeps the margin too. Self pairs of the wrist links change
/// only with the wrist joints: a single spare for all joints would be held down by them.
///
/// **Reach.** The lever arms bound every configuration; at the measured one the moving parts
/// may lie much nearer some axes (the arm folded, the tool near the base). A spare can carry
/// that reach (`reach[j]`, metres: no moving part lies farther from joint `j`'s axis at the
/// measured configuration). A point's distance from joint `j`'s axis changes only with the
/// joints after `j` (the axis is fixed in link `j`'s frame), by at most `Σ_{k>j} r_k |Δq_k|`, so
/// over a straight move `Δq` joint `j` turns every point by at most
/// `min(r_j, reach[j] + Σ_{k>j} r_k |Δq_k|) |Δq_j|` ([`JointSpare::levers`]), and so does every
/// pair of parts relative to each other. Without a reach (infinite, the default) the lever arms
/// alone count.
///
/// A spare with a reach must hold every pair's true clearance in every range: a checker whose
/// spares are divided by a per-pair ratio of the lever arms (the screen's `kappa`, below 1 for
/// links across a short chain) must not give one. Mixing the two was measured slower: for such
/// a pair the ratio that keeps the bound at the reach costs more than the reach gains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointSpare {
    /// `by_range[lo][hi]` for `lo ≤ hi`, metres; unused below the diagonal.
    by_range: [[f64; 6]; 6],
    /// How far the moving parts reach from each joint's axis at the measured configuration,
    /// metres; infinite where unknown.
    reach: [f64; 6],
}

impl JointSpare {
    /// No spare anywhere: vouches for nothing.
    pub const NONE: JointSpare = JointSpare {
        by_range: [[0.0; 6]; 6],
        reach: [f64::INFINITY; 6],
    };

    /// The same spare `s` (metres) for every range, no reach known.
    pub fn uniform(s: f64) -> Self {
        Self {
            by_range: [[s; 6]; 6],
            reach: [f64::INFINITY; 6],
        }
    }

    /// The spare with the reach of the moving parts from each joint's axis at the measured
    /// configuration (metres; see the type's docs). Every range's spare must be the true
    /// clearance of its pairs, not divided by a ratio of the lever arms.
    pub fn with_reach(mut self, reach: [f64; 6]) -> Self {
        self.reach = reach;
        self
    }

    /// The spare worth measuring for a move of `want` steps of `step` (radians per step) from
    /// the measured configuration: in each range, what the move's lever-arm displacement
    /// `want · Σ_{j in range} arms[j] |step_j|` uses (metres; `arms`: metres per radian), at most
    /// `cap`; `cap` in every range when nothing moves. A spare measured up to it holds the
    /// move by the lever arms alone ([`JointSpare::steps_along`]); a checker need not measure a
    /// pair that surely keeps more.
    pub fn wanted(arms: &[f64; 6], step: &[f64; 6], want: f64, cap: f64) -> Self {
        let mut arm = [0.0; 7];
        for j in 0..6 {
            arm[j + 1] = arm[j] + arms[j] * step[j].abs();
        }
        if want * arm[6] <= 0.0 {
            return Self::uniform(cap);
        }
        let mut caps = Self::uniform(cap);
        for lo in 0..6 {
            for hi in lo..6 {
                caps.by_range[lo][hi] = (want * (arm[hi + 1] - arm[lo])).min(cap);
            }
        }
        caps
    }

    /// The reach from each joint's axis at the measured configuration, metres (infinite:
    /// unknown).
    pub fn reach(&self) -> [f64; 6] {
        self.reach
    }

    /// The spare of the range `lo..=hi` (joint indices, `lo ≤ hi ≤ 5`), metres.
    pub fn get(&self, lo: usize, hi: usize) -> f64 {
        self.by_range[lo][hi]
    }

    /// Lowers the spare of the range `lo..=hi` to `s` metres (to 0 for a negative `s`: a bound
    /// too weak to vouch) if it is less.
    pub fn tighten(&mut self, lo: usize, hi: usize, s: f64) {
        let v = &mut self.by_range[lo][hi];
        *v = v.min(s.max(0.0));
    }

    /// The least spare of any range, metres.
    pub fn least(&self) -> f64 {
        (0..6)
            .flat_map(|lo| (lo..6).map(move |hi| (lo, hi)))
            .map(|(lo, hi)| self.by_range[lo][hi])
            .fold(f64::INFINITY, f64::min)
    }

    /// How far each joint turns the moving parts over the straight move `dq` (radians) from the
    /// measured configuration, metres: `min(arms[j], reach[j] + Σ_{k>j} arms[k] |dq_k|) |dq_j|`
    /// (`arms`: lever arms bounding every configuration, metres per radian).
    pub fn levers(&self, arms: &[f64; 6], dq: &[f64; 6]) -> [f64; 6] {
        let later = later_turns(arms, dq);
        std::array::from_fn(|j| arms[j].min(self.reach[j] + later[j]) * dq[j].abs())
    }

    /// True when the straight move `dq` (radians) from the measured configuration surely uses up
    /// the whole chain's spare: the least the joints can turn the parts by,
    /// `Σ_j min(arms[j], reach[j]) |dq_j|`, exceeds it. A quick test before
    /// [`JointSpare::after`].
    #[inline]
    pub fn surely_beyond(&self, arms: &[f64; 6], dq: &[f64; 6]) -> bool {
        let mut least = 0.0;
        for j in 0..6 {
            least += arms[j].min(self.reach[j]) * dq[j].abs();
        }
        least > self.by_range[0][5]
    }

    /// The spare left after the straight move `dq` (radians) from the measured configuration:
    /// each range's spare less its [`levers`](JointSpare::levers), with the reach grown by what
    /// the move can add to it; `None` when a range's spare is used up.
    pub fn after(&self, arms: &[f64; 6], dq: &[f64; 6]) -> Option<JointSpare> {
        let mut rest = self.less(&self.levers(arms, dq))?;
        let later = later_turns(arms, dq);
        rest.reach = std::array::from_fn(|j| self.reach[j] + later[j]);
        Some(rest)
    }

    /// The spare left after displacements `moved[j]` (metres: what joint `j` turned the parts
    /// by): each range's spare less its sum, `None` when one falls below zero. A point of the
    /// robot has moved at most that sum relative to its partner, so the rest still bounds its
    /// clearance beyond the margin (the triangle inequality). The reach is kept as it is: use
    /// [`JointSpare::after`] for a move.
    pub fn less(&self, moved: &[f64; 6]) -> Option<JointSpare> {
        let mut prefix = [0.0; 7];
        for j in 0..6 {
            prefix[j + 1] = prefix[j] + moved[j];
        }
        let mut rest = *self;
        for lo in 0..6 {
            for hi in lo..6 {
                let v = self.by_range[lo][hi] - (prefix[hi + 1] - prefix[lo]);
                if v < 0.0 {
                    return None;
                }
                rest.by_range[lo][hi] = v;
            }
        }
        Some(rest)
    }

    /// How many steps `step` (radians per step) every range's spare holds, not necessarily
    /// whole: the largest `k` found with `Σ_{j in range} levers(k · step)[j] ≤` the range's
    /// spare for every range (infinite when nothing moves). Two bounds on the levers count, and
    /// the larger `k` is kept: the lever arms alone (`k · Σ arms[j] |step_j|`, linear in `k`), and
    /// the reach (`Σ (reach[j] + k · Σ_{i>j} arms[i] |step_i|) · k |step_j|`, quadratic in `k`).
    pub fn steps_along(&self, arms: &[f64; 6], step: &[f64; 6]) -> f64 {
        // Per joint: the lever-arm displacement per step, the reach's, and the growth of the
        // reach per step times the turn per step.
        let mut arm = [0.0; 7];
        let mut near = [0.0; 7];
        let mut grow = [0.0; 7];
        let tail = later_turns(arms, step);
        for j in 0..6 {
            let turn = step[j].abs();
            arm[j + 1] = arm[j] + arms[j] * turn;
            near[j + 1] = near[j] + self.reach[j] * turn;
            grow[j + 1] = grow[j] + tail[j] * turn;
        }
        let mut k = f64::INFINITY;
        for lo in 0..6 {
            for hi in lo..6 {
                let s = self.by_range[lo][hi];
                let linear = arm[hi + 1] - arm[lo];
                if linear <= 0.0 {
                    continue;
                }
                let mut within = s / linear;
                let (b, a) = (near[hi + 1] - near[lo], grow[hi + 1] - grow[lo]);
                if b.is_finite() {
                    // The positive root of a k² + b k = s (k = s / b when a is zero).
                    let quad = if a > 0.0 {
                        2.0 * s / (b + (b * b + 4.0 * a * s).sqrt())
                    } else if b > 0.0 {
                        s / b
                    } else {
                        f64::INFINITY
                    };
                    within = within.max(quad);
                }
                k = k.min(within);
            }
        }
        k
    }

    /// True when displacements `moved[j]` (metres: what joint `j` turned the parts by) keep
    /// every range's sum within its spare.
    pub fn covers(&self, moved: &[f64; 6]) -> bool {
        self.less(moved).is_some()
    }
}

/// For each joint `j`, how far the joints after it turn the parts over the move `dq` (radians)
/// by the lever arms `arms` (metres per radian): `Σ_{k>j} arms[k] |dq_k|`, metres; what the move
/// can add to the parts' distance from joint `j`'s axis.
fn later_turns(arms: &[f64; 6], dq: &[f64; 6]) -> [f64; 6] {
    let mut out = [0.0; 6];
    let mut sum = 0.0;
    for j in (0..6).rev() {
        out[j] = sum;
        sum += arms[j] * dq[j].abs();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_joint_spare_bounds_each_range_by_its_own_joints() {
        // 3 cm everywhere but the wrists' own pairs (joints 4..=5): 5 mm.
        let mut spare = JointSpare::uniform(0.03);
        spare.tighten(4, 5, 0.005);
        assert_eq!(spare.least(), 0.005);
        assert_eq!(spare.get(4, 5), 0.005);
        // A negative bound leaves no spare (0), and a larger one never raises it again.
        spare.tighten(0, 0, -1.0);
        assert_eq!(spare.get(0, 0), 0.0);
        spare.tighten(0, 0, 0.03);
        assert_eq!(spare.get(0, 0), 0.0);
        assert!(
            !spare.covers(&[0.015, 0.01, 0.0, 0.0, 0.0, 0.0]),
            "range 0..=0 has no spare"
        );
        // The base and shoulder move 2.5 cm between them: every range within its spare.
        let mut spare = JointSpare::uniform(0.03);
        spare.tighten(4, 5, 0.005);
        assert!(spare.covers(&[0.015, 0.01, 0.0, 0.0, 0.0, 0.0]));
        // Past the whole chain's spare: not covered.
        assert!(!spare.covers(&[0.015, 0.01, 0.006, 0.0, 0.0, 0.0]));
        // The wrists move 6 mm between them: range 4..=5 fails although the sum is small.
        assert!(!spare.covers(&[0.0, 0.0, 0.0, 0.0, 0.003, 0.003]));
        assert!(spare.covers(&[0.0, 0.0, 0.0, 0.0, 0.002, 0.003]));
        // Wrist 2 alone, 6 mm: range 4..=4 keeps 3 cm, but the wrists' pairs (4..=5) move by
        // joint 4 too, 6 mm against 5 mm.
        assert!(!spare.covers(&[0.0, 0.0, 0.0, 0.0, 0.006, 0.0]));
        assert!(JointSpare::NONE.covers(&[0.0; 6]));
        assert!(!JointSpare::NONE.covers(&[0.0, 0.0, 0.0, 1e-9, 0.0, 0.0]));
    }

    #[test]
    fn a_spare_holds_as_many_steps_as_its_tightest_range_allows() {
        // 3 cm everywhere but the wrists' own pairs (joints 4..=5): 5 mm.
        let mut spare = JointSpare::uniform(0.03);
        spare.tighten(4, 5, 0.005);
        let arms = [1.0; 6];
        // The base turning 1 cm per step: 3 steps; the wrists 2 mm each per step: 1.25 steps.
        let near = |x: f64, y: f64| (x - y).abs() < 1e-9;
        assert!(near(
            spare.steps_along(&arms, &[0.01, 0.0, 0.0, 0.0, 0.0, 0.0]),
            3.0
        ));
        assert!(near(
            spare.steps_along(&arms, &[0.0, 0.0, 0.0, 0.0, 0.002, 0.002]),
            1.25
        ));
        assert_eq!(spare.steps_along(&arms, &[0.0; 6]), f64::INFINITY);
        assert_eq!(
            JointSpare::NONE.steps_along(&arms, &[1e-9, 0.0, 0.0, 0.0, 0.0, 0.0]),
            0.0
        );
        // The spare left after moving: each range less its own sum, none once one is exceeded.
        let rest = spare.less(&[0.0, 0.0, 0.0, 0.0, 0.002, 0.0]).unwrap();
        assert!((rest.get(4, 5) - 0.003).abs() < 1e-12 && (rest.get(0, 3) - 0.03).abs() < 1e-12);
        assert!(spare.less(&[0.0, 0.0, 0.0, 0.0, 0.003, 0.003]).is_none());
    }

    #[test]
    fn the_spare_wanted_is_what_the_move_uses_of_each_range() {
        let arms = [1.0, 1.0, 0.5, 0.4, 0.3, 0.1];
        // Ten steps of the base (1 mm per step) and of wrist 3 (0.2 mm per step).
        let step = [0.001, 0.0, 0.0, 0.0, 0.0, 0.002];
        let caps = JointSpare::wanted(&arms, &step, 10.0, 0.15);
        let near = |x: f64, y: f64| (x - y).abs() < 1e-12;
        assert!(near(caps.get(0, 5), 0.012) && near(caps.get(0, 0), 0.01));
        assert!(near(caps.get(5, 5), 0.002) && near(caps.get(1, 4), 0.0));
        // A spare measured up to it holds the ten steps in every range, and no more than a
        // larger spare would.
        let mut full = JointSpare::uniform(0.15);
        full.tighten(0, 5, 0.03);
        let mut capped = caps;
        for lo in 0..6 {
            for hi in lo..6 {
                capped.tighten(lo, hi, full.get(lo, hi));
            }
        }
        assert!(near(capped.steps_along(&arms, &step), 10.0));
        assert!(full.steps_along(&arms, &step) > 10.0);
        // Capped at `cap`, and the cap everywhere when nothing moves.
        assert!(near(JointSpare::wanted(&arms, &step, 1e6, 0.15).get(0, 5), 0.15));
        assert_eq!(
            JointSpare::wanted(&arms, &[0.0; 6], 10.0, 0.15),
            JointSpare::uniform(0.15)
        );
    }

    #[test]
    fn a_reach_nearer_the_axes_than_the_lever_arms_vouches_for_more() {
        let arms = [1.0, 1.0, 0.5, 0.4, 0.3, 0.1];
        let spare = JointSpare::uniform(0.02);
        // The parts lie within 40 cm of the base axis: the base turns them by at most
        // 0.4 m per radian, plus what the later joints add to that reach on the way.
        let near = spare.with_reach([0.4, 1.0, 0.5, 0.4, 0.3, 0.1]);
        let base = [0.04, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!(spare.after(&arms, &base).is_none(), "4 cm by the lever arm");
        let rest = near.after(&arms, &base).expect("1.6 cm by the reach");
        assert!((rest.get(0, 5) - 0.004).abs() < 1e-12);
        // The wrist turning with the base grows the base's reach by its own lever: 0.1 m per
        // radian × 0.05 rad = 5 mm.
        let both = [0.03, 0.0, 0.0, 0.0, 0.0, 0.05];
        let levers = near.levers(&arms, &both);
        assert!((levers[0] - 0.405 * 0.03).abs() < 1e-12 && (levers[5] - 0.005).abs() < 1e-12);
        let rest = near.after(&arms, &both).expect("within the spare");
        assert!((rest.reach()[0] - 0.405).abs() < 1e-12 && rest.reach()[5] == 0.1);
        // A reach beyond the lever arm counts the lever arm.
        let far = spare.with_reach([5.0; 6]);
        assert_eq!(far.levers(&arms, &base), spare.levers(&arms, &base));
        // The steps along a line: the move by that many steps keeps every range within.
        for step in [
            [0.002, 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.001, 0.002, -0.003, 0.004, 0.0, 0.01],
        ] {
            let k = near.steps_along(&arms, &step);
            assert!(k > spare.steps_along(&arms, &step), "{step:?}");
            let dq: [f64; 6] = std::array::from_fn(|j| step[j] * k * (1.0 - 1e-9));
            assert!(near.after(&arms, &dq).is_some(), "{step:?}: {k} steps");
        }
        // The base alone at 40 cm: 0.02 m / (0.4 m × 0.002 rad) = 25 steps, and no more.
        let base = [0.002, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!((near.steps_along(&arms, &base) - 25.0).abs() < 1e-9);
    }
}
