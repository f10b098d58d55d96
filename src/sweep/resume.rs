//! `sweep --resume`: continue an interrupted sweep from the results already in its JSONL file.
//!
//! A sweep writes its lines in scenario order, each whole, so an interrupted sweep leaves a
//! prefix of the complete file, possibly followed by one truncated line. [`read_existing`] keeps
//! the complete lines (reading one at a time: memory does not grow with the file) and drops the
//! truncated tail; the sweep then runs only the scenarios after
//! them ([`super::run_sweep_from`]), so the final file is byte-identical to that of an
//! uninterrupted run, and so is the summary (but for the wall time).
//!
//! The file carries no header; the lines themselves show that they belong to this sweep:
//!
//! - line `n` is scenario `n` of this sweep's (shard's) indices: the scenario count and the
//!   shard match;
//! - its `sweep_seed`, `fault`, episode `seed` and `layout` are those of that scenario of this
//!   sweep seed ([`SweepConfig::scenario`](super::SweepConfig::scenario)): the seed matches;
//! - its `success` agrees with its `tree_status` and goal (or `checks.in_bowl`) under this `--goal`;
//! - its `tree`, `scenarios`, `sweep_goal`, `max_sim_time`, `scene_file`, `substitutions`, `collision_policy` (and `suite`
//!   for `macrotree test`) are this sweep's;
//! - it is exactly what this version writes for the result it holds (no unknown or reordered
//!   fields);
//! - and [`spot_check`] runs the last kept scenario again and compares the line byte for byte:
//!   episodes are deterministic, so a different tree, goal or time limit shows up there.

use std::fmt;
use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde_json::Value;

use super::{ScenarioResult, SweepConfig, run_scenario};
use crate::actions::{CONTROL_PERIOD, Cell, Checks};
use crate::episode::{CubeBowlReport, EpisodeOutcome, Goal};
use crate::faults::FaultKind;
use crate::plan::Plan;
use crate::sim::{Layout, Scene};

/// The complete results found in an existing output file (read in bounded memory: each result
/// is handed to the caller and dropped).
#[derive(Debug, Clone, Default)]
pub struct Resumed {
    /// Bytes of the complete lines kept (a prefix of the file).
    pub kept_len: u64,
    /// Complete lines kept: scenario positions `0..count` of the sweep.
    pub count: u64,
    /// The last result kept (for [`spot_check`]).
    pub last: Option<ScenarioResult>,
    /// Bytes of a truncated last line that were dropped (0 when the file ended with a newline).
    pub dropped_bytes: u64,
}

/// Longest line read back, bytes (a result line is a few kilobytes).
pub const MAX_LINE_BYTES: u64 = 16 << 20;

/// Why an existing file cannot be resumed. `Display` says what and what to do.
#[derive(Debug)]
pub enum ResumeError {
    /// The file could not be read.
    Read {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A complete line is not a result of this sweep.
    Foreign {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// Why.
        reason: String,
    },
}

impl fmt::Display for ResumeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Read { path, source } => write!(f, "cannot resume from {}: {source}", path.display()),
            Self::Foreign { path, line, reason } => write!(
                f,
                "cannot resume from {}: line {line} is not a result of this sweep ({reason}); \
                 resume with the same tree, --scenarios, --seed, --fault, --goal, --shard and \
                 --max-sim-time, or run without --resume to start over",
                path.display()
            ),
        }
    }
}

impl std::error::Error for ResumeError {}

