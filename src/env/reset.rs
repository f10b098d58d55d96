//! [`Reset`]: where an episode starts — the scene's poses, a seeded draw, scenario K of sweep
//! seed S exactly as `macrotree run --scenario K --sweep-seed S` places it, or an explicit
//! placement.

use crate::error::Error;
use crate::scene::Placement;
use crate::sim::Scene;

/// How [`super::MacroEnv::reset`] places the scene's objects. Every reset puts the arm at home
/// with the gripper open, zero velocities and time zero.
#[derive(Debug, Clone, PartialEq)]
pub enum Reset {
    /// The scene's own poses ([`Scene::default_placement`]); the episode seed is
    /// `EnvConfig::seed`.
    Default,
    /// A random placement from the scene's sampler: the same draw as
    /// `Scenario { index: 0, sweep_seed: seed }` (for the built-in `cube_bowl`, the tutorial's
    /// task-region sampler; otherwise the scene's `random:` ranges). Different seeds give
    /// independent placements.
    Seed(u64),
    /// Scenario `index` of sweep seed `sweep_seed`: exactly the placement and episode seed of
    /// `macrotree run --scenario K --sweep-seed S` and of that scenario in `macrotree sweep`
    /// (both call [`crate::episode::scenario::draw`]).
    Scenario {
        /// The scenario index `K`.
        index: u64,
        /// The sweep seed `S`.
        sweep_seed: u64,
    },
    /// Every object at the given pose (one per object, scene order; x, y in metres, yaw in
    /// radians). It is checked as `run --cube/--bowl` is: on the table, clear of the robot's
    /// base and of each other, blocks within reach.
    Placement(Placement),
}

/// Where `how` puts the objects of `scene`, and the episode seed it brings (`None`: use the
/// configured one).
pub(super) fn resolve(scene: &Scene, how: &Reset) -> Result<(Placement, Option<u64>), Error> {
    let invalid = |message: String| Error::Action { message };
    match how {
        Reset::Default => Ok((scene.default_placement(), None)),
        Reset::Seed(seed) => {
            let d = crate::episode::scenario::draw(scene, *seed, 0)
                .map_err(|e| invalid(format!("reset with seed {seed}: {e}")))?;
            Ok((d.placement, Some(d.seed)))
        }
        Reset::Scenario { index, sweep_seed } => {
            let d = crate::episode::scenario::draw(scene, *sweep_seed, *index).map_err(|e| {
                invalid(format!(
                    "reset to scenario {index} of sweep seed {sweep_seed}: {e}"
                ))
            })?;
            Ok((d.placement, Some(d.seed)))
        }
        Reset::Placement(p) => {
            let n = scene.spec.objects.len();
            if p.poses.len() != n {
                return Err(invalid(format!(
                    "reset placement has {} poses, but scene `{}` has {n} objects ({}); give one pose per object, in scene order",
                    p.poses.len(),
                    scene.spec.name,
                    scene
                        .spec
                        .objects
                        .iter()
                        .map(|o| o.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
            let mut p = p.clone();
            p.settle(&scene.spec); // heights come from the scene (`z:`, what each block rests on)
            p.check(&scene.spec).map_err(|e| {
                invalid(format!(
                    "reset placement is not allowed: {e}; objects stand on the table (|x|, |y| ≤ 1 m), clear of the robot's base (within {} m of the origin) and of each other; blocks {:.2} … {:.2} m from the base",
                    crate::scene::ROBOT_BASE_RADIUS,
                    crate::scene::reach_limits()[0],
                    crate::scene::reach_limits()[1]
                ))
            })?;
            Ok((p, None))
        }
    }
}
