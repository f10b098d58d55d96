//! Shards: `--shard K/M` and the shard a Slurm array or Kubernetes Indexed Job task runs.

use std::str::FromStr;

use serde::Serialize;

/// `--shard K/M`: the scenarios whose index is ≡ K (mod M), `0 ≤ K < M`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Shard {
    /// K.
    pub index: u64,
    /// M.
    pub count: u64,
}

impl Shard {
    /// Scenario `i` belongs to this shard.
    pub fn contains(&self, i: u64) -> bool {
        i % self.count == self.index
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let form = "expected K/M with 0 ≤ K < M, e.g. 0/4 (shard K of M, counted from 0)";
        let (k, m) = s.split_once('/').ok_or_else(|| format!("{s:?}: {form}"))?;
        let k: u64 = k.trim().parse().map_err(|_| format!("{s:?}: {form}"))?;
        let m: u64 = m.trim().parse().map_err(|_| format!("{s:?}: {form}"))?;
        if m == 0 || k >= m {
            return Err(format!("{s:?}: {form}"));
        }
        Ok(Self { index: k, count: m })
    }
}

/// `--shard`: a fixed `K/M`, or `auto` (from a Slurm array or a Kubernetes Indexed Job).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShardSpec {
    /// `K/M`.
    Fixed(Shard),
    /// `auto`: see [`Shard::from_env`].
    Auto,
}

impl FromStr for ShardSpec {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s.trim() == "auto" {
            Ok(ShardSpec::Auto)
        } else {
            s.parse()
                .map(ShardSpec::Fixed)
                .map_err(|e| format!("{e}, or auto"))
        }
    }
}

/// Most shards `--shard auto` accepts from the environment.
pub const MAX_AUTO_SHARDS: u64 = 1_000_000;

impl Shard {
    /// The shard of this process in a job array, read through `var` (the environment):
    ///
    /// - Slurm array (`sbatch --array=0-3`): K = `SLURM_ARRAY_TASK_ID` − `SLURM_ARRAY_TASK_MIN`
    ///   (0 when unset), M = `SLURM_ARRAY_TASK_COUNT`; `count`, if given, must equal M;
    /// - Kubernetes Indexed Job: K = `JOB_COMPLETION_INDEX`, M = `count` (the Job's
    ///   `completions`, which the pod cannot read), required.
    ///
    /// Errors say which variable is missing or inconsistent.
    pub fn from_env(var: impl Fn(&str) -> Option<String>, count: Option<u64>) -> Result<Shard, String> {
        let num = |name: &str| -> Result<Option<u64>, String> {
            match var(name) {
                None => Ok(None),
                Some(v) => v
                    .trim()
                    .parse::<u64>()
                    .map(Some)
                    .map_err(|_| format!("{name}={v:?} is not a whole number")),
            }
        };
        let check = |k: u64, m: u64, how: &str| -> Result<Shard, String> {
            if m == 0 || m > MAX_AUTO_SHARDS {
                return Err(format!(
                    "{how}: the shard count must be 1 to {MAX_AUTO_SHARDS}, got {m}"
                ));
            }
            if k >= m {
                return Err(format!("{how}: index {k} is not below the shard count {m}"));
            }
            Ok(Shard { index: k, count: m })
        };
        if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
            let m = num("SLURM_ARRAY_TASK_COUNT")?.ok_or(
                "SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not (run as an array job: sbatch --array=0-M-1)",
            )?;
            let min = num("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let k = id
                .checked_sub(min)
                .ok_or_else(|| format!("SLURM_ARRAY_TASK_ID {id} is below SLURM_ARRAY_TASK_MIN {min}"))?;
            if let Some(c) = count
                && c != m
            {
                return Err(format!(
                    "--shard-count {c} disagrees with SLURM_ARRAY_TASK_COUNT {m}"
                ));
            }
            if let Some(step) = num("SLURM_ARRAY_TASK_STEP")?
                && step != 1
            {
                return Err(format!(
                    "SLURM_ARRAY_TASK_STEP is {step}: use a contiguous array (--array=0-{})",
                    m.saturating_sub(1)
                ));
            }
            return check(k, m, "Slurm array");
        }
        if let Some(k) = num("JOB_COMPLETION_INDEX")? {
            let m =
                count.ok_or("JOB_COMPLETION_INDEX is set: give the Job's completions as --shard-count M")?;
            return check(k, m, "Kubernetes Indexed Job");
        }
        Err(
            "neither a Slurm array (SLURM_ARRAY_TASK_ID, SLURM_ARRAY_TASK_COUNT) nor a Kubernetes \
             Indexed Job (JOB_COMPLETION_INDEX) is in the environment; give --shard K/M"
                .into(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::SweepConfig;

    #[test]
    fn shards_parse_and_reject_bad_input() {
        assert_eq!("1/4".parse::<Shard>(), Ok(Shard { index: 1, count: 4 }));
        for bad in ["3/2", "2/2", "0/0", "1", "a/2", "-1/2", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn shards_partition_the_indices() {
        let all = SweepConfig {
            scenarios: 10,
            ..SweepConfig::default()
        };
        let mut union: Vec<u64> = (0..3)
            .flat_map(|k| {
                SweepConfig {
                    shard: Some(Shard { index: k, count: 3 }),
                    ..all.clone()
                }
                .indices()
            })
            .collect();
        union.sort();
        assert_eq!(union, all.indices().collect::<Vec<_>>());
    }
}
