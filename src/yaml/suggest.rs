//! "Did you mean …?" suggestions by edit distance.

/// Edit distance between two strings, in characters (case-insensitive): insertions, deletions,
/// substitutions and swaps of two neighbouring characters each cost 1 (optimal string
/// alignment distance).
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.to_lowercase().chars().collect();
    let b: Vec<char> = b.to_lowercase().chars().collect();
    let w = b.len() + 1;
    let mut d = vec![0usize; (a.len() + 1) * w];
    for i in 0..=a.len() {
        d[i * w] = i;
    }
    for (j, cell) in d.iter_mut().enumerate().take(w) {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[(i - 1) * w + j] + 1)
                .min(d[i * w + j - 1] + 1)
                .min(d[(i - 1) * w + j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[(i - 2) * w + j - 2] + 1);
            }
            d[i * w + j] = v;
        }
    }
    d[a.len() * w + b.len()]
}

/// The closest candidate to `word`, if it is close enough to be a plausible typo
/// (distance ≤ 1/3 of the length, at least 1; or one is a prefix of the other, or they differ
/// only in `-`/`_`).
pub fn closest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let norm = |s: &str| s.to_lowercase().replace(['-', ' '], "_");
    let w = norm(word);
    if w.chars().count() > 64 {
        return None;
    }
    // Ranked by (plausibility, edit distance): a prefix counts as one edit for plausibility, and
    // the true edit distance breaks ties (`reac` → `reach`, not `reactive_sequence`).
    let mut best: Option<((usize, usize), &str)> = None;
    for c in candidates {
        let cn = norm(c);
        let ed = edit_distance(&w, &cn);
        let d = if w.len() >= 3 && (cn.starts_with(&w) || w.starts_with(&cn)) {
            ed.min(1)
        } else {
            ed
        };
        let limit = (w.chars().count().max(cn.chars().count()) / 3).max(1);
        if d <= limit && best.is_none_or(|(bd, _)| (d, ed) < bd) {
            best = Some(((d, ed), c));
        }
    }
    best.map(|(_, c)| c)
}

/// `Some("did you mean `x`?")` when a candidate is close to `word`.
pub fn did_you_mean<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<String> {
    closest(word, candidates).map(|c| format!("did you mean `{c}`?"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("same", "same"), 0);
        assert_eq!(edit_distance("spede", "speed"), 1);
    }

    #[test]
    fn suggestions() {
        let kinds = ["sequence", "fallback", "reactive_sequence", "retry", "reach"];
        assert_eq!(closest("sequnce", kinds), Some("sequence"));
        // Regression: a prefix of several kinds suggested the first, not the nearest.
        assert_eq!(closest("reac", kinds), Some("reach"));
        assert_eq!(closest("reactive", kinds), Some("reactive_sequence"));
        assert_eq!(closest("reactive-sequence", kinds), Some("reactive_sequence"));
        assert_eq!(closest("retyr", kinds), Some("retry"));
        assert_eq!(closest("banana", kinds), None);
    }
}
