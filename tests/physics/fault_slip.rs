//! `--fault slip` on real physics: the cube really falls out of the gripper during the first
//! carry, the trace reads grasp lost → carry fails → retry → re-grasp where the cube now lies →
//! success, and a seeded batch of 10 all recover with a second grasp.

use macrotree::actions::{CONTROL_PERIOD, Cell};
use macrotree::episode::{EpisodeConfig, EpisodeObserver, run_in_cell};
use macrotree::faults::{FaultKind, injector_with_log};
use macrotree::runtime::{NodeStatus, Transition, TreeRunner};
use macrotree::sim::Layout;
use macrotree::sweep::{SweepConfig, sample_layout};
use nalgebra::Vector3;

/// Half the edge of the 44 mm cube of the built-in scene, metres.
const CUBE_HALF: f64 = 0.022;

use crate::support::flagship;
use crate::support::logs;
use crate::support::oracle;
use flagship::{plan, scene, sweep_flagship};

/// Records the transitions and the cube's position at every tick.
#[derive(Default)]
struct Trace {
    transitions: Vec<Transition>,
    cube: Vec<(f64, Vector3<f64>)>,
}

impl EpisodeObserver for Trace {
    fn on_tick(&mut self, cell: &Cell, runner: &mut TreeRunner) {
        self.transitions.extend(runner.drain_transitions());
        let w = cell.world();
        self.cube.push((w.time, w.objects[w.cube().expect("a cube")].pos));
    }
}

fn leaf(t: &Transition) -> &str {
    t.path.rsplit('/').next().unwrap_or("")
}

#[test]
fn a_slip_drops_the_cube_and_the_tree_picks_it_up_where_it_fell() {
    let (seed, layout) = sample_layout(1, 0);
    let config = EpisodeConfig {
        placement: Some(scene().placement_from_layout(&layout.to_layout())),
        seed,
        ..EpisodeConfig::default()
    };
    let mut cell = Cell::new(scene(), &Layout::default(), CONTROL_PERIOD);
    let (slip, log) = injector_with_log(FaultKind::Slip, config.seed);
    cell.observers.push(slip);
    let mut trace = Trace::default();
    let (report, lines) = logs::capture(|| {
        run_in_cell(
            &mut cell,
            plan(),
            &macrotree::factory::Factory::builtin(),
            &config,
            &mut trace,
        )
    });
    assert!(report.outcome.success, "{:?}", report.outcome.failure_reason);
    assert_eq!(report.outcome.grasp_attempts, 2);
    oracle::assert_no_warning(cell.sim(), "slip episode");
    // The slip fired once, and said so once.
    let fired = lines.iter().filter(|l| l.contains("fault slip: ")).count();
    assert_eq!(fired, 1, "logged firings: {lines:#?}");

    let fired = log.lock().unwrap().clone().expect("the slip fired");
    assert_eq!(fired.kind, FaultKind::Slip);
    // The cube really fell: within half a second it rests on the table again.
    let fell = trace
        .cube
        .iter()
        .find(|(t, c)| *t > fired.time && *t < fired.time + 0.5 && c.z < CUBE_HALF + 0.003);
    let (landed_at, landed) = *fell.expect("the cube falls to the table after the slip");

    let tr = &trace.transitions;
    let pos = |pred: &dyn Fn(&Transition) -> bool| tr.iter().position(pred);
    // grasp lost: the carry's guard condition turns false after the fault; the carry stops.
    let lost = pos(&|t| {
        t.sim_time >= fired.time
            && t.kind == "cube_grasped"
            && t.path.contains("guard[")
            && t.to == NodeStatus::Failure
    })
    .expect("the guard sees the grasp lost");
    let carry_stops = pos(&|t| {
        t.sim_time >= fired.time
            && leaf(t) == "carry"
            && matches!(t.to, NodeStatus::Failure | NodeStatus::Halted)
    })
    .expect("the carry stops");
    let guard_fails =
        pos(&|t| t.kind == "guard" && t.to == NodeStatus::Failure).expect("the guarded carry fails");
    // The guard stopped the carry: the carry did not fail on its own, it was halted in the same
    // tick, and its reason names the guard and its condition (not an ancestor further up).
    let (carry, guard) = (&tr[carry_stops], &tr[guard_fails]);
    assert_eq!(carry.to, NodeStatus::Halted, "{carry:?}");
    assert_eq!(carry.tick, guard.tick, "halted in the tick the guard failed");
    assert_eq!(
        carry.reason.as_deref(),
        Some(
            format!(
                "preempted: `{}` failed (condition failed: cube_grasped: not satisfied)",
                guard.path
            )
            .as_str()
        ),
        "{carry:?}"
    );
    assert!(guard.path.ends_with("guard[carry while held]"), "{}", guard.path);
    // retry: the next grasp runs in attempt 2 …
    let regrasp = pos(&|t| leaf(t) == "grasp" && t.to == NodeStatus::Running && t.attempt == Some(2))
        .expect("a second grasp in attempt 2");
    let regrasp_ok = pos(&|t| leaf(t) == "grasp" && t.to == NodeStatus::Success && t.attempt == Some(2))
        .expect("the second grasp holds");
    let done = pos(&|t| t.kind == "retry" && t.to == NodeStatus::Success).expect("the retry succeeds");
    assert!(lost <= guard_fails && carry_stops <= regrasp && guard_fails < regrasp);
    assert!(regrasp < regrasp_ok && regrasp_ok < done);
    // … where the cube lay: at the second grasp the cube is where it landed (it was not
    // teleported back), between the fingers.
    let t_regrasp = tr[regrasp].sim_time;
    assert!(landed_at < t_regrasp);
    let at_regrasp = trace
        .cube
        .iter()
        .find(|(t, _)| *t >= t_regrasp)
        .expect("cube sample")
        .1;
    assert!(
        (at_regrasp.xy() - landed.xy()).norm() < 0.01,
        "the cube lies at {landed:?} after the fall and at {at_regrasp:?} at the re-grasp"
    );
    assert!(at_regrasp.z < CUBE_HALF + 0.003, "re-grasped from the table");
    oracle::assert_in(cell.sim_mut(), "cube", "bowl", "after the slip");
}

