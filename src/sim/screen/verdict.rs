//! The screen's verdict at a configuration: free, blocked or undecided, with the spare clearance
//! by joint range that a "free" vouches for.

use super::pairs::{Group, Partner};
use super::shapes::{Shape, Sphere, separation, surely_beyond};
use super::{Screen, Undecided};
use crate::motion::plan::JointSpare;
use crate::sim::chain::{Frame, JointAxis};

/// Two geom ids (MuJoCo's).
pub type GeomPair = (usize, usize);

impl Screen {
    /// The screen's verdict at `q` (radians): `Some(true)` when every tested pair keeps its
    /// margin plus [`PAD`](super::PAD) (MuJoCo then reports no contact), `Some(false)` when a
    /// pair of exact shapes (no bounds) penetrates by more than [`PAD`](super::PAD) (MuJoCo then
    /// reports that contact), `None` otherwise.
    pub fn classify(&mut self, q: &[f64; 6]) -> Option<bool> {
        self.decide(q).0
    }

    /// The verdict at `q` (radians) and the geom pair that decided a "blocked".
    pub fn decide(&mut self, q: &[f64; 6]) -> (Option<bool>, Option<GeomPair>) {
        let (verdict, hit, _) = self.judge::<false>(q, &JointSpare::NONE);
        (verdict, hit)
    }

    /// The verdict at `q` (radians), as [`Screen::classify`], and with a "free" the spare
    /// clearance by joint range ([`JointSpare`], in each range at most `caps`' (metres: the
    /// spare worth measuring, [`JointSpare::wanted`]); none with any other verdict): for each
    /// tested pair, a lower bound on how much farther apart than its margin plus
    /// [`PAD`](super::PAD) its primitives are, divided by the pair's lever-arm ratio (its parts
    /// move relative to each other at most that fraction of the planner's lever-arm bound), in
    /// the range of the joints that move the pair's parts relative to each other. Geoms lie
    /// inside their primitives, so the geoms keep the margin wherever the lever-arm bound of the
    /// range's joint changes stays within its spare.
    ///
    /// With no verdict (`None`), the spare is that of the pairs the screen decided, and
    /// [`Screen::undecided`] lists the others: a checker that measures them exactly can settle
    /// the verdict and the spare ([`Undecided`]).
    pub fn free_spare(&mut self, q: &[f64; 6], caps: &JointSpare) -> (Option<bool>, JointSpare) {
        let (verdict, _, spare) = self.judge::<true>(q, caps);
        (
            verdict,
            if verdict == Some(false) {
                JointSpare::NONE
            } else {
                spare
            },
        )
    }

    /// The pairs the last [`Screen::free_spare`] could not decide (none after a verdict).
    pub fn undecided(&self) -> &[Undecided] {
        &self.undecided
    }

    /// The verdict, the pair that decided a "blocked", and with `SPARE` the spare clearance by
    /// joint range up to `caps`' (metres; only meaningful with a "free").
    fn judge<const SPARE: bool>(
        &mut self,
        q: &[f64; 6],
        caps: &JointSpare,
    ) -> (Option<bool>, Option<GeomPair>, JointSpare) {
        let frames = self.chain.link_poses(q);
        // Every moving shape posed again when first needed.
        self.posed.renew();
        let spheres = self.world_spheres(&frames);
        let capsules = self.world_capsules(&frames);
        let nm = self.moving.len();
        let mut unsure = false;
        let mut spare = *caps;
        self.undecided.clear();
        for g in &self.groups {
            // The joints that move the group's pairs relative to each other (none: the pairs
            // never move apart or closer, and limit no spare).
            let range = g.joints();
            // The range whose spare is wanted.
            let wanted = range.filter(|_| SPARE);
            // The link keeps the group's gap, and with a spare wanted the range's spare found so
            // far too: nothing to learn from the group's pairs (else they may keep more than
            // the link's bound does, or not their gap).
            let keep = match wanted {
                Some(r) => g.gap + g.kappa * spare.get(r.first, r.last),
                None => g.gap,
            };
            if self.group_apart(g, &spheres, &capsules, keep) {
                continue;
            }
            for p in &self.pairs[g.start as usize..g.end as usize] {
                let (a, b) = (p.a as usize, p.b as usize);
                self.posed.ensure(a, &self.moving, &frames);
                self.posed.ensure(b, &self.moving, &frames);
                let (x, y) = (self.posed.get(a, &self.fixed), self.posed.get(b, &self.fixed));
                if let (Some(sx), Some(sy)) = (&x.sphere, &y.sphere) {
                    let d2 = sx.centre_dist2(sy);
                    if sx.keeps_at(d2, sy, p.gap) || (b >= nm && sx.keeps_from_box(&y.shape, p.gap)) {
                        if let Some(r) = wanted {
                            let need = p.gap + p.kappa * spare.get(r.first, r.last);
                            let far =
                                sx.keeps_at(d2, sy, need) || (b >= nm && sx.keeps_from_box(&y.shape, need));
                            if !far && !surely_beyond(&x.shape, &y.shape, need) {
                                // The spheres may lie far inside each other's reach (a wrist
                                // housing and the flange): the primitives' own clearance,
                                // which the spheres' gap only bounds from below.
                                let bound = sx.gap_to(y);
                                let c = separation(&x.shape, &y.shape)
                                    .apart(p.gap)
                                    .map_or(bound, |c| c.max(bound));
                                spare.tighten(r.first, r.last, (c - p.gap) / p.kappa);
                            }
                        }
                        continue;
                    }
                }
                // Near, or the clearance when it is wanted (one distance for both); nothing
                // to learn from a pair the quick bound keeps beyond what it could tighten.
                let quick = match wanted {
                    Some(r) => p.gap + p.kappa * spare.get(r.first, r.last),
                    None => p.gap,
                };
                if surely_beyond(&x.shape, &y.shape, quick) {
                    continue;
                }
                let sep = separation(&x.shape, &y.shape);
                let kept = if wanted.is_some() {
                    sep.apart(p.gap)
                } else {
                    (!sep.near(p.gap)).then_some(f64::INFINITY)
                };
                match (kept, wanted) {
                    (None, _) => {
                        if x.exact && y.exact && sep.within(p.block) {
                            self.undecided.clear();
                            return (
                                Some(false),
                                Some((self.geoms[a], self.geoms[b])),
                                JointSpare::NONE,
                            );
                        }
                        unsure = true;
                        if SPARE {
                            self.undecided.push(Undecided {
                                geoms: (self.geoms[a], self.geoms[b]),
                                gap: p.gap,
                                kappa: p.kappa,
                                range,
                            });
                        }
                    }
                    (Some(c), Some(r)) => spare.tighten(r.first, r.last, (c - p.gap) / p.kappa),
                    (Some(_), None) => {}
                }
            }
        }
        if !unsure {
            self.undecided.clear();
        }
        ((!unsure).then_some(true), None, spare)
    }

