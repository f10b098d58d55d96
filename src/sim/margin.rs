//! The clearance margin completed where MuJoCo's narrow phase leaves it out.
//!
//! `mj_collision` reports every penetration, but for capsule–box, box–box and box–plane pairs
//! MuJoCo 3.17's primitive colliders do not report every pair that is closer than the pair's
//! margin yet not touching: measured on the `go_around` cell (3000 arm configurations near the
//! fixture, every robot geom against every scene geom, a 5 mm margin), 66 of 174 capsule–box, 53
//! of 73 box–box and 44 of 81 box–plane pairs 0–5 mm apart were not reported, while every
//! mesh and cylinder pair was. A planned path could then pass 1.5 mm from the fixture (the
//! forearm's capsule) although the planner keeps 5 mm, and the servos' few millimetres of
//! tracking error put the forearm on the fixture. (Part of those omissions was the broad
//! phase, which grows each body's box by the body's compiled margin: the checker now writes the
//! bodies' margins with the geoms'. The colliders' own omissions remain.)
//!
//! [`MarginPairs`] lists the pairs of those types that MuJoCo tests in a model (contact bitmasks,
//! body filters, `<exclude>`) and, after `mj_collision`, measures each one that MuJoCo did not
//! report and that may be within the margin (the other geom's bounding sphere against the box, or
//! against the plane's half-space) with `mj_geomDistance` (GJK on the exact shapes), so a checker
//! counts it when it is closer than the margin, as for every other pair.

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;

use super::pair_filter::PairFilter;

/// A pair whose MuJoCo collider does not honour the margin: capsule–box, box–box, box–plane.
fn margin_unreliable(a: MjtGeomBase, b: MjtGeomBase) -> bool {
    type G = MjtGeomBase;
    let other = match (a, b) {
        (G::mjGEOM_BOX, o) | (o, G::mjGEOM_BOX) => o,
        _ => return false,
    };
    matches!(other, G::mjGEOM_BOX | G::mjGEOM_CAPSULE | G::mjGEOM_PLANE)
}

/// One pair to measure: geoms `a`, `b`, the pair's margin (the larger geom margin), metres, and
/// the arm joints `lo..=hi` that move the two relative to each other (`lo > hi`: none).
#[derive(Clone, Copy, Debug)]
struct Pair {
    a: usize,
    b: usize,
    margin: f64,
    lo: u8,
    hi: u8,
}

/// The arm joints (0-based, `lo..=hi`) that move geoms of arm groups `ga` and `gb` relative to
/// each other (group 0: fixed; `k` in 1..=6: moved by arm joints `0..k`): a fixed geom and one
/// of group `k`, joints `0..=k−1`; groups `a < b`, joints `a..=b−1` (`lo > hi`: none).
fn joint_range(ga: u8, gb: u8) -> (u8, u8) {
    let (a, b) = (ga.min(gb), ga.max(gb));
    if b == 0 { (1, 0) } else { (a, b - 1) }
}

/// The geom pairs of a model whose margin MuJoCo's narrow phase may leave out (see the module
/// docs), measured directly.
#[derive(Clone, Debug, Default)]
pub(crate) struct MarginPairs {
    pairs: Vec<Pair>,
    /// Every pair MuJoCo tests in the model with a positive margin, whatever its types (for
    /// [`MarginPairs::least`]).
    all: Vec<Pair>,
    /// The index in `all` of the closest pair at the last [`MarginPairs::least`], measured
    /// first the next time: the least so far then prunes most of the others.
    closest: usize,
    /// Lower bounds on each pair's distance from earlier calls of [`MarginPairs::least`].
    known: Known,
}

/// Lower bounds on the pairs' distances, carried from call to call of [`MarginPairs::least`]:
/// between two calls a point moved by joints `lo..=hi` moves relative to its partner at most the
/// lever-arm bound `Σ_{j in lo..=hi} r_j |Δq_j|`, so no pair comes closer by more than that.
#[derive(Clone, Debug, Default)]
struct Known {
    /// The joints of the last call, radians (`None`: nothing known).
    at: Option<[f64; 6]>,
    /// `travelled[k]`: the lever-arm displacements of joints `0..k` summed over the calls since
    /// `at` was first set, metres (a prefix sum: joints `lo..=hi` moved `travelled[hi + 1] −
    /// travelled[lo]`).
    travelled: [f64; 7],
    /// Per pair of `all`: a lower bound of its distance at the call that set it plus its joints'
    /// travel then, metres (the bound now is this less its joints' travel now).
    lower: Vec<f64>,
}

