//! IK properties (pure kinematics, no physics): FK∘IK round trips, nearest-to-seed choice, joint
//! limits, failures with reasons, and `ik_down` coverage of the task region.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

use macrotree::motion::ik::{TASK_REGION, ik_branches};
use macrotree::motion::kinematics::rotation_vector;
use macrotree::motion::{HOME_Q, IkError, JOINT_LIMITS, down_pose, fk, ik, ik_down};
use nalgebra::{Isometry3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn pose_error(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
    let dp = (a.translation.vector - b.translation.vector).norm();
    let dr = rotation_vector(
        &(a.rotation.to_rotation_matrix() * b.rotation.to_rotation_matrix().inverse()).into_inner(),
    )
    .norm();
    (dp, dr)
}

fn dist2(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

fn within_limits(q: &[f64; 6]) -> bool {
    q.iter()
        .zip(JOINT_LIMITS)
        .all(|(v, (lo, hi))| *v >= lo && *v <= hi)
}

fn random_q(rng: &mut ChaCha8Rng) -> [f64; 6] {
    std::array::from_fn(|j| {
        let (lo, hi) = JOINT_LIMITS[j];
        rng.random_range(lo..hi)
    })
}

/// The branch `ik` should pick: each closed-form branch moved by 2π per joint to the admissible
/// equivalent nearest the seed, then the nearest branch.
fn brute_force_nearest(target: &Isometry3<f64>, seed: &[f64; 6]) -> Option<[f64; 6]> {
    let mut best: Option<[f64; 6]> = None;
    'b: for sol in ik_branches(target) {
        let mut q = [0.0; 6];
        for j in 0..6 {
            let (lo, hi) = JOINT_LIMITS[j];
            let cands = (-3..=3)
                .map(|k| sol[j] + k as f64 * TAU)
                .filter(|c| *c >= lo && *c <= hi);
            match cands.min_by(|a, b| (a - seed[j]).abs().total_cmp(&(b - seed[j]).abs())) {
                Some(c) => q[j] = c,
                None => continue 'b,
            }
        }
        if best.is_none_or(|b| dist2(&q, seed) < dist2(&b, seed)) {
            best = Some(q);
        }
    }
    best
}

#[test]
fn round_trips_over_random_reachable_poses() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let mut worst = (0.0f64, 0.0f64);
    let mut same = 0;
    for i in 0..2000 {
        let q_true = random_q(&mut rng);
        let target = fk(&q_true);
        // Half the seeds near the true joints, half anywhere.
        let seed: [f64; 6] = if i % 2 == 0 {
            std::array::from_fn(|j| q_true[j] + rng.random_range(-0.1..0.1))
        } else {
            random_q(&mut rng)
        };
        let q = ik(&target, &seed).unwrap_or_else(|e| panic!("{i}: {q_true:?}: {e}"));
        assert!(within_limits(&q), "{q:?}");
        let (dp, dr) = pose_error(&fk(&q), &target);
        worst = (worst.0.max(dp), worst.1.max(dr));
        assert!(dp <= 1e-6 && dr <= 1e-5, "{i}: residual {dp:e} m {dr:e} rad");
        // Nearest to the seed among all admissible branches (ties within 1e-6 rad²).
        let nearest = brute_force_nearest(&target, &seed).expect("a branch");
        assert!(
            dist2(&q, &seed) <= dist2(&nearest, &seed) + 1e-6,
            "{i}: {q:?} vs {nearest:?}"
        );
        // The generating joints are one admissible answer: nothing farther from the seed is returned.
        assert!(
            dist2(&q, &seed) <= dist2(&q_true, &seed) + 1e-9,
            "{i}: {q:?} vs {q_true:?}"
        );
        if i % 2 == 0 && dist2(&nearest, &q_true) < 1e-12 {
            same += 1;
            assert!(dist2(&q, &q_true) < 1e-10, "{i}: {q:?} vs {q_true:?}");
        }
    }
    eprintln!(
        "worst round-trip residual: {:.2e} m, {:.2e} rad",
        worst.0, worst.1
    );
    // With a seed within 0.1 rad of the generating joints, those are almost always the nearest.
    assert!(same > 950, "{same}");
}

#[test]
fn wrist_singular_poses_still_solve() {
    // sin q5 = 0: wrist 1 and wrist 3 axes align; the seed's wrist 3 is kept.
    for q5 in [0.0, PI, -PI, 1e-9, 1e-6, 1e-4] {
        let q_true = [0.3, -1.2, 1.5, -0.9, q5, 0.7];
        let seed = [0.25, -1.1, 1.4, -1.0, q5 + 0.05, 0.6];
        let target = fk(&q_true);
        let q = ik(&target, &seed).unwrap_or_else(|e| panic!("q5 {q5}: {e}"));
        let (dp, dr) = pose_error(&fk(&q), &target);
        assert!(dp <= 1e-6 && dr <= 1e-5, "q5 {q5}: {dp:e} {dr:e}");
    }
}

