//! [`Timings`]: how long the lines of a sweep's `--out` file took to make, written beside it
//! (`FILE.timing.json`) so that `macrotree report` gives a merged run the wall time, job count
//! and physics and planning shares one run prints. The lines themselves stay the same bytes for
//! any machine and `--jobs`; the times live only here.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// Largest timing file read, bytes.
pub const MAX_TIMING_BYTES: u64 = 1 << 20;
/// Most runs one timing file records (a file resumed this many times stops adding to it).
pub const MAX_RUNS: usize = 1000;
/// Largest time a run may record, seconds (a year).
const MAX_SECONDS: f64 = 366.0 * 86_400.0;

/// One run of `sweep --out` (a resumed file has one per run that added lines to it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunTiming {
    /// Result lines this run wrote.
    pub lines: u64,
    /// Worker threads.
    pub jobs: usize,
    /// Wall-clock time of the sweep, seconds.
    pub wall_time_s: f64,
    /// Wall-clock time of the whole process up to the end of the sweep, seconds.
    pub process_wall_time_s: f64,
    /// Time inside `mj_step`, summed over the workers, seconds.
    pub physics_time_s: f64,
    /// Time checking and planning motions, summed over the workers, seconds.
    pub planning_time_s: f64,
}

/// The runs behind one `--out` file, in the order they ran.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Timings {
    /// Each run.
    pub runs: Vec<RunTiming>,
}

/// The times of runs put together ([`Timings::total`], [`Total::beside`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Total {
    /// Result lines covered.
    pub lines: u64,
    /// Worker threads: the most of one file's runs, summed over files (shards run side by side).
    pub jobs: usize,
    /// Wall-clock time: one file's runs added (they ran one after another), the longest file.
    pub wall_time_s: f64,
    /// Worker time: jobs × the process's wall-clock time, summed over every run, seconds.
    pub worker_time_s: f64,
    /// Time inside `mj_step`, summed over every run, seconds.
    pub physics_time_s: f64,
    /// Time checking and planning motions, summed over every run, seconds.
    pub planning_time_s: f64,
}

impl RunTiming {
    /// Why this run's figures cannot be true, if they cannot.
    fn check(&self) -> Result<(), String> {
        let times = [
            ("wall_time_s", self.wall_time_s),
            ("process_wall_time_s", self.process_wall_time_s),
            ("physics_time_s", self.physics_time_s),
            ("planning_time_s", self.planning_time_s),
        ];
        for (name, t) in times {
            if !(0.0..=MAX_SECONDS).contains(&t) {
                return Err(format!(
                    "`{name}` is {t}; expected seconds within 0 … {MAX_SECONDS}"
                ));
            }
        }
        if !(1..=crate::sweep::MAX_JOBS).contains(&self.jobs) {
            return Err(format!(
                "`jobs` is {}; expected 1 … {}",
                self.jobs,
                crate::sweep::MAX_JOBS
            ));
        }
        if self.lines > super::MAX_LINES as u64 {
            return Err(format!(
                "`lines` is {}; expected at most {}",
                self.lines,
                super::MAX_LINES
            ));
        }
        Ok(())
    }
}

impl Timings {
    /// The timing file of the `--out` file `out`: `out` with `.timing.json` added.
    pub fn path_beside(out: &Path) -> PathBuf {
        let mut name = out.as_os_str().to_owned();
        name.push(".timing.json");
        PathBuf::from(name)
    }

    /// These runs and then `run` (the oldest forgotten beyond [`MAX_RUNS`]).
    #[must_use]
    pub fn then(mut self, run: RunTiming) -> Timings {
        self.runs.push(run);
        if self.runs.len() > MAX_RUNS {
            self.runs.remove(0);
        }
        self
    }

    /// Result lines of all runs.
    pub fn lines(&self) -> u64 {
        self.runs.iter().map(|r| r.lines).sum()
    }

    /// The runs of one file put together (`None` for none).
    pub fn total(&self) -> Option<Total> {
        let first = self.runs.first()?;
        let mut t = Total {
            lines: 0,
            jobs: first.jobs,
            wall_time_s: 0.0,
            worker_time_s: 0.0,
            physics_time_s: 0.0,
            planning_time_s: 0.0,
        };
        for r in &self.runs {
            t.lines += r.lines;
            t.jobs = t.jobs.max(r.jobs);
            t.wall_time_s += r.wall_time_s;
            t.worker_time_s += r.jobs as f64 * r.process_wall_time_s;
            t.physics_time_s += r.physics_time_s;
            t.planning_time_s += r.planning_time_s;
        }
        Some(t)
    }

