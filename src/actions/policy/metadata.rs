//! What a model declares beside its graph, in its ONNX metadata properties.

use std::collections::BTreeMap;

/// The metadata key of the action's meaning ([`ActionMode`]).
pub(super) const ACTION_KEY: &str = "macrotree.action";
/// The metadata key of the time between two model calls, seconds.
pub(super) const PERIOD_KEY: &str = "macrotree.period";
/// The metadata key of the normalisation statistics ([`Normalization`], as JSON).
pub(super) const NORMALIZATION_KEY: &str = "macrotree.normalization";
/// The name the action's statistics go by in [`NORMALIZATION_KEY`].
pub(super) const ACTION_NAME: &str = "action";

/// What the model's joint values mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ActionMode {
    /// Joint set points, radians.
    #[default]
    Absolute,
    /// Offsets added to the arm's current set point, radians (the gripper command stays
    /// absolute).
    Relative,
}

/// How one vector is normalised (LeRobot's `meta/stats.json` statistics).
#[derive(Debug, Clone, PartialEq)]
pub enum Normalization {
    /// `(x - mean) / std`.
    MeanStd {
        /// Per value.
        mean: Vec<f32>,
        /// Per value (> 0).
        std: Vec<f32>,
    },
    /// `2 (x - min) / (max - min) - 1`.
    MinMax {
        /// Per value.
        min: Vec<f32>,
        /// Per value (> min).
        max: Vec<f32>,
    },
}

/// The smallest spread a statistic may have (LeRobot's epsilon).
const EPS: f32 = 1e-8;

impl Normalization {
    /// How many values it normalises.
    pub fn len(&self) -> usize {
        match self {
            Normalization::MeanStd { mean, .. } => mean.len(),
            Normalization::MinMax { min, .. } => min.len(),
        }
    }

    /// Whether it normalises no value.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Normalises `x` in place.
    pub fn apply(&self, x: &mut [f32]) {
        match self {
            Normalization::MeanStd { mean, std } => {
                for ((v, m), s) in x.iter_mut().zip(mean).zip(std) {
                    *v = (*v - m) / (s + EPS);
                }
            }
            Normalization::MinMax { min, max } => {
                for ((v, lo), hi) in x.iter_mut().zip(min).zip(max) {
                    *v = 2.0 * (*v - lo) / (hi - lo + EPS) - 1.0;
                }
            }
        }
    }

    /// Undoes [`Self::apply`] in place.
    pub fn invert(&self, x: &mut [f32]) {
        match self {
            Normalization::MeanStd { mean, std } => {
                for ((v, m), s) in x.iter_mut().zip(mean).zip(std) {
                    *v = *v * (s + EPS) + m;
                }
            }
            Normalization::MinMax { min, max } => {
                for ((v, lo), hi) in x.iter_mut().zip(min).zip(max) {
                    *v = (*v + 1.0) / 2.0 * (hi - lo + EPS) + lo;
                }
            }
        }
    }
}

/// The metadata a model declares.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct Metadata {
    pub action: ActionMode,
    pub period: Option<f64>,
    pub normalization: BTreeMap<String, Normalization>,
}

/// Longest metadata value read, bytes (statistics of a few hundred values fit many times).
const MAX_VALUE_BYTES: usize = 1 << 20;

impl Metadata {
    /// Reads the three keys from `get` (a model's custom metadata); an error names the key and
    /// says what it must hold.
    pub fn read(get: impl Fn(&str) -> Option<String>) -> Result<Metadata, String> {
        let mut m = Metadata::default();
        if let Some(a) = get(ACTION_KEY) {
            m.action = match a.as_str() {
                "absolute" => ActionMode::Absolute,
                "relative" => ActionMode::Relative,
                other => {
                    return Err(format!(
                        "metadata `{ACTION_KEY}` is `{}`; expected `absolute` or `relative`",
                        other.chars().take(40).collect::<String>()
                    ));
                }
            };
        }
        if let Some(p) = get(PERIOD_KEY) {
            let max = crate::kinds::MAX_POLICY_PERIOD;
            match p.trim().parse::<f64>() {
                Ok(x) if x > 0.0 && x <= max => m.period = Some(x),
                _ => {
                    return Err(format!(
                        "metadata `{PERIOD_KEY}` is `{}`; expected seconds in (0, {max}]",
                        p.chars().take(40).collect::<String>()
                    ));
                }
            }
        }
        if let Some(text) = get(NORMALIZATION_KEY) {
            if text.len() > MAX_VALUE_BYTES {
                return Err(format!(
                    "metadata `{NORMALIZATION_KEY}` has {} bytes; at most {MAX_VALUE_BYTES} are read",
                    text.len()
                ));
            }
            m.normalization = parse_normalization(&text)?;
        }
        Ok(m)
    }
}