impl Known {
    /// How far joints `lo..=hi` have moved a point, summed over the calls, metres.
    fn moved(&self, p: &Pair) -> f64 {
        if p.lo > p.hi {
            return 0.0;
        }
        self.travelled[p.hi as usize + 1] - self.travelled[p.lo as usize]
    }
}

impl MarginPairs {
    /// The capsule–box, box–box and box–plane pairs MuJoCo tests in `m` (its contact bitmasks,
    /// its body filters, `<exclude>`) with a positive margin; `group` gives each geom's arm group
    /// (0: fixed; `k` in 1..=6: moved by arm joint `k − 1`, a held block's geoms 6).
    pub(crate) fn new(m: &MjModel, group: &[u8]) -> Self {
        let ngeom = m.ffi().ngeom as usize;
        let (types, margin) = (m.geom_type(), m.geom_margin());
        let filter = PairFilter::new(m);
        let (mut pairs, mut all) = (Vec::new(), Vec::new());
        for g1 in 0..ngeom {
            for g2 in g1 + 1..ngeom {
                let pair_margin = margin[g1].max(margin[g2]);
                if pair_margin > 0.0 && filter.tested(g1, g2) {
                    let (lo, hi) = joint_range(group[g1], group[g2]);
                    let p = Pair {
                        a: g1,
                        b: g2,
                        margin: pair_margin,
                        lo,
                        hi,
                    };
                    all.push(p);
                    if margin_unreliable(types[g1], types[g2]) {
                        pairs.push(p);
                    }
                }
            }
        }
        Self {
            pairs,
            all,
            closest: 0,
            known: Known::default(),
        }
    }

    /// The listed pairs of `data` (posed: `mj_kinematics` run) closer than their margin that
    /// `mj_collision` did not report in `data.contact()`, as `(geom, geom, distance)`
    /// (metres, positive: apart; a penetration is always reported by MuJoCo itself).
    pub(crate) fn missing<M: ModelType>(&self, data: &mut MjData<M>) -> Vec<(usize, usize, f64)> {
        let mut out = Vec::new();
        for p in &self.pairs {
            if !near(data, p, p.margin) {
                continue;
            }
            let reported = data.contact().iter().any(|c| {
                let (x, y) = (c.geom[0] as usize, c.geom[1] as usize);
                (x == p.a && y == p.b) || (x == p.b && y == p.a)
            });
            if reported {
                continue;
            }
            let d = data.geom_distance(p.a, p.b, p.margin, None);
            if d < p.margin {
                out.push((p.a, p.b, d));
            }
        }
        out
    }
}

impl MarginPairs {
    /// The least distance of every pair MuJoCo tests in the model (with a positive margin) at
    /// `data` (posed), metres, at most `wide`: each pair that may be closer (bounding spheres,
    /// a box's or a plane's own bound, then `tighter(a, b)`: any lower bound on the distance
    /// of geoms `a` and `b` as posed, such as the screen's primitives'; `−∞` for none) measured
    /// with `mj_geomDistance`, the exact distance of the shapes MuJoCo collides (a mesh's
    /// convex hull); the pair closest at the last call first, so the least so far prunes the
    /// others. A pair left out by a bound is at least the least so far apart, so the least is
    /// the one every pair's `mj_geomDistance` gives. One least for every pair, not one per
    /// joint range as the screen's spare: measured on the motion benchmark, the pruning by the
    /// least so far saves more `mj_geomDistance` calls than ranges would vouch for.
    ///
    /// `q` (radians) is the configuration `data` is posed at and `arms` the lever arms (metres)
    /// that bound how far a point moves per radian of each joint: each pair's bound is carried
    /// to the next calls, less how far the joints that move the pair have moved since, and a
    /// pair still at least the least so far apart is not looked at again. The least is the same
    /// as measured afresh; [`MarginPairs::forget`] drops the bounds when the scene changes.
    pub(crate) fn least<M: ModelType>(
        &mut self,
        data: &mut MjData<M>,
        q: &[f64; 6],
        arms: &[f64; 6],
        wide: f64,
        mut tighter: impl FnMut(usize, usize) -> f64,
    ) -> f64 {
        let known = &mut self.known;
        match known.at {
            Some(prev) => {
                let mut sum = 0.0;
                for j in 0..6 {
                    sum += arms[j] * (q[j] - prev[j]).abs();
                    known.travelled[j + 1] += sum;
                }
            }
            None => {
                known.lower.clear();
                known.lower.resize(self.all.len(), f64::NEG_INFINITY);
                known.travelled = [0.0; 7];
            }
        }
        known.at = Some(*q);
        let mut least = wide;
        let first = self.closest.min(self.all.len().saturating_sub(1));
        let order = std::iter::once(first).chain((0..self.all.len()).filter(|&i| i != first));
        for i in order {
            let p = &self.all[i];
            // Apart by at least `least` still, since the call that bounded it.
            let moved = known.moved(p);
            if known.lower[i] - moved >= least {
                continue;
            }
            let bound = apart(data, p, least);
            if bound >= least {
                known.lower[i] = bound + moved;
                continue;
            }
            let bound = bound.max(tighter(p.a, p.b));
            if bound >= least {
                known.lower[i] = bound + moved;
                continue;
            }
            let d = data.geom_distance(p.a, p.b, least, None);
            known.lower[i] = d + moved;
            if d < least {
                least = d;
                self.closest = i;
            }
        }
        least
    }

