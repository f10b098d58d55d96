//! Contacts that should not happen, typed: who touched (the arm, the fingers, the held block),
//! what kind of thing it touched (a container, an obstacle, another block), which object, when,
//! and at which leaf; the counts by kind that sweep summaries and `macrotree test` reports give;
//! and the policy (`--collisions count|fail`).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::scene::ObjectKind;
use crate::world::conditions::Tolerances;
use crate::world::{Part, Piece, World};

/// How far above the top of the block under it the held block's bottom may be for their
/// contact to count as setting it down (a stack), not as a brush, metres.
pub const SET_ON_SLACK: f64 = 0.005;

/// The robot part (or the block it holds) that touched something it should not.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Hitter {
    /// An arm link or the gripper's base.
    Arm,
    /// The gripper's fingers or pads.
    Fingers,
    /// The block the gripper holds.
    HeldBlock,
}

impl Hitter {
    /// Every hitter, in report order.
    pub const ALL: [Hitter; 3] = [Hitter::Arm, Hitter::Fingers, Hitter::HeldBlock];

    /// `arm`, `fingers`, `held_block`.
    pub fn name(self) -> &'static str {
        match self {
            Hitter::Arm => "arm",
            Hitter::Fingers => "fingers",
            Hitter::HeldBlock => "held_block",
        }
    }
}

/// What kind of object was touched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HitKind {
    /// A container (its wall; for the arm and the fingers, any part of it).
    Container,
    /// An obstacle.
    Obstacle,
    /// A block other than the one held (and, for the held block, not the one it is set on).
    Block,
}

impl HitKind {
    /// Every kind, in report order.
    pub const ALL: [HitKind; 3] = [HitKind::Container, HitKind::Obstacle, HitKind::Block];

    /// `container`, `obstacle`, `block`.
    pub fn name(self) -> &'static str {
        match self {
            HitKind::Container => "container",
            HitKind::Obstacle => "obstacle",
            HitKind::Block => "block",
        }
    }
}

/// A contact that should not happen (the fingers on a wall, the carried block on an obstacle),
/// recorded once per (who, object touched, piece) in an episode, when first seen. JSON:
/// `{"time", "what", "who", "kind", "object", "node"}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Collision {
    /// Simulated time it was first seen, seconds.
    pub time: f64,
    /// What hit what, e.g. `the fingers hit bowl wall`.
    pub what: String,
    /// Who touched.
    pub who: Hitter,
    /// What kind of object it touched.
    pub kind: HitKind,
    /// The object it touched (its scene name).
    pub object: String,
    /// The path of the action leaf running when it was seen, if one was.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node: Option<String>,
}

impl Collision {
    /// The kind label counts are kept under: `fingers-container`, `held_block-obstacle`, ….
    pub fn label(&self) -> String {
        label(self.who, self.kind)
    }
}

/// The label of `who` touching a `kind`: `fingers-container`.
pub fn label(who: Hitter, kind: HitKind) -> String {
    format!("{}-{}", who.name(), kind.name())
}

/// Collisions counted over many episodes, by kind.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CollisionCounts {
    /// Collisions in all (each counted once per episode, see [`Collision`]).
    pub total: u64,
    /// Episodes with at least one.
    pub episodes: u64,
    /// Collisions by kind label ([`Collision::label`]), only the kinds seen.
    pub by_kind: BTreeMap<String, u64>,
}

impl CollisionCounts {
    /// Adds one episode's collisions.
    pub fn add(&mut self, collisions: &[Collision]) {
        if collisions.is_empty() {
            return;
        }
        self.episodes += 1;
        for c in collisions {
            self.total += 1;
            *self.by_kind.entry(c.label()).or_default() += 1;
        }
    }

    /// One line: `3 in 2 episode(s): 2 fingers-container, 1 arm-obstacle`, or `none`.
    pub fn line(&self) -> String {
        if self.total == 0 {
            return "none".into();
        }
        let kinds: Vec<String> = self.by_kind.iter().map(|(k, n)| format!("{n} {k}")).collect();
        format!(
            "{} in {} episode(s): {}",
            self.total,
            self.episodes,
            kinds.join(", ")
        )
    }
}

/// What a collision does to the episode (`--collisions`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CollisionPolicy {
    /// Record and count it (the default).
    #[default]
    Count,
    /// Record it and fail the episode at once, with kind `collision`.
    Fail,
}

