//! [`Sim`]: one MuJoCo data instance of the [`Scene`], reset to a [`Layout`], stepped, and read
//! back into a [`World`].

use std::sync::Arc;

use mujoco_rs::prelude::*;
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::layout::Layout;
use super::scene::Scene;
use crate::scene::{Placement, Shape};
use crate::world::{ObjectState, Part, World};

pub use crate::motion::HOME_Q;

/// Half-thickness of a 2F-85 pad box across the grip (Menagerie `pad_box1/2` size y), metres.
pub const PAD_HALF_THICKNESS: f64 = 0.004;

/// Physics time step of the scene, seconds (set in assets/scene.xml).
pub const TIMESTEP: f64 = 0.002;

/// A running simulation of the task scene.
pub struct Sim {
    scene: Scene,
    data: MjData<Arc<MjModel>>,
    steps: u64,
    /// Wall-clock time spent inside `mj_step` since this simulation was created (never reset).
    physics_time: std::time::Duration,
    /// Scratch for [`Sim::command_arm`]: the commanded joint accelerations (rad/s², `nv`).
    accel: Vec<f64>,
    /// Scratch for [`Sim::command_arm`]: the inertial torques `M q̈` (N·m, `nv`).
    inertial: Vec<f64>,
}

impl Sim {
    /// A fresh simulation of `scene`, reset to the default layout.
    pub fn new(scene: &Scene) -> Self {
        let data = MjData::new(scene.model.clone());
        let mut sim = Self {
            scene: scene.clone(),
            data,
            steps: 0,
            physics_time: std::time::Duration::ZERO,
            accel: Vec::new(),
            inertial: Vec::new(),
        };
        let placement = scene.default_placement();
        sim.reset_placement(&placement);
        sim
    }

    /// The scene this simulation runs.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Puts the arm at home with its servos holding home, the gripper open, the cube resting on
    /// the table at the layout's pose and the bowl at its place; the scene's other objects at
    /// their default poses ([`Scene::placement_from_layout`]); time and step count go to zero.
    pub fn reset(&mut self, layout: &Layout) {
        let placement = self.scene.placement_from_layout(layout);
        self.reset_placement(&placement);
    }

    /// Puts the arm at home with its servos holding home, the gripper open, every block resting
    /// at its pose in `placement` (its bottom at the pose's height `z`: the table, a container's
    /// floor, a shelf board) and every container and obstacle at its pose (base at `z`), one
    /// pose per object, scene order; time, step count and MuJoCo's warning counters go to zero.
    pub fn reset_placement(&mut self, placement: &Placement) {
        self.data.reset();
        let scene = self.scene.clone();
        {
            let qpos = self.data.qpos_mut();
            for (i, &a) in scene.ids.arm_qpos.iter().enumerate() {
                qpos[a] = HOME_Q[i];
            }
            for ((o, ids), p) in scene
                .spec
                .objects
                .iter()
                .zip(&scene.objects)
                .zip(&placement.poses)
            {
                if let (Shape::Block { half, .. }, Some(c)) = (&o.shape, ids.qpos) {
                    let h = p.yaw / 2.0;
                    qpos[c..c + 7].copy_from_slice(&[p.x, p.y, p.z + *half, h.cos(), 0.0, 0.0, h.sin()]);
                }
            }
        }
        for (ids, p) in scene.objects.iter().zip(&placement.poses) {
            if let Some(m) = ids.mocap {
                let h = p.yaw / 2.0;
                self.data.mocap_pos_mut()[m] = [p.x, p.y, p.z];
                self.data.mocap_quat_mut()[m] = [h.cos(), 0.0, 0.0, h.sin()];
            }
        }
        self.set_arm_ctrl(&HOME_Q);
        self.set_gripper_ctrl(0.0);
        self.data.forward();
        self.steps = 0;
    }

    /// MuJoCo's instability warnings since the last reset (bad qpos, qvel or qacc: MuJoCo then
    /// resets its state and the episode is no longer physics), as one sentence, or `None`.
    pub fn instability(&self) -> Option<String> {
        let w = &self.data.ffi().warning;
        let kinds = [(3, "bad qpos"), (4, "bad qvel"), (5, "bad qacc")];
        let found: Vec<String> = kinds
            .iter()
            .filter(|(k, _)| w[*k].number > 0)
            .map(|(k, what)| format!("{what} ×{} (first at dof {})", w[*k].number, w[*k].lastinfo))
            .collect();
        (!found.is_empty()).then(|| format!("MuJoCo reported an unstable simulation: {}", found.join(", ")))
    }

