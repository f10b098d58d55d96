//! Sweeps on real physics through the library API: a fixed seeded batch all succeeds; the JSONL
//! is identical for 1 and 2 jobs; the shards of a sweep together are the full sweep; a scenario's
//! printed `macrotree run …` command parses to exactly the sweep's episode and reproduces it.

use std::sync::Arc;

use clap::Parser;
use macrotree::actions::{CONTROL_PERIOD, Cell};
use macrotree::cli::{Cli, Command};
use macrotree::episode::{Goal, NoObserver, run_episode};
use macrotree::faults::FaultKind;
use macrotree::plan::Plan;
use macrotree::sim::Layout;
use macrotree::sweep::{ScenarioResult, Shard, Summary, SweepConfig, run_scenario, run_sweep, sample_layout};

const TREE: &str = "trees/cube_to_bowl.yaml";

use crate::support::flagship;
use flagship::scene;

fn plan() -> Arc<Plan> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(TREE);
    Arc::new(
        macrotree::plan::Loader::default()
            .load(&path)
            .expect("flagship tree is valid"),
    )
}

fn sweep(config: &SweepConfig) -> Vec<ScenarioResult> {
    let mut streamed = Vec::new();
    let run = run_sweep(
        scene(),
        &plan(),
        &macrotree::factory::Factory::builtin(),
        config,
        |r| streamed.push(r.index),
    )
    .expect("thread pool");
    let indices: Vec<u64> = run.results.iter().map(|r| r.index).collect();
    assert_eq!(
        indices,
        config.indices().collect::<Vec<_>>(),
        "results come in scenario order"
    );
    assert_eq!(streamed, indices, "results are streamed in scenario order");
    run.results
}

fn jsonl(results: &[ScenarioResult]) -> String {
    results.iter().map(|r| r.to_jsonl() + "\n").collect()
}

#[test]
fn a_fixed_seeded_batch_of_30_all_succeeds() {
    let config = SweepConfig {
        scenarios: 30,
        seed: 1,
        jobs: 2,
        ..SweepConfig::default()
    };
    let results = sweep(&config);
    let summary = Summary::new(TREE, &config, &results, 1.0, 2);
    eprint!("{}", summary.to_text());
    assert!(summary.all_succeeded(), "{}", summary.to_text());
    assert_eq!(summary.scenarios, 30);
    assert_eq!(summary.success_rate, 1.0);
    for r in &results {
        assert!(r.outcome.in_bowl() && r.outcome.grasp_attempts >= 1, "{r:?}");
    }
}

#[test]
fn the_same_seed_gives_identical_jsonl_for_one_and_two_jobs() {
    // With a fault, so that the fault's seeded timing is covered too.
    let config = SweepConfig {
        scenarios: 6,
        seed: 11,
        fault: Some(FaultKind::Slip),
        ..SweepConfig::default()
    };
    let one = jsonl(&sweep(&SweepConfig {
        jobs: 1,
        ..config.clone()
    }));
    let two = jsonl(&sweep(&SweepConfig { jobs: 2, ..config }));
    assert_eq!(one, two);
    assert!(
        !one.contains("wall_time"),
        "JSONL lines must not depend on the machine"
    );
}

#[test]
fn the_shards_of_a_sweep_together_are_the_full_sweep() {
    let config = SweepConfig {
        scenarios: 7,
        seed: 5,
        jobs: 2,
        ..SweepConfig::default()
    };
    let full = sweep(&config);
    let mut merged: Vec<ScenarioResult> = (0..3)
        .flat_map(|k| {
            let shard = Shard { index: k, count: 3 };
            let part = sweep(&SweepConfig {
                shard: Some(shard),
                ..config.clone()
            });
            assert!(part.iter().all(|r| shard.contains(r.index)));
            part
        })
        .collect();
    merged.sort_by_key(|r| r.index);
    assert_eq!(jsonl(&merged), jsonl(&full));
}

