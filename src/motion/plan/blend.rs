//! Smoothing: the shortcut polyline with its corners replaced by circular arcs in joint space
//! (the path geometry of Kunz & Stilman's time-optimal trajectory generation, as MoveIt's TOTG
//! uses), each arc at most a given deviation from its corner, collision-checked at the edge
//! resolution and shrunk until free. A corner left unblended (or a reversal) is a stop.

use super::checker::FastChecks;
use super::edge::Resolution;
use super::stats::distance;

/// One piece of the smoothed path, parameterised by joint-space arc length (radians).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Piece {
    /// `from + dir·s` for `s` in `[0, len]`, `dir` a unit vector.
    Line { from: [f64; 6], dir: [f64; 6], len: f64 },
    /// `center + r·(x cos φ + y sin φ)`, `φ = s / r` in `[0, angle]`; `x`, `y` orthonormal.
    Arc {
        center: [f64; 6],
        x: [f64; 6],
        y: [f64; 6],
        r: f64,
        angle: f64,
    },
}

impl Piece {
    /// Arc length, radians.
    pub(crate) fn len(&self) -> f64 {
        match self {
            Piece::Line { len, .. } => *len,
            Piece::Arc { r, angle, .. } => r * angle,
        }
    }

    /// Joints, their first and second derivatives by arc length, at `s` (radians) into the piece.
    pub(crate) fn eval(&self, s: f64) -> ([f64; 6], [f64; 6], [f64; 6]) {
        let (mut q, mut d1, mut d2) = ([0.0; 6], [0.0; 6], [0.0; 6]);
        match self {
            Piece::Line { from, dir, len } => {
                let s = s.clamp(0.0, *len);
                for j in 0..6 {
                    q[j] = from[j] + dir[j] * s;
                    d1[j] = dir[j];
                }
            }
            Piece::Arc {
                center,
                x,
                y,
                r,
                angle,
            } => {
                let phi = (s / r).clamp(0.0, *angle);
                let (sn, cs) = phi.sin_cos();
                for j in 0..6 {
                    q[j] = center[j] + r * (x[j] * cs + y[j] * sn);
                    d1[j] = -x[j] * sn + y[j] * cs;
                    d2[j] = -(x[j] * cs + y[j] * sn) / r;
                }
            }
        }
        (q, d1, d2)
    }
}

/// The smoothed path: its pieces, and for each whether the arm stops at its start.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Smoothed {
    pub(crate) pieces: Vec<(Piece, bool)>,
    pub(crate) blends: usize,
}

fn unit(a: &[f64; 6], b: &[f64; 6]) -> ([f64; 6], f64) {
    let len = distance(a, b);
    let mut d = [0.0; 6];
    for j in 0..6 {
        d[j] = (b[j] - a[j]) / len;
    }
    (d, len)
}

/// The corner arc at `v` between incoming unit `y_in` and outgoing unit `y_out`, at most
/// `deviation` radians from `v` and trimming at most `max_trim` of either segment; `None` if the
/// segments are (nearly) collinear or reversed. Returns the arc and its trim length.
fn corner(
    v: &[f64; 6],
    y_in: &[f64; 6],
    y_out: &[f64; 6],
    deviation: f64,
    max_trim: f64,
) -> Option<(Piece, f64)> {
    let cos: f64 = (0..6).map(|j| y_in[j] * y_out[j]).sum::<f64>().clamp(-1.0, 1.0);
    let alpha = cos.acos();
    if !(1e-6..=std::f64::consts::PI - 1e-3).contains(&alpha) || deviation <= 0.0 {
        return None;
    }
    let half = alpha / 2.0;
    let trim = (deviation * half.sin() / (1.0 - half.cos())).min(max_trim);
    let r = trim / half.tan();
    if !(trim > 1e-9 && r > 1e-9) {
        return None;
    }
    let mut bis = [0.0; 6];
    for j in 0..6 {
        bis[j] = y_out[j] - y_in[j];
    }
    let bl = bis.iter().map(|b| b * b).sum::<f64>().sqrt();
    let mut center = [0.0; 6];
    let mut x = [0.0; 6];
    for j in 0..6 {
        center[j] = v[j] + bis[j] / bl * (r / half.cos());
    }
    for j in 0..6 {
        x[j] = (v[j] - trim * y_in[j]) - center[j];
    }
    let xl = x.iter().map(|c| c * c).sum::<f64>().sqrt();
    for xj in &mut x {
        *xj /= xl;
    }
    Some((
        Piece::Arc {
            center,
            x,
            y: *y_in,
            r,
            angle: alpha,
        },
        trim,
    ))
}