    /// Drops the pairs' lower bounds ([`MarginPairs::least`]): the scene or a held block moved.
    pub(crate) fn forget(&mut self) {
        self.known.at = None;
    }

    /// True when the model has no pair with a positive margin.
    pub(crate) fn is_empty(&self) -> bool {
        self.all.is_empty()
    }
}

/// False when the pair surely keeps its margin: a box's distance from the other geom's centre
/// less the other's bounding radius (both ways round when both are boxes), or a plane's
/// half-space against the other's bounding sphere, is at least the margin; the geoms then keep
/// it too.
fn near<M: ModelType>(data: &MjData<M>, p: &Pair, margin: f64) -> bool {
    apart(data, p, margin) < margin
}

/// A lower bound on the pair's distance, metres, from the bounds [`near`] uses (the bounding
/// spheres alone when they keep `margin`).
fn apart<M: ModelType>(data: &MjData<M>, p: &Pair, margin: f64) -> f64 {
    let m = data.model();
    let (pos, mat, rbound, types) = (data.geom_xpos(), data.geom_xmat(), m.geom_rbound(), m.geom_type());
    // A lower bound of the distance from geom `shape` (a box or a plane) to geom `other`.
    let bound = |shape: usize, other: usize| -> f64 {
        let (o, r, x) = (pos[shape], mat[shape], pos[other]);
        let d = [x[0] - o[0], x[1] - o[1], x[2] - o[2]];
        // The offset in the shape's frame (`geom_xmat` is row-major: columns are its axes).
        let local = |i: usize| d[0] * r[i] + d[1] * r[3 + i] + d[2] * r[6 + i];
        let apart = match types[shape] {
            MjtGeomBase::mjGEOM_PLANE => local(2),
            _ => {
                let size = m.geom_size()[shape];
                (0..3)
                    .map(|i| (local(i).abs() - size[i]).max(0.0).powi(2))
                    .sum::<f64>()
                    .sqrt()
            }
        };
        apart - rbound[other]
    };
    let is_box = |g: usize| types[g] == MjtGeomBase::mjGEOM_BOX;
    let plane = |g: usize| types[g] == MjtGeomBase::mjGEOM_PLANE;
    let mut apart = f64::NEG_INFINITY;
    if !plane(p.a) && !plane(p.b) {
        // The bounding spheres first: most pairs are far apart, and the box bounds cost more.
        let (x, y) = (pos[p.a], pos[p.b]);
        let d2 = (x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2);
        apart = d2.sqrt() - rbound[p.a] - rbound[p.b];
        if apart >= margin {
            return apart;
        }
    }
    // A plane is unbounded: only its own half-space bounds the distance to it.
    if plane(p.a) || (is_box(p.a) && !plane(p.b)) {
        apart = apart.max(bound(p.a, p.b));
    }
    if plane(p.b) || (is_box(p.b) && !plane(p.a)) {
        apart = apart.max(bound(p.b, p.a));
    }
    apart
}

#[cfg(test)]
mod tests {
    use super::joint_range;

    #[test]
    fn a_pair_is_moved_by_the_joints_between_its_links() {
        // The fixed cell against link k (group k + 1): every joint up to k.
        assert_eq!(joint_range(0, 1), (0, 0));
        assert_eq!(joint_range(6, 0), (0, 5));
        // Wrist 1 (group 4) against wrist 3 or a held block (group 6): wrists 2 and 3 only.
        assert_eq!(joint_range(4, 6), (4, 5));
        assert_eq!(joint_range(6, 4), (4, 5));
        // Two fixed geoms, or two of one link, never move relative to each other.
        let (lo, hi) = joint_range(0, 0);
        assert!(lo > hi);
        let (lo, hi) = joint_range(3, 3);
        assert!(lo > hi);
    }
}