#[test]
fn elbow_limit_is_respected() {
    // Elbow at its geometric extreme (folded) is beyond ±3.1415 → JointLimits.
    let q_true = [0.0, -1.0, PI - 1e-5, 0.0, 1.0, 0.0];
    let target = fk(&q_true);
    match ik(&target, &q_true) {
        Ok(q) => assert!(q[2].abs() <= JOINT_LIMITS[2].1, "{q:?}"),
        Err(IkError::JointLimits { reason }) => assert!(reason.contains("elbow"), "{reason}"),
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn unreachable_targets_fail_with_a_reason() {
    let far = [
        Vector3::new(1.0, 0.0, 0.2),
        Vector3::new(0.0, -0.9, 0.5),
        Vector3::new(0.3, 0.3, 1.2),
    ];
    for p in far {
        match ik_down(&p, 0.0, false, &HOME_Q) {
            Err(IkError::Unreachable { reason }) => {
                assert!(reason.contains("beyond the 0.817 m reach"), "{reason}")
            }
            other => panic!("{p}: {other:?}"),
        }
    }
    // Straight down onto the base axis: the wrist centre would be inside the shoulder offset.
    match ik_down(&Vector3::new(0.0, 0.0, 0.3), 0.0, false, &HOME_Q) {
        Err(IkError::Unreachable { reason }) => assert!(reason.contains("too close"), "{reason}"),
        other => panic!("{other:?}"),
    }
    // Display is human readable.
    let e = ik_down(&Vector3::new(1.0, 0.0, 0.2), 0.0, false, &HOME_Q).unwrap_err();
    assert!(e.to_string().starts_with("IK: pose unreachable: target"), "{e}");
}

/// Wraps into (−π, π].
fn wrap(a: f64) -> f64 {
    let x = a.rem_euclid(TAU);
    if x > PI { x - TAU } else { x }
}

#[test]
fn ik_down_covers_the_task_region_from_home() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut n = 0;
    for quarter in [false, true] {
        let period = if quarter { FRAC_PI_2 } else { PI };
        for _ in 0..3000 {
            let p = Vector3::new(
                rng.random_range(TASK_REGION[0].0..=TASK_REGION[0].1),
                rng.random_range(TASK_REGION[1].0..=TASK_REGION[1].1),
                rng.random_range(TASK_REGION[2].0..=TASK_REGION[2].1),
            );
            let yaw = rng.random_range(-PI..PI);
            let q = ik_down(&p, yaw, quarter, &HOME_Q).unwrap_or_else(|e| panic!("{p} yaw {yaw}: {e}"));
            n += 1;
            assert!(within_limits(&q));
            // Same arm configuration as home: shoulder towards the target, elbow up, wrist down.
            assert!(q[2] > 0.0, "elbow flipped: {q:?}");
            assert!((q[4] + FRAC_PI_2).abs() < 1e-6, "wrist 2 not at −π/2: {q:?}");
            assert!((q[0] - HOME_Q[0]).abs() < PI, "{q:?}");
            // The wrist turns at most half the symmetry period away from home's wrist 3.
            assert!(
                (q[5] - HOME_Q[5]).abs() <= period / 2.0 + 1e-9,
                "wrist 3 spun: {q:?}"
            );
            // The pose reached is the requested one up to the symmetry.
            let reached = fk(&q);
            assert!((reached.translation.vector - p).norm() <= 1e-6);
            let z = reached.rotation * Vector3::z();
            assert!((z + Vector3::z()).norm() < 1e-5);
            let x = reached.rotation * Vector3::x();
            let reached_yaw = (-x.x).atan2(x.y);
            let k = ((reached_yaw - yaw) / period).round();
            assert!(
                wrap(reached_yaw - yaw - k * period).abs() < 1e-5,
                "yaw {yaw} reached {reached_yaw}"
            );
        }
    }
    assert_eq!(n, 6000);
}

#[test]
fn ik_down_picks_the_yaw_equivalent_nearest_the_seed_wrist() {
    let p = Vector3::new(0.45, -0.1, 0.2);
    let q0 = ik_down(&p, 0.0, false, &HOME_Q).unwrap();
    // Yaw π is the same grasp: no wrist motion at all.
    let q1 = ik_down(&p, PI, false, &q0).unwrap();
    assert!(dist2(&q0, &q1) < 1e-18, "{q0:?} {q1:?}");
    // Quarter symmetry: yaw π/2 is equivalent to 0 → no motion; without it the wrist turns π/2.
    let q2 = ik_down(&p, FRAC_PI_2, true, &q0).unwrap();
    assert!(dist2(&q0, &q2) < 1e-18);
    let q3 = ik_down(&p, FRAC_PI_2, false, &q0).unwrap();
    assert!(((q3[5] - q0[5]).abs() - FRAC_PI_2).abs() < 1e-9);
    // 0.7 rad with quarter symmetry: 0.7 − π/2 = −0.87 is farther than 0.7 → turns 0.7.
    let q4 = ik_down(&p, 0.7, true, &q0).unwrap();
    assert!(((q4[5] - q0[5]).abs() - 0.7).abs() < 1e-9);
    let q5 = ik_down(&p, 1.0, true, &q0).unwrap();
    assert!(((q5[5] - q0[5]).abs() - (FRAC_PI_2 - 1.0)).abs() < 1e-9);
    // The result agrees with down_pose at the equivalent yaw (q0 itself may sit at yaw 0 or π).
    let target = down_pose(&p, 1.0 - FRAC_PI_2);
    let (dp, dr) = pose_error(&fk(&q5), &target);
    assert!(dp < 1e-6 && (dr < 1e-5 || (dr - PI).abs() < 1e-5), "{dp} {dr}");
    let _ = FRAC_PI_4;
}
