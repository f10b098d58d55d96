//! Physics cross-check: trajectories at the default limits, commanded sample by sample to the
//! simulated position servos through `Sim::command_arm` (velocity, inertia and gravity
//! feed-forward), are tracked to a few millimetres; without the inertia term the pinch lags
//! while accelerating, and the bare positions lag by decimetres (printed for the record).

use macrotree::motion::{CartesianMove, HOME_Q, JointMove, MotionLimits, Trajectory, fk, ik_down_with_pose};
use macrotree::sim::{Scene, Sim, TIMESTEP};
use nalgebra::Vector3;

/// How the servos are commanded.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Feed {
    /// The bare joint positions as set points.
    Bare,
    /// Velocity and gravity feed-forward (no inertia term: the acceleration passed as zero).
    VelocityGravity,
    /// Velocity, inertia and gravity feed-forward (the trajectory's accelerations).
    Full,
}

/// Runs `tr` through the servos plus `settle` seconds (commands sampled at the end of each
/// physics step); returns (max pinch error against the planned joints' FK during the motion,
/// final pinch error), metres.
fn track(sim: &mut Sim, tr: &dyn Trajectory, settle: f64, feed: Feed) -> (f64, f64) {
    let steps = ((tr.duration() + settle) / TIMESTEP).ceil() as usize;
    let mut worst = 0.0f64;
    for k in 1..=steps {
        let t = k as f64 * TIMESTEP;
        let (q, qd) = tr.sample(t);
        match feed {
            Feed::Bare => sim.set_arm_ctrl(&q),
            Feed::VelocityGravity => sim.command_arm(&q, &qd, &[0.0; 6]),
            Feed::Full => sim.command_arm(&q, &qd, &tr.acceleration(t)),
        }
        sim.step();
        let w = sim.observe();
        worst = worst.max((w.pinch_pos - fk(&q).translation.vector).norm());
    }
    let end = fk(&tr.end()).translation.vector;
    (worst, (sim.observe().pinch_pos - end).norm())
}

/// Home → above the cube (joint move) → down to it (line) → carry over the bowl (line).
fn pick_sequence(feed: Feed) -> Vec<(&'static str, f64, f64, f64)> {
    let scene = Scene::load().expect("scene (run tools/bootstrap)");
    let mut sim = Sim::new(&scene);
    let lim = MotionLimits::default();
    let mut out = Vec::new();
    let (_, sag) = track(&mut sim, &JointMove::new(HOME_Q, HOME_Q, &lim), 1.0, feed);
    out.push(("hold home", 0.0, 0.0, sag));
    let (q_above, _) = ik_down_with_pose(&Vector3::new(0.45, -0.18, 0.2), 0.0, false, &HOME_Q).unwrap();
    let jm = JointMove::new(HOME_Q, q_above, &lim);
    let (w, f) = track(&mut sim, &jm, 0.5, feed);
    out.push(("joint move", jm.duration(), w, f));
    let (_, down) = ik_down_with_pose(&Vector3::new(0.45, -0.18, 0.03), 0.0, false, &q_above).unwrap();
    let cm = CartesianMove::new(q_above, down, &lim).unwrap();
    let (w, f) = track(&mut sim, &cm, 0.5, feed);
    out.push(("descent", cm.duration(), w, f));
    let (_, carry) = ik_down_with_pose(&Vector3::new(0.45, 0.08, 0.25), 0.0, false, &cm.end()).unwrap();
    let cm2 = CartesianMove::new(cm.end(), carry, &lim).unwrap();
    let (w, f) = track(&mut sim, &cm2, 0.5, feed);
    out.push(("carry", cm2.duration(), w, f));
    out
}

#[test]
fn servos_track_default_limit_moves_with_feedforward() {
    let mut worst_of = Vec::new();
    for feed in [Feed::Bare, Feed::VelocityGravity, Feed::Full] {
        let rows = pick_sequence(feed);
        eprintln!("{feed:?}:");
        for (what, dur, worst, fin) in &rows {
            eprintln!(
                "  {what:10} {dur:.2} s: worst {:.2} mm, final {:.3} mm",
                worst * 1e3,
                fin * 1e3
            );
        }
        if feed != Feed::Bare {
            for (what, _, worst, fin) in &rows {
                assert!(*worst < 0.005, "{feed:?}, {what}: tracking error {worst} m");
                assert!(*fin < 0.0005, "{feed:?}, {what}: final error {fin} m");
            }
        }
        worst_of.push(rows.iter().map(|r| r.2).fold(0.0, f64::max));
    }
    // The inertia term takes most of the lag while accelerating away.
    assert!(
        worst_of[2] < 0.5 * worst_of[1],
        "worst tracking error with inertia feed-forward {} m, without {} m",
        worst_of[2],
        worst_of[1]
    );
}

/// The trajectories' accelerations are the derivatives of their velocities: the joint move's
/// closed form and the straight line's default difference agree with a wide central difference.
#[test]
fn accelerations_are_the_derivatives_of_the_velocities() {
    let lim = MotionLimits::default();
    let (q_above, _) = ik_down_with_pose(&Vector3::new(0.45, -0.18, 0.2), 0.0, false, &HOME_Q).unwrap();
    let (_, down) = ik_down_with_pose(&Vector3::new(0.45, -0.18, 0.03), 0.0, false, &q_above).unwrap();
    let moves: [Box<dyn Trajectory>; 2] = [
        Box::new(JointMove::new(HOME_Q, q_above, &lim)),
        Box::new(CartesianMove::new(q_above, down, &lim).unwrap()),
    ];
    for tr in &moves {
        let d = tr.duration();
        let h = 0.01;
        let mut peak = 0.0f64;
        for k in 1..40 {
            let t = d * k as f64 / 40.0;
            let (_, va) = tr.sample(t - h);
            let (_, vb) = tr.sample(t + h);
            let a = tr.acceleration(t);
            for j in 0..6 {
                let fd = (vb[j] - va[j]) / (2.0 * h);
                peak = peak.max(fd.abs());
                assert!(
                    (a[j] - fd).abs() < 0.05 + 0.02 * fd.abs(),
                    "{}: t {t}, joint {j}: {} vs {fd}",
                    tr.name(),
                    a[j]
                );
            }
        }
        assert!(peak > 0.1, "{}: the move accelerates ({peak} rad/s²)", tr.name());
        assert_eq!(tr.acceleration(d + 0.1), [0.0; 6]);
    }
}