#[test]
fn ten_seeded_slips_all_recover_with_a_second_grasp() {
    let config = SweepConfig {
        scenarios: 10,
        seed: 2024,
        jobs: 2,
        fault: Some(FaultKind::Slip),
        ..SweepConfig::default()
    };
    let run = sweep_flagship(&config);
    for r in &run.results {
        eprintln!(
            "#{}: success {} after {} grasp(s)",
            r.index, r.outcome.success, r.outcome.grasp_attempts
        );
    }
    for r in &run.results {
        assert!(
            r.outcome.success,
            "#{} {:?}: {:?}",
            r.index, r.layout, r.outcome.failure_reason
        );
        assert!(
            r.outcome.grasp_attempts >= 2,
            "#{}: the slip did not take the cube ({} grasp)",
            r.index,
            r.outcome.grasp_attempts
        );
        assert!(
            r.outcome.grasp_attempts <= 3,
            "#{}: {} grasps",
            r.index,
            r.outcome.grasp_attempts
        );
    }
}

#[test]
fn a_slip_is_deterministic_and_fires_once() {
    let layout = Layout::default();
    let run = |seed: u64| {
        let mut cell = Cell::new(scene(), &layout, CONTROL_PERIOD);
        let (slip, log) = injector_with_log(FaultKind::Slip, seed);
        cell.observers.push(slip);
        let config = EpisodeConfig {
            placement: Some(scene().placement_from_layout(&layout)),
            seed,
            ..EpisodeConfig::default()
        };
        let mut report = run_in_cell(
            &mut cell,
            plan(),
            &macrotree::factory::Factory::builtin(),
            &config,
            &mut macrotree::episode::NoObserver,
        );
        oracle::assert_no_warning(cell.sim(), &format!("seed {seed}"));
        report.wall_time_s = 0.0;
        report.planning.planning_wall_s = 0.0;
        let event = log.lock().unwrap().clone().expect("fired");
        (report, event, cell.sim().state_fingerprint())
    };
    let a = run(3);
    let b = run(3);
    assert_eq!(a, b, "same seed, same episode, bit for bit");
    let c = run(4);
    assert_ne!(a.1.time, c.1.time, "another seed, another moment");
    assert_eq!(a.0.outcome.grasp_attempts, 2, "it fires once: one re-grasp");
}
