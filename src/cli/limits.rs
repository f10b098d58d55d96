//! Bounds of the numeric options, as `clap` value parsers: a value out of range is a usage error
//! (exit 2) that names the range, before anything runs.

/// Largest `--max-sim-time`, seconds of simulated time (one hour; the flagship task takes ~6 s);
/// defined with the episode.
pub use crate::episode::MAX_SIM_TIME_S;
/// Slowest `--speed` (a hundredth of real time).
pub const MIN_SPEED: f64 = 0.01;
/// Fastest `--speed` (a thousand times real time; faster than the simulation runs anyway).
pub const MAX_SPEED: f64 = 1000.0;
/// Most scenarios in one sweep (before sharding): about a week of one core at the flagship
/// tree's ~1000 scenarios per minute. Split bigger studies by `--seed`.
pub const MAX_SCENARIOS: u64 = 10_000_000;
pub use crate::sweep::MAX_JOBS;
/// Most repetitions of `bench --repeat` (each runs the whole episode twice).
pub const MAX_REPEAT: usize = 1000;

/// `--fault NAME`: one of the faults' names (the library's [`crate::faults::FaultKind`] has no
/// command-line types).
pub fn fault() -> impl clap::builder::TypedValueParser<Value = crate::faults::FaultKind> {
    use clap::builder::TypedValueParser as _;
    clap::builder::PossibleValuesParser::new(crate::faults::FaultKind::ALL.map(|k| k.name()))
        .try_map(|s| s.parse::<crate::faults::FaultKind>())
}

/// `--goal NAME`: `scene`, `bowl` or `tree`.
pub fn goal() -> impl clap::builder::TypedValueParser<Value = crate::episode::Goal> {
    use clap::builder::TypedValueParser as _;
    clap::builder::PossibleValuesParser::new(crate::episode::Goal::ALL.map(|g| g.name()))
        .try_map(|s| s.parse::<crate::episode::Goal>())
}

/// `--collisions POLICY`: `count` or `fail`.
pub fn collisions() -> impl clap::builder::TypedValueParser<Value = crate::episode::CollisionPolicy> {
    use clap::builder::TypedValueParser as _;
    clap::builder::PossibleValuesParser::new(["count", "fail"])
        .try_map(|s| s.parse::<crate::episode::CollisionPolicy>())
}

/// `s` as a number accepted by `ok`, or an error that gives the `range`.
fn number_in(s: &str, ok: impl Fn(f64) -> bool, range: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && ok(v) => Ok(v),
        _ => Err(format!("must be {range}, got {s}")),
    }
}

/// `--max-sim-time S`: 0 < S ≤ [`MAX_SIM_TIME_S`].
pub fn max_sim_time(s: &str) -> Result<f64, String> {
    number_in(
        s,
        |v| v > 0.0 && v <= MAX_SIM_TIME_S,
        &format!("more than 0 and at most {MAX_SIM_TIME_S} seconds of simulated time"),
    )
}

/// `--speed X`: [`MIN_SPEED`] ≤ X ≤ [`MAX_SPEED`].
pub fn speed(s: &str) -> Result<f64, String> {
    number_in(
        s,
        |v| (MIN_SPEED..=MAX_SPEED).contains(&v),
        &format!("between {MIN_SPEED} and {MAX_SPEED} times real time"),
    )
}

/// `--scenarios N`: 1 ≤ N ≤ [`MAX_SCENARIOS`].
pub fn scenarios(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(n) if (1..=MAX_SCENARIOS).contains(&n) => Ok(n),
        Ok(n) => Err(format!(
            "must be between 1 and {MAX_SCENARIOS}, got {n} (split a bigger study into sweeps with different --seed)"
        )),
        Err(_) => Err(format!(
            "{s:?} is not a whole number of scenarios between 1 and {MAX_SCENARIOS}"
        )),
    }
}

/// `--jobs J`: 1 ≤ J ≤ [`MAX_JOBS`].
pub fn jobs(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(n) if (1..=MAX_JOBS as u64).contains(&n) => Ok(n),
        _ => Err(format!(
            "must be a whole number of worker threads between 1 and {MAX_JOBS}, got {s}"
        )),
    }
}

/// `--repeat N`: 1 ≤ N ≤ [`MAX_REPEAT`].
pub fn repeat(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=MAX_REPEAT).contains(&n) => Ok(n),
        _ => Err(format!(
            "must be a whole number of repetitions between 1 and {MAX_REPEAT}, got {s}"
        )),
    }
}

/// `plan --margin M`: 0 ≤ M ≤ [`crate::sim::collision::MAX_MARGIN`], metres.
pub fn margin(s: &str) -> Result<f64, String> {
    let max = crate::sim::collision::MAX_MARGIN;
    number_in(
        s,
        |v| (0.0..=max).contains(&v),
        &format!("metres from 0 to {max}"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds() {
        assert_eq!(speed("2"), Ok(2.0));
        for bad in ["1e-22", "1e-18", "0", "-1", "1001", "inf", "NaN", "x"] {
            assert!(speed(bad).is_err(), "{bad}");
        }
        assert_eq!(max_sim_time("3600"), Ok(3600.0));
        for bad in ["0", "3600.5", "1e300", "nan"] {
            assert!(max_sim_time(bad).is_err(), "{bad}");
        }
        assert_eq!(scenarios("10000000"), Ok(10_000_000));
        for bad in ["0", "10000001", "18446744073709551615", "-1", "1e3"] {
            assert!(scenarios(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn sweep_jobs_and_bench_repeat_are_bounded() {
        assert_eq!(jobs("1024"), Ok(1024));
        for bad in ["0", "1025", "100000", "-1", "x"] {
            assert!(jobs(bad).is_err(), "{bad}");
        }
        assert_eq!(super::super::args::yaw_degrees("-360"), Ok(-360.0));
        for bad in ["360.5", "nan", "inf"] {
            assert!(super::super::args::yaw_degrees(bad).is_err(), "{bad}");
        }
        assert_eq!(margin("0"), Ok(0.0));
        for bad in ["-0.001", "0.2", "nan"] {
            assert!(margin(bad).is_err(), "{bad}");
        }
        assert_eq!(repeat("1000"), Ok(1000));
        for bad in ["0", "1001", "1000000000000", "-3"] {
            assert!(repeat(bad).is_err(), "{bad}");
        }
    }
}
