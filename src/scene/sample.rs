//! Placements: where every object of a scene starts, checked against the cell's limits, and
//! drawn at random for sweeps.
//!
//! Scenario `k` of sweep seed `S` is a pure function of `(S, k)`: a ChaCha8 generator seeded with
//! `S` on stream `k` gives, in this order, the episode seed (one `u64`), then for every object in
//! scene order that has `random:` its x, y and (when a yaw range is given) yaw; objects without
//! `random:` keep their `pose:`. The whole draw is rejected and repeated until every check of
//! [`Placement::check`] passes, at most [`MAX_DRAWS`] times. Uniform floats are built from the
//! top 53 bits of a `u64` draw (`lo + (hi − lo)·u`, `u ∈ [0, 1)`), the same on every platform.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{RngCore, SeedableRng};
use serde::Serialize;

use super::types::{ObjectKind, Pose, ROBOT_BASE_RADIUS, SceneSpec, reach_limits};

/// Most draws before a sampling gives up (the constraints cannot be met).
pub const MAX_DRAWS: usize = 100_000;

/// Half-width of the table the objects stand on (the floor plane), metres.
const TABLE_HALF: f64 = 1.0;

/// Every object's starting pose, in scene order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Placement {
    /// One pose per object of the scene, in scene order.
    pub poses: Vec<Pose>,
}

/// Why a placement is not allowed.
#[derive(Clone, Debug, PartialEq)]
pub enum PlacementError {
    /// A coordinate is not a finite number, or lies off the table.
    OffTable {
        /// The object.
        object: String,
        /// Its pose.
        pose: Pose,
    },
    /// The object overlaps the robot's base.
    OnRobotBase {
        /// The object.
        object: String,
        /// Its distance from the base axis, metres.
        distance: f64,
    },
    /// A block lies where the arm cannot pick it from above.
    OutOfReach {
        /// The block.
        object: String,
        /// Its distance from the base axis, metres.
        distance: f64,
    },
    /// Two objects' footprints overlap (or come closer than the clearance asked for).
    TooClose {
        /// The first object.
        a: String,
        /// The second object.
        b: String,
        /// Their centre distance, metres.
        distance: f64,
        /// The smallest centre distance allowed, metres.
        min: f64,
    },
    /// No draw met the constraints.
    Unsatisfiable {
        /// Draws tried.
        draws: usize,
        /// The last draw's problem.
        last: Box<PlacementError>,
    },
    /// The placement does not have one pose per object.
    WrongCount {
        /// Poses given.
        given: usize,
        /// Objects in the scene.
        objects: usize,
    },
}

impl PlacementError {
    /// The object the problem is about (the first of a pair), when there is one.
    pub fn object(&self) -> Option<&str> {
        match self {
            PlacementError::OffTable { object, .. }
            | PlacementError::OnRobotBase { object, .. }
            | PlacementError::OutOfReach { object, .. } => Some(object),
            PlacementError::TooClose { a, .. } => Some(a),
            PlacementError::Unsatisfiable { last, .. } => last.object(),
            PlacementError::WrongCount { .. } => None,
        }
    }
}

impl std::fmt::Display for PlacementError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [rmin, rmax] = reach_limits();
        match self {
            PlacementError::OffTable { object, pose } => write!(
                f,
                "`{object}` at ({}, {}) is off the table: x and y must be finite and within ±{TABLE_HALF} m",
                pose.x, pose.y
            ),
            PlacementError::OnRobotBase { object, distance } => write!(
                f,
                "`{object}` overlaps the robot's base: its footprint comes within {distance:.3} m of the base axis (keep it clear of {ROBOT_BASE_RADIUS} m)"
            ),
            PlacementError::OutOfReach { object, distance } => write!(
                f,
                "block `{object}` is {distance:.3} m from the robot's base: blocks must be {rmin} … {rmax} m away to be picked from above"
            ),
            PlacementError::TooClose { a, b, distance, min } => write!(
                f,
                "`{a}` and `{b}` are {distance:.3} m apart (centres); at least {min:.3} m is needed so they do not overlap"
            ),
            PlacementError::Unsatisfiable { draws, last } => {
                write!(
                    f,
                    "no placement found in {draws} draws; the last one failed because {last}"
                )
            }
            PlacementError::WrongCount { given, objects } => {
                write!(f, "{given} poses given for {objects} objects")
            }
        }
    }
}