    /// How far the moving shapes reach from each joint's axis at the link frames `frames`
    /// ([`ArmChain::link_poses`](crate::sim::chain::ArmChain::link_poses)), metres, through each
    /// link's bounding sphere: every moving collidable geom lies inside them.
    pub(crate) fn reach(&self, frames: &[Frame; 6]) -> [f64; 6] {
        let spheres = self.world_spheres(frames);
        let mut reach = [0.0f64; 6];
        for (j, out) in reach.iter_mut().enumerate() {
            let JointAxis {
                point: a,
                direction: u,
            } = self.chain.joint_axis(frames, j);
            for s in spheres[j..].iter().flatten() {
                let c = &s.centre;
                let d = nalgebra::Vector3::new(c[0] - a.x, c[1] - a.y, c[2] - a.z);
                *out = out.max(d.cross(&u).norm() + s.radius);
            }
        }
        reach
    }

    /// Each link's bounding sphere in the world at the link frames `frames` (`None`: a link
    /// without shapes).
    fn world_spheres(&self, frames: &[Frame; 6]) -> [Option<Sphere>; 6] {
        std::array::from_fn(|k| {
            self.link_spheres[k].map(|s| Sphere {
                centre: frames[k].rot * s.centre + frames[k].pos,
                radius: s.radius,
            })
        })
    }

    /// Each link's bounding capsule in the world at the link frames `frames` (`None`: a link
    /// without shapes).
    fn world_capsules(&self, frames: &[Frame; 6]) -> [Option<Shape>; 6] {
        std::array::from_fn(|k| {
            self.link_capsules[k]
                .as_ref()
                .map(|l| l.posed(&frames[k].rot, &frames[k].pos))
        })
    }

    /// True when group `g`'s link keeps `gap` metres from the group's partner: its sphere
    /// (`spheres`: each link's, world frame) from the other link's sphere, or from a fixed
    /// shape's bounding sphere, its box or its half-space; else its capsule (`capsules`) from
    /// the other link's capsule, or from the fixed shape (a box by the quick bound first).
    fn group_apart(
        &self,
        g: &Group,
        spheres: &[Option<Sphere>; 6],
        capsules: &[Option<Shape>; 6],
        gap: f64,
    ) -> bool {
        // A link without shapes keeps every gap.
        let Some(link) = &spheres[g.link] else {
            return true;
        };
        let by_spheres = match g.partner {
            Partner::Link(m) => spheres[m].as_ref().is_none_or(|other| link.keeps(other, gap)),
            Partner::Fixed(f) => {
                let fixed = &self.fixed[f];
                match (&fixed.shape, &fixed.sphere) {
                    (y, Some(s)) => link.keeps(s, gap) || link.keeps_from_box(y, gap),
                    (Shape::HalfSpace { normal, offset }, None) => link.above(normal, *offset) >= gap,
                    _ => false,
                }
            }
        };
        if by_spheres {
            return true;
        }
        let Some(capsule) = &capsules[g.link] else {
            return true;
        };
        match g.partner {
            Partner::Link(m) => capsules[m]
                .as_ref()
                .is_none_or(|other| !separation(capsule, other).near(gap)),
            Partner::Fixed(f) => {
                let y = &self.fixed[f].shape;
                match y {
                    Shape::Box { .. } => surely_beyond(capsule, y, gap),
                    _ => !separation(capsule, y).near(gap),
                }
            }
        }
    }
}
