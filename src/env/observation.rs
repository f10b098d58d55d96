//! [`Observation`]: what the environment tells its caller after a reset or a step — the robot,
//! every object by name, the contacts — and the flat vectors shared with the LeRobot dataset
//! (`observation.state`, `observation.environment_state`, `action`): one definition for both,
//! in [`crate::episode::vectors`].

use nalgebra::UnitQuaternion;
use serde::Serialize;

use crate::actions::Cell;
use crate::world::conditions::Tolerances;

use crate::episode::vectors::{RobotState, command_vector, pinch_quat, pose_vector, state_vector};
pub use crate::episode::vectors::{
    STATE_LEN, STATE_NAMES, VALUES_PER_OBJECT as ENVIRONMENT_VALUES_PER_OBJECT,
};

/// The cell at one instant, as the environment reports it. Units: metres, radians, seconds;
/// quaternions are `[w, x, y, z]`, world frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Observation {
    /// Simulated time since the last reset, seconds.
    pub time: f64,
    /// Measured arm joint angles (shoulder pan … wrist 3), radians.
    pub joint_pos: [f64; 6],
    /// Measured arm joint velocities, rad/s.
    pub joint_vel: [f64; 6],
    /// The joint angles the arm is commanded to now (the set point its servos track), radians.
    pub joint_target: [f64; 6],
    /// Gripper closure: the right driver joint's angle, radians (0 open … about 0.8 closed).
    pub gripper_joint: f64,
    /// Gripper opening: free distance between the two pad faces, metres.
    pub gripper_width: f64,
    /// Gripper actuator command (0 open … 255 closed).
    pub gripper_command: f64,
    /// The command of the last control period ([`crate::motion::CellCommand::to_vector`]: set
    /// points, velocities, accelerations, gripper); holding at the set point before the first.
    pub last_command: [f64; crate::motion::COMMAND_LEN],
    /// Pinch point (between the fingertips) position, metres.
    pub pinch_pos: [f64; 3],
    /// Pinch frame orientation `[w, x, y, z]` (its z axis points out of the fingers).
    pub pinch_quat: [f64; 4],
    /// Centre of the left pads, metres.
    pub left_pad_pos: [f64; 3],
    /// Centre of the right pads, metres.
    pub right_pad_pos: [f64; 3],
    /// Every object of the scene, in scene order; serialized as a map from each object's name
    /// to the object.
    #[serde(serialize_with = "objects_by_name")]
    pub objects: Vec<ObjectObservation>,
    /// The contacts between distinct parts of the cell (robot–object, object–object; table
    /// contacts left out), each pair once.
    pub contacts: Vec<Contact>,
}

/// One object of the scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObjectObservation {
    /// Its name in the scene file (serialized as the object's key, see
    /// [`Observation::objects`]).
    #[serde(skip)]
    pub name: String,
    /// `block`, `container` or `obstacle`.
    pub kind: &'static str,
    /// Half extents of its bounding box in its own frame, metres ([`crate::scene::Shape`]).
    pub half_extents: [f64; 3],
    /// Position (a block's centre; a container's or obstacle's base on the table), metres.
    pub pos: [f64; 3],
    /// Orientation `[w, x, y, z]`.
    pub quat: [f64; 4],
    /// Linear velocity, m/s (zero for containers and obstacles, which do not move by physics).
    pub linvel: [f64; 3],
    /// Angular velocity, rad/s.
    pub angvel: [f64; 3],
    /// Held between the pads (both pads touch it, its centre within 3 cm of the pinch axis).
    pub grasped: bool,
}

/// Two parts of the cell in contact, named as failure messages name them (`cube`, `bowl wall`,
/// `the fingers`, `the arm`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Contact {
    /// One part.
    pub a: String,
    /// The other.
    pub b: String,
}

/// Serializes the objects as a map from name to object, in scene order.
fn objects_by_name<S: serde::Serializer>(objects: &[ObjectObservation], s: S) -> Result<S::Ok, S::Error> {
    s.collect_map(objects.iter().map(|o| (&o.name, o)))
}

