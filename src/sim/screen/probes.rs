//! Probes of the screen's bounds for its tests: each bound pair by pair, without the verdict's
//! shortcuts.

use nalgebra::Vector3;

use super::Screen;
use super::local::Local;
use super::pairs::JointRange;
use super::shapes::{Shape, separation};
use super::turned::{Places, axial_places, turned_apart};
use crate::motion::plan::JointSpare;
use crate::motion::ur5e::LEVER_ARMS;
use crate::sim::chain::Frame;

/// Two moving shapes of different links: the bound on their distance at any angles of the
/// joints between them (metres), and the two primitives posed at another configuration.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TurnedBound {
    /// The bound ([`turned_apart`]), metres.
    pub(crate) bound: f64,
    /// The first shape, posed at the other configuration.
    pub(crate) x: Shape,
    /// The second shape, posed there.
    pub(crate) y: Shape,
}

/// How far a pair's distal shape moved relative to its partner between two configurations, and
/// the bound the spare's vouching relies on.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PairMove {
    /// The pair's lever-arm ratio.
    pub(crate) kappa: f64,
    /// The largest displacement of a point of the distal shape's hull, metres.
    pub(crate) moved: f64,
    /// `kappa · Σ_range r_j |Δq_j|`, metres.
    pub(crate) bound: f64,
}

impl Screen {
    /// Bounds on the spare [`Screen::free_spare`] finds at `q` (radians), pair by pair and
    /// without its shortcuts: for each joint range, the least over the range's pairs of
    /// `(c − gap) / kappa`, at most `cap` (metres), with `c` each pair's primitive clearance
    /// ([`Separation::clearance`](super::shapes::Separation::clearance)) in the first spare, and the
    /// larger of that and its bounding-sphere bound in the second.
    pub(crate) fn pair_spares(&self, q: &[f64; 6], cap: f64) -> (JointSpare, JointSpare) {
        let frames = self.chain.link_poses(q);
        let nm = self.moving.len();
        let (mut low, mut high) = (JointSpare::uniform(cap), JointSpare::uniform(cap));
        for g in &self.groups {
            let Some(JointRange { first: lo, last: hi }) = g.joints() else {
                continue;
            };
            for p in &self.pairs[g.start as usize..g.end as usize] {
                let (a, b) = (p.a as usize, p.b as usize);
                let x = self.moving[a].pose(&frames);
                let y = if b < nm {
                    self.moving[b].pose(&frames)
                } else {
                    self.fixed[b - nm]
                };
                let c = separation(&x.shape, &y.shape).clearance();
                let spheres = x.sphere.map_or(f64::NEG_INFINITY, |s| s.gap_to(&y));
                low.tighten(lo, hi, (c - p.gap) / p.kappa);
                high.tighten(lo, hi, (c.max(spheres) - p.gap) / p.kappa);
            }
        }
        (low, high)
    }

    /// For every two moving shapes on different links: the bound on their distance at any
    /// angles of the joints between them ([`turned_apart`]) from the link frames at `q`, and
    /// the two primitives posed at `q2` (radians, metres).
    pub(crate) fn turned_bounds(&self, q: &[f64; 6], q2: &[f64; 6]) -> Vec<TurnedBound> {
        let (f1, f2) = (self.chain.link_poses(q), self.chain.link_poses(q2));
        let mut out = Vec::new();
        let chain = &self.chain;
        let places: Vec<Places> = self.moving.iter().map(|m| axial_places(chain, &f1, m)).collect();
        for (i, x) in self.moving.iter().enumerate() {
            for (k, y) in self.moving.iter().enumerate().skip(i + 1) {
                if x.link != y.link {
                    let bound = turned_apart(chain, &f1, (x.link, &places[i]), (y.link, &places[k]));
                    out.push(TurnedBound {
                        bound,
                        x: x.pose(&f2).shape,
                        y: y.pose(&f2).shape,
                    });
                }
            }
        }
        out
    }

    /// For every pair: its lever-arm ratio, and between joints `q` and `q2` (radians) the
    /// largest displacement of a point of its distal shape's hull (box corners; capsule ends
    /// pushed out by the radius along each axis) relative to the frame of its partner's link
    /// (the world for a fixed partner), with the bound `kappa · Σ_range r_j |q2_j − q_j|`
    /// (metres) that the spare's vouching relies on.
    pub(crate) fn pair_moves(&self, q: &[f64; 6], q2: &[f64; 6]) -> Vec<PairMove> {
        let (f1, f2) = (self.chain.link_poses(q), self.chain.link_poses(q2));
        let nm = self.moving.len();
        let points = |l: &Local| -> Vec<Vector3<f64>> {
            match l {
                Local::Capsule { a, b, radius } => [a, b]
                    .iter()
                    .flat_map(|e| {
                        (0..3).flat_map(move |i| [-1.0, 1.0].map(|sgn| *e + Vector3::ith(i, sgn * radius)))
                    })
                    .collect(),
                Local::Box { center, axes, half } => (0..8)
                    .map(|c| {
                        let s = |i: usize| if c >> i & 1 == 1 { 1.0 } else { -1.0 };
                        center
                            + (0..3)
                                .map(|i| axes.column(i) * (s(i) * half[i]))
                                .sum::<Vector3<f64>>()
                    })
                    .collect(),
            }
        };
        self.pairs
            .iter()
            .map(|p| {
                let (a, b) = (p.a as usize, p.b as usize);
                let (far, near_link, range) = if b < nm {
                    let (ka, kb) = (self.moving[a].link, self.moving[b].link);
                    let far = if ka >= kb { a } else { b };
                    (far, Some(ka.min(kb)), ka.min(kb) + 1..=ka.max(kb))
                } else {
                    (a, None, 0..=self.moving[a].link)
                };
                let k = self.moving[far].link;
                let in_near = |f: &[Frame; 6], x: &Vector3<f64>| {
                    let w = f[k].rot * x + f[k].pos;
                    match near_link {
                        Some(n) => f[n].rot.transpose() * (w - f[n].pos),
                        None => w,
                    }
                };
                let moved = points(&self.moving[far].local)
                    .iter()
                    .map(|x| (in_near(&f2, x) - in_near(&f1, x)).norm())
                    .fold(0.0, f64::max);
                let bound: f64 = range.map(|j| LEVER_ARMS[j] * (q2[j] - q[j]).abs()).sum();
                PairMove {
                    kappa: p.kappa,
                    moved,
                    bound: p.kappa * bound,
                }
            })
            .collect()
    }
}
