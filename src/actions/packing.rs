//! The packing look-ahead of `carry`'s spot choice in a container: how many of the blocks the
//! scene's goal still sends into the container would fit after the held block is set down at a
//! candidate spot.
//!
//! The estimate packs the blocks still to come, largest first, each at the first spot of a
//! fill order that the set-down check ([`SetDown`]) accepts against the container's walls, the
//! blocks already in it and the blocks the estimate has put down before it (bottom-left fill:
//! the orders start in each of the container's four corners, filling along either of its axes,
//! with the fingers closing along either axis), and keeps the best of the eight orders. The
//! candidate spots are those of a grid over the floor; a block's set-down against the world
//! (walls, blocks in the container) is checked once per spot, and only the blocks the estimate
//! puts down are checked per order.

use nalgebra::{Rotation2, Vector2, Vector3};

use super::clearance::{MARGIN, SetDown, release_opening};
use crate::world::World;

/// Fill orders the estimate tries: from each of the container's four corners, along either axis.
const FILL_ORDERS: usize = 8;

/// A block as the look-ahead puts it down: footprint centre (world table plane), a side along
/// the unit `axis`, half-edge and top, metres.
#[derive(Clone, Copy, Debug)]
pub struct Planned {
    /// Footprint centre, world frame, metres.
    pub centre: Vector2<f64>,
    /// A side of the cube (its faces square to the fingers' closing axis), unit.
    pub axis: Vector2<f64>,
    /// Half the edge, metres.
    pub half: f64,
    /// Height of its top, metres.
    pub top: f64,
}

/// A spot one block still to come could be set down at: where, with the fingers closing along
/// `closing`, and its coordinates in the container's frame (for the fill orders).
#[derive(Clone, Copy, Debug)]
struct Spot {
    down: SetDown,
    local: Vector2<f64>,
}

/// One block still to come: its half-edge and, for each of the eight fill orders, the spots the
/// world leaves it in that order.
struct Coming {
    half: f64,
    orders: Vec<Vec<Spot>>,
}

/// The look-ahead for one container and one held block.
pub struct Lookahead {
    coming: Vec<Coming>,
    floor: f64,
    /// Spot tests left of [`WORK_BUDGET`].
    budget: std::cell::Cell<u64>,
}

/// Most blocks still to come the estimate packs (the largest): enough to see whether a spot
/// wastes room, and a bound on its work.
pub const MAX_COMING: usize = 4;

/// Spot tests (one candidate spot against the blocks the estimate has put down) one look-ahead
/// may make over all its [`Lookahead::capacity`] calls; once spent, `capacity` answers 0 and the
/// search keeps the best spot it has. A count, not a time, so the choice is deterministic.
pub const WORK_BUDGET: u64 = 2_000_000;

/// The half-edges of the blocks (other than `held`) that the scene's goal sends into container
/// `c` and that are not inside it yet, largest first, metres.
pub fn still_to_come(w: &World, c: usize, held: usize) -> Vec<f64> {
    let mut halves: Vec<f64> = (0..w.objects.len())
        .filter(|&j| j != held && crate::world::goal::destination(w, j) == Some(c) && !w.inside(j, c))
        .map(|j| w.half(j))
        .collect();
    halves.sort_by(|a, b| b.total_cmp(a));
    halves
}

impl Lookahead {
    /// The look-ahead for container `c` (floor top at `floor`, metres) while `held` is carried
    /// to it: the blocks of [`still_to_come`], set down `place_height` above the floor with the
    /// fingertips `tip` metres above their centre (as the held block's), on a `grid` × `grid`
    /// grid over the floor.
    pub fn new(w: &World, c: usize, held: usize, floor: f64, place_height: f64, tip: f64, grid: i32) -> Self {
        let crate::scene::Shape::Container { inner_half, .. } = w.spec(c).shape else {
            return Self {
                coming: Vec::new(),
                floor,
                budget: std::cell::Cell::new(WORK_BUDGET),
            };
        };
        let yaw = crate::world::angles::yaw_of(&w.objects[c].quat);
        let to_world = Rotation2::new(yaw);
        let centre = w.objects[c].pos.xy();
        let axes = [to_world * Vector2::x(), to_world * Vector2::y()];
        let n = grid / 2;
        let coming = still_to_come(w, c, held)
            .into_iter()
            .take(MAX_COMING)
            .map(|half| {
                let usable = inner_half.map(|h| (h - half).max(0.0));
                let mut free = Vec::new();
                for i in -n..=n {
                    for k in -n..=n {
                        let local = Vector2::new(
                            usable[0] * f64::from(i) / f64::from(n.max(1)),
                            usable[1] * f64::from(k) / f64::from(n.max(1)),
                        );
                        let p = centre + to_world * local;
                        for closing in axes {
                            let down = SetDown {
                                centre: Vector3::new(p.x, p.y, floor + place_height + half),
                                closing,
                                half,
                                tip,
                                opening: release_opening(half),
                            };
                            if down.obstruction(w, held, Some(c)).is_none() {
                                free.push(Spot { down, local });
                            }
                        }
                    }
                }
                let orders = (0..FILL_ORDERS)
                    .map(|order| {
                        let mut o = free.clone();
                        o.sort_by(|a, b| {
                            let (ka, kb) = (fill_key(order, &a.local), fill_key(order, &b.local));
                            ka.0.total_cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
                        });
                        o
                    })
                    .collect();
                Coming { half, orders }
            })
            .collect();
        Self {
            coming,
            floor,
            budget: std::cell::Cell::new(WORK_BUDGET),
        }
    }