    /// Commands the arm's position servos, radians.
    pub fn set_arm_ctrl(&mut self, q: &[f64; 6]) {
        let acts = self.scene.ids.arm_act;
        let ctrl = self.data.ctrl_mut();
        for (i, &a) in acts.iter().enumerate() {
            ctrl[a] = q[i];
        }
    }

    /// Commands the arm to track joint angles `q` (radians) moving at `qd` (rad/s) and
    /// accelerating at `qdd` (rad/s²), with feedforward.
    ///
    /// Menagerie's UR5e servos are plain PD position actuators, `τ = kp (ctrl − q) − kv q̇`, with
    /// no gravity compensation: holding a pose they sag by about 0.6° (≈1 cm at the tool), and
    /// tracking a moving target they lag by `kv/kp · q̇`, and by `M q̈ / kp` while accelerating
    /// (about 1 cm at the pinch at the default limits). This command shifts the servo set point
    /// so that `τ = kp (q − q_meas) + kv (qd − q̇_meas) + M qdd + bias`, where `M` is MuJoCo's
    /// joint-space inertia (with the gripper and the joints' armature) and `bias` its gravity +
    /// Coriolis torque, both at the state of the last step (`qM`, `qfrc_bias`): the computed-torque
    /// feedforward of a real UR controller. Call it before every physics step while tracking.
    pub fn command_arm(&mut self, q: &[f64; 6], qd: &[f64; 6], qdd: &[f64; 6]) {
        let ids = &self.scene.ids;
        let nv = self.data.model().ffi().nv as usize;
        self.accel.clear();
        self.accel.resize(nv, 0.0);
        self.inertial.clear();
        self.inertial.resize(nv, 0.0);
        // Holding (no acceleration) needs no inertial torque: M · 0 is 0.
        if qdd.iter().any(|a| *a != 0.0 && a.is_finite()) {
            for (&dof, &a) in ids.arm_dof.iter().zip(qdd) {
                self.accel[dof] = if a.is_finite() { a } else { 0.0 };
            }
            // SAFETY: `accel` and `inertial` hold exactly `nv` numbers, what mj_mulM reads and
            // writes; the model and data are MuJoCo's own, valid for this call.
            unsafe {
                mujoco_rs::mujoco_c::mj_mulM(
                    self.data.model().ffi(),
                    self.data.ffi(),
                    self.inertial.as_mut_ptr(),
                    self.accel.as_ptr(),
                );
            }
        }
        let bias = self.data.qfrc_bias();
        let mut set = [0.0; 6];
        for i in 0..6 {
            let (kp, kv) = self.scene.arm_gains[i];
            let dof = ids.arm_dof[i];
            let u = q[i] + (kv * qd[i] + self.inertial[dof] + bias[dof]) / kp;
            let [lo, hi] = self.scene.arm_ctrlrange[i];
            set[i] = u.clamp(lo, hi);
        }
        self.set_arm_ctrl(&set);
    }

    /// Commands the gripper actuator (0 = open … 255 = closed).
    pub fn set_gripper_ctrl(&mut self, u: f64) {
        let a = self.scene.ids.gripper_act;
        self.data.ctrl_mut()[a] = u.clamp(0.0, 255.0);
    }

    /// The current actuator commands (6 arm + gripper, in actuator order).
    pub fn ctrl(&self) -> &[f64] {
        self.data.ctrl()
    }

    /// Overwrites all actuator commands (used by replays).
    pub fn set_ctrl(&mut self, ctrl: &[f64]) {
        self.data.ctrl_mut().copy_from_slice(ctrl);
    }

    /// Advances the physics by one time step ([`TIMESTEP`]).
    pub fn step(&mut self) {
        let start = std::time::Instant::now();
        self.data.step();
        self.physics_time += start.elapsed();
        self.steps += 1;
    }

    /// Wall-clock time spent inside `mj_step` since this simulation was created (resets do not
    /// clear it), for measuring how much of a run is physics.
    pub fn physics_time(&self) -> std::time::Duration {
        self.physics_time
    }

    /// Physics steps taken since the last reset.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Simulated time since the last reset, seconds.
    pub fn time(&self) -> f64 {
        self.data.ffi().time
    }

    /// The gripper's closure: its right driver joint's angle, radians (0 open … about 0.8
    /// closed), which the world snapshot does not keep.
    pub fn gripper_joint(&self) -> f64 {
        self.data.qpos()[self.scene.ids.gripper_driver_qpos]
    }

    /// Read-only access to the MuJoCo data (for the viewer and tests).
    pub fn data(&self) -> &MjData<Arc<MjModel>> {
        &self.data
    }

