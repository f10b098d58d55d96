//! Re-measures the 2F-85 calibration table (`motion::gripper::CALIBRATION`) in the simulator and
//! checks it, and checks that `ctrl_for_width` makes the gripper settle at the asked opening.

use macrotree::motion::gripper::{CALIBRATION, ctrl_for_width};
use macrotree::sim::{Scene, Sim, TIMESTEP};

/// Seconds each command is held before the opening is read.
const HOLD_S: f64 = 2.0;

fn hold(sim: &mut Sim, ctrl: f64) -> f64 {
    sim.set_gripper_ctrl(ctrl);
    for _ in 0..(HOLD_S / TIMESTEP).round() as usize {
        sim.step();
    }
    sim.observe().gripper_width
}

#[test]
fn calibration_table_matches_the_simulator() {
    let scene = Scene::load().expect("scene (run tools/bootstrap)");
    let mut sim = Sim::new(&scene);
    // The cube starts far from the fingers (default layout), the arm holds home.
    let mut worst = 0.0f64;
    let mut report = String::new();
    for &(ctrl, width) in &CALIBRATION {
        let measured = hold(&mut sim, ctrl);
        // Settled: the fingers no longer move.
        assert!(
            sim.observe().gripper_speed.abs() < 1e-4,
            "ctrl {ctrl} not settled"
        );
        report += &format!("    ({ctrl:.1}, {measured:.5}),\n");
        worst = worst.max((measured - width).abs());
    }
    eprintln!("measured table:\n{report}worst difference {:.3} mm", worst * 1e3);
    assert!(
        worst <= 2e-4,
        "calibration drifted by {:.3} mm:\n{report}",
        worst * 1e3
    );
}

#[test]
fn ctrl_for_width_reaches_the_asked_opening() {
    let scene = Scene::load().expect("scene");
    let mut sim = Sim::new(&scene);
    // Between table points too (linear interpolation error of the mildly curved linkage).
    for width in [0.084, 0.08, 0.0735, 0.06, 0.044, 0.03, 0.0205, 0.01, 0.005, 0.002] {
        let measured = hold(&mut sim, ctrl_for_width(width));
        assert!(
            (measured - width).abs() <= 2e-4,
            "asked {width} m, got {measured} m"
        );
    }
}
