//! Preemption on real physics: a running macro action that a decorator abandons is halted — the
//! arm holds where it was commanded to be, and a `halted` transition is recorded.

use std::sync::Arc;

use macrotree::actions::Cell;
use macrotree::episode::{EpisodeConfig, EpisodeObserver, run_in_cell};
use macrotree::runtime::{NodeStatus, Transition, TreeRunner};
use macrotree::sim::{Layout, Scene};

use crate::support::oracle;

/// Collects transitions and the pinch position after every tick.
#[derive(Default)]
struct Trace {
    transitions: Vec<Transition>,
    pinch: Vec<(f64, nalgebra::Vector3<f64>)>,
}

impl EpisodeObserver for Trace {
    fn on_tick(&mut self, cell: &Cell, runner: &mut TreeRunner) {
        self.transitions.extend(runner.drain_transitions());
        self.pinch.push((cell.world().time, cell.world().pinch_pos));
    }
}

#[test]
fn a_timeout_halts_a_running_reach_and_the_arm_holds() {
    // The reach to a point 0.5 m away takes well over 0.3 s; the timeout preempts it mid-motion.
    let yaml = r#"
main:
  sequence:
    children:
      - force_success:
          child:
            timeout:
              seconds: 0.3
              child: {reach: {target: [0.45, -0.25, 0.25]}}
      - wait: {seconds: 1.0}
"#;
    let plan = Arc::new(
        macrotree::plan::Loader::default()
            .compile_str(yaml, "halt.yaml")
            .expect("valid"),
    );
    let scene = Scene::load().expect("scene");
    let mut cell = Cell::new(&scene, &Layout::default(), macrotree::actions::CONTROL_PERIOD);
    let mut trace = Trace::default();
    let report = run_in_cell(
        &mut cell,
        plan,
        &macrotree::factory::Factory::builtin(),
        &EpisodeConfig::default(),
        &mut trace,
    );
    assert_eq!(report.outcome.tree_status, "success");
    assert_eq!(report.outcome.halts, 1, "exactly one leaf halted");
    let halted: Vec<&Transition> = trace
        .transitions
        .iter()
        .filter(|t| t.to == NodeStatus::Halted)
        .collect();
    assert_eq!(halted.len(), 1, "transitions: {:?}", trace.transitions);
    assert_eq!(halted[0].kind, "reach");
    let t_halt = halted[0].sim_time;
    assert!((0.28..0.35).contains(&t_halt), "halted at {t_halt} s");
    // After the halt the arm comes to rest near where it was and stays there: the last 0.5 s of
    // the wait move the pinch by less than a millimetre, and it stopped well short of the target.
    let late: Vec<_> = trace
        .pinch
        .iter()
        .filter(|(t, _)| *t > t_halt + 0.5)
        .map(|(_, p)| *p)
        .collect();
    let spread = late.iter().map(|p| (p - late[0]).norm()).fold(0.0, f64::max);
    assert!(spread < 1e-3, "arm still moving {spread} m after the halt");
    // … and it holds within 1 cm of where it was when halted, over the whole 1 s that follows.
    let at_halt = trace
        .pinch
        .iter()
        .find(|(t, _)| *t >= t_halt)
        .expect("a sample at the halt")
        .1;
    let farthest = trace
        .pinch
        .iter()
        .filter(|(t, _)| *t >= t_halt)
        .map(|(_, p)| (p - at_halt).norm())
        .fold(0.0, f64::max);
    eprintln!(
        "after the halt the pinch stayed within {:.2} mm of where it was",
        farthest * 1e3
    );
    assert!(farthest < 0.01, "the halted arm drifted {farthest} m");
    oracle::assert_no_warning(cell.sim(), "halt episode");
    let target = nalgebra::Vector3::new(0.45, -0.25, 0.25);
    assert!((late[0] - target).norm() > 0.1, "the reach was not interrupted");
}
