//! [`CubeBowlReport`]: the flagship's legacy section of a report — the scene's cube and bowl, as
//! the reference tutorial reports them.

use serde::Serialize;

use crate::actions::Checks;
use crate::world::World;

/// The reference tutorial's figures on the scene's cube and bowl ([`World::cube`],
/// [`World::bowl`]): reported only for a scene with a cube. Positions in metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CubeBowlReport {
    /// Final centre [x, y, z] of the scene's cube.
    pub cube_final: [f64; 3],
    /// The bowl target [x, y, z] at the end (the centre of the top of the bowl's floor,
    /// [`World::bowl_target`]); absent without a bowl.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bowl_target: Option<[f64; 3]>,
    /// The reference tutorial's checks.
    pub checks: Checks,
}

impl CubeBowlReport {
    /// The section for the episode that ended in `world` with `checks`; `None` when the scene
    /// has no cube.
    pub fn of(world: &World, checks: Checks) -> Option<Self> {
        let cube = world.cube()?;
        Some(Self {
            cube_final: world.objects[cube].pos.into(),
            bowl_target: world.bowl_target().map(Into::into),
            checks,
        })
    }
}