fn parse_normalization(text: &str) -> Result<BTreeMap<String, Normalization>, String> {
    let bad = |why: String| format!("metadata `{NORMALIZATION_KEY}`: {why}");
    let json: serde_json::Value = serde_json::from_str(text).map_err(|e| bad(format!("not JSON ({e})")))?;
    let serde_json::Value::Object(entries) = json else {
        return Err(bad(
            "expected an object of `{name: {mean, std} or {min, max}}`".into()
        ));
    };
    let mut out = BTreeMap::new();
    for (name, stats) in entries {
        let numbers = |key: &str| -> Result<Option<Vec<f32>>, String> {
            let Some(v) = stats.get(key) else { return Ok(None) };
            let list = v
                .as_array()
                .ok_or_else(|| bad(format!("`{name}.{key}` is not a list of numbers")))?;
            list.iter()
                .map(|x| {
                    x.as_f64()
                        .filter(|x| x.is_finite() && x.abs() <= f32::MAX as f64)
                        .map(|x| x as f32)
                        .ok_or_else(|| {
                            bad(format!(
                                "`{name}.{key}` holds a value that is not a finite number"
                            ))
                        })
                })
                .collect::<Result<Vec<f32>, String>>()
                .map(Some)
        };
        let n = match (
            numbers("mean")?,
            numbers("std")?,
            numbers("min")?,
            numbers("max")?,
        ) {
            (Some(mean), Some(std), None, None) => {
                if std.iter().any(|s| *s < 0.0) {
                    return Err(bad(format!("`{name}.std` has a negative value")));
                }
                (mean.len() == std.len()).then_some(Normalization::MeanStd { mean, std })
            }
            (None, None, Some(min), Some(max)) => {
                if min.iter().zip(&max).any(|(lo, hi)| hi < lo) {
                    return Err(bad(format!("`{name}` has a `max` below its `min`")));
                }
                (min.len() == max.len()).then_some(Normalization::MinMax { min, max })
            }
            _ => {
                return Err(bad(format!(
                    "`{name}` must have exactly `mean` and `std`, or `min` and `max`"
                )));
            }
        };
        let n = n.ok_or_else(|| bad(format!("the two lists of `{name}` differ in length")))?;
        out.insert(name, n);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(pairs: &[(&str, &str)]) -> Result<Metadata, String> {
        let map: BTreeMap<String, String> = pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        Metadata::read(|k| map.get(k).cloned())
    }

    #[test]
    fn metadata_defaults_to_absolute_actions_without_statistics() {
        assert_eq!(read(&[]).unwrap(), Metadata::default());
    }

    #[test]
    fn normalisation_round_trips_both_kinds_of_statistics() {
        let m = read(&[
            (ACTION_KEY, "relative"),
            (PERIOD_KEY, "0.04"),
            (
                NORMALIZATION_KEY,
                r#"{"observation.state": {"mean": [1, 2], "std": [2, 4]}, "action": {"min": [0, -1], "max": [10, 1]}}"#,
            ),
        ])
        .unwrap();
        assert_eq!(m.action, ActionMode::Relative);
        assert_eq!(m.period, Some(0.04));
        let state = &m.normalization["observation.state"];
        let mut x = [3.0f32, 2.0];
        state.apply(&mut x);
        assert!((x[0] - 1.0).abs() < 1e-6 && x[1].abs() < 1e-6, "{x:?}");
        let action = &m.normalization[ACTION_NAME];
        let mut a = [5.0f32, 1.0];
        action.apply(&mut a);
        assert!(a[0].abs() < 1e-6 && (a[1] - 1.0).abs() < 1e-6, "{a:?}");
        action.invert(&mut a);
        assert!((a[0] - 5.0).abs() < 1e-5 && (a[1] - 1.0).abs() < 1e-5, "{a:?}");
    }

    #[test]
    fn bad_metadata_is_refused_with_the_key() {
        for (pairs, key) in [
            (vec![(ACTION_KEY, "delta")], ACTION_KEY),
            (vec![(PERIOD_KEY, "0")], PERIOD_KEY),
            (vec![(PERIOD_KEY, "nan")], PERIOD_KEY),
            (vec![(NORMALIZATION_KEY, "[1]")], NORMALIZATION_KEY),
            (
                vec![(NORMALIZATION_KEY, r#"{"a": {"mean": [1], "std": [1, 2]}}"#)],
                NORMALIZATION_KEY,
            ),
            (
                vec![(NORMALIZATION_KEY, r#"{"a": {"mean": [1], "max": [2]}}"#)],
                NORMALIZATION_KEY,
            ),
            (
                vec![(NORMALIZATION_KEY, r#"{"a": {"min": [3], "max": [2]}}"#)],
                NORMALIZATION_KEY,
            ),
        ] {
            let e = read(&pairs).unwrap_err();
            assert!(e.contains(key), "{e}");
        }
    }
}
