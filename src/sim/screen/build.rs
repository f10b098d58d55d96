//! Building the screen of one snapshot of the cell: its shapes, the pairs MuJoCo tests, and
//! their groups.

use mujoco_rs::prelude::*;
use nalgebra::Vector3;

use super::lever::lever_ratio;
use super::link_capsule::link_capsule;
use super::local::{GeomShape, exact, geom_local};
use super::pairs::{Group, Pair, Partner};
use super::posed::{MovingShape, Posed, Posing};
use super::shapes::Shape;
use super::sphere::link_sphere;
use super::turned::{Places, axial_places, turned_apart};
use super::{PAD, Screen};
use crate::sim::chain::{ArmChain, Frame, mat};
use crate::sim::pair_filter::PairFilter;

/// What the screen needs of the checker that builds it.
pub(crate) struct Build<'a> {
    /// The checker's private data, posed by `mj_kinematics` (any arm joints; a held block at
    /// its pose for those joints).
    pub(crate) data: &'a MjData<Box<MjModel>>,
    /// Arm group of each geom (0 fixed, 1..=6 moved by that arm joint; a held block's geoms 6).
    pub(crate) group: &'a [u8],
    /// Body ids of the six arm links, base to wrist 3.
    pub(crate) link_bodies: [usize; 6],
    /// The six arm links as a chain (their frames at any joints).
    pub(crate) chain: &'a ArmChain,
}

