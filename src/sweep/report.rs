//! `macrotree report FILE.jsonl…`: shard outputs merged back into one run.
//!
//! Every line of a sweep's (or a suite's) JSONL carries the sweep's identity — tree, scene file,
//! scene, scenario count, seed, fault, goal, time limit, collision policy, substitutions and,
//! for `macrotree test`, the scenario file — so the lines of all shards can be checked to belong to one run and put
//! back in scenario order. The merged results are exactly those of one unsharded run (the
//! lines are byte-identical), so the summary built from them is too, but for the wall time and
//! job count, which the lines do not carry (a merged summary says 0 for both).

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use super::resume::parse_line;
use super::{ScenarioResult, SweepConfig};
use crate::faults::FaultKind;

/// Most lines `report` reads (over all files).
pub const MAX_LINES: usize = 10_000_000;

/// Why shard outputs cannot be merged. `Display` names the file, line and what differs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MergeError(pub String);

impl fmt::Display for MergeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for MergeError {}

/// One merged run: the sweep it was and its results in scenario order.
#[derive(Debug, Clone)]
pub struct Merged {
    /// The sweep (its shard is `None`, its jobs 0).
    pub config: SweepConfig,
    /// All its results, by index.
    pub results: Vec<ScenarioResult>,
    /// The files its lines came from, in the order given, with how many lines each held.
    pub sources: Vec<Source>,
}

/// A file some of a merged run's lines came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Source {
    /// The file, as given.
    pub path: PathBuf,
    /// Its result lines of this run.
    pub lines: u64,
}

/// Where a line came from.
#[derive(Debug, Clone)]
struct Origin {
    file: PathBuf,
    line: usize,
}

impl fmt::Display for Origin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.file.display(), self.line)
    }
}

/// The identity a line claims, compared across lines of one run.
fn identity(r: &ScenarioResult) -> Vec<(&'static str, String)> {
    vec![
        ("tree", r.tree.clone()),
        ("scene file", format!("{:?}", r.scene_file)),
        ("scene", r.outcome.scene.clone()),
        ("tree digest", r.tree_digest.clone().unwrap_or_default()),
        ("scenario count", r.scenarios.to_string()),
        ("seed", r.sweep_seed.to_string()),
        ("fault", r.fault.map_or("none", FaultKind::name).to_string()),
        ("goal", r.sweep_goal.name().to_string()),
        ("max sim time", format!("{:?}", r.max_sim_time)),
        ("collision policy", r.collision_policy.name().to_string()),
        (
            "substitutions",
            r.substitutions
                .iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(" "),
        ),
    ]
}

/// Reads `files` (JSONL written by `sweep --out` or `test --out`, any shards, any order) and
/// merges them: one [`Merged`] per scenario file (`suite`), sorted by its path, or a single
/// one for a sweep. Refuses lines that are not results, results of different runs mixed
/// (naming what differs), duplicate scenarios and missing ones (naming them).
pub fn merge_results(files: &[PathBuf]) -> Result<Vec<Merged>, MergeError> {
    let mut groups: BTreeMap<Option<String>, Vec<(Origin, ScenarioResult)>> = BTreeMap::new();
    let mut per_file: BTreeMap<(Option<String>, usize), u64> = BTreeMap::new();
    let mut total = 0usize;
    for (file_index, file) in files.iter().enumerate() {
        let text = read(file)?;
        for (i, line) in text.lines().enumerate() {
            let origin = Origin {
                file: file.clone(),
                line: i + 1,
            };
            if line.trim().is_empty() {
                continue;
            }
            total += 1;
            if total > MAX_LINES {
                return Err(MergeError(format!(
                    "more than {MAX_LINES} lines; merge fewer files at once"
                )));
            }
            let r = parse_line(line).map_err(|e| {
                MergeError(format!(
                    "{origin}: not a result line of `macrotree sweep --out` or `test --out` ({e})"
                ))
            })?;
            if r.to_jsonl() != line {
                return Err(MergeError(format!(
                    "{origin}: not exactly what this version writes (edited, or written by another version)"
                )));
            }
            *per_file.entry((r.suite.clone(), file_index)).or_default() += 1;
            groups.entry(r.suite.clone()).or_default().push((origin, r));
        }
    }
    if groups.is_empty() {
        return Err(MergeError("no results in the given files".into()));
    }
    if groups.contains_key(&None) && groups.len() > 1 {
        return Err(MergeError(
            "the files mix sweep results and `macrotree test` results; report them separately".into(),
        ));
    }
    groups
        .into_iter()
        .map(|(suite, g)| {
            let sources = files
                .iter()
                .enumerate()
                .filter_map(|(i, path)| {
                    let lines = *per_file.get(&(suite.clone(), i))?;
                    Some(Source {
                        path: path.clone(),
                        lines,
                    })
                })
                .collect();
            merge_group(g, sources)
        })
        .collect()
}