    /// Reads the timing file at `path`: `Ok(None)` when there is none; an error says what is
    /// wrong with one that is there (too large, not this JSON, a figure out of range).
    pub fn read(path: &Path) -> Result<Option<Timings>, String> {
        let meta = match std::fs::metadata(path) {
            Ok(m) => m,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(format!("{}: {e}", path.display())),
        };
        if !meta.is_file() || meta.len() > MAX_TIMING_BYTES {
            return Err(format!(
                "{}: not a timing file (a regular file of at most {MAX_TIMING_BYTES} bytes)",
                path.display()
            ));
        }
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let t: Timings = serde_json::from_str(&text).map_err(|e| {
            format!(
                "{}: not a timing file of `sweep --out` ({e}); delete it to report without timings",
                path.display()
            )
        })?;
        if t.runs.len() > MAX_RUNS {
            return Err(format!("{}: more than {MAX_RUNS} runs", path.display()));
        }
        for (i, r) in t.runs.iter().enumerate() {
            r.check()
                .map_err(|e| format!("{}: run {}: {e}", path.display(), i + 1))?;
        }
        Ok(Some(t))
    }

    /// The file's text.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("timings serialize");
        s.push('\n');
        s
    }
}

impl Total {
    /// These times and those of files run side by side with them (the shards of one sweep).
    #[must_use]
    pub fn beside(self, other: Total) -> Total {
        Total {
            lines: self.lines + other.lines,
            jobs: self.jobs + other.jobs,
            wall_time_s: self.wall_time_s.max(other.wall_time_s),
            worker_time_s: self.worker_time_s + other.worker_time_s,
            physics_time_s: self.physics_time_s + other.physics_time_s,
            planning_time_s: self.planning_time_s + other.planning_time_s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(lines: u64, jobs: usize, wall: f64) -> RunTiming {
        RunTiming {
            lines,
            jobs,
            wall_time_s: wall,
            process_wall_time_s: wall + 1.0,
            physics_time_s: wall * jobs as f64 * 0.5,
            planning_time_s: 0.25,
        }
    }

    #[test]
    fn a_resumed_files_runs_add_up_and_shards_run_side_by_side() {
        let a = Timings::default().then(run(3, 2, 10.0)).then(run(2, 1, 4.0));
        let ta = a.total().unwrap();
        assert_eq!((ta.lines, ta.jobs), (5, 2));
        assert_eq!(ta.wall_time_s, 14.0);
        assert_eq!(ta.worker_time_s, 2.0 * 11.0 + 5.0);
        assert_eq!(ta.physics_time_s, 10.0 + 2.0);
        let b = Timings::default().then(run(5, 2, 12.0)).total().unwrap();
        let both = ta.beside(b);
        assert_eq!((both.lines, both.jobs), (10, 4));
        assert_eq!(both.wall_time_s, 14.0);
        assert_eq!(both.planning_time_s, 0.75);
        assert_eq!(Timings::default().total(), None);
    }

    #[test]
    fn a_timing_file_is_read_back_and_a_bad_one_is_refused_with_what_is_wrong() {
        let dir = std::env::temp_dir().join(format!("macrotree-timing-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = Timings::path_beside(&dir.join("out.jsonl"));
        assert!(path.ends_with("out.jsonl.timing.json"));
        assert_eq!(Timings::read(&path), Ok(None));
        let t = Timings::default().then(run(3, 2, 1.5));
        std::fs::write(&path, t.to_json()).unwrap();
        assert_eq!(Timings::read(&path), Ok(Some(t)));
        for (text, says) in [
            ("{\"runs\": 3}", "not a timing file"),
            ("{\"runs\": [], \"extra\": 1}", "unknown field"),
            (
                "{\"runs\": [{\"lines\": 1, \"jobs\": 0, \"wall_time_s\": 1, \"process_wall_time_s\": 1, \"physics_time_s\": 0, \"planning_time_s\": 0}]}",
                "`jobs` is 0",
            ),
            (
                "{\"runs\": [{\"lines\": 1, \"jobs\": 1, \"wall_time_s\": -1, \"process_wall_time_s\": 1, \"physics_time_s\": 0, \"planning_time_s\": 0}]}",
                "`wall_time_s` is -1",
            ),
        ] {
            std::fs::write(&path, text).unwrap();
            let e = Timings::read(&path).unwrap_err();
            assert!(e.contains(says), "{text}: {e}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