impl Observation {
    /// The observation of `cell` now (its world snapshot, refreshed after every control period,
    /// and the simulation's gripper joint).
    pub fn of(cell: &Cell) -> Observation {
        let w = cell.world();
        let sim = cell.sim();
        let v3 = |v: &nalgebra::Vector3<f64>| [v.x, v.y, v.z];
        let wxyz = |q: &UnitQuaternion<f64>| [q.w, q.i, q.j, q.k];
        let objects = w
            .objects
            .iter()
            .enumerate()
            .map(|(i, o)| ObjectObservation {
                name: w.name(i).to_string(),
                kind: w.spec(i).kind().name(),
                half_extents: w.spec(i).shape.half_extents(),
                pos: v3(&o.pos),
                quat: wxyz(&o.quat),
                linvel: v3(&o.linvel),
                angvel: v3(&o.angvel),
                grasped: w.holds(i, Tolerances::GRASP_OFF_AXIS),
            })
            .collect();
        let contacts = w
            .touches
            .iter()
            .map(|&(a, b)| Contact {
                a: w.describe(a),
                b: w.describe(b),
            })
            .collect();
        Observation {
            time: w.time,
            joint_pos: w.arm_q,
            joint_vel: w.arm_qd,
            joint_target: cell.arm_setpoint(),
            gripper_joint: sim.gripper_joint(),
            gripper_width: w.gripper_width,
            gripper_command: cell.gripper_command(),
            last_command: cell
                .last_command()
                .unwrap_or(crate::motion::CellCommand {
                    arm: crate::motion::ArmCommand::hold(cell.arm_setpoint()),
                    gripper: cell.gripper_command(),
                })
                .to_vector(),
            pinch_pos: v3(&w.pinch_pos),
            pinch_quat: pinch_quat(&w.pinch_rot),
            left_pad_pos: v3(&w.left_pad_pos),
            right_pad_pos: v3(&w.right_pad_pos),
            objects,
            contacts,
        }
    }

    /// The dataset's `observation.state` (and the Python env's `agent_pos`): joint angles,
    /// gripper closure, joint velocities and the pinch pose ([`state_vector`]), as `f32`.
    /// Names: [`STATE_NAMES`].
    pub fn state(&self) -> [f32; STATE_LEN] {
        state_vector(&RobotState {
            joint_pos: self.joint_pos,
            gripper_joint: self.gripper_joint,
            joint_vel: self.joint_vel,
            pinch_pos: self.pinch_pos,
            pinch_quat: self.pinch_quat,
        })
    }

    /// The dataset's `action` of the last control period, as `f32` — the layout
    /// `env::Action::Ctrl` takes ([`Self::last_command`]).
    pub fn command(&self) -> [f32; crate::motion::COMMAND_LEN] {
        command_vector(&self.last_command)
    }

    /// The dataset's `observation.environment_state`: every object's pose in scene order, each
    /// as x, y, z (metres), qw, qx, qy, qz, as `f32` ([`ENVIRONMENT_VALUES_PER_OBJECT`] values
    /// per object).
    pub fn environment_state(&self) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.objects.len() * ENVIRONMENT_VALUES_PER_OBJECT);
        for o in &self.objects {
            out.extend(pose_vector(&o.pos, &o.quat));
        }
        out
    }

    /// The Python env's `pinch`: the pinch point (metres) and its orientation `[w, x, y, z]`,
    /// world frame, as `f32` ([`pose_vector`], [`ENVIRONMENT_VALUES_PER_OBJECT`] values).
    pub fn pinch(&self) -> [f32; ENVIRONMENT_VALUES_PER_OBJECT] {
        pose_vector(&self.pinch_pos, &self.pinch_quat)
    }

    /// The object called `name`, if the scene has one.
    pub fn object(&self, name: &str) -> Option<&ObjectObservation> {
        self.objects.iter().find(|o| o.name == name)
    }
}
