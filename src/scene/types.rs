//! The scene's data: objects, their shapes, poses and randomization. Metres, kilograms, radians.

use serde::Serialize;

use super::color::Color;
use super::goal::Goal;

/// Thickness of a container's walls, metres.
pub const CONTAINER_WALL: f64 = 0.01;
/// Thickness of a container's floor, metres (its top surface is this high above the table).
pub const CONTAINER_FLOOR: f64 = 0.01;
/// Radius of the circle around the robot's base (at the world origin) that no object may
/// overlap, metres (the UR5e base is 149 mm across; 5 cm margin).
pub const ROBOT_BASE_RADIUS: f64 = 0.125;

/// Horizontal distance from the robot's base within which a block can be picked from above and
/// put down, metres: `[min, max]`. Closer than `min` the wrist folds onto the base; farther than
/// `max` the arm cannot point the tool straight down at table height.
pub fn reach_limits() -> [f64; 2] {
    [0.22, 0.72]
}

/// What an object is for.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectKind {
    /// A movable cube on a free joint: picked, carried, stacked, put in containers.
    Block,
    /// A tray or bin with a floor and four walls; fixed to the table during an episode (its pose
    /// comes from the layout).
    Container,
    /// A fixed box on the table that motions must clear.
    Obstacle,
}

impl ObjectKind {
    /// `block`, `container` or `obstacle`.
    pub fn name(self) -> &'static str {
        match self {
            ObjectKind::Block => "block",
            ObjectKind::Container => "container",
            ObjectKind::Obstacle => "obstacle",
        }
    }
}

impl std::fmt::Display for ObjectKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// An object's shape and physical parameters.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// A cube.
    Block {
        /// Half the edge, metres.
        half: f64,
        /// Mass, kg.
        mass: f64,
        /// Sliding friction coefficient against the pads and the table.
        friction: f64,
    },
    /// An open box: floor [`CONTAINER_FLOOR`] thick, walls [`CONTAINER_WALL`] thick.
    Container {
        /// Half of the free space inside the walls along the container's x and y, metres.
        inner_half: [f64; 2],
        /// Height of the rim above the table, metres.
        wall_height: f64,
    },
    /// A fixed box.
    Obstacle {
        /// Half extents along the obstacle's x, y, z, metres.
        half: [f64; 3],
    },
}

impl Shape {
    /// The kind of object this shape makes.
    pub fn kind(&self) -> ObjectKind {
        match self {
            Shape::Block { .. } => ObjectKind::Block,
            Shape::Container { .. } => ObjectKind::Container,
            Shape::Obstacle { .. } => ObjectKind::Obstacle,
        }
    }

    /// Half extents of the footprint on the table, in the object's own frame, metres.
    pub fn footprint_half(&self) -> [f64; 2] {
        match self {
            Shape::Block { half, .. } => [*half, *half],
            Shape::Container { inner_half, .. } => {
                [inner_half[0] + CONTAINER_WALL, inner_half[1] + CONTAINER_WALL]
            }
            Shape::Obstacle { half } => [half[0], half[1]],
        }
    }

    /// Half extents of the object's bounding box in its own frame (footprint halves, half the
    /// height), metres.
    pub fn half_extents(&self) -> [f64; 3] {
        let [hx, hy] = self.footprint_half();
        [hx, hy, self.height() / 2.0]
    }

    /// The footprint at `pose`: a rectangle turned by the pose's yaw.
    pub fn footprint(&self, pose: &Pose) -> super::footprint::Rect {
        super::footprint::Rect {
            centre: [pose.x, pose.y],
            half: self.footprint_half(),
            yaw: pose.yaw,
        }
    }

    /// Height above its base of the surface a block set on this object rests on, metres: a
    /// container's floor top, a block's or an obstacle's top.
    pub fn support_surface(&self) -> f64 {
        match self {
            Shape::Container { .. } => CONTAINER_FLOOR,
            other => other.height(),
        }
    }

    /// Half extents of the area a block set on this object can rest on, in the object's frame,
    /// metres: inside a container's walls, a block's or an obstacle's top.
    pub fn support_half(&self) -> [f64; 2] {
        match self {
            Shape::Container { inner_half, .. } => *inner_half,
            other => other.footprint_half(),
        }
    }

