//! `--fault nudge` (and the other faults) on real physics: the cube is really pushed as the
//! gripper closes, and a seeded batch of 10 all still succeed.

use macrotree::actions::{CONTROL_PERIOD, Cell};
use macrotree::episode::{EpisodeConfig, EpisodeObserver, run_in_cell};
use macrotree::faults::{FaultKind, injector_with_log};
use macrotree::runtime::TreeRunner;
use macrotree::sim::Layout;
use macrotree::sweep::SweepConfig;

use crate::support::flagship;
use crate::support::logs;
use crate::support::oracle;
use flagship::{plan, scene, sweep_flagship};

#[test]
fn ten_seeded_nudges_all_succeed() {
    let config = SweepConfig {
        scenarios: 10,
        seed: 2024,
        jobs: 2,
        fault: Some(FaultKind::Nudge),
        ..SweepConfig::default()
    };
    let run = sweep_flagship(&config);
    for r in &run.results {
        assert!(
            r.outcome.success,
            "#{} {:?}: {:?}",
            r.index, r.layout, r.outcome.failure_reason
        );
    }
}

/// The largest horizontal distance the cube moved from its start before the first grasp ended.
#[derive(Default)]
struct Moved {
    start: Option<nalgebra::Vector3<f64>>,
    max: f64,
}

impl EpisodeObserver for Moved {
    fn on_tick(&mut self, cell: &Cell, _runner: &mut TreeRunner) {
        let w = cell.world();
        let cube = w.objects[w.cube().expect("a cube")].pos;
        let start = *self.start.get_or_insert(cube);
        if cell.gripper_command() > 0.0 && cube.z < 0.03 {
            self.max = self.max.max((cube - start).xy().norm());
        }
    }
}

#[test]
fn a_nudge_really_moves_the_cube_as_the_gripper_closes() {
    // The hand is pre-shaped to 65 mm around the 44 mm cube: pushed along the finger axis the
    // cube stops against a finger after 5–10 mm, pushed across it the closing fingers catch it
    // 1–2 cm off-centre. Either way it really moved before the fingers closed on it.
    let mut moves = Vec::new();
    for seed in [1, 2, 3, 4, 5, 6] {
        let layout = Layout::default();
        let mut cell = Cell::new(scene(), &layout, CONTROL_PERIOD);
        let (nudge, log) = injector_with_log(FaultKind::Nudge, seed);
        cell.observers.push(nudge);
        let config = EpisodeConfig {
            placement: Some(scene().placement_from_layout(&layout)),
            seed,
            ..EpisodeConfig::default()
        };
        let mut moved = Moved::default();
        let report = run_in_cell(
            &mut cell,
            plan(),
            &macrotree::factory::Factory::builtin(),
            &config,
            &mut moved,
        );
        let event = log.lock().unwrap().clone().expect("the nudge fired");
        eprintln!(
            "seed {seed}: {}; moved {:.1} mm; {} grasp(s)",
            event.detail,
            moved.max * 1e3,
            report.outcome.grasp_attempts
        );
        assert!(
            report.outcome.success,
            "seed {seed}: {:?}",
            report.outcome.failure_reason
        );
        oracle::assert_no_warning(cell.sim(), &format!("seed {seed}"));
        oracle::assert_in(cell.sim_mut(), "cube", "bowl", &format!("seed {seed}"));
        assert!(
            moved.max > 0.005,
            "seed {seed}: the cube moved only {:.1} mm",
            moved.max * 1e3
        );
        moves.push(moved.max);
    }
    let farthest = moves.iter().copied().fold(0.0, f64::max);
    assert!(
        farthest > 0.01,
        "no nudge moved the cube more than {:.1} mm",
        farthest * 1e3
    );
}

#[test]
fn every_fault_fires_exactly_once_in_an_episode() {
    let layout = Layout::default();
    let mut cell = Cell::new(scene(), &layout, CONTROL_PERIOD);
    for kind in FaultKind::ALL {
        let (fault, log) = injector_with_log(kind, 7);
        cell.observers.push(fault);
        let config = EpisodeConfig {
            placement: Some(scene().placement_from_layout(&layout)),
            seed: 7,
            ..EpisodeConfig::default()
        };
        let (report, lines) = logs::capture(|| {
            run_in_cell(
                &mut cell,
                plan(),
                &macrotree::factory::Factory::builtin(),
                &config,
                &mut macrotree::episode::NoObserver,
            )
        });
        cell.observers.clear();
        oracle::assert_no_warning(cell.sim(), kind.name());
        let event = log.lock().unwrap().clone();
        let event = event.unwrap_or_else(|| panic!("{kind} never fired"));
        eprintln!(
            "{kind}: {} at {:.2} s; success {}",
            event.detail, event.time, report.outcome.success
        );
        assert_eq!(event.kind, kind);
        // Every firing is logged, and there is exactly one: one `fault KIND:` line, at the
        // recorded time.
        let fired: Vec<&String> = lines
            .iter()
            .filter(|l| l.contains(&format!("fault {kind}: ")))
            .collect();
        assert_eq!(fired.len(), 1, "{kind}: {fired:#?}");
        assert!(fired[0].contains(&event.detail), "{kind}: {}", fired[0]);
        assert!(
            report.outcome.success,
            "{kind}: {:?}",
            report.outcome.failure_reason
        );
        oracle::assert_in(cell.sim_mut(), "cube", "bowl", kind.name());
    }
}
