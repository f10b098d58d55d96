//! Running a sweep: worker threads with one cell each, results handed on in scenario order,
//! bounded by a reorder window; a panicking episode is recorded as a failure.

use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use rayon::prelude::*;

use crate::actions::{CONTROL_PERIOD, Cell};
use crate::episode::{EpisodeObserver, NoObserver, run_in_cell};
use crate::factory::Factory;
use crate::failure::FailureKind;
use crate::plan::Plan;
use crate::sim::{Layout, Scene};
use crate::sweep::{ScenarioResult, SweepConfig};

/// Runs scenario `index` of `config` on the cell's scene in `cell` (reset first), with
/// `observer` seeing every control tick (a dataset recorder; [`NoObserver`] for none). A
/// scenario whose layout cannot be drawn is a `layout` failure that did not run.
pub fn run_scenario(
    cell: &mut Cell,
    plan: &Arc<Plan>,
    factory: &Factory,
    config: &SweepConfig,
    index: u64,
    observer: &mut dyn EpisodeObserver,
) -> ScenarioResult {
    match config.scenario(cell.sim().scene(), index) {
        Ok(scenario) => {
            let episode = config.episode_config(&scenario);
            let report = run_in_cell(cell, plan.clone(), factory, &episode, observer);
            ScenarioResult::new(&scenario, config, report)
        }
        Err(e) => ScenarioResult::not_run(
            config,
            index,
            0,
            None,
            crate::failure::Failure::new(FailureKind::Layout, format!("layout: {e}")),
        ),
    }
}

/// Most scenarios a sweep runs ahead of the first one not yet handed to its callback (at least
/// four per worker): bounds the results held while a slow scenario holds up the ones after it.
pub const REORDER_WINDOW: usize = 1024;

/// The outcome of a sweep.
#[derive(Debug, Clone)]
pub struct SweepRun {
    /// One result per scenario run, in index order.
    pub results: Vec<ScenarioResult>,
    /// Wall-clock time of the whole sweep, seconds.
    pub wall_time_s: f64,
    /// Worker threads used.
    pub jobs: usize,
    /// Wall-clock time the workers spent inside `mj_step`, summed over workers, seconds.
    pub physics_time_s: f64,
}

/// Runs the sweep on `config.jobs` worker threads (one [`Cell`] each) and calls `on_result` on
/// the calling thread for every scenario, in index order, as soon as it and all before it are
/// done. An episode that panics is recorded as a failure (its worker gets a fresh cell).
pub fn run_sweep(
    scene: &Scene,
    plan: &Arc<Plan>,
    factory: &Factory,
    config: &SweepConfig,
    mut on_result: impl FnMut(&ScenarioResult),
) -> Result<SweepRun, rayon::ThreadPoolBuildError> {
    run_sweep_from(scene, plan, factory, config, 0, |r| {
        on_result(r);
        ControlFlow::Continue(())
    })
}

/// [`run_sweep`] without the first `skip` scenarios of the sweep (those already done, see
/// [`resume`](crate::sweep::resume)), stopping as soon as `on_result` breaks: no scenario starts after that, the ones
/// already running are finished and dropped, and `results` ends with the one that broke.
pub fn run_sweep_from(
    scene: &Scene,
    plan: &Arc<Plan>,
    factory: &Factory,
    config: &SweepConfig,
    skip: u64,
    mut on_result: impl FnMut(&ScenarioResult) -> ControlFlow<()>,
) -> Result<SweepRun, rayon::ThreadPoolBuildError> {
    run_sweep_with(
        scene,
        config,
        skip,
        |cell, index| {
            (
                run_scenario(cell, plan, factory, config, index, &mut NoObserver),
                (),
            )
        },
        |r, _| on_result(r),
    )
}

/// [`run_sweep_from`] with a per-episode payload: `episode` runs scenario `index` in a worker's
/// cell and returns its result with a payload of any kind (a dataset recording), and
/// `on_result` receives both in scenario order (the payload is `None` for an episode that
/// panicked).
pub fn run_sweep_with<T: Send>(
    scene: &Scene,
    config: &SweepConfig,
    skip: u64,
    episode: impl Fn(&mut Cell, u64) -> (ScenarioResult, T) + Sync,
    mut on_result: impl FnMut(&ScenarioResult, Option<T>) -> ControlFlow<()>,
) -> Result<SweepRun, rayon::ThreadPoolBuildError> {
    // Memory grows with the results, not with the size of the sweep.
    let mut results = Vec::with_capacity(config.indices().skip_first(skip).len().min(4096));
    let mut run = run_sweep_streaming(scene, config, skip, episode, |r, payload| {
        let flow = on_result(&r, payload);
        results.push(r);
        flow
    })?;
    run.results = results;
    Ok(run)
}