    /// How many blocks are still to come.
    pub fn total(&self) -> usize {
        self.coming.len()
    }

    /// The block `half` (metres) set down at `down` as the look-ahead sees it once released: on
    /// the floor, a side along the closing axis.
    pub fn planned(&self, down: &SetDown) -> Planned {
        Planned {
            centre: down.centre.xy(),
            axis: down.closing,
            half: down.half,
            top: self.floor + 2.0 * down.half,
        }
    }

    /// Spot tests made so far.
    pub fn work(&self) -> u64 {
        WORK_BUDGET - self.budget.get()
    }

    /// Whether the work budget is spent.
    pub fn spent(&self) -> bool {
        self.budget.get() == 0
    }

    /// How many of the blocks still to come (at most [`MAX_COMING`]) fit (by the best fill
    /// order) once `first` is down; 0 once the work budget is spent.
    pub fn capacity(&self, first: Planned) -> usize {
        let total = self.total();
        let mut best = 0;
        if self.spent() {
            return 0;
        }
        for o in 0..FILL_ORDERS {
            let mut placed = vec![first];
            let mut fitted = 0;
            for block in &self.coming {
                let spot = block.orders[o].iter().find(|s| {
                    let left = self.budget.get();
                    if left == 0 {
                        return false;
                    }
                    self.budget.set(left - 1);
                    placed.iter().all(|p| {
                        s.down
                            .gap_to_cube(p.centre, p.axis, p.half, p.top)
                            .is_none_or(|g| g >= MARGIN)
                            && cube_clear(s, block.half, p)
                    })
                });
                if let Some(s) = spot {
                    placed.push(self.planned(&s.down));
                    fitted += 1;
                }
            }
            if self.spent() {
                return 0;
            }
            best = best.max(fitted);
            if best == total {
                break;
            }
        }
        best
    }
}

/// The block set down at `s` (half-edge `half`) does not land on `p`: the set-down check skips
/// a block whose top is below the fingertips, so the two blocks' own footprints are tested too.
fn cube_clear(s: &Spot, half: f64, p: &Planned) -> bool {
    let d = p.centre - s.down.centre.xy();
    // Separating axes of two squares: each one's two sides.
    let a = s.down.closing;
    let b = p.axis;
    [a, Vector2::new(-a.y, a.x), b, Vector2::new(-b.y, b.x)]
        .iter()
        .any(|n| {
            let ra = half * (a.dot(n).abs() + a.perp(n).abs());
            let rb = p.half * (b.dot(n).abs() + b.perp(n).abs());
            d.dot(n).abs() - ra - rb >= MARGIN
        })
}

/// The sort key of fill order `order` (0…7) over a spot's coordinates in the container's frame:
/// from each of the four corners (the signs), along either axis first.
fn fill_key(order: usize, l: &Vector2<f64>) -> (f64, f64) {
    let sx = if order & 4 == 0 { 1.0 } else { -1.0 };
    let sy = if order & 2 == 0 { 1.0 } else { -1.0 };
    if order & 1 == 0 {
        (sy * l.y, sx * l.x)
    } else {
        (sx * l.x, sy * l.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn there_are_eight_distinct_fill_orders() {
        let p = Vector2::new(0.3, -0.7);
        let keys: Vec<(f64, f64)> = (0..FILL_ORDERS).map(|o| fill_key(o, &p)).collect();
        for (i, a) in keys.iter().enumerate() {
            for b in &keys[i + 1..] {
                assert_ne!(a, b);
            }
        }
    }

    #[test]
    fn squares_apart_and_touching() {
        let down = SetDown {
            centre: Vector3::new(0.0, 0.0, 0.03),
            closing: Vector2::x(),
            half: 0.02,
            tip: -0.019,
            opening: release_opening(0.02),
        };
        let s = Spot {
            down,
            local: Vector2::zeros(),
        };
        let far = Planned {
            centre: Vector2::new(0.0, 0.05),
            axis: Vector2::x(),
            half: 0.02,
            top: 0.05,
        };
        assert!(cube_clear(&s, 0.02, &far));
        let near = Planned {
            centre: Vector2::new(0.0, 0.042),
            ..far
        };
        assert!(!cube_clear(&s, 0.02, &near));
    }
}
