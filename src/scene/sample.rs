//! Placements: where every object of a scene starts, checked against the cell's limits, and
//! drawn at random for sweeps.
//!
//! Scenario `k` of sweep seed `S` is a pure function of `(S, k)`: a ChaCha8 generator seeded with
//! `S` on stream `k` gives, in this order, the episode seed (one `u64`), then for every object
//! that has `random:` — in scene order, except that an object is drawn after what it rests on
//! (`on:`, `random: {in: ..}`) — its x, y and (when a yaw range is given) yaw; a block drawn
//! over its support (`random: {in: bin}`) draws its yaw first, then x and y in the support's
//! frame. Objects without `random:` keep their `pose:`. Heights follow from each object's `z:`
//! and what it rests on ([`Placement::settle`]). The whole draw is rejected and repeated until
//! every check of [`Placement::check`] passes, at most [`MAX_DRAWS`] times; when none passes,
//! the error names the constraint most draws broke. Uniform floats are built from the top 53
//! bits of a `u64` draw (`lo + (hi − lo)·u`, `u ∈ [0, 1)`), the same on every platform.

use std::collections::BTreeMap;

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{RngCore, SeedableRng};
use serde::Serialize;

use super::footprint::Rect;
pub use super::placement_error::PlacementError;
use super::placement_error::TABLE_HALF;
use super::types::{ObjectKind, Pose, ROBOT_BASE_RADIUS, RegionRole, SceneSpec, Shape, reach_limits};

/// Most draws before a sampling gives up (the constraints cannot be met).
pub const MAX_DRAWS: usize = 100_000;

/// Tolerance of the geometric checks (heights, margins), metres.
const EPS: f64 = 1e-9;

/// Every object's starting pose, in scene order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Placement {
    /// One pose per object of the scene, in scene order.
    pub poses: Vec<Pose>,
}

/// Index of what object `i` rests on (its `on:`), if not the table.
pub fn support_of(scene: &SceneSpec, i: usize) -> Option<usize> {
    scene.objects[i].on.as_deref().and_then(|s| scene.index_of(s))
}

/// The objects in the order they are placed: scene order, except that each object comes after
/// what it rests on. (The loader refuses support cycles; a cycle left here is broken at its
/// first member.)
pub fn placement_order(scene: &SceneSpec) -> Vec<usize> {
    fn visit(scene: &SceneSpec, i: usize, state: &mut [u8], out: &mut Vec<usize>) {
        if state[i] != 0 {
            return;
        }
        state[i] = 1;
        if let Some(s) = support_of(scene, i) {
            visit(scene, s, state, out);
        }
        state[i] = 2;
        out.push(i);
    }
    let mut state = vec![0u8; scene.objects.len()];
    let mut out = Vec::with_capacity(scene.objects.len());
    for i in 0..scene.objects.len() {
        visit(scene, i, &mut state, &mut out);
    }
    out
}

/// The area a block set on object `s` (at `pose`) can rest on, as a rectangle in the table plane.
fn support_rect(shape: &Shape, pose: &Pose) -> Rect {
    Rect {
        centre: [pose.x, pose.y],
        half: shape.support_half(),
        yaw: pose.yaw,
    }
}

