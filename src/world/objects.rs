//! The scene's objects as the world sees them at one instant, and the questions every leaf asks
//! of them: which one is called what, where its bottom and top are, whether the pads hold it,
//! which container it is in, what it rests on.

use nalgebra::{UnitQuaternion, Vector2, Vector3};
use serde::Serialize;

use super::World;
use super::angles::{fold_quarter_turn, yaw_of};
use crate::scene::{CONTAINER_FLOOR, ObjectKind, ObjectSpec, Shape};

/// One object's state. For a block, `pos` is its centre; for a container or an obstacle, the
/// centre of its base (on the table, or at the object's height `z:` for a shelf board or a
/// raised bin).
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectState {
    /// Position, world frame, metres.
    pub pos: Vector3<f64>,
    /// Orientation, world frame (unit quaternion; a block's axes are its faces' normals).
    pub quat: UnitQuaternion<f64>,
    /// Linear velocity, world frame, m/s.
    pub linvel: Vector3<f64>,
    /// Angular velocity, world frame, rad/s.
    pub angvel: Vector3<f64>,
    /// A left pad touches it.
    pub left_pad_contact: bool,
    /// A right pad touches it.
    pub right_pad_contact: bool,
}

/// Something in the cell a contact can involve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Part {
    /// Scene object `index` (`piece` tells a container's floor from its walls).
    Object {
        /// Index into [`World::objects`].
        index: usize,
        /// Which piece of it.
        piece: Piece,
    },
    /// The gripper's fingers or pads.
    Fingers,
    /// The rest of the robot (arm links, gripper base).
    Robot,
    /// The table.
    Table,
}

/// A piece of an object.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Piece {
    /// A block or an obstacle as a whole.
    Whole,
    /// A container's floor.
    Floor,
    /// A container's wall.
    Wall,
}

/// Two parts in contact (in no particular order: check both sides).
pub type Touch = (Part, Part);