impl CollisionPolicy {
    /// True for the default, [`CollisionPolicy::Count`].
    pub fn is_count(&self) -> bool {
        *self == CollisionPolicy::Count
    }

    /// `count` or `fail`.
    pub fn name(self) -> &'static str {
        match self {
            CollisionPolicy::Count => "count",
            CollisionPolicy::Fail => "fail",
        }
    }
}

impl std::str::FromStr for CollisionPolicy {
    type Err = String;

    /// Reads `count` or `fail`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "count" => Ok(CollisionPolicy::Count),
            "fail" => Ok(CollisionPolicy::Fail),
            _ => Err(format!(
                "unknown collision policy `{s}`: expected `count` or `fail`"
            )),
        }
    }
}

/// True when held block `h` rests on obstacle `o`'s top (a shelf board it is picked from or set
/// down on): its bottom no more than [`SET_ON_SLACK`] below the obstacle's top and its centre over
/// the obstacle's footprint. Touching an obstacle any other way counts.
fn rests_on(w: &World, h: usize, o: usize) -> bool {
    w.bottom(h) + SET_ON_SLACK >= w.top(o) && w.from_footprint(o, &w.objects[h].pos).norm() == 0.0
}

/// The contacts of `w` that should not happen, in the order of [`World::touches`] (times set,
/// node unset, possibly repeated):
///
/// | who | counted when it touches |
/// |---|---|
/// | the arm (links, gripper base) | a container, an obstacle, a block no pad touches |
/// | the fingers | a container, an obstacle, a block no pad touches |
/// | the held block ([`World::held_block`]) | a container's wall, an obstacle (not one whose top it rests on), a block beside it (not one it is set down on) |
///
/// A container's floor under the held block, the block between the pads and the table are
/// intended contacts.
pub fn classify(w: &World) -> Vec<Collision> {
    let held = w.held_block(Tolerances::GRASP_OFF_AXIS);
    let mut out = Vec::new();
    for &(a, b) in &w.touches {
        for (me, other) in [(a, b), (b, a)] {
            let Part::Object { index, piece } = other else {
                continue;
            };
            let kind = match w.spec(index).kind() {
                ObjectKind::Container => HitKind::Container,
                ObjectKind::Obstacle => HitKind::Obstacle,
                ObjectKind::Block => HitKind::Block,
            };
            let who = match me {
                Part::Robot => Hitter::Arm,
                Part::Fingers => Hitter::Fingers,
                Part::Object { index: h, .. } if Some(h) == held && h != index => Hitter::HeldBlock,
                _ => continue,
            };
            let counts = match (who, kind) {
                (Hitter::Arm | Hitter::Fingers, HitKind::Block) => w.released(index) && Some(index) != held,
                (Hitter::Arm | Hitter::Fingers, _) => true,
                (Hitter::HeldBlock, HitKind::Container) => piece == Piece::Wall,
                (Hitter::HeldBlock, HitKind::Obstacle) => !rests_on(w, held.expect("a held block"), index),
                (Hitter::HeldBlock, HitKind::Block) => {
                    let h = held.expect("a held block");
                    w.bottom(h) + SET_ON_SLACK < w.top(index)
                }
            };
            if !counts {
                continue;
            }
            let me_name = match who {
                Hitter::HeldBlock => format!("the carried {}", w.name(held.expect("a held block"))),
                Hitter::Arm => "the arm".to_string(),
                Hitter::Fingers => "the fingers".to_string(),
            };
            out.push(Collision {
                time: w.time,
                what: format!("{me_name} hit {}", w.describe(other)),
                who,
                kind,
                object: w.name(index).to_string(),
                node: None,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(who: Hitter, kind: HitKind) -> Collision {
        Collision {
            time: 1.0,
            what: "x".into(),
            who,
            kind,
            object: "bin".into(),
            node: None,
        }
    }

    use crate::world::tests_support::{held, resting};
    use crate::world::{Part, Piece};
    use nalgebra::Vector3;

    fn obj(index: usize, piece: Piece) -> Part {
        Part::Object { index, piece }
    }

    #[test]
    fn contacts_are_typed_by_who_and_what() {
        // The built-in scene: object 0 the cube, 1 the bowl.
        let mut w = resting();
        w.touches = vec![
            (Part::Fingers, obj(1, Piece::Wall)),
            (obj(1, Piece::Floor), Part::Robot),
            (Part::Fingers, obj(0, Piece::Whole)),
            (Part::Table, obj(0, Piece::Whole)),
        ];
        let c = classify(&w);
        let labels: Vec<String> = c.iter().map(Collision::label).collect();
        assert_eq!(labels, ["fingers-container", "arm-container", "fingers-block"]);
        assert_eq!(c[0].what, "the fingers hit bowl wall");
        assert_eq!(c[1].object, "bowl");
        assert_eq!(c[2].what, "the fingers hit cube");
    }

    #[test]
    fn the_held_block_counts_on_walls_but_not_on_the_floor_and_the_pads_on_it_do_not_count() {
        let mut w = held();
        w.touches = vec![
            (Part::Fingers, obj(0, Piece::Whole)),
            (obj(0, Piece::Whole), obj(1, Piece::Floor)),
            (obj(0, Piece::Whole), obj(1, Piece::Wall)),
        ];
        let c = classify(&w);
        assert_eq!(c.len(), 1, "{c:?}");
        assert_eq!((c[0].who, c[0].kind), (Hitter::HeldBlock, HitKind::Container));
        assert_eq!(c[0].what, "the carried cube hit bowl wall");
    }

    #[test]
    fn the_held_block_resting_on_a_board_does_not_count_but_hitting_its_side_does() {
        // The held cube of `held()` (bottom 0.10 m) over a board whose top is 0.10 m high.
        let mut w = held();
        let scene = crate::scene::SceneSpec::from_str(
            "objects:\n  cube: {block: {size: 0.044}, pose: [0.45, -0.18]}\n  board: {obstacle: {size: [0.10, 0.10, 0.02]}, pose: [0.45, -0.18], z: 0.08}\n",
            "board.yaml",
        )
        .expect("a valid scene");
        w.scene = std::sync::Arc::new(scene);
        w.objects[1].pos = Vector3::new(0.45, -0.18, 0.08);
        w.touches = vec![(obj(0, Piece::Whole), obj(1, Piece::Whole))];
        assert!(classify(&w).is_empty(), "resting on the board's top");
        // 1 cm lower: the block is in the board, it hit it.
        let mut low = w.clone();
        for p in [
            &mut low.objects[0].pos,
            &mut low.left_pad_pos,
            &mut low.right_pad_pos,
        ] {
            p.z -= 0.01;
        }
        assert_eq!(classify(&low).len(), 1);
        // Beside the board at its top's height: its centre is not over the board.
        let mut beside = w.clone();
        for p in [
            &mut beside.objects[0].pos,
            &mut beside.left_pad_pos,
            &mut beside.right_pad_pos,
        ] {
            p.x += 0.08;
        }
        let c = classify(&beside);
        assert_eq!((c.len(), c[0].kind), (1, HitKind::Obstacle), "{c:?}");
    }

    #[test]
    fn counts_are_kept_by_kind_and_episode() {
        let mut c = CollisionCounts::default();
        c.add(&[]);
        assert_eq!(c.line(), "none");
        c.add(&[
            hit(Hitter::Fingers, HitKind::Container),
            hit(Hitter::Arm, HitKind::Obstacle),
        ]);
        c.add(&[hit(Hitter::Fingers, HitKind::Container)]);
        assert_eq!((c.total, c.episodes), (3, 2));
        assert_eq!(c.by_kind["fingers-container"], 2);
        assert_eq!(c.line(), "3 in 2 episode(s): 1 arm-obstacle, 2 fingers-container");
    }

    #[test]
    fn a_collision_reads_back_from_its_json() {
        let mut c = hit(Hitter::HeldBlock, HitKind::Block);
        c.node = Some("main/carry".into());
        let json = serde_json::to_string(&c).unwrap();
        assert!(
            json.contains("\"who\":\"held_block\"") && json.contains("\"kind\":\"block\""),
            "{json}"
        );
        assert_eq!(serde_json::from_str::<Collision>(&json).unwrap(), c);
        assert_eq!("fail".parse::<CollisionPolicy>(), Ok(CollisionPolicy::Fail));
        assert!("stop".parse::<CollisionPolicy>().is_err());
    }
}