/// Steps needed along `arc` so that no joint turns more than `res.joint` radians and no point
/// moves more than `res.displacement` metres between neighbouring samples: on the arc
/// `q_j = c_j + r (x_j cos φ + y_j sin φ)`, joint `j` moves at most `√(x_j² + y_j²)` radians per
/// radian of arc length, so over a piece of length `l` it moves at most `l √(x_j² + y_j²)` and a
/// point at most `l Σ_j r_j √(x_j² + y_j²)` (at most [`Resolution::curve_steps`]; a line piece
/// takes that bound).
pub(crate) fn arc_steps(arc: &Piece, res: &Resolution) -> usize {
    let Piece::Arc { x, y, .. } = arc else {
        return res.curve_steps(arc.len());
    };
    let (mut fastest, mut sweep) = (0.0f64, 0.0);
    for j in 0..6 {
        let w = (x[j] * x[j] + y[j] * y[j]).sqrt();
        fastest = fastest.max(w);
        sweep += res.lever_arms[j] * w;
    }
    let len = arc.len();
    (((len * fastest) / res.joint)
        .max(len * sweep / res.displacement)
        .ceil() as usize)
        .max(1)
}

/// True when the arc is free at `res` (its ends lie on the checked segments).
fn arc_free<C: FastChecks + ?Sized>(checker: &mut C, arc: &Piece, res: &Resolution) -> bool {
    let n = arc_steps(arc, res);
    (1..n).all(|k| checker.is_free(&arc.eval(arc.len() * k as f64 / n as f64).0))
}

/// Halvings of the deviation tried before a corner is left unblended.
const HALVINGS: usize = 3;