/// Reads the results of `config` already in `file` (open at `path`; see the
/// [module docs](self)), handing each to `on_result` in order. An empty file has none.
pub fn read_existing(
    file: &std::fs::File,
    path: &Path,
    scene: &Scene,
    config: &SweepConfig,
    mut on_result: impl FnMut(&ScenarioResult),
) -> Result<Resumed, ResumeError> {
    use std::io::{BufRead, Seek};
    let read_error = |source| ResumeError::Read {
        path: path.to_path_buf(),
        source,
    };
    if !file.metadata().map_err(read_error)?.is_file() {
        return Err(read_error(std::io::Error::other("not a regular file")));
    }
    let mut f = file;
    f.seek(std::io::SeekFrom::Start(0)).map_err(read_error)?;
    let mut reader = std::io::BufReader::new(f);
    let indices = config.indices();
    let mut out = Resumed::default();
    let mut line = Vec::new();
    loop {
        line.clear();
        let n = (&mut reader)
            .take(MAX_LINE_BYTES + 1)
            .read_until(b'\n', &mut line)
            .map_err(read_error)?;
        if n == 0 {
            break;
        }
        let foreign = |reason: String| ResumeError::Foreign {
            path: path.to_path_buf(),
            line: out.count + 1,
            reason,
        };
        if line.last() != Some(&b'\n') {
            if n as u64 > MAX_LINE_BYTES {
                return Err(foreign(format!("longer than {MAX_LINE_BYTES} bytes")));
            }
            out.dropped_bytes = n as u64; // a truncated last line
            break;
        }
        let text = std::str::from_utf8(&line[..n - 1]).map_err(|_| foreign("not UTF-8".into()))?;
        let Some(index) = indices.get(out.count) else {
            return Err(foreign(format!(
                "this sweep has only {} scenario(s)",
                indices.count_left()
            )));
        };
        let result = parse_line(text).map_err(foreign)?;
        check_result(&result, text, index, scene, config).map_err(foreign)?;
        on_result(&result);
        out.count += 1;
        out.kept_len += n as u64;
        out.last = Some(result);
    }
    Ok(out)
}

/// Runs the last kept scenario (`last`) again with this tree and configuration and checks that
/// it gives the same line: the check for what the lines do not carry (goal, time limit).
pub fn spot_check(
    scene: &Scene,
    plan: &Arc<Plan>,
    factory: &crate::factory::Factory,
    config: &SweepConfig,
    last: Option<&ScenarioResult>,
) -> Result<(), String> {
    let Some(last) = last else {
        return Ok(());
    };
    let mut cell = Cell::new(scene, &Layout::default(), CONTROL_PERIOD);
    let again = run_scenario(
        &mut cell,
        plan,
        factory,
        config,
        last.index,
        &mut crate::episode::NoObserver,
    );
    if again.to_jsonl() == last.to_jsonl() {
        Ok(())
    } else {
        Err(format!(
            "scenario {} gives a different result with this tree and options than the one in the \
             file (a different tree, --goal or --max-sim-time?)",
            last.index
        ))
    }
}

