//! Object queries: which object a `select` or `for_each` picks. Pure functions of a [`World`].

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::World;
use super::conditions::Tolerances;
use super::goal;
use crate::scene::ObjectKind;

/// What kind of object a query looks for.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema, Default)]
#[serde(rename_all = "snake_case")]
pub enum KindFilter {
    /// Movable blocks.
    #[default]
    Block,
    /// Containers.
    Container,
    /// Obstacles.
    Obstacle,
}

impl KindFilter {
    /// The object kind.
    pub fn kind(self) -> ObjectKind {
        match self {
            KindFilter::Block => ObjectKind::Block,
            KindFilter::Container => ObjectKind::Container,
            KindFilter::Obstacle => ObjectKind::Obstacle,
        }
    }
}

/// A condition an object must meet to be selected.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Filter {
    /// A block whose goal (from the scene's `goal:`) does not hold yet and can be worked on now
    /// (not covered by another block; for a stack, the block under it is finished).
    Pending,
    /// A block whose goal holds.
    Done,
    /// A block resting on the table (bottom within 1 cm of it, not in a container), released (no
    /// pad touches it) and at rest.
    OnTable,
    /// A block no pad touches.
    Free,
}

/// In what order matching objects are considered; the first one is selected.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema, Default)]
#[serde(rename_all = "snake_case")]
pub enum Order {
    /// Nearest to the gripper's pinch point in the table plane first (ties by scene order).
    #[default]
    Nearest,
    /// By name, alphabetically.
    Name,
    /// In the scene file's order.
    Scene,
}

/// Which object to pick. YAML: `{kind: block, color: red, where: [pending], order: nearest}`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema, Default)]
#[serde(deny_unknown_fields)]
pub struct Query {
    /// `block` (default), `container` or `obstacle`.
    #[serde(default)]
    pub kind: KindFilter,
    /// Only objects of this colour name (`red`, …).
    #[serde(default)]
    pub color: Option<String>,
    /// Conditions every selected object meets (all of them).
    #[serde(default, rename = "where")]
    pub filters: Vec<Filter>,
    /// Which match comes first: `nearest` (default), `name` or `scene`.
    #[serde(default)]
    pub order: Order,
}

impl Query {
    /// Short description for logs and labels: `nearest pending block`.
    pub fn describe(&self) -> String {
        let mut words = vec![
            match self.order {
                Order::Nearest => "nearest",
                Order::Name => "first by name",
                Order::Scene => "first",
            }
            .to_string(),
        ];
        for f in &self.filters {
            words.push(
                match f {
                    Filter::Pending => "pending",
                    Filter::Done => "done",
                    Filter::OnTable => "on-table",
                    Filter::Free => "free",
                }
                .into(),
            );
        }
        if let Some(c) = &self.color {
            words.push(c.clone());
        }
        words.push(self.kind.kind().name().into());
        words.join(" ")
    }
}

fn passes(w: &World, i: usize, f: Filter) -> bool {
    match f {
        Filter::Pending => goal::pending(w, i),
        Filter::Done => goal::done(w, i),
        Filter::OnTable => {
            w.bottom(i) <= Tolerances::ON_TABLE_HEIGHT
                && w.container_of(i).is_none()
                && w.released(i)
                && w.at_rest(i, Tolerances::REST_SPEED)
        }
        Filter::Free => w.released(i),
    }
}

/// The objects matching `q`, best first.
pub fn matches(w: &World, q: &Query) -> Vec<usize> {
    let mut found: Vec<usize> = w
        .scene
        .of_kind(q.kind.kind())
        .filter(|&i| {
            q.color
                .as_deref()
                .is_none_or(|c| w.spec(i).color.name.as_deref() == Some(c))
        })
        .filter(|&i| q.filters.iter().all(|&f| passes(w, i, f)))
        .collect();
    match q.order {
        Order::Scene => {}
        Order::Name => found.sort_by(|&a, &b| w.name(a).cmp(w.name(b))),
        Order::Nearest => {
            let d = |i: usize| (w.objects[i].pos.xy() - w.pinch_pos.xy()).norm();
            found.sort_by(|&a, &b| d(a).total_cmp(&d(b)));
        }
    }
    found
}

/// The first object matching `q`.
pub fn select(w: &World, q: &Query) -> Option<usize> {
    matches(w, q).into_iter().next()
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::world::tests_support::{HALF, two_blocks};

    #[test]
    fn done_and_on_table_leave_out_a_block_placed_but_still_in_the_gripper() {
        // `a` and `b` swapped places, `b` still in the gripper: not done, and `done` does not
        // select it.
        let mut w = two_blocks(
            "  - at: {object: a, point: [0.40, 0.10]}\n  - at: {object: b, point: [0.40, -0.10]}\n",
        );
        w.objects[0].pos = Vector3::new(0.40, 0.10, HALF);
        w.objects[1].pos = Vector3::new(0.40, -0.10, HALF);
        w.objects[1].left_pad_contact = true;
        w.objects[1].right_pad_contact = true;
        let q = Query {
            kind: KindFilter::default(),
            color: None,
            filters: vec![Filter::Done],
            order: Order::Scene,
        };
        assert_eq!(matches(&w, &q), vec![0]);
        let q = Query {
            filters: vec![Filter::OnTable],
            ..q
        };
        assert_eq!(matches(&w, &q), vec![0], "a held block is not `on_table`");
    }
}