    /// Radius of the circle around the footprint (any yaw), metres.
    pub fn footprint_radius(&self) -> f64 {
        let [a, b] = self.footprint_half();
        a.hypot(b)
    }

    /// Height of the object's top above its base, metres (a container's rim).
    pub fn height(&self) -> f64 {
        match self {
            Shape::Block { half, .. } => 2.0 * half,
            Shape::Container { wall_height, .. } => *wall_height,
            Shape::Obstacle { half } => 2.0 * half[2],
        }
    }
}

/// A pose in the cell: centre x, y (metres), yaw about the vertical (radians) and the height
/// of the object's base above the table (metres; 0 for an object standing on the table).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Default)]
pub struct Pose {
    /// Centre x, metres.
    pub x: f64,
    /// Centre y, metres.
    pub y: f64,
    /// Yaw about world z, radians.
    pub yaw: f64,
    /// Height of the object's base (a block's bottom face, a container's floor underside, an
    /// obstacle's bottom face) above the table, metres. Placements fill it in from the object's
    /// `z:` or from what it rests on ([`super::Placement::settle`]).
    #[serde(skip_serializing_if = "is_zero")]
    pub z: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl Pose {
    /// Horizontal distance between two poses' centres, metres.
    pub fn distance(&self, other: &Pose) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }
}

/// Where a randomized object may start.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RandomPlacement {
    /// Range of the centre x, metres (inclusive).
    pub x: [f64; 2],
    /// Range of the centre y, metres (inclusive).
    pub y: [f64; 2],
    /// Range of the yaw, radians (`[lo, hi)`); `None` keeps the fixed pose's yaw (or 0) and
    /// draws nothing.
    pub yaw: Option<[f64; 2]>,
    /// Smallest gap between this object's footprint and any other object's (and, for a block
    /// drawn on a support, the support's walls or edges), metres.
    pub clearance: f64,
    /// What a block is drawn on (`random: {in: bin}` or `{on: shelf}`): x and y are then drawn
    /// over the support's top (a container's floor inside its walls), in the support's frame.
    /// `None`: the table.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub support: Option<String>,
    /// The `allowed` regions (by name) the object's footprint must lie within, one of them
    /// (`random: {region: left}`). Empty: anywhere.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub regions: Vec<String>,
}

/// One object of the scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ObjectSpec {
    /// The object's name (`[a-z][a-z0-9_]*`), used in trees and reports.
    pub name: String,
    /// Shape and physics.
    pub shape: Shape,
    /// Colour.
    pub color: Color,
    /// The pose `macrotree run` uses when no randomization is asked for.
    pub pose: Option<Pose>,
    /// The randomization sweeps draw from.
    pub random: Option<RandomPlacement>,
    /// Height of a container's or obstacle's base above the table (`z:`), metres; 0 for blocks
    /// (their height comes from what they rest on).
    #[serde(skip_serializing_if = "is_zero")]
    pub z: f64,
    /// What a block with a fixed `pose:` rests on (`on: NAME`): a container's floor, an
    /// obstacle's or another block's top. `None`: the table.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub on: Option<String>,
}

impl ObjectSpec {
    /// What the object is.
    pub fn kind(&self) -> ObjectKind {
        self.shape.kind()
    }
}

/// How sweeps draw a scene's starting layouts (the scene file's `sampler:`).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampler {
    /// Every randomized object from its own `random:` region ([`super::sample_placement`]).
    #[default]
    Objects,
    /// The reference tutorial's sampler: the scene's cube ([`SceneSpec::legacy_cube`]) and bowl
    /// ([`SceneSpec::legacy_bowl`]) drawn together from its task region (x 0.30…0.60 m,
    /// y −0.30…0.30 m, cube yaw −45°…45°, centres at least 0.16 m apart); the other objects at
    /// their default poses. Sweeps then print `run --cube X,Y,YAW --bowl X,Y` reproductions.
    Tutorial,
}