/// Smooths `path` (consecutive duplicates allowed): every corner blended with the largest of
/// `deviation`, `deviation/2`, …, `deviation/8` whose arc is free, else left as a stop.
pub(crate) fn smooth<C: FastChecks + ?Sized>(
    checker: &mut C,
    path: &[[f64; 6]],
    deviation: f64,
    res: &Resolution,
) -> Smoothed {
    let mut v: Vec<[f64; 6]> = Vec::with_capacity(path.len());
    for q in path {
        if v.last().is_none_or(|l| distance(l, q) > 1e-12) {
            v.push(*q);
        }
    }
    let mut out = Smoothed {
        pieces: Vec::new(),
        blends: 0,
    };
    if v.len() < 2 {
        return out;
    }
    let segs: Vec<([f64; 6], f64)> = v.windows(2).map(|w| unit(&w[0], &w[1])).collect();
    // Per vertex: trim length, its arc, and whether the arm stops there.
    let n = v.len();
    let mut trim = vec![0.0; n];
    let mut arcs: Vec<Option<Piece>> = vec![None; n];
    let mut stop = vec![false; n];
    for i in 1..n - 1 {
        let (y_in, l_in) = &segs[i - 1];
        let (y_out, l_out) = &segs[i];
        let cos: f64 = (0..6).map(|j| y_in[j] * y_out[j]).sum();
        if cos > (1e-6f64).cos() {
            continue; // straight on: no corner
        }
        let mut dev = deviation;
        let mut found = None;
        for _ in 0..=HALVINGS {
            match corner(&v[i], y_in, y_out, dev, 0.5 * l_in.min(*l_out)) {
                Some((arc, t)) if arc_free(checker, &arc, res) => {
                    found = Some((arc, t));
                    break;
                }
                Some(_) => dev *= 0.5,
                None => break,
            }
        }
        match found {
            Some((arc, t)) => {
                trim[i] = t;
                arcs[i] = Some(arc);
                out.blends += 1;
            }
            None => stop[i] = true,
        }
    }
    for k in 0..n - 1 {
        let (dir, len) = segs[k];
        let mut from = [0.0; 6];
        for j in 0..6 {
            from[j] = v[k][j] + dir[j] * trim[k];
        }
        let line_len = (len - trim[k] - trim[k + 1]).max(0.0);
        if line_len > 1e-12 || stop[k] {
            out.pieces.push((
                Piece::Line {
                    from,
                    dir,
                    len: line_len,
                },
                stop[k],
            ));
        }
        if let Some(arc) = arcs[k + 1].take() {
            out.pieces.push((arc, false));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::plan::CollisionChecker;

    struct Free;
    impl CollisionChecker for Free {
        fn is_free(&mut self, _q: &[f64; 6]) -> bool {
            true
        }
    }

    impl FastChecks for Free {}

    #[test]
    fn a_corner_arc_is_tangent_to_both_segments_and_within_the_deviation() {
        let path = [
            [0.0; 6],
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        ];
        let s = smooth(&mut Free, &path, 0.1, &Resolution::joint(0.05));
        assert_eq!(s.blends, 1);
        assert_eq!(s.pieces.len(), 3);
        let (arc, _) = &s.pieces[1];
        let (q0, d0, _) = arc.eval(0.0);
        let (q1, d1, _) = arc.eval(arc.len());
        let (l0, _, _) = s.pieces[0].0.eval(s.pieces[0].0.len());
        let (l1, _, _) = s.pieces[2].0.eval(0.0);
        for j in 0..6 {
            assert!((q0[j] - l0[j]).abs() < 1e-12 && (q1[j] - l1[j]).abs() < 1e-12);
        }
        assert!(
            (d0[0] - 1.0).abs() < 1e-12 && (d1[1] - 1.0).abs() < 1e-12,
            "{d0:?} {d1:?}"
        );
        let (mid, _, _) = arc.eval(arc.len() / 2.0);
        let dev = distance(&mid, &path[1]);
        assert!((dev - 0.1).abs() < 1e-9, "deviation {dev}");
    }

    #[test]
    fn arc_steps_keep_the_resolution_between_samples_and_never_exceed_the_curve_bound() {
        let res = Resolution {
            joint: 0.05,
            displacement: 0.01,
            lever_arms: [1.16, 1.19, 0.77, 0.38, 0.34, 0.12],
        };
        let y_in = [0.6, 0.0, 0.8, 0.0, 0.0, 0.0];
        let y_out = [0.0, 0.0, 0.6, 0.0, 0.8, 0.0];
        let (arc, _) = corner(&[0.3, -1.0, 1.2, 0.0, 0.5, 0.0], &y_in, &y_out, 0.1, 1.0).unwrap();
        let n = arc_steps(&arc, &res);
        assert!(
            n <= res.curve_steps(arc.len()),
            "{n} > {}",
            res.curve_steps(arc.len())
        );
        assert!(
            n < res.curve_steps(arc.len()),
            "no gain on an arc in two joints' planes"
        );
        // Between neighbouring samples (and finely inside each), no joint moves more than the
        // joint step and the lever-arm sweep stays within the displacement bound.
        let fine = 50;
        for k in 0..n {
            let q0 = arc.eval(arc.len() * k as f64 / n as f64).0;
            for m in 1..=fine {
                let s = arc.len() * (k as f64 + m as f64 / fine as f64) / n as f64;
                let q = arc.eval(s).0;
                let sweep: f64 = (0..6).map(|j| res.lever_arms[j] * (q[j] - q0[j]).abs()).sum();
                assert!(sweep <= res.displacement + 1e-12, "sweep {sweep} at {k}/{m}");
                assert!((0..6).all(|j| (q[j] - q0[j]).abs() <= res.joint + 1e-12));
            }
        }
    }

    #[test]
    fn a_blocked_corner_is_a_stop() {
        /// Everything off the two segments is blocked.
        struct OnlyTheCorner;
        impl CollisionChecker for OnlyTheCorner {
            fn is_free(&mut self, q: &[f64; 6]) -> bool {
                q[0].abs() < 1e-9 || (q[1] - 1.0).abs() < 1e-9 || q[1].abs() < 1e-9
            }
        }

        impl FastChecks for OnlyTheCorner {}
        let path = [
            [0.0; 6],
            [0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        ];
        let s = smooth(&mut OnlyTheCorner, &path, 0.1, &Resolution::joint(0.002));
        assert_eq!(s.blends, 0);
        assert_eq!(s.pieces.len(), 2);
        assert!(s.pieces[1].1, "the arm stops at the corner");
    }
}