impl std::error::Error for PlacementError {}

impl Placement {
    /// The scene's fixed poses (`pose:`), if every object has one.
    pub fn fixed(scene: &SceneSpec) -> Option<Placement> {
        scene
            .objects
            .iter()
            .map(|o| o.pose)
            .collect::<Option<Vec<_>>>()
            .map(|poses| Placement { poses })
    }

    /// Checks one object's pose alone: finite, on the table, clear of the robot's base, and
    /// for a block, within the arm's reach.
    pub fn check_one(scene: &SceneSpec, i: usize, p: &Pose) -> Result<(), PlacementError> {
        let o = &scene.objects[i];
        let finite = p.x.is_finite() && p.y.is_finite() && p.yaw.is_finite();
        if !finite || p.x.abs() > TABLE_HALF || p.y.abs() > TABLE_HALF {
            return Err(PlacementError::OffTable {
                object: o.name.clone(),
                pose: *p,
            });
        }
        let r = p.x.hypot(p.y);
        if r - o.shape.footprint_radius() < ROBOT_BASE_RADIUS {
            return Err(PlacementError::OnRobotBase {
                object: o.name.clone(),
                distance: (r - o.shape.footprint_radius()).max(0.0),
            });
        }
        let [rmin, rmax] = reach_limits();
        if o.kind() == ObjectKind::Block && !(rmin..=rmax).contains(&r) {
            return Err(PlacementError::OutOfReach {
                object: o.name.clone(),
                distance: r,
            });
        }
        Ok(())
    }

    /// Checks the whole placement: every pose alone ([`Self::check_one`]), and every pair of
    /// objects at least `r_a + r_b + clearance` apart (footprint circles; the clearance is the
    /// larger of the two objects' `random.clearance`, 0 for fixed objects).
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
        let clearance = |i: usize| scene.objects[i].random.as_ref().map_or(0.0, |r| r.clearance);
        for i in 0..self.poses.len() {
            for j in i + 1..self.poses.len() {
                let (a, b) = (&scene.objects[i], &scene.objects[j]);
                let min =
                    a.shape.footprint_radius() + b.shape.footprint_radius() + clearance(i).max(clearance(j));
                let distance = self.poses[i].distance(&self.poses[j]);
                if distance < min {
                    return Err(PlacementError::TooClose {
                        a: a.name.clone(),
                        b: b.name.clone(),
                        distance,
                        min,
                    });
                }
            }
        }
        Ok(())
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
    let mut last = None;
    for _ in 0..MAX_DRAWS {
        let mut poses = Vec::with_capacity(scene.objects.len());
        for o in &scene.objects {
            let fixed = o.pose.unwrap_or_default();
            let pose = match &o.random {
                None => fixed,
                Some(r) => {
                    let x = draw(&mut rng, r.x);
                    let y = draw(&mut rng, r.y);
                    let yaw = r.yaw.map_or(fixed.yaw, |range| draw(&mut rng, range));
                    Pose { x, y, yaw }
                }
            };
            poses.push(pose);
        }
        let placement = Placement { poses };
        match placement.check(scene) {
            Ok(()) => return Ok((seed, placement)),
            Err(e) => last = Some(e),
        }
    }
    Err(PlacementError::Unsatisfiable {
        draws: MAX_DRAWS,
        last: Box::new(last.expect("at least one draw")),
    })
}

fn draw(rng: &mut ChaCha8Rng, [lo, hi]: [f64; 2]) -> f64 {
    lo + (hi - lo) * ((rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64))
}
