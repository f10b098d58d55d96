//! Physics cross-check: trajectories at the default limits, commanded sample by sample to the
//! simulated position servos through `Sim::command_arm` (velocity + gravity feed-forward), are
//! tracked to a few millimetres; the bare positions lag by decimetres (printed for the record).

use macrotree::motion::{CartesianMove, HOME_Q, JointMove, MotionLimits, Trajectory, fk, ik_down_with_pose};
use macrotree::sim::{Scene, Sim, TIMESTEP};
use nalgebra::Vector3;

/// Runs `tr` through the servos plus `settle` seconds (commands sampled at the end of each
/// physics step); returns (max pinch error against the planned joints' FK during the motion,
/// final pinch error), metres.
fn track(sim: &mut Sim, tr: &dyn Trajectory, settle: f64, feedforward: bool) -> (f64, f64) {
    let steps = ((tr.duration() + settle) / TIMESTEP).ceil() as usize;
    let mut worst = 0.0f64;
    for k in 1..=steps {
        let t = k as f64 * TIMESTEP;
        let (q, qd) = tr.sample(t);
        if feedforward {
            sim.command_arm(&q, &qd);
        } else {
            sim.set_arm_ctrl(&q);
        }
        sim.step();
        let w = sim.observe();
        worst = worst.max((w.pinch_pos - fk(&q).translation.vector).norm());
    }
    let end = fk(&tr.end()).translation.vector;
    (worst, (sim.observe().pinch_pos - end).norm())
}

/// Home → above the cube (joint move) → down to it (line) → carry over the bowl (line).
fn pick_sequence(feedforward: bool) -> Vec<(&'static str, f64, f64, f64)> {
    let scene = Scene::load().expect("scene (run tools/bootstrap)");
    let mut sim = Sim::new(&scene);
    let lim = MotionLimits::default();
    let mut out = Vec::new();
    let (_, sag) = track(&mut sim, &JointMove::new(HOME_Q, HOME_Q, &lim), 1.0, feedforward);
    out.push(("hold home", 0.0, 0.0, sag));
    let (q_above, _) = ik_down_with_pose(&Vector3::new(0.45, -0.18, 0.2), 0.0, false, &HOME_Q).unwrap();
    let jm = JointMove::new(HOME_Q, q_above, &lim);
    let (w, f) = track(&mut sim, &jm, 0.5, feedforward);
    out.push(("joint move", jm.duration(), w, f));
    let (_, down) = ik_down_with_pose(&Vector3::new(0.45, -0.18, 0.03), 0.0, false, &q_above).unwrap();
    let cm = CartesianMove::new(q_above, down, &lim).unwrap();
    let (w, f) = track(&mut sim, &cm, 0.5, feedforward);
    out.push(("descent", cm.duration(), w, f));
    let (_, carry) = ik_down_with_pose(&Vector3::new(0.45, 0.08, 0.25), 0.0, false, &cm.end()).unwrap();
    let cm2 = CartesianMove::new(cm.end(), carry, &lim).unwrap();
    let (w, f) = track(&mut sim, &cm2, 0.5, feedforward);
    out.push(("carry", cm2.duration(), w, f));
    out
}

#[test]
fn servos_track_default_limit_moves_with_feedforward() {
    for feedforward in [false, true] {
        let rows = pick_sequence(feedforward);
        eprintln!("feed-forward {feedforward}:");
        for (what, dur, worst, fin) in &rows {
            eprintln!(
                "  {what:10} {dur:.2} s: worst {:.2} mm, final {:.3} mm",
                worst * 1e3,
                fin * 1e3
            );
        }
        if feedforward {
            for (what, _, worst, fin) in rows {
                assert!(worst < 0.005, "{what}: tracking error {worst} m");
                assert!(fin < 0.0005, "{what}: final error {fin} m");
            }
        }
    }
}