/// [`run_sweep_with`] that keeps no result: each is handed to `on_result` (in scenario order)
/// and dropped, so memory does not grow with the number of scenarios. The returned
/// [`SweepRun`] has no `results`.
pub fn run_sweep_streaming<T: Send>(
    scene: &Scene,
    config: &SweepConfig,
    skip: u64,
    episode: impl Fn(&mut Cell, u64) -> (ScenarioResult, T) + Sync,
    mut on_result: impl FnMut(ScenarioResult, Option<T>) -> ControlFlow<()>,
) -> Result<SweepRun, rayon::ThreadPoolBuildError> {
    let wall = Instant::now();
    let episode = &episode;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(config.jobs)
        .thread_name(|i| format!("sweep-{i}"))
        .build()?;
    let jobs = pool.current_num_threads();
    let indices = config.indices().skip_first(skip);
    let mut next = 0usize;
    let (tx, rx) = mpsc::channel::<(usize, ScenarioResult, Option<T>)>();
    let stop = AtomicBool::new(false);
    let physics_ns = AtomicU64::new(0);
    // Results handed to `on_result` so far: a worker does not start a scenario more than
    // `window` places ahead, so results waiting for a slow earlier one stay bounded.
    let delivered = AtomicUsize::new(0);
    let window = REORDER_WINDOW.max(4 * jobs);
    std::thread::scope(|s| {
        let stop = &stop;
        let physics_ns = &physics_ns;
        let delivered = &delivered;
        s.spawn(move || {
            let new_cell = || Cell::new(scene, &Layout::default(), CONTROL_PERIOD);
            pool.install(|| {
                // par_bridge hands out scenarios in index order, so results arrive nearly in order.
                let todo = indices.take_while(|_| !stop.load(Ordering::Relaxed)).enumerate();
                todo.par_bridge().for_each_init(new_cell, |cell, (pos, index)| {
                    // Every scenario before `pos` is done or running on another worker, so the
                    // one the consumer waits for always progresses.
                    while pos >= delivered.load(Ordering::Acquire) + window && !stop.load(Ordering::Relaxed) {
                        std::thread::sleep(std::time::Duration::from_millis(1));
                    }
                    if stop.load(Ordering::Relaxed) {
                        return; // the consumer stopped: its result would be dropped
                    }
                    let before = cell.sim().physics_time();
                    let outcome = catch_unwind(AssertUnwindSafe(|| episode(cell, index)));
                    let spent = cell.sim().physics_time().saturating_sub(before);
                    physics_ns.fetch_add(
                        u64::try_from(spent.as_nanos()).unwrap_or(u64::MAX),
                        Ordering::Relaxed,
                    );
                    let (result, payload) = match outcome {
                        Ok((r, t)) => (r, Some(t)),
                        Err(payload) => {
                            *cell = new_cell();
                            let s = config.scenario(scene, index).ok();
                            let r = ScenarioResult::not_run(
                                config,
                                index,
                                s.as_ref().map_or(0, |s| s.seed),
                                s.and_then(|s| s.layout),
                                crate::failure::Failure::new(
                                    FailureKind::Panicked,
                                    format!("panicked: {}", panic_message(&*payload)),
                                ),
                            );
                            (r, None)
                        }
                    };
                    // The receiver lives until every result is in.
                    let _ = tx.send((pos, result, payload));
                });
            });
        });
        let mut pending = BTreeMap::new();
        for (pos, result, payload) in rx {
            if stop.load(Ordering::Relaxed) {
                continue; // draining the scenarios that were running
            }
            pending.insert(pos, (result, payload));
            while let Some((result, payload)) = pending.remove(&next) {
                next += 1;
                delivered.store(next, Ordering::Release);
                if on_result(result, payload).is_break() {
                    stop.store(true, Ordering::Relaxed);
                    break;
                }
            }
        }
    });
    Ok(SweepRun {
        results: Vec::new(),
        wall_time_s: wall.elapsed().as_secs_f64(),
        jobs,
        physics_time_s: physics_ns.load(Ordering::Relaxed) as f64 * 1e-9,
    })
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}