/// A named place on the table (the scene file's `spots:`): a point and a yaw, usable as a
/// `carry`/`place` target, a goal point and a blackboard value.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spot {
    /// The spot's name (`[a-z][a-z0-9_]*`), unique among the scene's spots and objects.
    pub name: String,
    /// Centre x, metres.
    pub x: f64,
    /// Centre y, metres.
    pub y: f64,
    /// Yaw about world z, radians.
    pub yaw: f64,
    /// The obstacle or block a block set down at the spot rests on (`on:`), when the scene names
    /// one: the lower board of a two-level shelf, under the upper one. `None`: whatever is
    /// under the point with the highest top (or the table).
    pub on: Option<String>,
}

/// A loaded, validated scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneSpec {
    /// The scene's name (its file stem, e.g. `sort_three`).
    pub name: String,
    /// One line on what the cell is.
    pub description: Option<String>,
    /// The objects, in file order (which is also their order in the MuJoCo model and reports).
    pub objects: Vec<ObjectSpec>,
    /// The task's goal, evaluated when the episode ends.
    pub goal: Goal,
    /// How sweeps draw the starting layouts.
    pub sampler: Sampler,
    /// Named places on the table, in file order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub spots: Vec<Spot>,
    /// Named boxes on the table that random placement keeps out of or draws within, in file
    /// order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub regions: Vec<Region>,
}

/// What a [`Region`] is for.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RegionRole {
    /// No randomized object's footprint may enter it.
    KeepOut,
    /// Objects whose `random:` names it must keep their footprint within it.
    Allowed,
}

/// A named axis-aligned box on the table (the scene file's `regions:`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Region {
    /// The region's name (`[a-z][a-z0-9_]*`), unique among the scene's regions, spots and
    /// objects.
    pub name: String,
    /// Range of x, metres (`lo < hi`).
    pub x: [f64; 2],
    /// Range of y, metres (`lo < hi`).
    pub y: [f64; 2],
    /// What it is for.
    pub role: RegionRole,
}

impl Region {
    /// The region as a footprint rectangle.
    pub fn rect(&self) -> super::footprint::Rect {
        super::footprint::Rect {
            centre: [(self.x[0] + self.x[1]) / 2.0, (self.y[0] + self.y[1]) / 2.0],
            half: [(self.x[1] - self.x[0]) / 2.0, (self.y[1] - self.y[0]) / 2.0],
            yaw: 0.0,
        }
    }
}

impl SceneSpec {
    /// Index of the object called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.objects.iter().position(|o| o.name == name)
    }

    /// The object called `name`.
    pub fn object(&self, name: &str) -> Option<&ObjectSpec> {
        self.objects.iter().find(|o| o.name == name)
    }

    /// The spot called `name`.
    pub fn spot(&self, name: &str) -> Option<&Spot> {
        self.spots.iter().find(|s| s.name == name)
    }

    /// The region called `name`.
    pub fn region(&self, name: &str) -> Option<&Region> {
        self.regions.iter().find(|r| r.name == name)
    }

    /// Indices of the objects of `kind`, in scene order.
    pub fn of_kind(&self, kind: ObjectKind) -> impl Iterator<Item = usize> + '_ {
        (0..self.objects.len()).filter(move |&i| self.objects[i].kind() == kind)
    }

    /// The object the legacy name `cube` stands for: the block called `cube`, else the scene's
    /// only block.
    pub fn legacy_cube(&self) -> Option<usize> {
        self.legacy(ObjectKind::Block, "cube")
    }

    /// The object the legacy name `bowl` stands for: the container called `bowl`, else the
    /// scene's only container.
    pub fn legacy_bowl(&self) -> Option<usize> {
        self.legacy(ObjectKind::Container, "bowl")
    }

    fn legacy(&self, kind: ObjectKind, name: &str) -> Option<usize> {
        if let Some(i) = self.index_of(name).filter(|&i| self.objects[i].kind() == kind) {
            return Some(i);
        }
        let mut of_kind = self.of_kind(kind);
        match (of_kind.next(), of_kind.next()) {
            (Some(i), None) => Some(i),
            _ => None,
        }
    }

    /// True when every object has a fixed pose (so `run` needs no sampling).
    pub fn fully_posed(&self) -> bool {
        self.objects.iter().all(|o| o.pose.is_some())
    }

    /// True when some object is randomized (so sweeps vary the layout).
    pub fn randomized(&self) -> bool {
        self.objects.iter().any(|o| o.random.is_some())
    }
}
