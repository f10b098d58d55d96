//! An action kind declares the part it plays in the pick-and-place cycle (`ActionRole`): the
//! episode's grasp count and grasp checks and the grasp faults follow the role, not the name
//! `grasp`, so a custom pick registered as a grasp is counted, checked and faulted like one.

use std::sync::Arc;

use macrotree::actions::{CONTROL_PERIOD, Cell, MacroAction, Progress};
use macrotree::episode::{EpisodeConfig, EpisodeReport, Goal, NoObserver, run_in_cell};
use macrotree::faults::{FaultKind, injector_with_log};
use macrotree::kinds::ActionRole;
use macrotree::sim::{Layout, Scene};
use macrotree::{App, Failure, Params};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `pinch: {seconds}`: closes the gripper where it is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct Pinch {
    /// How long the fingers close, simulated seconds.
    #[serde(default = "one_second")]
    seconds: f64,
}

fn one_second() -> f64 {
    1.0
}

impl Params for Pinch {}

/// Closes the gripper fully and waits.
struct PinchAction {
    seconds: f64,
    until: f64,
}

impl MacroAction for PinchAction {
    fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        cell.set_gripper(255.0);
        self.until = cell.world().time + self.seconds;
        Ok(())
    }
    fn update(&mut self, cell: &mut Cell) -> Progress {
        if cell.world().time < self.until {
            Progress::Running
        } else {
            Progress::Done
        }
    }
}

const PINCH_DOC: &str = "Close the fingers where they are.\n\nHalt: the fingers stay as they are.\n\n```yaml\npinch: {seconds: 1}\n```\n";

/// Reaches down around the cube and pinches it, with `pinch` registered as `role`.
fn pick(role: ActionRole, fault: Option<FaultKind>) -> (EpisodeReport, bool) {
    let mut app = App::new();
    app.register_action_as("pinch", PINCH_DOC, role, |p: &Pinch| {
        Box::new(PinchAction {
            seconds: p.seconds,
            until: 0.0,
        })
    })
    .unwrap();
    let plan = app
        .compile_str(
            "main:\n  sequence:\n    children:\n      - reach: {target: cube, offset: [0, 0, 0.12]}\n      - reach: {target: cube, offset: [0, 0, 0.0], path: cartesian}\n      - pinch: {}\n",
            "pinch.yaml",
        )
        .unwrap();
    let scene = Scene::load().expect("scene (run tools/bootstrap)");
    let mut cell = Cell::new(&scene, &Layout::default(), CONTROL_PERIOD);
    let log = fault.map(|kind| {
        let (observer, log) = injector_with_log(kind, 3);
        cell.observers.push(observer);
        log
    });
    let config = EpisodeConfig {
        goal: Goal::Tree,
        ..EpisodeConfig::default()
    };
    let report = run_in_cell(&mut cell, Arc::new(plan), app.factory(), &config, &mut NoObserver);
    let fired = log.is_some_and(|l| l.lock().unwrap().is_some());
    (report, fired)
}

#[test]
fn a_custom_pick_declared_as_a_grasp_is_counted_checked_and_faulted_as_one() {
    let (r, _) = pick(ActionRole::Grasp, None);
    assert!(r.outcome.success, "{:?}", r.outcome.failure_reason);
    assert_eq!(r.outcome.grasp_attempts, 1, "counted as a grasp attempt");
    let d = r
        .outcome
        .cube_bowl
        .expect("the scene has a cube")
        .checks
        .grasp_distance
        .expect("the grasp checks were taken when it ended");
    assert!(d < 0.03, "the pads closed on the cube: {d} m");
    let (_, fired) = pick(ActionRole::Grasp, Some(FaultKind::Nudge));
    assert!(fired, "the nudge fault armed when the pick started and fired");
}

#[test]
fn a_custom_action_of_no_role_is_neither_counted_nor_faulted() {
    let (r, _) = pick(ActionRole::Other, None);
    assert!(r.outcome.success, "{:?}", r.outcome.failure_reason);
    assert_eq!(r.outcome.grasp_attempts, 0);
    assert_eq!(
        r.outcome
            .cube_bowl
            .expect("the scene has a cube")
            .checks
            .grasp_distance,
        None
    );
    let (_, fired) = pick(ActionRole::Other, Some(FaultKind::Nudge));
    assert!(!fired, "the nudge fault waits for a grasp that never comes");
}
