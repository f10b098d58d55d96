//! Feature statistics as LeRobot keeps them (`min`, `max`, `mean`, `std`, `count`, `q01`, `q10`,
//! `q50`, `q90`, `q99`): exact per episode; over the dataset, min/max/count exact, mean and std
//! combined exactly from the episodes', quantiles the frame-weighted mean of the episodes' (as
//! LeRobot aggregates them).

use serde_json::{Value, json};

/// The quantiles kept, as fractions.
pub const QUANTILES: [(&str, f64); 5] = [
    ("q01", 0.01),
    ("q10", 0.10),
    ("q50", 0.50),
    ("q90", 0.90),
    ("q99", 0.99),
];

/// Statistics of a vector feature (one entry per dimension).
#[derive(Debug, Clone, PartialEq)]
pub struct VecStats {
    /// Smallest value per dimension.
    pub min: Vec<f64>,
    /// Largest value per dimension.
    pub max: Vec<f64>,
    /// Mean per dimension.
    pub mean: Vec<f64>,
    /// Population standard deviation per dimension.
    pub std: Vec<f64>,
    /// Frames counted.
    pub count: u64,
    /// [`QUANTILES`] per dimension (outer index: quantile).
    pub quantiles: Vec<Vec<f64>>,
}

/// The `q`-quantile of sorted `v` by linear interpolation between closest ranks (NumPy's
/// default).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let pos = q * (sorted.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64)
}

impl VecStats {
    /// Exact statistics of `rows` (each of the same width).
    pub fn of<R: AsRef<[f64]>>(rows: &[R]) -> Self {
        let width = rows.first().map_or(0, |r| r.as_ref().len());
        let n = rows.len();
        let mut s = Self {
            min: vec![f64::INFINITY; width],
            max: vec![f64::NEG_INFINITY; width],
            mean: vec![0.0; width],
            std: vec![0.0; width],
            count: n as u64,
            quantiles: vec![vec![0.0; width]; QUANTILES.len()],
        };
        let mut column = Vec::with_capacity(n);
        for d in 0..width {
            column.clear();
            column.extend(rows.iter().map(|r| r.as_ref()[d]));
            let mean = column.iter().sum::<f64>() / n.max(1) as f64;
            let var = column.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n.max(1) as f64;
            column.sort_by(f64::total_cmp);
            s.min[d] = column.first().copied().unwrap_or(f64::NAN);
            s.max[d] = column.last().copied().unwrap_or(f64::NAN);
            s.mean[d] = mean;
            s.std[d] = var.sqrt();
            for (k, (_, q)) in QUANTILES.iter().enumerate() {
                s.quantiles[k][d] = quantile(&column, *q);
            }
        }
        s
    }

    /// Statistics of the union of `parts` (in order): see the module docs.
    pub fn combine(parts: &[&VecStats]) -> Option<Self> {
        let first = parts.iter().find(|p| p.count > 0)?;
        let width = first.mean.len();
        let total: u64 = parts.iter().map(|p| p.count).sum();
        let mut s = Self {
            min: vec![f64::INFINITY; width],
            max: vec![f64::NEG_INFINITY; width],
            mean: vec![0.0; width],
            std: vec![0.0; width],
            count: total,
            quantiles: vec![vec![0.0; width]; QUANTILES.len()],
        };
        for d in 0..width {
            let mut mean = 0.0;
            for p in parts.iter().filter(|p| p.count > 0) {
                let w = p.count as f64 / total as f64;
                s.min[d] = s.min[d].min(p.min[d]);
                s.max[d] = s.max[d].max(p.max[d]);
                mean += w * p.mean[d];
                for k in 0..QUANTILES.len() {
                    s.quantiles[k][d] += w * p.quantiles[k][d];
                }
            }
            let var: f64 = parts
                .iter()
                .filter(|p| p.count > 0)
                .map(|p| p.count as f64 / total as f64 * (p.std[d].powi(2) + (p.mean[d] - mean).powi(2)))
                .sum();
            s.mean[d] = mean;
            s.std[d] = var.sqrt();
        }
        Some(s)
    }

    /// As `stats.json` writes a feature: every statistic a list (one entry per dimension).
    pub fn to_json(&self) -> Value {
        let mut m = serde_json::Map::new();
        m.insert("min".into(), json!(self.min));
        m.insert("max".into(), json!(self.max));
        m.insert("mean".into(), json!(self.mean));
        m.insert("std".into(), json!(self.std));
        m.insert("count".into(), json!([self.count]));
        for (k, (name, _)) in QUANTILES.iter().enumerate() {
            m.insert((*name).into(), json!(self.quantiles[k]));
        }
        Value::Object(m)
    }
}

