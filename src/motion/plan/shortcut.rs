//! Shortcutting: seeded random shortcuts between points anywhere on the path (not only its
//! vertices), each new segment checked at the edge resolution, then a sweep that drops every vertex
//! its neighbours see each other past.

use super::checker::FastChecks;
use super::edge::{Resolution, check_segment};
use super::rng::Stream;
use super::stats::distance;

/// The point at arc length `s` along `path` (radians), with the index of its segment.
fn at(path: &[[f64; 6]], cum: &[f64], s: f64) -> (usize, [f64; 6]) {
    let i = cum
        .partition_point(|&c| c <= s)
        .saturating_sub(1)
        .min(path.len() - 2);
    let len = cum[i + 1] - cum[i];
    let u = if len > 0.0 {
        ((s - cum[i]) / len).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut q = [0.0; 6];
    for j in 0..6 {
        q[j] = path[i][j] + (path[i + 1][j] - path[i][j]) * u;
    }
    (i, q)
}

fn cumulative(path: &[[f64; 6]]) -> Vec<f64> {
    let mut cum = Vec::with_capacity(path.len());
    cum.push(0.0);
    for w in path.windows(2) {
        cum.push(cum[cum.len() - 1] + distance(&w[0], &w[1]));
    }
    cum
}

/// Keeps, from each kept vertex, the farthest later vertex the straight segment reaches free
/// (tried from the end backwards): a path whose segments are each checked once, before the
/// random shortcuts refine its corners.
fn greedy<C: FastChecks + ?Sized>(checker: &mut C, path: Vec<[f64; 6]>, res: &Resolution) -> Vec<[f64; 6]> {
    let n = path.len();
    if n < 3 {
        return path;
    }
    let mut out = vec![path[0]];
    let mut i = 0;
    while i + 1 < n {
        let mut j = n - 1;
        while j > i + 1 && check_segment(checker, &path[i], &path[j], res).is_err() {
            j -= 1;
        }
        out.push(path[j]);
        i = j;
    }
    out
}

/// Shortens `path` (start and end kept exactly): a greedy pass over its vertices, then
/// `attempts` seeded random shortcuts and a final vertex-dropping sweep. A random shortcut is
/// checked only when its segment is shorter than `1 − min_gain` times the path between its ends
/// (radians); the others are skipped, their draws spent all the same. Every segment of the
/// result is free at `res`, given the input's segments were.
pub(crate) fn shortcut<C: FastChecks + ?Sized>(
    checker: &mut C,
    path: Vec<[f64; 6]>,
    attempts: usize,
    min_gain: f64,
    res: &Resolution,
    seed: u64,
) -> Vec<[f64; 6]> {
    let mut path = greedy(checker, path, res);
    let mut rng = Stream::new(seed, 2);
    for _ in 0..attempts {
        if path.len() < 3 {
            break;
        }
        let cum = cumulative(&path);
        let total = cum[cum.len() - 1];
        let (mut s1, mut s2) = (rng.range(0.0, total), rng.range(0.0, total));
        if s1 > s2 {
            std::mem::swap(&mut s1, &mut s2);
        }
        let (i1, p1) = at(&path, &cum, s1);
        let (i2, p2) = at(&path, &cum, s2);
        if i1 == i2 {
            continue; // one straight segment already
        }
        if distance(&p1, &p2) >= (1.0 - min_gain) * (s2 - s1) {
            continue; // too little to gain for a check of the whole stretch
        }
        // p1 and p2 lie on checked segments; check them exactly too, then the new segment.
        if !checker.is_free(&p1) || !checker.is_free(&p2) {
            continue;
        }
        if check_segment(checker, &p1, &p2, res).is_err() {
            continue;
        }
        let mut next = Vec::with_capacity(path.len());
        next.extend_from_slice(&path[..=i1]);
        if distance(&p1, &path[i1]) > 1e-12 {
            next.push(p1);
        }
        if distance(&p2, &path[i2 + 1]) > 1e-12 {
            next.push(p2);
        }
        next.extend_from_slice(&path[i2 + 1..]);
        path = next;
    }
    // Drop every vertex whose neighbours are joined by a free segment.
    let mut i = 1;
    while i + 1 < path.len() {
        if check_segment(checker, &path[i - 1], &path[i + 1], res).is_ok() {
            path.remove(i);
        } else {
            i += 1;
        }
    }
    path
}
