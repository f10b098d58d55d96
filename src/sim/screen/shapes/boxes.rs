//! Two oriented boxes: whether they overlap (separating axes) and the widest gap of their face
//! projections.

use super::{V3, dot, sub};

/// True when two oriented boxes overlap (the separating axis test over the 15 candidate axes;
/// Ericson 4.4.1). Touching counts as overlapping; near-parallel edge axes are treated
/// conservatively (an epsilon added to the projections).
pub(super) fn boxes_overlap(c1: &V3, a1: &[V3; 3], h1: &V3, c2: &V3, a2: &[V3; 3], h2: &V3) -> bool {
    const EPS: f64 = 1e-9;
    let mut r = [[0.0; 3]; 3];
    let mut abs_r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = dot(&a1[i], &a2[j]);
            abs_r[i][j] = r[i][j].abs() + EPS;
        }
    }
    let tw = sub(c2, c1);
    let t = [dot(&tw, &a1[0]), dot(&tw, &a1[1]), dot(&tw, &a1[2])];
    for i in 0..3 {
        let ra = h1[i];
        let rb = h2[0] * abs_r[i][0] + h2[1] * abs_r[i][1] + h2[2] * abs_r[i][2];
        if t[i].abs() > ra + rb {
            return false;
        }
    }
    for j in 0..3 {
        let ra = h1[0] * abs_r[0][j] + h1[1] * abs_r[1][j] + h1[2] * abs_r[2][j];
        let rb = h2[j];
        let tj = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
        if tj.abs() > ra + rb {
            return false;
        }
    }
    for i in 0..3 {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        for j in 0..3 {
            let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
            let ra = h1[i1] * abs_r[i2][j] + h1[i2] * abs_r[i1][j];
            let rb = h2[j1] * abs_r[i][j2] + h2[j2] * abs_r[i][j1];
            let tl = (t[i2] * r[i1][j] - t[i1] * r[i2][j]).abs();
            if tl > ra + rb {
                return false;
            }
        }
    }
    true
}

/// The widest gap between the projections of two oriented boxes on their six face axes,
/// metres (negative when every projection overlaps): a lower bound on their distance when
/// positive.
pub(super) fn boxes_face_gap(c1: &V3, a1: &[V3; 3], h1: &V3, c2: &V3, a2: &[V3; 3], h2: &V3) -> f64 {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = dot(&a1[i], &a2[j]).abs();
        }
    }
    let tw = sub(c2, c1);
    let mut best = f64::NEG_INFINITY;
    for i in 0..3 {
        let rb = h2[0] * r[i][0] + h2[1] * r[i][1] + h2[2] * r[i][2];
        best = best.max(dot(&tw, &a1[i]).abs() - h1[i] - rb);
    }
    for j in 0..3 {
        let ra = h1[0] * r[0][j] + h1[1] * r[1][j] + h1[2] * r[2][j];
        best = best.max(dot(&tw, &a2[j]).abs() - ra - h2[j]);
    }
    best
}
