//! [`ScenarioIndices`]: the scenario indices of a sweep or of one shard, enumerated by
//! arithmetic (shard `K/M` of `N` scenarios is `K, K+M, K+2M, …` below `N`), so that no list of
//! all indices is ever built, whatever `N` and `M` are.

use super::Shard;

/// The ascending scenario indices `first, first+step, …` (`len` of them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScenarioIndices {
    next: u64,
    step: u64,
    remaining: u64,
}

impl ScenarioIndices {
    /// Indices `0..scenarios`, or only those of `shard`.
    pub fn new(scenarios: u64, shard: Option<Shard>) -> Self {
        let (first, step) = shard.map_or((0, 1), |s| (s.index, s.count.max(1)));
        let remaining = if first < scenarios {
            (scenarios - 1 - first) / step + 1
        } else {
            0
        };
        Self {
            next: first,
            step,
            remaining,
        }
    }

    /// The index at position `pos` (0-based), if there is one.
    pub fn get(&self, pos: u64) -> Option<u64> {
        // Below `remaining`, the index is at most the last one, so nothing overflows.
        (pos < self.remaining).then(|| self.next + pos * self.step)
    }

    /// These indices without the first `n`.
    #[must_use]
    pub fn skip_first(self, n: u64) -> Self {
        match self.get(n) {
            Some(next) => Self {
                next,
                step: self.step,
                remaining: self.remaining - n,
            },
            None => Self { remaining: 0, ..self },
        }
    }

    /// How many indices are left.
    pub fn count_left(&self) -> u64 {
        self.remaining
    }
}

impl Iterator for ScenarioIndices {
    type Item = u64;

    fn next(&mut self) -> Option<u64> {
        let i = self.get(0)?;
        *self = self.skip_first(1);
        Some(i)
    }

    fn nth(&mut self, n: usize) -> Option<u64> {
        *self = self.skip_first(n as u64);
        self.next()
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = usize::try_from(self.remaining).unwrap_or(usize::MAX);
        (n, usize::try_from(self.remaining).ok())
    }
}

impl ExactSizeIterator for ScenarioIndices {}

#[cfg(test)]
mod tests {
    use super::*;

    fn shard(index: u64, count: u64) -> Option<Shard> {
        Some(Shard { index, count })
    }

    #[test]
    fn matches_filtering_every_index() {
        for n in 0..20 {
            for m in 1..7 {
                for k in 0..m {
                    let want: Vec<u64> = (0..n).filter(|i| i % m == k).collect();
                    let got: Vec<u64> = ScenarioIndices::new(n, shard(k, m)).collect();
                    assert_eq!(got, want, "{k}/{m} of {n}");
                    assert_eq!(ScenarioIndices::new(n, shard(k, m)).len(), want.len());
                    for skip in 0..=want.len() + 1 {
                        let rest: Vec<u64> = ScenarioIndices::new(n, shard(k, m))
                            .skip_first(skip as u64)
                            .collect();
                        assert_eq!(rest, want.iter().copied().skip(skip).collect::<Vec<_>>());
                    }
                }
            }
        }
    }

    #[test]
    fn huge_sweeps_and_shards_cost_nothing() {
        let m = u64::MAX;
        let s = ScenarioIndices::new(u64::MAX, shard(0, m));
        assert_eq!(s.collect::<Vec<_>>(), [0]);
        let s = ScenarioIndices::new(u64::MAX, shard(m - 1, m));
        assert_eq!(s.collect::<Vec<_>>(), [m - 1]);
        assert_eq!(ScenarioIndices::new(m - 1, shard(m - 1, m)).count_left(), 0);
        let s = ScenarioIndices::new(u64::MAX, shard(3, 7));
        assert_eq!(s.count_left(), (u64::MAX - 1 - 3) / 7 + 1);
        let last = s.get(s.count_left() - 1).unwrap();
        assert!(last % 7 == 3 && u64::MAX - last <= 7);
        assert_eq!(s.skip_first(s.count_left() - 1).next(), Some(last));
        assert_eq!(ScenarioIndices::new(u64::MAX, None).nth(1 << 40), Some(1 << 40));
    }
}
