//! The model inputs a `policy` leaf can feed, by the name the model gives them.

use crate::world::World;
use crate::world::vectors::{self, OBJECT_LEN, RobotState, STATE_LEN, VALUES_PER_OBJECT};

/// A model input a leaf knows how to fill, one `[1, n]` float32 tensor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// `observation.state`: [`vectors::state_vector`] ([`STATE_LEN`] values).
    State,
    /// `observation.environment_state`: [`vectors::environment_vector`] (7 per object).
    EnvironmentState,
    /// `observation.object`: [`vectors::object_vector`] of the leaf's `object` ([`OBJECT_LEN`]
    /// values).
    Object,
}

impl Feature {
    /// Every feature, in the order the docs list them.
    pub const ALL: [Feature; 3] = [Feature::State, Feature::EnvironmentState, Feature::Object];

    /// The input name a model gives it (LeRobot's keys).
    pub fn name(self) -> &'static str {
        match self {
            Feature::State => "observation.state",
            Feature::EnvironmentState => "observation.environment_state",
            Feature::Object => "observation.object",
        }
    }

    /// The feature a model's input `name` asks for.
    pub fn named(name: &str) -> Option<Feature> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Whether `n` values fit: the fixed length, or for the environment state, 7 per object of
    /// a scene with at least one object (its scene is checked when the leaf starts).
    pub fn fits(self, n: usize) -> bool {
        match self {
            Feature::State => n == STATE_LEN,
            Feature::Object => n == OBJECT_LEN,
            Feature::EnvironmentState => n > 0 && n.is_multiple_of(VALUES_PER_OBJECT),
        }
    }

    /// What [`Self::fits`] accepts, in words.
    pub fn expected(self) -> String {
        match self {
            Feature::State => format!("{STATE_LEN} values"),
            Feature::Object => format!("{OBJECT_LEN} values"),
            Feature::EnvironmentState => format!("{VALUES_PER_OBJECT} values per object of the scene"),
        }
    }

    /// Appends the feature's values in `world` to `out`: `gripper_joint` is the gripper's
    /// closure (radians), `object` the index of the leaf's object (`None`: the leaf names none).
    pub fn fill(
        self,
        world: &World,
        gripper_joint: f64,
        object: Option<usize>,
        out: &mut Vec<f32>,
    ) -> Result<(), String> {
        match self {
            Feature::State => out.extend(vectors::state_vector(&RobotState::of(world, gripper_joint))),
            Feature::EnvironmentState => out.extend(vectors::environment_vector(world)),
            Feature::Object => match object {
                Some(i) => out.extend(vectors::object_vector(world, i)),
                None => {
                    return Err(
                        "the model reads `observation.object`, but the leaf names no `object`".into(),
                    );
                }
            },
        }
        Ok(())
    }
}
