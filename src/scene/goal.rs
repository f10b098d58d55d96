//! The scene's goal: predicates that must hold when the episode ends, independently of the
//! tree. YAML (`goal:` in a scene file), a list of:
//!
//! | YAML | meaning |
//! |---|---|
//! | `in: {object: red, container: red_bin}` | the block rests in the container |
//! | `on: {object: red, support: green}` | the block rests on top of the other block |
//! | `all_in: {container: bin}` | every block rests in the container |
//! | `stack: [red, green, blue]` | red on green on blue (the last one stays on the table) |
//! | `sorted_by_color: {}` | every block rests in the container of its colour |
//!
//! They expand into [`GoalAtom`]s, at most one per block; the atom of a block is also what
//! `select` and `for_each` queries call its goal (`where: [pending]`).

use serde::Serialize;

/// One predicate of the goal.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
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
        /// The block under it.
        support: String,
    },
}

impl GoalAtom {
    /// The block this predicate is about.
    pub fn object(&self) -> &str {
        match self {
            GoalAtom::In { object, .. } | GoalAtom::On { object, .. } => object,
        }
    }

    /// Where the block should end up (a container or the supporting block).
    pub fn destination(&self) -> &str {
        match self {
            GoalAtom::In { container, .. } => container,
            GoalAtom::On { support, .. } => support,
        }
    }
}

impl std::fmt::Display for GoalAtom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GoalAtom::In { object, container } => write!(f, "{object} in {container}"),
            GoalAtom::On { object, support } => write!(f, "{object} on {support}"),
        }
    }
}

/// The whole goal: every atom must hold. Empty when the scene declares none (then only the
/// tree's own result counts).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Default)]
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