impl World {
    /// Index of the object called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.scene.index_of(name)
    }

    /// The scene description of object `i`.
    pub fn spec(&self, i: usize) -> &ObjectSpec {
        &self.scene.objects[i]
    }

    /// Object `i`'s name.
    pub fn name(&self, i: usize) -> &str {
        &self.scene.objects[i].name
    }

    /// Half the edge of block `i` (0 for other objects), metres.
    pub fn half(&self, i: usize) -> f64 {
        match self.spec(i).shape {
            Shape::Block { half, .. } => half,
            _ => 0.0,
        }
    }

    /// Lowest point of object `i` above the table, metres (exact for a block in any orientation).
    pub fn bottom(&self, i: usize) -> f64 {
        let o = &self.objects[i];
        match self.spec(i).shape {
            Shape::Block { half, .. } => {
                let r = o.quat.to_rotation_matrix();
                o.pos.z - (0..3).map(|k| r[(2, k)].abs() * half).sum::<f64>()
            }
            _ => o.pos.z,
        }
    }

    /// Highest point of object `i` above the table, metres (a container's rim).
    pub fn top(&self, i: usize) -> f64 {
        let o = &self.objects[i];
        match self.spec(i).shape {
            Shape::Block { half, .. } => {
                let r = o.quat.to_rotation_matrix();
                o.pos.z + (0..3).map(|k| r[(2, k)].abs() * half).sum::<f64>()
            }
            ref s => o.pos.z + s.height(),
        }
    }

    /// Where a block set down on object `i` rests its bottom, metres: a container's floor, a
    /// block's or obstacle's top.
    pub fn support_height(&self, i: usize) -> f64 {
        match self.spec(i).kind() {
            ObjectKind::Container => self.objects[i].pos.z + CONTAINER_FLOOR,
            _ => self.top(i),
        }
    }

    /// Yaw of object `i` about world z, radians: for a block, of its side faces folded into
    /// [−45°, 45°) (a cube looks the same every quarter turn, whatever face it rests on); for
    /// other objects, of their x axis.
    pub fn yaw(&self, i: usize) -> f64 {
        let q = &self.objects[i].quat;
        match self.spec(i).kind() {
            ObjectKind::Block => {
                let r = q.to_rotation_matrix();
                let axis = (0..3)
                    .map(|k| r.matrix().column(k).into_owned())
                    .min_by(|a, b| a.z.abs().total_cmp(&b.z.abs()))
                    .expect("three axes");
                fold_quarter_turn(axis.y.atan2(axis.x))
            }
            _ => yaw_of(q),
        }
    }

    /// `p` in the table plane of object `i`'s own frame (relative to its centre, turned by its
    /// yaw), metres.
    pub fn local_xy(&self, i: usize, p: &Vector3<f64>) -> Vector2<f64> {
        let o = &self.objects[i];
        let d = Vector2::new(p.x - o.pos.x, p.y - o.pos.y);
        let (s, c) = yaw_of(&o.quat).sin_cos();
        Vector2::new(c * d.x + s * d.y, -s * d.x + c * d.y)
    }

    /// Horizontal vector from the nearest point of object `i`'s footprint to `p` (zero over the
    /// footprint), in the object's frame, metres.
    pub fn from_footprint(&self, i: usize, p: &Vector3<f64>) -> Vector2<f64> {
        let [hx, hy] = self.spec(i).shape.footprint_half();
        let d = self.local_xy(i, p);
        Vector2::new(d.x - d.x.clamp(-hx, hx), d.y - d.y.clamp(-hy, hy))
    }

    /// Both pads touch block `i` and its centre lies between them (within `off_axis` metres of
    /// the line through the pad centres).
    pub fn holds(&self, i: usize, off_axis: f64) -> bool {
        let o = &self.objects[i];
        if !(o.left_pad_contact && o.right_pad_contact) {
            return false;
        }
        let axis = self.right_pad_pos - self.left_pad_pos;
        let len2 = axis.norm_squared();
        if len2 < 1e-12 {
            return false;
        }
        let rel = o.pos - self.left_pad_pos;
        let t = rel.dot(&axis) / len2;
        (0.0..=1.0).contains(&t) && (rel - axis * t).norm() <= off_axis
    }

    /// The block the gripper holds, if any.
    pub fn held_block(&self, off_axis: f64) -> Option<usize> {
        self.scene
            .of_kind(ObjectKind::Block)
            .find(|&i| self.holds(i, off_axis))
    }

    /// Block `i` lies inside container `c`'s walls, below its rim and above its base: its centre
    /// at most (inner half-width − its half-size) from the container's centre along each of the
    /// container's axes, so the whole block fits between the walls. (A block under a raised
    /// container is not in it.)
    pub fn inside(&self, i: usize, c: usize) -> bool {
        let Shape::Container {
            inner_half,
            wall_height,
        } = self.spec(c).shape
        else {
            return false;
        };
        let [half, _] = self.spec(i).shape.footprint_half();
        let d = self.local_xy(c, &self.objects[i].pos);
        d.x.abs() <= inner_half[0] - half
            && d.y.abs() <= inner_half[1] - half
            && self.objects[i].pos.z < self.objects[c].pos.z + wall_height
            && self.objects[i].pos.z > self.objects[c].pos.z
    }

    /// The container block `i` is inside, if any.
    pub fn container_of(&self, i: usize) -> Option<usize> {
        self.scene
            .of_kind(ObjectKind::Container)
            .find(|&c| self.inside(i, c))
    }

    /// No pad touches object `i`.
    pub fn released(&self, i: usize) -> bool {
        !(self.objects[i].left_pad_contact || self.objects[i].right_pad_contact)
    }

    /// Object `i` moves slower than `speed` m/s.
    pub fn at_rest(&self, i: usize, speed: f64) -> bool {
        self.objects[i].linvel.norm() < speed
    }

    /// What object `i` rests on: another object whose top it sits on, or `None` (the table, a
    /// container's floor, or nothing — see [`Self::container_of`] and [`Self::bottom`]).
    pub fn resting_on(&self, i: usize) -> Option<usize> {
        let bottom = self.bottom(i);
        (0..self.objects.len()).find(|&j| {
            j != i
                && self.spec(j).kind() != ObjectKind::Container
                && (bottom - self.top(j)).abs() < 0.005
                && self.from_footprint(j, &self.objects[i].pos).norm() == 0.0
        })
    }

    /// Describes part `p` for messages: `red`, `bowl wall`, `the fingers`, `the table`.
    pub fn describe(&self, p: Part) -> String {
        match p {
            Part::Object { index, piece } => match piece {
                Piece::Whole => self.name(index).to_string(),
                Piece::Floor => format!("{} floor", self.name(index)),
                Piece::Wall => format!("{} wall", self.name(index)),
            },
            Part::Fingers => "the fingers".into(),
            Part::Robot => "the arm".into(),
            Part::Table => "the table".into(),
        }
    }
}