/// The `run` arguments a printed reproduction command parses to.
fn parse_run_command(cmd: &str) -> macrotree::episode::EpisodeConfig {
    let words: Vec<&str> = cmd.split_whitespace().collect();
    assert_eq!(&words[..3], ["macrotree", "run", TREE], "{cmd}");
    let cli = Cli::try_parse_from(words).unwrap_or_else(|e| panic!("{cmd}: {e}"));
    match cli.command {
        Command::Run(args) => args
            .episode
            .config_on(scene())
            .unwrap_or_else(|_| panic!("{cmd}: bad input")),
        other => panic!("{cmd} parsed to {other:?}"),
    }
}

#[test]
fn the_printed_command_reproduces_the_scenario_bit_for_bit() {
    let plan = plan();
    let config = SweepConfig {
        seed: 77,
        ..SweepConfig::default()
    };
    let mut cell = Cell::new(scene(), &Layout::default(), CONTROL_PERIOD);
    // A worker cell that already ran another scenario, as in a sweep.
    run_scenario(
        &mut cell,
        &plan,
        &macrotree::factory::Factory::builtin(),
        &config,
        0,
        &mut NoObserver,
    );
    for index in [1, 2] {
        let scenario = config.scenario(scene(), index).expect("a layout");
        let swept = run_scenario(
            &mut cell,
            &plan,
            &macrotree::factory::Factory::builtin(),
            &config,
            index,
            &mut NoObserver,
        );
        let cmd = swept.reproduce(TREE, &config);
        let parsed = parse_run_command(&cmd);
        // Bit-exact: the same layout (floats compared with ==), seed, limits.
        assert_eq!(parsed, config.episode_config(&scenario), "{cmd}");
        // And the same episode, run the way `macrotree run` runs it (a fresh cell).
        let report = run_episode(
            scene(),
            plan.clone(),
            &macrotree::factory::Factory::builtin(),
            &parsed,
            &mut NoObserver,
        );
        let again = ScenarioResult::new(&scenario, &config, report);
        assert_eq!(again.to_jsonl(), swept.to_jsonl(), "{cmd}");
    }
}

#[test]
fn reproduction_commands_spell_the_fault_the_goal_and_the_time_limit() {
    let config = SweepConfig {
        seed: 3,
        fault: Some(FaultKind::LateBowl),
        goal: Goal::Tree,
        max_sim_time: 12.5,
        ..SweepConfig::default()
    };
    let scenario = config.scenario(scene(), 4).expect("a layout");
    let mut cell = Cell::new(scene(), &Layout::default(), CONTROL_PERIOD);
    let r = run_scenario(
        &mut cell,
        &plan(),
        &macrotree::factory::Factory::builtin(),
        &config,
        4,
        &mut NoObserver,
    );
    let cmd = r.reproduce(TREE, &config);
    assert!(
        cmd.ends_with(" --fault late_bowl --goal tree --max-sim-time 12.5"),
        "{cmd}"
    );
    let words: Vec<&str> = cmd.split_whitespace().collect();
    let Command::Run(args) = Cli::try_parse_from(words).expect("parses").command else {
        panic!("not a run command: {cmd}");
    };
    assert_eq!(args.episode.fault, Some(FaultKind::LateBowl));
    let parsed = args
        .episode
        .config_on(scene())
        .unwrap_or_else(|_| panic!("bad input"));
    assert_eq!(parsed.placement, config.episode_config(&scenario).placement);
    assert_eq!(parsed.seed, scenario.seed);
    assert_eq!(parsed.max_sim_time, 12.5);
    assert_eq!(parsed.goal, Goal::Tree);
}

/// `run --fault K` must inject K: the reproduction commands of faulted sweeps rely on it.
/// (Regression: `EpisodeArgs::config` once dropped `--fault`.)
#[test]
fn run_fault_option_reaches_the_episode() {
    let (_, cmd) = sample_layout(3, 4);
    let words = [
        "macrotree".to_string(),
        "run".into(),
        TREE.into(),
        format!("--cube={},{},{}", cmd.cube[0], cmd.cube[1], cmd.cube[2]),
        "--fault".into(),
        "slip".into(),
    ];
    let Command::Run(args) = Cli::try_parse_from(words).expect("parses").command else {
        panic!("not a run command");
    };
    let config = args.episode.config().unwrap_or_else(|_| panic!("bad input"));
    assert_eq!(config.fault, Some(FaultKind::Slip));
}