    /// Mutable access to the MuJoCo data, for fault injection through physics (pushes, friction).
    pub fn data_mut(&mut self) -> &mut MjData<Arc<MjModel>> {
        &mut self.data
    }

    /// Full physics state (qpos, qvel, act, ctrl, time) as bits, for determinism checks.
    pub fn state_fingerprint(&self) -> Vec<u64> {
        let d = &self.data;
        d.qpos()
            .iter()
            .chain(d.qvel())
            .chain(d.ctrl())
            .chain(std::iter::once(&d.ffi().time))
            .map(|v| v.to_bits())
            .collect()
    }

    /// Reads the current state into a [`World`] snapshot.
    pub fn observe(&self) -> World {
        let ids = &self.scene.ids;
        let d = &self.data;
        let qpos = d.qpos();
        let qvel = d.qvel();
        let ctrl = d.ctrl();
        let mut arm_q = [0.0; 6];
        let mut arm_qd = [0.0; 6];
        let mut arm_cmd = [0.0; 6];
        for i in 0..6 {
            arm_q[i] = qpos[ids.arm_qpos[i]];
            arm_qd[i] = qvel[ids.arm_dof[i]];
            arm_cmd[i] = ctrl[ids.arm_act[i]];
        }
        let gx = d.geom_xpos();
        let v3 = |p: [f64; 3]| Vector3::new(p[0], p[1], p[2]);
        let left_pad_pos = (v3(gx[ids.left_pads[0]]) + v3(gx[ids.left_pads[1]])) / 2.0;
        let right_pad_pos = (v3(gx[ids.right_pads[0]]) + v3(gx[ids.right_pads[1]])) / 2.0;
        let scene = &self.scene;
        let mut objects: Vec<ObjectState> = scene
            .objects
            .iter()
            .map(|o| match (o.qpos, o.dof, o.mocap) {
                (Some(q), Some(v), _) => ObjectState {
                    pos: Vector3::new(qpos[q], qpos[q + 1], qpos[q + 2]),
                    quat: UnitQuaternion::from_quaternion(Quaternion::new(
                        qpos[q + 3],
                        qpos[q + 4],
                        qpos[q + 5],
                        qpos[q + 6],
                    )),
                    linvel: Vector3::new(qvel[v], qvel[v + 1], qvel[v + 2]),
                    angvel: Vector3::new(qvel[v + 3], qvel[v + 4], qvel[v + 5]),
                    left_pad_contact: false,
                    right_pad_contact: false,
                },
                (_, _, Some(m)) => {
                    let [w, x, y, z] = d.mocap_quat()[m];
                    ObjectState {
                        pos: v3(d.mocap_pos()[m]),
                        quat: UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
                        linvel: Vector3::zeros(),
                        angvel: Vector3::zeros(),
                        left_pad_contact: false,
                        right_pad_contact: false,
                    }
                }
                _ => unreachable!("blocks have a free joint, the rest a mocap body"),
            })
            .collect();
        let mut touches = Vec::new();
        for c in d.contact() {
            let (a, b) = (c.geom[0] as usize, c.geom[1] as usize);
            let (pa, pb) = (scene.geom_parts[a], scene.geom_parts[b]);
            for (me, other) in [(pa, b), (pb, a)] {
                if let Part::Object { index, .. } = me {
                    objects[index].left_pad_contact |= ids.left_pads.contains(&other);
                    objects[index].right_pad_contact |= ids.right_pads.contains(&other);
                }
            }
            if pa != pb
                && pa != Part::Table
                && pb != Part::Table
                && !(pa == Part::Robot && pb == Part::Robot)
                && !touches.contains(&(pa, pb))
            {
                touches.push((pa, pb));
            }
        }
        let nsite = self.scene.model.ffi().nsite as usize;
        // SAFETY: site_xmat holds nsite * 9 doubles for the lifetime of `data`.
        let site_xmat = unsafe { std::slice::from_raw_parts(d.ffi().site_xmat, nsite * 9) };
        let m = &site_xmat[ids.pinch_site * 9..ids.pinch_site * 9 + 9];
        let pinch_rot = Matrix3::from_row_slice(m);
        let sx = d.site_xpos();
        World {
            time: d.ffi().time,
            arm_q,
            arm_qd,
            arm_cmd,
            gripper_width: (left_pad_pos - right_pad_pos).norm() - 2.0 * PAD_HALF_THICKNESS,
            gripper_speed: qvel[ids.gripper_driver_dof],
            pinch_pos: v3(sx[ids.pinch_site]),
            pinch_rot,
            left_pad_pos,
            right_pad_pos,
            home_q: HOME_Q,
            scene: scene.spec.clone(),
            objects,
            touches,
        }
    }
}