impl Screen {
    /// The screen of the private model and data in `b`; `None` when some geom that can touch
    /// the arm is of a type the screen cannot bound, or the arm is not a chain of six links.
    pub(crate) fn build(b: &Build<'_>) -> Option<Self> {
        let m: &MjModel = b.data.model();
        let d = b.data;
        let ngeom = m.ffi().ngeom as usize;
        let chain = b.chain.clone();
        let link_pose: [Frame; 6] = b.link_bodies.map(|l| Frame::of_body(d, l));
        let (ct, ca) = (m.geom_contype(), m.geom_conaffinity());
        let collidable = |g: usize| ct[g] != 0 || ca[g] != 0;
        // Index of each geom's shape: moving ones first, then fixed ones.
        let mut index: Vec<Option<usize>> = vec![None; ngeom];
        let mut moving: Vec<MovingShape> = Vec::new();
        let mut fixed: Vec<Posed> = Vec::new();
        let mut fixed_geoms: Vec<usize> = Vec::new();
        for (g, slot) in index.iter_mut().enumerate() {
            if !collidable(g) {
                continue;
            }
            let shape = geom_local(m, g);
            let k = b.group[g];
            let (gr, gt) = (mat(&d.geom_xmat()[g]), Vector3::from(d.geom_xpos()[g]));
            if k == 0 {
                let s = match shape {
                    // A fixed geom of a type the screen cannot bound: fine while nothing moving
                    // can touch it (checked below through the pairs).
                    None => continue,
                    Some(GeomShape::Plane) => {
                        let n = gr.column(2).into_owned();
                        Shape::HalfSpace {
                            normal: n,
                            offset: n.dot(&gt),
                        }
                    }
                    Some(GeomShape::Solid(l)) => l.posed(&gr, &gt),
                };
                fixed_geoms.push(g);
                fixed.push(Posed {
                    shape: s,
                    sphere: s.bounding_sphere(),
                    exact: exact(m, g),
                });
            } else {
                let Some(GeomShape::Solid(l)) = shape else {
                    return None;
                };
                let link = &link_pose[k as usize - 1];
                let lr = link.rot.transpose();
                let rel_r = lr * gr;
                let rel_t = lr * (gt - link.pos);
                *slot = Some(moving.len());
                let local = l.moved(&rel_r, &rel_t);
                moving.push(MovingShape {
                    link: k as usize - 1,
                    local,
                    exact: exact(m, g),
                    reach: local.reach(),
                });
            }
        }
        for (i, &g) in fixed_geoms.iter().enumerate() {
            index[g] = Some(moving.len() + i);
        }
        let mut geoms = vec![0; moving.len() + fixed.len()];
        for (g, i) in index.iter().enumerate() {
            if let Some(i) = i {
                geoms[*i] = g;
            }
        }
        // The pairs MuJoCo tests in this model.
        let filter = PairFilter::new(m);
        let (margin, gap) = (m.geom_margin(), m.geom_gap());
        let mut pairs = Vec::new();
        let mut add = |g1: usize, g2: usize, pair_margin: f64, pair_gap: f64| -> bool {
            if b.group[g1] == 0 && b.group[g2] == 0 {
                return true;
            }
            match (index[g1], index[g2]) {
                (Some(x), Some(y)) => {
                    let (a, bb) = if x < y { (x, y) } else { (y, x) };
                    pairs.push(Pair {
                        a: a as u16,
                        b: bb as u16,
                        gap: pair_margin.max(0.0) + PAD,
                        block: (pair_margin - pair_gap.max(0.0)).min(0.0) - PAD,
                        kappa: 1.0,
                    });
                    true
                }
                // A geom that can touch the arm but has no bounding shape.
                _ => false,
            }
        };
        for g1 in 0..ngeom {
            if !collidable(g1) {
                continue;
            }
            for g2 in g1 + 1..ngeom {
                if !collidable(g2) {
                    continue;
                }
                if !filter.tested(g1, g2) {
                    continue;
                }
                if !add(g1, g2, margin[g1].max(margin[g2]), gap[g1].max(gap[g2])) {
                    return None;
                }
            }
        }
        let (pg1, pg2, pm, pgap) = (m.pair_geom1(), m.pair_geom2(), m.pair_margin(), m.pair_gap());
        for p in 0..m.ffi().npair as usize {
            if !add(pg1[p] as usize, pg2[p] as usize, pm[p], pgap[p]) {
                return None;
            }
        }
        if moving.len() + fixed.len() > u16::MAX as usize {
            return None;
        }
        // Cheapest rejections first: fixed partners before self pairs.
        pairs.sort_by_key(|p| (p.b as usize) < moving.len());
        let nm = moving.len();
        for p in &mut pairs {
            p.kappa = lever_ratio(&chain.links, &moving, p.a as usize, p.b as usize);
        }
        // The arm's own pairs that keep their gap at any angles of the joints between their
        // links: never tested.
        let places: Vec<Places> = moving
            .iter()
            .map(|s| axial_places(&chain, &link_pose, s))
            .collect();
        pairs.retain(|p| {
            let (a, bb) = (p.a as usize, p.b as usize);
            bb >= nm
                || turned_apart(
                    &chain,
                    &link_pose,
                    (moving[a].link, &places[a]),
                    (moving[bb].link, &places[bb]),
                ) < p.gap
        });
        let partner = |p: &Pair| {
            if (p.b as usize) < nm {
                Partner::Link(moving[p.b as usize].link)
            } else {
                Partner::Fixed(p.b as usize - nm)
            }
        };
        // Each link–partner group together, the groups in the order of their first pair.
        let mut order: Vec<(usize, Partner)> = Vec::new();
        for p in &pairs {
            let key = (moving[p.a as usize].link, partner(p));
            if !order.contains(&key) {
                order.push(key);
            }
        }
        let mut grouped = Vec::with_capacity(pairs.len());
        let mut groups = Vec::with_capacity(order.len());
        for &(link, with) in &order {
            let start = grouped.len() as u32;
            let (mut gap, mut kappa): (f64, f64) = (0.0, 0.0);
            for p in pairs
                .iter()
                .filter(|p| (moving[p.a as usize].link, partner(p)) == (link, with))
            {
                gap = gap.max(p.gap);
                kappa = kappa.max(p.kappa);
                grouped.push(*p);
            }
            groups.push(Group {
                link,
                partner: with,
                gap,
                kappa,
                start,
                end: grouped.len() as u32,
            });
        }
        let link_capsules =
            std::array::from_fn(|k| link_capsule(moving.iter().filter(|s| s.link == k).map(|s| &s.local)));
        let link_spheres =
            std::array::from_fn(|k| link_sphere(moving.iter().filter(|s| s.link == k).map(|s| &s.local)));
        Some(Self {
            chain,
            moving,
            fixed,
            pairs: grouped,
            groups,
            link_spheres,
            link_capsules,
            geoms,
            undecided: Vec::new(),
            posed: Posing::new(nm),
            shape_of: index.iter().map(|i| i.map(|i| i as u32)).collect(),
            bound_posed: Posing::new(nm),
            bound_frames: link_pose,
        })
    }
}