/// How far the arm at home comes into the box of an object of `shape` at `pose` (its footprint,
/// from its base `pose.z` up its height): the deepest link and depth, metres; `None` when no
/// link's capsule ([`crate::motion::body::arm_capsules`]) reaches it.
fn arm_at_home_inside(shape: &Shape, pose: &Pose) -> Option<(&'static str, f64)> {
    let rect = shape.footprint(pose);
    let (bottom, top) = (pose.z, pose.z + shape.height());
    let mut deepest: Option<(&'static str, f64)> = None;
    for c in crate::motion::body::arm_capsules(&crate::motion::HOME_Q) {
        for p in c.axis_points(0.005) {
            let [u, v] = rect.local([p.x, p.y]);
            let dx = (u.abs() - rect.half[0]).max(0.0);
            let dy = (v.abs() - rect.half[1]).max(0.0);
            let dz = (p.z - top).max(bottom - p.z).max(0.0);
            let depth = c.radius - (dx * dx + dy * dy + dz * dz).sqrt();
            if depth > 0.0 && deepest.is_none_or(|(_, d)| depth > d) {
                deepest = Some((c.link, depth));
            }
        }
    }
    deepest
}

/// Object `i`'s `random.clearance`, 0 for an object without `random:`, metres.
fn clearance(scene: &SceneSpec, i: usize) -> f64 {
    scene.objects[i].random.as_ref().map_or(0.0, |r| r.clearance)
}

impl Placement {
    /// The scene's fixed poses (`pose:`), if every object has one, with their heights
    /// ([`Self::settle`]).
    pub fn fixed(scene: &SceneSpec) -> Option<Placement> {
        let mut p = scene
            .objects
            .iter()
            .map(|o| o.pose)
            .collect::<Option<Vec<_>>>()
            .map(|poses| Placement { poses })?;
        p.settle(scene);
        Some(p)
    }

    /// Sets every pose's height `z` from the scene: a container's or obstacle's own `z:`, a
    /// block's support's top (a container's floor top, an obstacle's or a block's top), or 0 on
    /// the table. A placement with a wrong number of poses is left as it is.
    pub fn settle(&mut self, scene: &SceneSpec) {
        if self.poses.len() != scene.objects.len() {
            return;
        }
        for i in placement_order(scene) {
            let o = &scene.objects[i];
            self.poses[i].z = match support_of(scene, i) {
                Some(s) => self.poses[s].z + scene.objects[s].shape.support_surface(),
                None => o.z,
            };
        }
    }

    /// Checks one object's pose alone: finite, on the table, its footprint clear of the
    /// robot's base, and for a block, within the arm's reach.
    pub fn check_one(scene: &SceneSpec, i: usize, p: &Pose) -> Result<(), PlacementError> {
        let o = &scene.objects[i];
        let finite = p.x.is_finite() && p.y.is_finite() && p.z.is_finite();
        if !finite || p.x.abs() > TABLE_HALF || p.y.abs() > TABLE_HALF {
            return Err(PlacementError::OffTable {
                object: o.name.clone(),
                pose: *p,
            });
        }
        if !(p.yaw.is_finite() && p.yaw.abs() <= crate::yaml::units::MAX_BARE_ANGLE) {
            return Err(PlacementError::BadYaw {
                object: o.name.clone(),
                yaw: p.yaw,
            });
        }
        let base = o.shape.footprint(p).distance_to_point([0.0, 0.0]);
        if base < ROBOT_BASE_RADIUS {
            return Err(PlacementError::OnRobotBase {
                object: o.name.clone(),
                distance: base,
            });
        }
        if o.kind() != ObjectKind::Block
            && let Some((link, depth)) = arm_at_home_inside(&o.shape, p)
        {
            return Err(PlacementError::InArmAtHome {
                object: o.name.clone(),
                link,
                depth,
            });
        }
        let r = p.x.hypot(p.y);
        let [rmin, rmax] = reach_limits();
        if o.kind() == ObjectKind::Block && !(rmin..=rmax).contains(&r) {
            return Err(PlacementError::OutOfReach {
                object: o.name.clone(),
                distance: r,
            });
        }
        Ok(())
    }

    /// Checks the whole placement: every pose alone ([`Self::check_one`]); every block on what
    /// it rests on (its footprint within the support's top, or inside a container's walls with
    /// its clearance); randomized objects out of `keep_out` regions and inside the `allowed`
    /// regions they name; and every pair of objects that stand at overlapping heights apart by
    /// the larger of their clearances (0 for fixed objects): two blocks by their footprint
    /// circles (centres at least `r_a + r_b + clearance` apart, whatever their yaws), any other
    /// pair by their oriented footprint rectangles (smallest gap at least the clearance, and
    /// never overlapping). A block resting on another object, or lying inside a container's
    /// walls above its floor, does not conflict with it.
    pub fn check(&self, scene: &SceneSpec) -> Result<(), PlacementError> {
        if self.poses.len() != scene.objects.len() {
            return Err(PlacementError::WrongCount {
                given: self.poses.len(),
                objects: scene.objects.len(),
            });
        }
        for (i, p) in self.poses.iter().enumerate() {
            Self::check_one(scene, i, p)?;
        }
        for i in 0..self.poses.len() {
            self.check_support(scene, i)?;
            self.check_regions(scene, i)?;
        }
        for i in 0..self.poses.len() {
            for j in i + 1..self.poses.len() {
                self.check_pair(scene, i, j)?;
            }
        }
        Ok(())
    }

    fn check_support(&self, scene: &SceneSpec, i: usize) -> Result<(), PlacementError> {
        let Some(s) = support_of(scene, i) else {
            return Ok(());
        };
        let (o, sup) = (&scene.objects[i], &scene.objects[s]);
        let margin =
            support_rect(&sup.shape, &self.poses[s]).margin_inside(&o.shape.footprint(&self.poses[i]));
        let min = if sup.kind() == ObjectKind::Container {
            clearance(scene, i)
        } else {
            0.0
        };
        if margin + EPS < min {
            return Err(PlacementError::OffSupport {
                object: o.name.clone(),
                support: sup.name.clone(),
                margin,
                min,
            });
        }
        Ok(())
    }

    fn check_regions(&self, scene: &SceneSpec, i: usize) -> Result<(), PlacementError> {
        let o = &scene.objects[i];
        let Some(r) = &o.random else {
            return Ok(());
        };
        let fp = o.shape.footprint(&self.poses[i]);
        for region in scene.regions.iter().filter(|g| g.role == RegionRole::KeepOut) {
            if region.rect().overlaps(&fp) {
                return Err(PlacementError::InKeepOut {
                    object: o.name.clone(),
                    region: region.name.clone(),
                });
            }
        }
        if !r.regions.is_empty()
            && !r
                .regions
                .iter()
                .filter_map(|n| scene.region(n))
                .any(|g| g.rect().margin_inside(&fp) >= -EPS)
        {
            return Err(PlacementError::OutsideRegions {
                object: o.name.clone(),
                regions: r.regions.clone(),
            });
        }
        Ok(())
    }

    fn check_pair(&self, scene: &SceneSpec, i: usize, j: usize) -> Result<(), PlacementError> {
        if support_of(scene, i) == Some(j) || support_of(scene, j) == Some(i) {
            return Ok(());
        }
        let (a, b) = (&scene.objects[i], &scene.objects[j]);
        let (pa, pb) = (&self.poses[i], &self.poses[j]);
        // Standing at heights that do not overlap (a block under a shelf board): no conflict.
        if pa.z + a.shape.height() <= pb.z + EPS || pb.z + b.shape.height() <= pa.z + EPS {
            return Ok(());
        }
        if self.inside_container(scene, i, j) || self.inside_container(scene, j, i) {
            return Ok(());
        }
        let min = clearance(scene, i).max(clearance(scene, j));
        let (fa, fb) = (a.shape.footprint(pa), b.shape.footprint(pb));
        let both_blocks = a.kind() == ObjectKind::Block && b.kind() == ObjectKind::Block;
        let (distance, min, ok, centres) = if both_blocks {
            let min = a.shape.footprint_radius() + b.shape.footprint_radius() + min;
            let d = pa.distance(pb);
            (d, min, d >= min, true)
        } else {
            let gap = fa.gap(&fb);
            (gap, min, !fa.overlaps(&fb) && gap + EPS >= min, false)
        };
        if ok {
            return Ok(());
        }
        // A block whose centre lies over the other's top (or inside its walls) was probably
        // meant to start on it: say so in the hint.
        let over = |blk: &super::ObjectSpec, p: &Pose, other: &super::ObjectSpec, q: &Pose| {
            blk.kind() == ObjectKind::Block
                && other.kind() != ObjectKind::Block
                && support_rect(&other.shape, q).distance_to_point([p.x, p.y]) == 0.0
        };
        let (first, second, on_b) = if over(b, pb, a, pa) {
            (b, a, true)
        } else {
            (a, b, over(a, pa, b, pb))
        };
        Err(PlacementError::TooClose {
            a: first.name.clone(),
            b: second.name.clone(),
            distance,
            min,
            centres,
            on_b,
            randomized: a.random.is_some() || b.random.is_some(),
        })
    }

    /// Block `i` lies inside container `c`'s walls (its footprint at least its clearance from
    /// them) and not below its floor's top.
    fn inside_container(&self, scene: &SceneSpec, i: usize, c: usize) -> bool {
        let (o, bin) = (&scene.objects[i], &scene.objects[c]);
        if o.kind() != ObjectKind::Block || bin.kind() != ObjectKind::Container {
            return false;
        }
        let (p, q) = (&self.poses[i], &self.poses[c]);
        p.z + EPS >= q.z + bin.shape.support_surface()
            && support_rect(&bin.shape, q).margin_inside(&o.shape.footprint(p)) + EPS >= clearance(scene, i)
    }
}

/// Scenario `index` of sweep seed `sweep_seed`: the episode seed and the placement (see the
/// module docs for the exact draw order).
pub fn sample_placement(
    scene: &SceneSpec,
    sweep_seed: u64,
    index: u64,
) -> Result<(u64, Placement), PlacementError> {
    let mut rng = ChaCha8Rng::seed_from_u64(sweep_seed);
    rng.set_stream(index);
    let seed = rng.next_u64();
    let order = placement_order(scene);
    // Failures by constraint: how many draws broke it, and the first such failure.
    let mut failures: BTreeMap<String, (usize, PlacementError)> = BTreeMap::new();
    for _ in 0..MAX_DRAWS {
        let mut poses: Vec<Pose> = scene.objects.iter().map(|o| o.pose.unwrap_or_default()).collect();
        for &i in &order {
            let o = &scene.objects[i];
            let Some(r) = &o.random else {
                continue;
            };
            let fixed = o.pose.unwrap_or_default();
            poses[i] = match r.support.as_deref().and_then(|n| scene.index_of(n)) {
                None => {
                    let x = draw(&mut rng, r.x);
                    let y = draw(&mut rng, r.y);
                    let yaw = r.yaw.map_or(fixed.yaw, |range| draw(&mut rng, range));
                    Pose { x, y, yaw, z: 0.0 }
                }
                Some(s) => {
                    let yaw = r.yaw.map_or(fixed.yaw, |range| draw(&mut rng, range));
                    let sup = &scene.objects[s];
                    let q = poses[s];
                    // Over the support's area, shrunk by the block's extent at this yaw (and,
                    // in a container, the clearance to the walls).
                    let [hx, hy] = o.shape.footprint_half();
                    let (sn, cs) = (yaw - q.yaw).sin_cos();
                    let ext = [hx * cs.abs() + hy * sn.abs(), hx * sn.abs() + hy * cs.abs()];
                    let wall = if sup.kind() == ObjectKind::Container {
                        r.clearance
                    } else {
                        0.0
                    };
                    let [sx, sy] = sup.shape.support_half();
                    let span = |h: f64, e: f64| (h - e - wall).max(0.0);
                    let (ux, uy) = (span(sx, ext[0]), span(sy, ext[1]));
                    let u = draw(&mut rng, [-ux, ux]);
                    let v = draw(&mut rng, [-uy, uy]);
                    let (s2, c2) = q.yaw.sin_cos();
                    Pose {
                        x: q.x + c2 * u - s2 * v,
                        y: q.y + s2 * u + c2 * v,
                        yaw,
                        z: 0.0,
                    }
                }
            };
        }
        let mut placement = Placement { poses };
        placement.settle(scene);
        match placement.check(scene) {
            Ok(()) => return Ok((seed, placement)),
            Err(e) => {
                failures.entry(e.constraint()).or_insert((0, e)).0 += 1;
            }
        }
    }
    let (count, most_common) = failures
        .into_values()
        .max_by_key(|(n, _)| *n)
        .expect("at least one draw");
    Err(PlacementError::Unsatisfiable {
        draws: MAX_DRAWS,
        count,
        most_common: Box::new(most_common),
    })
}

fn draw(rng: &mut ChaCha8Rng, [lo, hi]: [f64; 2]) -> f64 {
    lo + (hi - lo) * ((rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64))
}