/// Statistics of an image feature from per-channel histograms of its pixel values, scaled to
/// 0…1 and shaped `[3][1][1]` as LeRobot writes them; `count` is the number of frames.
pub fn image_stats_json(hist: &[[u64; 256]; 3], frames: u64) -> Value {
    let mut per: Vec<[f64; 4]> = Vec::new(); // min, max, mean, std per channel
    let mut qs = vec![[0.0f64; 3]; QUANTILES.len()];
    for (c, h) in hist.iter().enumerate() {
        let n: u64 = h.iter().sum();
        let nf = n.max(1) as f64;
        let min = h.iter().position(|&k| k > 0).unwrap_or(0) as f64 / 255.0;
        let max = h.iter().rposition(|&k| k > 0).unwrap_or(0) as f64 / 255.0;
        let mean = h
            .iter()
            .enumerate()
            .map(|(v, &k)| v as f64 * k as f64)
            .sum::<f64>()
            / nf
            / 255.0;
        let var = h
            .iter()
            .enumerate()
            .map(|(v, &k)| (v as f64 / 255.0 - mean).powi(2) * k as f64)
            .sum::<f64>()
            / nf;
        per.push([min, max, mean, var.sqrt()]);
        for (k, (_, q)) in QUANTILES.iter().enumerate() {
            // Linear interpolation between closest ranks, on the histogram.
            let pos = q * (n.saturating_sub(1)) as f64;
            let at = |rank: u64| -> f64 {
                let mut seen = 0;
                for (v, &cnt) in h.iter().enumerate() {
                    seen += cnt;
                    if seen > rank {
                        return v as f64;
                    }
                }
                255.0
            };
            let (lo, hi) = (pos.floor() as u64, pos.ceil() as u64);
            qs[k][c] = (at(lo) + (at(hi) - at(lo)) * (pos - lo as f64)) / 255.0;
        }
    }
    let shaped = |f: &dyn Fn(usize) -> f64| json!([[[f(0)]], [[f(1)]], [[f(2)]]]);
    let mut m = serde_json::Map::new();
    for (i, name) in ["min", "max", "mean", "std"].iter().enumerate() {
        m.insert((*name).into(), shaped(&|c| per[c][i]));
    }
    m.insert("count".into(), json!([frames]));
    for (k, (name, _)) in QUANTILES.iter().enumerate() {
        m.insert((*name).into(), shaped(&|c| qs[k][c]));
    }
    Value::Object(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_and_combined_statistics() {
        let a = VecStats::of(&[[0.0, 10.0], [1.0, 10.0], [2.0, 10.0]]);
        assert_eq!(a.min, [0.0, 10.0]);
        assert_eq!(a.max, [2.0, 10.0]);
        assert_eq!(a.mean, [1.0, 10.0]);
        assert!((a.std[0] - (2.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!(a.quantiles[2], [1.0, 10.0]); // median
        assert!((a.quantiles[0][0] - 0.02).abs() < 1e-12); // q01 of 0, 1, 2
        let b = VecStats::of(&[[3.0, 10.0], [4.0, 10.0], [5.0, 10.0]]);
        let all = VecStats::of(&[
            [0.0, 10.0],
            [1.0, 10.0],
            [2.0, 10.0],
            [3.0, 10.0],
            [4.0, 10.0],
            [5.0, 10.0],
        ]);
        let c = VecStats::combine(&[&a, &b]).unwrap();
        assert_eq!(
            (c.min.clone(), c.max.clone(), c.count),
            (all.min.clone(), all.max.clone(), 6)
        );
        for d in 0..2 {
            assert!((c.mean[d] - all.mean[d]).abs() < 1e-12);
            assert!((c.std[d] - all.std[d]).abs() < 1e-12);
        }
    }

    #[test]
    fn image_statistics_from_histograms() {
        let mut h = [[0u64; 256]; 3];
        h[0][0] = 1;
        h[0][255] = 1;
        h[1][51] = 2;
        h[2][255] = 2;
        let v = image_stats_json(&h, 1);
        assert_eq!(v["min"], json!([[[0.0]], [[0.2]], [[1.0]]]));
        assert_eq!(v["max"], json!([[[1.0]], [[0.2]], [[1.0]]]));
        assert_eq!(v["mean"][0], json!([[0.5]]));
        assert_eq!(v["std"][0], json!([[0.5]]));
        assert_eq!(v["q50"][0], json!([[0.5]]));
        assert_eq!(v["count"], json!([1]));
    }
}