/// Checks that `r` (read from `line`) is scenario `index` of `config`, exactly as written.
fn check_result(
    r: &ScenarioResult,
    line: &str,
    index: u64,
    scene: &Scene,
    config: &SweepConfig,
) -> Result<(), String> {
    if r.index != index {
        return Err(format!(
            "it holds scenario {}, expected scenario {index}",
            r.index
        ));
    }
    if r.tree != config.tree {
        return Err(format!("tree {:?}, not {:?}", r.tree, config.tree));
    }
    if r.tree_digest != config.tree_digest {
        return Err(match &r.tree_digest {
            None => "it was written by an earlier version of macrotree, whose lines carry no \
                     digest of the tree (run without --resume to start over)"
                .into(),
            Some(d) => format!(
                "the tree, a file it includes or the scene changed since it was written (digest \
                 {}…, now {}…)",
                d.chars().take(12).collect::<String>(),
                config
                    .tree_digest
                    .as_deref()
                    .map_or(String::from("none"), |c| c.chars().take(12).collect())
            ),
        });
    }
    if r.sweep_goal != config.goal {
        return Err(format!(
            "--goal {}, not {}",
            r.sweep_goal.name(),
            config.goal.name()
        ));
    }
    if r.max_sim_time.to_bits() != config.max_sim_time.to_bits() {
        return Err(format!(
            "--max-sim-time {}, not {}",
            r.max_sim_time, config.max_sim_time
        ));
    }
    if r.scenarios != config.scenarios {
        return Err(format!("{} scenarios, not {}", r.scenarios, config.scenarios));
    }
    if r.collision_policy != config.collisions {
        return Err(format!(
            "--collisions {}, not {}",
            r.collision_policy.name(),
            config.collisions.name()
        ));
    }
    if r.substitutions != config.substitutions {
        return Err("its --substitute rules differ".into());
    }
    if r.suite != config.suite || r.scene_file != config.scene_file {
        return Err("its scenario file or --scene differs".into());
    }
    if r.sweep_seed != config.seed {
        return Err(format!("sweep seed {}, not {}", r.sweep_seed, config.seed));
    }
    if r.fault != config.fault {
        let name = |f: Option<FaultKind>| f.map_or("none", FaultKind::name);
        return Err(format!("fault {}, not {}", name(r.fault), name(config.fault)));
    }
    let s = config
        .scenario(scene, index)
        .map_err(|e| format!("scenario {index} cannot be drawn: {e}"))?;
    let initial: Vec<[f64; 3]> = r
        .outcome
        .objects
        .iter()
        .map(|o| [o.initial[0], o.initial[1], o.initial[3]])
        .collect();
    let drawn: Vec<[f64; 3]> = s
        .placement
        .poses
        .iter()
        .map(|p| [p.x, p.y, p.yaw.to_degrees()])
        .collect();
    let same_objects = initial.len() == drawn.len()
        && initial
            .iter()
            .zip(&drawn)
            .all(|(a, b)| (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9);
    if r.seed != s.seed || r.layout != s.layout || !same_objects || r.outcome.scene != scene.spec.name {
        return Err("its scene, layout or episode seed is not that of this sweep seed".into());
    }
    let goal_ok = match config.goal {
        Goal::Scene => r.outcome.goal.iter().all(|g| g.holds),
        Goal::Bowl => r.outcome.in_bowl(),
        Goal::Tree => true,
    };
    let met = r.outcome.tree_status == "success" && goal_ok;
    if r.outcome.success != met {
        return Err(format!(
            "its success does not follow from --goal {}",
            config.goal.name()
        ));
    }
    if r.to_jsonl() != line {
        return Err("it is not exactly what this version writes".into());
    }
    Ok(())
}

/// Reads one JSONL line back into the result it was written from.
pub fn parse_line(line: &str) -> Result<ScenarioResult, String> {
    let unchecked = super::digest::strip_checksum(line)?;
    let v: Value =
        serde_json::from_str(unchecked.as_deref().unwrap_or(line)).map_err(|e| format!("not JSON: {e}"))?;
    let tree_digest = match v.get("tree_digest") {
        None => None,
        Some(d) => Some(d.as_str().ok_or("`tree_digest` is not text")?.to_string()),
    };
    if tree_digest.is_some() != unchecked.is_some() {
        return Err("a line with a `tree_digest` ends with its `crc32`, and only such a line".into());
    }
    let field = |k: &str| v.get(k).ok_or_else(|| format!("no `{k}`"));
    let u64_of = |k: &str| field(k)?.as_u64().ok_or_else(|| format!("`{k}` is not a count"));
    let u32_of = |k: &str| u32::try_from(u64_of(k)?).map_err(|_| format!("`{k}` is too large"));
    let parsed = |k: &str| -> Result<Value, String> { Ok(field(k)?.clone()) };
    let failure_reason = match field("failure_reason")? {
        Value::Null => None,
        r => Some(r.as_str().ok_or("`failure_reason` is not text")?.to_string()),
    };
    let failure_kind = match field("failure_kind")? {
        Value::Null => None,
        k => {
            let name = k.as_str().ok_or("`failure_kind` is not text")?;
            let kind =
                crate::failure::FailureKind::parse(name).map_err(|e| format!("`failure_kind`: {e}"))?;
            Some(kind)
        }
    };
    let status = field("tree_status")?.as_str().unwrap_or_default();
    let fault = match field("fault")? {
        Value::Null => None,
        f => Some(
            FaultKind::ALL
                .into_iter()
                .find(|k| f.as_str() == Some(k.name()))
                .ok_or("unknown `fault`")?,
        ),
    };
    let text = |k: &str| -> Result<String, String> {
        Ok(field(k)?
            .as_str()
            .ok_or_else(|| format!("`{k}` is not text"))?
            .to_string())
    };
    let sweep_goal = text("sweep_goal")?;
    let substitutions = match v.get("substitutions") {
        None => Vec::new(),
        Some(list) => list
            .as_array()
            .ok_or("`substitutions` is not a list")?
            .iter()
            .map(|x| {
                x.as_str()
                    .ok_or_else(|| "`substitutions` holds a non-text item".to_string())?
                    .parse()
            })
            .collect::<Result<Vec<_>, String>>()
            .map_err(|e| format!("`substitutions`: {e}"))?,
    };
    Ok(ScenarioResult {
        suite: match v.get("suite") {
            None => None,
            Some(s) => Some(s.as_str().ok_or("`suite` is not text")?.to_string()),
        },
        tree: text("tree")?,
        scene_file: match v.get("scene_file") {
            None => None,
            Some(s) => Some(s.as_str().ok_or("`scene_file` is not text")?.to_string()),
        },
        scenarios: u64_of("scenarios")?,
        sweep_goal: [Goal::Scene, Goal::Bowl, Goal::Tree]
            .into_iter()
            .find(|g| g.name() == sweep_goal)
            .ok_or("unknown `sweep_goal`")?,
        max_sim_time: float(field("max_sim_time")?, "max_sim_time")?,
        substitutions,
        collision_policy: match v.get("collision_policy") {
            None => crate::episode::CollisionPolicy::Count,
            Some(p) => p
                .as_str()
                .and_then(|p| p.parse().ok())
                .ok_or("`collision_policy` is not `count` or `fail`")?,
        },
        index: u64_of("index")?,
        sweep_seed: u64_of("sweep_seed")?,
        seed: u64_of("seed")?,
        fault,
        layout: match v.get("layout") {
            None => None,
            Some(layout) => Some(super::ScenarioLayout {
                cube: floats(layout.get("cube"), "layout.cube")?,
                bowl: floats(layout.get("bowl"), "layout.bowl")?,
            }),
        },
        outcome: EpisodeOutcome {
            success: field("success")?.as_bool().ok_or("`success` is not a boolean")?,
            tree_status: ["success", "failure", "running"]
                .into_iter()
                .find(|s| *s == status)
                .ok_or("unknown `tree_status`")?,
            failure_kind,
            failure_reason,
            sim_time_s: float(field("sim_time_s")?, "sim_time_s")?,
            grasp_attempts: u32_of("grasp_attempts")?,
            halts: u32_of("halts")?,
            physics_steps: u64_of("physics_steps")?,
            cube_bowl: v.get("cube_final").map(|c| cube_bowl(&v, c)).transpose()?,
            scene: field("scene")?.as_str().ok_or("`scene` is not text")?.to_string(),
            objects: serde_json::from_value(parsed("objects")?).map_err(|e| format!("`objects`: {e}"))?,
            goal: serde_json::from_value(parsed("goal")?).map_err(|e| format!("`goal`: {e}"))?,
            collisions: serde_json::from_value(parsed("collisions")?)
                .map_err(|e| format!("`collisions`: {e}"))?,
            failed_node: serde_json::from_value(parsed("failed_node")?)
                .map_err(|e| format!("`failed_node`: {e}"))?,
            nodes: serde_json::from_value(parsed("nodes")?).map_err(|e| format!("`nodes`: {e}"))?,
        },
        tree_digest,
        wall_time_s: 0.0,
        planning: match v.get("planning") {
            None => Default::default(),
            Some(p) => serde_json::from_value(p.clone()).map_err(|e| format!("`planning`: {e}"))?,
        },
        planning_wall_s: 0.0,
    })
}

/// A number; `null` stands for NaN (which JSON cannot spell).
fn float(v: &Value, name: &str) -> Result<f64, String> {
    match v {
        Value::Null => Ok(f64::NAN),
        v => v.as_f64().ok_or_else(|| format!("`{name}` is not a number")),
    }
}

/// The flagship's legacy section of line `v`, whose `cube_final` is `cube_final`.
fn cube_bowl(v: &Value, cube_final: &Value) -> Result<CubeBowlReport, String> {
    let checks = v.get("checks").ok_or("`cube_final` without `checks`")?;
    Ok(CubeBowlReport {
        cube_final: floats(Some(cube_final), "cube_final")?,
        bowl_target: v
            .get("bowl_target")
            .map(|x| floats(Some(x), "bowl_target"))
            .transpose()?,
        checks: Checks {
            grasp_distance: match checks.get("grasp_distance") {
                Some(Value::Null) => None,
                d => Some(float(
                    d.ok_or("no `checks.grasp_distance`")?,
                    "checks.grasp_distance",
                )?),
            },
            cube_motion_while_closed: float_at(checks, "cube_motion_while_closed")?,
            cube_lift_while_closed: float_at(checks, "cube_lift_while_closed")?,
            home_error: float_at(checks, "home_error")?,
            in_bowl: checks
                .get("in_bowl")
                .and_then(Value::as_bool)
                .ok_or("`checks.in_bowl` is not a boolean")?,
        },
    })
}

fn float_at(v: &Value, key: &str) -> Result<f64, String> {
    float(
        v.get(key).ok_or_else(|| format!("no `checks.{key}`"))?,
        &format!("checks.{key}"),
    )
}

fn floats<const N: usize>(v: Option<&Value>, name: &str) -> Result<[f64; N], String> {
    let items = v
        .and_then(Value::as_array)
        .filter(|a| a.len() == N)
        .ok_or_else(|| format!("`{name}` is not a list of {N} numbers"))?;
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(items) {
        *o = float(x, name)?;
    }
    Ok(out)
}