fn merge_group(mut lines: Vec<(Origin, ScenarioResult)>, sources: Vec<Source>) -> Result<Merged, MergeError> {
    let (first_origin, first) = lines[0].clone();
    let want = identity(&first);
    let what = first
        .suite
        .as_ref()
        .map_or("sweep".to_string(), |s| format!("scenario file {s}"));
    for (origin, r) in &lines[1..] {
        for ((name, a), (_, b)) in want.iter().zip(identity(r)) {
            if *a != b {
                return Err(MergeError(format!(
                    "{origin} is from another run of the {what}: its {name} is {b}, but {first_origin} has {a}; merge only the shards of one run"
                )));
            }
        }
    }
    lines.sort_by_key(|(_, r)| r.index);
    let mut duplicates = Vec::new();
    for w in lines.windows(2) {
        if w[0].1.index == w[1].1.index {
            duplicates.push(format!("scenario {} ({} and {})", w[1].1.index, w[0].0, w[1].0));
        }
    }
    if !duplicates.is_empty() {
        return Err(MergeError(format!(
            "{what}: duplicate scenarios: {}{} (was a shard given twice?)",
            duplicates.iter().take(10).cloned().collect::<Vec<_>>().join(", "),
            if duplicates.len() > 10 { ", …" } else { "" }
        )));
    }
    let n = first.scenarios;
    if lines.len() as u64 != n || lines.iter().any(|(_, r)| r.index >= n) {
        let present: std::collections::HashSet<u64> = lines.iter().map(|(_, r)| r.index).collect();
        let missing: Vec<u64> = (0..n).filter(|i| !present.contains(i)).take(11).collect();
        let extra: Vec<u64> = lines
            .iter()
            .map(|(_, r)| r.index)
            .filter(|&i| i >= n)
            .take(10)
            .collect();
        if !extra.is_empty() {
            return Err(MergeError(format!(
                "{what}: scenario(s) {extra:?} are beyond its {n} scenarios"
            )));
        }
        let listed: Vec<String> = missing.iter().take(10).map(u64::to_string).collect();
        return Err(MergeError(format!(
            "{what}: {} of {n} scenarios are missing: {}{} (a shard not finished or not given?)",
            n - lines.len() as u64,
            listed.join(", "),
            if missing.len() > 10 { ", …" } else { "" }
        )));
    }
    let config = SweepConfig {
        scenarios: n,
        seed: first.sweep_seed,
        jobs: 0,
        fault: first.fault,
        goal: first.sweep_goal,
        shard: None,
        max_sim_time: first.max_sim_time,
        scene_file: first.scene_file.clone(),
        tree: first.tree.clone(),
        substitutions: first.substitutions.clone(),
        suite: first.suite.clone(),
        tree_digest: first.tree_digest.clone(),
        collisions: first.collision_policy,
        ..SweepConfig::default()
    };
    Ok(Merged {
        config,
        results: lines.into_iter().map(|(_, r)| r).collect(),
        sources,
    })
}

fn read(path: &Path) -> Result<String, MergeError> {
    let meta = std::fs::metadata(path).map_err(|e| MergeError(format!("{}: {e}", path.display())))?;
    if !meta.is_file() {
        return Err(MergeError(format!("{}: not a regular file", path.display())));
    }
    let bytes = std::fs::read(path).map_err(|e| MergeError(format!("{}: {e}", path.display())))?;
    let text = String::from_utf8(bytes).map_err(|_| MergeError(format!("{}: not UTF-8", path.display())))?;
    if !text.is_empty() && !text.ends_with('\n') {
        return Err(MergeError(format!(
            "{}: the last line is incomplete (an interrupted run? finish it with --resume first)",
            path.display()
        )));
    }
    Ok(text)
}
