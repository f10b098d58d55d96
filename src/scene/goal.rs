//! The scene's goal: predicates that must hold when the episode ends, independently of the
//! tree. YAML (`goal:` in a scene file), a list of:
//!
//! | YAML | meaning |
//! |---|---|
//! | `in: {object: red, container: red_bin}` | the block rests in the container |
//! | `on: {object: red, support: green}` | the block rests on top of the other block (or of an obstacle: a shelf board) |
//! | `at: {object: red, point: [0.4, -0.2], yaw: deg(90)}` | the block rests at the point (or `spot: NAME`), at the yaw if given |
//! | `all_in: {container: bin}` | every block rests in the container |
//! | `stack: [red, green, blue]` | red on green on blue (the last one stays on the table) |
//! | `stack: {blocks: [red, green], base_at: {point: [0.4, 0.1]}}` | the same, the bottom block at the point |
//! | `sorted_by_color: {}` | every block rests in the container of its colour |
//!
//! They expand into [`GoalAtom`]s, at most one per block; the atom of a block is also what
//! `select` and `for_each` queries call its goal (`where: [pending]`).

use serde::Serialize;

/// Default largest horizontal distance of a block's centre from an `at` goal's point, metres.
pub const AT_TOLERANCE: f64 = 0.01;
/// Default largest yaw error of an `at` goal with a yaw, radians (5°).
pub const AT_YAW_TOLERANCE: f64 = 5.0 * std::f64::consts::PI / 180.0;
/// Largest `tolerance` an `at` goal accepts, metres (beyond it the goal says little).
pub const AT_MAX_TOLERANCE: f64 = 0.10;
/// Largest `yaw_tolerance` an `at` goal accepts, radians (45°: a cube's yaw is compared modulo a
/// quarter turn, so 45° accepts every yaw).
pub const AT_MAX_YAW_TOLERANCE: f64 = std::f64::consts::FRAC_PI_4;

/// Where an `at` goal wants a block: a point on the table (given, or a named spot's), an optional
/// yaw, and the tolerances.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GoalPlace {
    /// The spot the goal names (`spot: NAME`), if it names one; its point is `point`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spot: Option<String>,
    /// The block centre's place `[x, y]`, world frame, metres.
    pub point: [f64; 2],
    /// The yaw of the block's side faces, radians (compared modulo a quarter turn); `None`: any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yaw: Option<f64>,
    /// Largest horizontal distance of the block's centre from `point`, metres.
    pub tolerance: f64,
    /// Largest yaw error when `yaw` is given, radians.
    pub yaw_tolerance: f64,
}

impl std::fmt::Display for GoalPlace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if let Some(s) = &self.spot {
            write!(f, "{s} ")?;
        }
        write!(f, "({:.3}, {:.3})", self.point[0], self.point[1])?;
        if let Some(y) = self.yaw {
            write!(f, " yaw {:.1}°", y.to_degrees())?;
        }
        Ok(())
    }
}

/// One predicate of the goal.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GoalAtom {
    /// `object` rests in `container`.
    In {
        /// The block.
        object: String,
        /// The container.
        container: String,
    },
    /// `object` rests on top of `support`.
    On {
        /// The block on top.
        object: String,
        /// The block or obstacle (a shelf board, a pedestal) under it.
        support: String,
    },
    /// `object` rests at a place: released, at rest, on the table, the floor of the container
    /// it is in, or the top of what it rests on (a shelf board, a pedestal, a block), its centre
    /// within the tolerance of the point, at the yaw if given.
    At {
        /// The block.
        object: String,
        /// Where.
        #[serde(flatten)]
        place: GoalPlace,
    },
}

impl GoalAtom {
    /// The block this predicate is about.
    pub fn object(&self) -> &str {
        match self {
            GoalAtom::In { object, .. } | GoalAtom::On { object, .. } | GoalAtom::At { object, .. } => object,
        }
    }

    /// The object the block should end up in or on (a container or the supporting block); `None`
    /// for an `at` goal, whose destination is a place ([`Self::place`]).
    pub fn destination_object(&self) -> Option<&str> {
        match self {
            GoalAtom::In { container, .. } => Some(container),
            GoalAtom::On { support, .. } => Some(support),
            GoalAtom::At { .. } => None,
        }
    }

    /// The name of where the block should end up, as `select … goal_as` writes it: a container,
    /// the supporting block, or the spot an `at` goal names (`None` for an `at` goal at a bare
    /// point, which has no name).
    pub fn destination(&self) -> Option<&str> {
        match self {
            GoalAtom::At { place, .. } => place.spot.as_deref(),
            _ => self.destination_object(),
        }
    }

    /// The place an `at` goal names.
    pub fn place(&self) -> Option<&GoalPlace> {
        match self {
            GoalAtom::At { place, .. } => Some(place),
            _ => None,
        }
    }
}

impl std::fmt::Display for GoalAtom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GoalAtom::In { object, container } => write!(f, "{object} in {container}"),
            GoalAtom::On { object, support } => write!(f, "{object} on {support}"),
            GoalAtom::At { object, place } => write!(f, "{object} at {place}"),
        }
    }
}

/// The whole goal: every atom must hold. Empty when the scene declares none (then only the
/// tree's own result counts).
#[derive(Clone, Debug, PartialEq, Serialize, Default)]
pub struct Goal {
    /// The predicates, in the order written (expanded).
    pub atoms: Vec<GoalAtom>,
}

impl Goal {
    /// The predicate about block `object`, if the goal has one.
    pub fn of(&self, object: &str) -> Option<&GoalAtom> {
        self.atoms.iter().find(|a| a.object() == object)
    }

    /// True when the scene declares no goal.
    pub fn is_empty(&self) -> bool {
        self.atoms.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(spot: Option<&str>, yaw: Option<f64>) -> GoalAtom {
        GoalAtom::At {
            object: "red".into(),
            place: GoalPlace {
                spot: spot.map(Into::into),
                point: [0.4, -0.2],
                yaw,
                tolerance: AT_TOLERANCE,
                yaw_tolerance: AT_YAW_TOLERANCE,
            },
        }
    }

    #[test]
    fn an_at_goal_names_its_spot_as_destination_and_reads_as_a_place() {
        let bare = at(None, None);
        assert_eq!(bare.destination(), None);
        assert_eq!(bare.destination_object(), None);
        assert_eq!(bare.to_string(), "red at (0.400, -0.200)");
        let spot = at(Some("slot_a"), Some(std::f64::consts::FRAC_PI_2));
        assert_eq!(spot.destination(), Some("slot_a"));
        assert_eq!(spot.destination_object(), None);
        assert_eq!(spot.to_string(), "red at slot_a (0.400, -0.200) yaw 90.0°");
        let json = serde_json::to_value(&spot).unwrap();
        assert_eq!(json["at"]["spot"], "slot_a");
        assert_eq!(json["at"]["point"][0], 0.4);
    }
}
