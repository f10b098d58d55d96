//! `--fault bump` and `--fault late_bowl` on real physics: the fault really moves the object (the
//! cube is knocked along the table; the bowl slides), the flagship tree still puts the cube in the
//! bowl where the bowl now is (judged by the independent oracle), and seeded batches of 20
//! recover.

use macrotree::actions::{CONTROL_PERIOD, Cell};
use macrotree::episode::{EpisodeConfig, EpisodeObserver, run_in_cell};
use macrotree::faults::{FaultKind, injector_with_log};
use macrotree::runtime::TreeRunner;
use macrotree::sim::Layout;
use macrotree::sweep::{SweepConfig, sample_layout};
use nalgebra::Vector3;

use crate::support::flagship;
use crate::support::logs;
use crate::support::oracle;
use flagship::{plan, scene, sweep_flagship};

/// The cube's and the bowl's positions after every tick.
#[derive(Default)]
struct Track {
    samples: Vec<(f64, Vector3<f64>, Vector3<f64>)>,
}

impl EpisodeObserver for Track {
    fn on_tick(&mut self, cell: &Cell, _runner: &mut TreeRunner) {
        let w = cell.world();
        let (cube, bowl) = (w.cube().expect("a cube"), w.bowl().expect("a bowl"));
        self.samples
            .push((w.time, w.objects[cube].pos, w.objects[bowl].pos));
    }
}

/// The cube's and the bowl's positions, metres.
type Positions = (Vector3<f64>, Vector3<f64>);

/// What one faulted episode left: its cell, report, the fault's firing and the track.
type Episode = (
    Cell,
    macrotree::episode::EpisodeReport,
    macrotree::faults::FaultEvent,
    Track,
);

impl Track {
    /// The last sample before `t` and the first sample at least `after` seconds later.
    fn around(&self, t: f64, after: f64) -> (Positions, Positions) {
        let before = self
            .samples
            .iter()
            .rev()
            .find(|s| s.0 < t)
            .expect("a sample before the fault");
        let later = self
            .samples
            .iter()
            .find(|s| s.0 >= t + after)
            .expect("a sample after the fault");
        ((before.1, before.2), (later.1, later.2))
    }
}

/// Runs scenario `index` of sweep seed 2024 with `kind` injected, in a fresh cell; returns the
/// cell, the report, the fault's firing and the track.
fn episode(kind: FaultKind, index: u64) -> Episode {
    let (seed, layout) = sample_layout(2024, index);
    let config = EpisodeConfig {
        placement: Some(scene().placement_from_layout(&layout.to_layout())),
        seed,
        ..EpisodeConfig::default()
    };
    let mut cell = Cell::new(scene(), &Layout::default(), CONTROL_PERIOD);
    let (fault, log) = injector_with_log(kind, config.seed);
    cell.observers.push(fault);
    let mut track = Track::default();
    let (report, lines) = logs::capture(|| {
        run_in_cell(
            &mut cell,
            plan(),
            &macrotree::factory::Factory::builtin(),
            &config,
            &mut track,
        )
    });
    let event = log
        .lock()
        .unwrap()
        .clone()
        .unwrap_or_else(|| panic!("{kind} #{index} never fired"));
    let fired = lines
        .iter()
        .filter(|l| l.contains(&format!("fault {kind}: ")))
        .count();
    assert_eq!(fired, 1, "{kind} #{index}: logged {fired} firings");
    oracle::assert_no_warning(cell.sim(), &format!("{kind} #{index}"));
    (cell, report, event, track)
}

#[test]
fn a_bump_really_knocks_the_cube_and_the_tree_picks_it_up_where_it_lies() {
    for index in 0..3 {
        let (mut cell, report, event, track) = episode(FaultKind::Bump, index);
        // The bump pushes for a few steps; 0.3 s later the cube has come to rest 3–6 cm away
        // (docs/faults.md), along the table.
        let ((cube0, _), (cube1, _)) = track.around(event.time, 0.3);
        let moved = (cube1 - cube0).xy().norm();
        eprintln!(
            "bump #{index}: {}; moved {:.1} mm; {:?}",
            event.detail,
            moved * 1e3,
            report.outcome.failure_reason
        );
        assert!(
            (0.02..0.08).contains(&moved),
            "bump #{index}: the cube moved {moved} m"
        );
        assert!(
            cube1.z < 0.03,
            "bump #{index}: the cube left the table: {cube1:?}"
        );
        assert!(
            report.outcome.success,
            "bump #{index}: {:?}",
            report.outcome.failure_reason
        );
        oracle::assert_in(cell.sim_mut(), "cube", "bowl", &format!("bump #{index}"));
    }
}

#[test]
fn a_late_bowl_really_moves_the_bowl_and_the_cube_lands_where_it_now_is() {
    for index in 0..3 {
        let (mut cell, report, event, track) = episode(FaultKind::LateBowl, index);
        // The bowl slides over 0.25 s; 0.3 s after it starts it stands 3–6 cm from where it was.
        let ((_, bowl0), (_, bowl1)) = track.around(event.time, 0.3);
        let moved = (bowl1 - bowl0).xy().norm();
        eprintln!(
            "late_bowl #{index}: {}; moved {:.1} mm",
            event.detail,
            moved * 1e3
        );
        assert!(
            (0.03..=0.0601).contains(&moved),
            "late_bowl #{index}: the bowl moved {moved} m"
        );
        let end = track.samples.last().unwrap().2;
        assert!(
            (end - bowl1).norm() < 1e-9,
            "late_bowl #{index}: the bowl moved again"
        );
        assert!(
            report.outcome.success,
            "late_bowl #{index}: {:?}",
            report.outcome.failure_reason
        );
        // In the bowl where it is now (the oracle reads the bowl's floor geom in MuJoCo).
        oracle::assert_in(cell.sim_mut(), "cube", "bowl", &format!("late_bowl #{index}"));
    }
}

fn batch(kind: FaultKind) {
    let config = SweepConfig {
        scenarios: 20,
        seed: 77,
        jobs: 2,
        fault: Some(kind),
        ..SweepConfig::default()
    };
    let run = sweep_flagship(&config);
    assert_eq!(run.results.len(), 20);
    let ok = run.results.iter().filter(|r| r.outcome.success).count();
    eprintln!("{kind}: {ok}/20 recovered");
    for r in &run.results {
        // A MuJoCo warning would be a failure with its reason (the episode stops on it).
        assert!(
            r.outcome.success,
            "{kind} #{} {:?}: {:?}",
            r.index, r.layout, r.outcome.failure_reason
        );
        assert!(r.outcome.in_bowl(), "{kind} #{}", r.index);
    }
}

#[test]
fn twenty_seeded_bumps_all_recover() {
    batch(FaultKind::Bump);
}

#[test]
fn twenty_seeded_late_bowls_all_recover() {
    batch(FaultKind::LateBowl);
}
