//! [`SceneChecker`]: the planner's [`CollisionChecker`] on MuJoCo's own geometry of the cell —
//! a scratch `MjData` of a private copy of the scene's model, posed by `mj_kinematics` and tested
//! by `mj_collision`.
//!
//! What is checked: every collidable geom of the UR5e and the 2F-85 against every collidable
//! geom of the scene (the table, containers, obstacles, the blocks at their snapshot poses) and
//! against the robot's own geoms, and, when a block is held, that block (posed rigidly from the
//! pinch) against the scene and the arm. Pairs that cannot change with the arm's joints are never
//! tested: geoms moved by the same arm joint (a link's own geoms; the gripper's geoms with each
//! other and with a held block, the fingers being held at their snapshot opening), the robot's
//! fixed base against the table, and scene objects against each other. MuJoCo's own filters
//! (parent–child bodies, `<exclude>`) still apply. The private copy implements this with
//! contact bitmasks (one bit per arm joint) and sets the clearance margin as `geom_margin` on the
//! moving geoms, so MuJoCo reports every pair closer than the margin; the scene's model is not
//! changed.
//!
//! One checker per thread: it owns its `MjData`. [`SceneChecker::sync`] takes a new snapshot
//! (block poses, container and obstacle poses, the gripper's opening) from the running
//! simulation without copying the model again.

use std::sync::Arc;

use mujoco_rs::prelude::*;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use super::chain::{ArmChain, MovingGeoms};
use super::error::SimError;
use super::margin::MarginPairs;
use super::scene::{ARM_JOINTS, Scene};
use super::screen::{Build, PAD, Screen};
use crate::motion::fk;
use crate::motion::plan::config::HELD_BLOCK_REACH;
use crate::motion::plan::{Collision, CollisionChecker, FastChecks, JointSpare};
use crate::motion::ur5e::LEVER_ARMS as UR5E_LEVER_ARMS;
use crate::scene::OBJECT_PREFIX;

/// Default clearance margin, metres: the arm, gripper and held block must stay this far from
/// everything they must not touch.
pub const DEFAULT_MARGIN: f64 = 0.005;

/// What the spare clearance ([`FastChecks::exact_spare`]) leaves for MuJoCo's own
/// tolerances, metres: its `mj_geomDistance` and `mj_collision`'s contact distances of the same
/// pair differ by the convex-hull iterations' tolerance (about 1e-6 m); the screen's
/// [`PAD`] again.
pub const SPARE_TOLERANCE: f64 = 5e-4;

/// Largest clearance margin accepted, metres.
pub const MAX_MARGIN: f64 = 0.1;

/// The arm-joint group of the wrist 3 link, which carries the gripper and a held block.
const WRIST_3: u8 = 6;

/// A block held in the gripper: posed from the pinch at query time.
#[derive(Clone, Debug)]
struct Held {
    /// Scene index of the block.
    object: usize,
    /// `qpos` address of its free joint.
    qpos: usize,
    /// Its pose in the pinch frame.
    in_pinch: Isometry3<f64>,
    /// Every point of its geoms lies within [`HELD_BLOCK_REACH`] of the pinch point, so the
    /// lever arms the planner vouches with cover it.
    within_arms: bool,
}

/// A MuJoCo collision checker of the cell for the motion planner (see the module docs).
pub struct SceneChecker {
    scene: Scene,
    /// The private data, owning its private copy of the scene's model (edited in place when
    /// the groups or the margin change).
    data: MjData<Box<MjModel>>,
    /// Arm group of each geom: 0 = fixed (scene, robot base), 1..=6 = moved by that arm joint.
    group: Vec<u8>,
    /// Collidable in the scene's model (contype or conaffinity set).
    collidable: Vec<bool>,
    /// A label per geom for messages.
    labels: Vec<String>,
    /// The snapshot's arm joints, radians.
    snapshot_q: [f64; 6],
    held: Option<Held>,
    margin: f64,
    /// What the private model's bitmasks and margins are written for: (held block, margin
    /// bits); `None` before the first write.
    built_for: Option<BuildKey>,
    /// What is derived from the current snapshot (the [`Screen`], the moving geoms' frames),
    /// built on first use after a change.
    derived: Option<Derived>,
    /// Whether [`FastChecks::screen`] asks the screen (default true).
    screen_on: bool,
    /// Body and joint ids of the six arm links.
    arm_links: ([usize; 6], [usize; 6]),
    /// The private model's pairs whose margin MuJoCo's narrow phase may leave out, and the pairs
    /// that counted at the last configuration detected (geoms, distance, metres).
    margin_pairs: (MarginPairs, Vec<(usize, usize, f64)>),
}

/// What a checker derives from its snapshot.
struct Derived {
    /// The conservative fast model ([`Screen`]); `None` when the cell has geometry it cannot
    /// bound.
    screen: Option<Screen>,
    /// The moving geoms posed without `mj_kinematics`; `None` when the arm is not a chain.
    moving: Option<MovingGeoms>,
}

/// What a private model is edited for: the held block (scene index), the margin's bits.
type BuildKey = (Option<usize>, u64);

/// `a` if the geom's name is set, else its body's; the scene-object prefix dropped; the floor
/// is `table`.
fn label(m: &MjModel, g: usize) -> String {
    let name = m
        .id_to_name(MjtObjBase::mjOBJ_GEOM, g)
        .unwrap_or_default()
        .to_string();
    let name = if name.is_empty() {
        let b = m.geom_bodyid()[g] as usize;
        m.id_to_name(MjtObjBase::mjOBJ_BODY, b)
            .unwrap_or_default()
            .to_string()
    } else {
        name
    };
    if name == "floor" {
        return "table".into();
    }
    name.strip_prefix(OBJECT_PREFIX)
        .map(str::to_string)
        .unwrap_or(name)
}

impl SceneChecker {
    /// A checker of `scene` with its current state taken from `data` (a running simulation's
    /// data of the same scene: block, container and obstacle poses, the gripper's opening) and a
    /// clearance `margin` in metres (0 to `MAX_MARGIN`).
    ///
    /// # Errors
    /// A margin out of range, or `data` not of this scene's model.
    pub fn new(scene: &Scene, data: &MjData<Arc<MjModel>>, margin: f64) -> Result<Self, SimError> {
        let model = scene.collision_model()?;
        Self::on_model(scene, data, margin, &model)
    }

    /// [`SceneChecker::new`] on a copy of `model`, a model of `scene` with its ids (its
    /// collision model, or in tests the whole model).
    fn on_model(
        scene: &Scene,
        data: &MjData<Arc<MjModel>>,
        margin: f64,
        model: &MjModel,
    ) -> Result<Self, SimError> {
        if !(margin.is_finite() && (0.0..=MAX_MARGIN).contains(&margin)) {
            return Err(SimError::Scene(format!(
                "collision margin {margin} m: use a value in [0, {MAX_MARGIN}] metres"
            )));
        }
        let src = &scene.model;
        let ngeom = src.ffi().ngeom as usize;
        if data.qpos().len() != src.ffi().nq as usize || data.mocap_pos().len() != src.ffi().nmocap as usize {
            return Err(SimError::Scene(
                "the checker's snapshot is not of this scene's model".into(),
            ));
        }
        let arm_joints: Vec<usize> = ARM_JOINTS
            .iter()
            .map(|n| {
                src.name_to_id(MjtObjBase::mjOBJ_JOINT, &format!("ur5e/{n}_joint"))
                    .ok_or_else(|| SimError::Scene(format!("no joint ur5e/{n}_joint")))
            })
            .collect::<Result<_, _>>()?;
        let (parent, jadr, jnum) = (src.body_parentid(), src.body_jntadr(), src.body_jntnum());
        let body_group = |mut b: usize| -> u8 {
            while b != 0 {
                let (a, n) = (jadr[b], jnum[b]);
                if a >= 0 {
                    for j in a as usize..(a + n) as usize {
                        if let Some(k) = arm_joints.iter().position(|&x| x == j) {
                            return k as u8 + 1;
                        }
                    }
                }
                b = parent[b] as usize;
            }
            0
        };
        let group: Vec<u8> = src
            .geom_bodyid()
            .iter()
            .map(|&b| body_group(b as usize))
            .collect();
        let collidable: Vec<bool> = (0..ngeom)
            .map(|g| src.geom_contype()[g] != 0 || src.geom_conaffinity()[g] != 0)
            .collect();
        let labels = (0..ngeom).map(|g| label(src, g)).collect();
        let joints: [usize; 6] = std::array::from_fn(|k| arm_joints[k]);
        let bodies: [usize; 6] = std::array::from_fn(|k| src.jnt_bodyid()[arm_joints[k]] as usize);
        let mut checker = Self {
            scene: scene.clone(),
            // The one copy of the model this checker makes (holds, releases and margin changes
            // edit it in place).
            data: MjData::new(Box::new(model.clone())),
            group,
            collidable,
            labels,
            snapshot_q: [0.0; 6],
            held: None,
            margin,
            built_for: None,
            derived: None,
            screen_on: true,
            arm_links: (bodies, joints),
            margin_pairs: Default::default(),
        };
        checker.rebuild_model();
        checker.sync(data)?;
        Ok(checker)
    }

    /// A checker of `sim`'s scene and current state with the clearance `margin` (metres).
    ///
    /// # Errors
    /// As [`SceneChecker::new`].
    pub fn from_sim(sim: &super::Sim, margin: f64) -> Result<Self, SimError> {
        Self::new(sim.scene(), sim.data(), margin)
    }

    /// Writes the contact bitmasks and margins of the private model for the current groups
    /// (a held block joins the wrist-3 group) and margin, in place: the model's sizes do not
    /// change, so the private data stays valid.
    fn rebuild_model(&mut self) {
        self.derived = None;
        let key = (self.held.as_ref().map(|h| h.object), self.margin.to_bits());
        if self.built_for == Some(key) {
            return;
        }
        self.built_for = Some(key);
        let mut group = self.group.clone();
        if let Some(h) = &self.held {
            let [g0, g1] = self.scene.objects[h.object].geoms;
            for g in group.iter_mut().take(g1).skip(g0) {
                *g = WRIST_3;
            }
        }
        let margin = self.margin;
        let collidable = &self.collidable;
        let floor = self.scene.ids.floor_geom;
        // SAFETY: only per-geom values (contact bitmasks, margins, gaps) and the per-body values
        // compiled from them are written; no size, address or index table of the model
        // changes, so the data stays consistent with it.
        let model = unsafe { self.data.model_mut() };
        // Bits: 0 = fixed scene geoms, 1..=6 = moved by arm joint k, 7 = the table. A geom of
        // group k collides with every bit but its own (and but the table's for k = 1: the
        // shoulder link only turns about the vertical axis above the table, its distance to it
        // never changes); fixed geoms and the table collide with nothing by themselves.
        for (g, c) in model.geom_contype_mut().iter_mut().enumerate() {
            *c = match (collidable[g], group[g]) {
                (false, _) => 0,
                (true, 0) if g == floor => 1 << 7,
                (true, 0) => 1,
                (true, k) => 1 << k,
            };
        }
        for (g, c) in model.geom_conaffinity_mut().iter_mut().enumerate() {
            *c = match (collidable[g], group[g]) {
                (false, _) | (true, 0) => 0,
                (true, 1) => 0x7F & !(1 << 1),
                (true, k) => 0xFF & !(1 << k),
            };
        }
        for (g, m) in model.geom_margin_mut().iter_mut().enumerate() {
            *m = if collidable[g] && group[g] != 0 {
                margin
            } else {
                0.0
            };
        }
        for (g, m) in model.geom_gap_mut().iter_mut().enumerate() {
            if collidable[g] && group[g] != 0 {
                *m = 0.0;
            }
        }
        // The broadphase keeps a pair of bodies only when their bounding boxes, grown by each
        // body's margin, overlap, and only when the bodies' OR-ed bitmasks let them collide:
        // both are compiled from the geoms and must follow them, or a pair within the margin
        // whose bodies' boxes keep apart is never tested (the coupler 4.8 mm from a bin wall
        // went unreported with a 5 mm margin).
        let body_of = model.geom_bodyid().to_vec();
        let nbody = model.ffi().nbody as usize;
        let (mut margin_of, mut contype_of, mut conaffinity_of) =
            (vec![0.0f64; nbody], vec![0i32; nbody], vec![0i32; nbody]);
        for (g, &b) in body_of.iter().enumerate() {
            let b = b as usize;
            margin_of[b] = margin_of[b].max(model.geom_margin()[g] + model.geom_gap()[g]);
            contype_of[b] |= model.geom_contype()[g];
            conaffinity_of[b] |= model.geom_conaffinity()[g];
        }
        model.body_margin_mut().copy_from_slice(&margin_of);
        model.body_contype_mut().copy_from_slice(&contype_of);
        model.body_conaffinity_mut().copy_from_slice(&conaffinity_of);
        self.margin_pairs = (MarginPairs::new(self.data.model(), &group), Vec::new());
    }

    /// Takes a new snapshot from `data` (a running simulation of the same scene): every block's
    /// pose, every container's and obstacle's pose, the gripper's opening and the arm's joints
    /// (the reference for a held block's pose). A held block stays held, at its pose relative to
    /// the pinch in this snapshot.
    ///
    /// # Errors
    /// `data` not of this scene's model.
    pub fn sync(&mut self, data: &MjData<Arc<MjModel>>) -> Result<(), SimError> {
        if data.qpos().len() != self.data.qpos().len()
            || data.mocap_pos().len() != self.data.mocap_pos().len()
        {
            return Err(SimError::Scene(
                "the checker's snapshot is not of this scene's model".into(),
            ));
        }
        self.data.qpos_mut().copy_from_slice(data.qpos());
        self.data.mocap_pos_mut().copy_from_slice(data.mocap_pos());
        self.data.mocap_quat_mut().copy_from_slice(data.mocap_quat());
        let ids = &self.scene.ids;
        self.snapshot_q = ids.arm_qpos.map(|a| data.qpos()[a]);
        self.derived = None;
        self.margin_pairs.0.forget();
        if let Some(h) = self.held.clone() {
            self.hold(h.object)?;
        }
        Ok(())
    }

    /// Treats block `object` (its index in the scene) as held: from now on it moves rigidly with
    /// the pinch, at its pose relative to the pinch in the current snapshot, and is checked
    /// against the scene and the arm (not against the gripper holding it).
    ///
    /// # Errors
    /// `object` is not a block of the scene.
    pub fn hold(&mut self, object: usize) -> Result<(), SimError> {
        let qpos = self
            .scene
            .objects
            .get(object)
            .and_then(|o| o.qpos)
            .ok_or_else(|| SimError::Scene(format!("object {object} is not a block of the scene")))?;
        let p = &self.data.qpos()[qpos..qpos + 7];
        let block = Isometry3::from_parts(
            Translation3::new(p[0], p[1], p[2]),
            UnitQuaternion::from_quaternion(Quaternion::new(p[3], p[4], p[5], p[6])),
        );
        let in_pinch = fk(&self.snapshot_q).inverse() * block;
        let [g0, g1] = self.scene.objects[object].geoms;
        let m = self.data.model();
        let (pos, rbound) = (m.geom_pos(), m.geom_rbound());
        // Geom positions in the block's body frame: a point of a geom lies within its bounding
        // radius of its centre.
        let within_arms = (g0..g1).all(|g| {
            let c = in_pinch * nalgebra::Point3::new(pos[g][0], pos[g][1], pos[g][2]);
            c.coords.norm() + rbound[g] <= HELD_BLOCK_REACH
        });
        let regroup = self.held.as_ref().is_none_or(|h| h.object != object);
        self.held = Some(Held {
            object,
            qpos,
            in_pinch,
            within_arms,
        });
        self.derived = None;
        self.margin_pairs.0.forget();
        if regroup {
            self.rebuild_model();
        }
        Ok(())
    }

    /// Lets go of a held block: it stays where the snapshot has it, as part of the scene.
    pub fn release(&mut self) {
        if let Some(h) = self.held.take() {
            // Back at its snapshot pose: the pose at the snapshot's arm joints.
            let pose = fk(&self.snapshot_q) * h.in_pinch;
            write_pose(self.data.qpos_mut(), h.qpos, &pose);
            self.derived = None;
            self.rebuild_model();
        }
    }

    /// The held block's scene index, if one is held.
    pub fn held(&self) -> Option<usize> {
        self.held.as_ref().map(|h| h.object)
    }

    /// The clearance margin, metres.
    pub fn margin(&self) -> f64 {
        self.margin
    }

    /// Sets the clearance margin, metres (0 to `MAX_MARGIN`).
    ///
    /// # Errors
    /// A margin out of range (the old one stays).
    pub fn set_margin(&mut self, margin: f64) -> Result<(), SimError> {
        if !(margin.is_finite() && (0.0..=MAX_MARGIN).contains(&margin)) {
            return Err(SimError::Scene(format!(
                "collision margin {margin} m: use a value in [0, {MAX_MARGIN}] metres"
            )));
        }
        if margin != self.margin {
            self.margin = margin;
            self.rebuild_model();
        }
        Ok(())
    }

    /// Poses the arm (and a held block) at `q` and runs MuJoCo's collision detection; the
    /// number of geom pairs that count (kept in `margin_pairs.1`): those that penetrate, and
    /// those whose distance (`mj_geomDistance`) is under the margin.
    ///
    /// A contact MuJoCo reports within the margin carries its collider's estimate of the gap,
    /// which can be under the distance (a box–box pair's separation along one axis where the
    /// boxes pass edge by edge): each such pair is measured once, so the checker's "closer than
    /// the margin" is the same as the screen's and the spare's.
    fn detect(&mut self, q: &[f64; 6]) -> usize {
        self.detect_pose(q);
        self.data.collision();
        let margin = self.margin;
        let mut near: Vec<(usize, usize, f64)> = Vec::new();
        let mut measured: Vec<(usize, usize)> = Vec::new();
        let reported: Vec<(usize, usize, f64)> = self
            .data
            .contact()
            .iter()
            .filter(|c| c.dist < margin)
            .map(|c| {
                let (g1, g2) = (c.geom[0] as usize, c.geom[1] as usize);
                (g1.min(g2), g1.max(g2), c.dist)
            })
            .collect();
        for (a, b, dist) in reported {
            if dist < 0.0 {
                match near.iter_mut().find(|n| (n.0, n.1) == (a, b)) {
                    Some(n) => n.2 = n.2.min(dist),
                    None => near.push((a, b, dist)),
                }
                continue;
            }
            if measured.contains(&(a, b)) || near.iter().any(|n| (n.0, n.1) == (a, b)) {
                continue;
            }
            measured.push((a, b));
            let d = self.data.geom_distance(a, b, margin, None);
            if d < margin {
                near.push((a, b, d));
            }
        }
        near.extend(self.margin_pairs.0.missing(&mut self.data));
        self.margin_pairs.1 = near;
        self.margin_pairs.1.len()
    }

    /// The least distance at `q` (radians) of every pair the checker tests, metres, at most
    /// `wide`: `mj_geomDistance` of each pair that may be closer ([`MarginPairs::least`]); with
    /// how far the moving parts reach from each joint's axis there (metres, infinite when
    /// unknown: see [`SceneChecker::pose_moving`]). `None` when the margin is zero (no pairs
    /// listed).
    fn least_distance(&mut self, q: &[f64; 6], wide: f64) -> Option<(f64, [f64; 6])> {
        if self.margin_pairs.0.is_empty() {
            return None;
        }
        let reach = self.pose_moving(q);
        // The screen's primitives, posed at `q` too where the moving geoms were posed from the
        // link frames, bound a pair before `mj_geomDistance`.
        let mut screen = self
            .derived
            .as_mut()
            .filter(|d| d.moving.is_some())
            .and_then(|d| d.screen.as_mut());
        let least = self
            .margin_pairs
            .0
            .least(&mut self.data, q, &UR5E_LEVER_ARMS, wide, |a, b| {
                screen
                    .as_mut()
                    .map_or(f64::NEG_INFINITY, |s| s.geom_clearance(a, b))
            });
        Some((least, reach))
    }

    /// Poses the arm (and a held block) at `q` with `mj_kinematics`.
    fn detect_pose(&mut self, q: &[f64; 6]) {
        let ids = self.scene.ids.arm_qpos;
        {
            let qpos = self.data.qpos_mut();
            for (i, &a) in ids.iter().enumerate() {
                qpos[a] = q[i];
            }
        }
        if let Some(h) = &self.held {
            let pose = fk(q) * h.in_pinch;
            let at = h.qpos;
            write_pose(self.data.qpos_mut(), at, &pose);
        }
        self.data.kinematics();
    }
}

fn write_pose(qpos: &mut [f64], at: usize, pose: &Isometry3<f64>) {
    let t = pose.translation.vector;
    let r = pose.rotation.quaternion();
    qpos[at..at + 7].copy_from_slice(&[t.x, t.y, t.z, r.w, r.i, r.j, r.k]);
}

impl CollisionChecker for SceneChecker {
    fn is_free(&mut self, q: &[f64; 6]) -> bool {
        if !q.iter().all(|v| v.is_finite()) {
            return false;
        }
        self.detect(q) == 0
    }

    fn collisions(&mut self, q: &[f64; 6]) -> Vec<Collision> {
        if !q.iter().all(|v| v.is_finite()) {
            return Vec::new();
        }
        self.detect(q);
        let mut out: Vec<Collision> = Vec::new();
        for (g1, g2, dist) in self.margin_pairs.1.clone() {
            // The moving part first (the higher arm group: nearer the tool).
            let (a, b) = if self.group_of(g1) >= self.group_of(g2) {
                (g1, g2)
            } else {
                (g2, g1)
            };
            let (a, b) = (self.labels[a].clone(), self.labels[b].clone());
            match out.iter_mut().find(|o| o.a == a && o.b == b) {
                Some(o) => o.distance = o.distance.min(dist),
                None => out.push(Collision { a, b, distance: dist }),
            }
        }
        out.sort_by(|x, y| x.distance.total_cmp(&y.distance));
        out
    }
}

impl FastChecks for SceneChecker {
    /// The `Screen`'s verdict (`Screen::classify`); `None` when the screen is off or the
    /// cell has geometry it cannot bound.
    fn screen(&mut self, q: &[f64; 6]) -> Option<bool> {
        if !self.screen_on || !q.iter().all(|v| v.is_finite()) {
            return None;
        }
        self.screen_model()?.classify(q)
    }

    /// The `Screen`'s verdict and spare clearance (`Screen::free_spare`), settled where the
    /// screen cannot tell by measuring its undecided pairs alone with `mj_geomDistance` (the
    /// moving geoms posed from the arm's link frames, `sim::chain::MovingGeoms`): blocked when
    /// one is closer than the margin, else free with their exact clearances in the spare. Every other
    /// pair keeps the margin by the screen's bound, so the verdict is the one a full MuJoCo pass
    /// gives (up to MuJoCo's own tolerances, about 1e-6 m), at a few pairs' cost instead of
    /// the whole cell's. With a held block beyond `HELD_BLOCK_REACH` of the pinch, the
    /// screen's verdict alone.
    fn screen_spare(&mut self, q: &[f64; 6], caps: &JointSpare) -> (Option<bool>, JointSpare) {
        if !self.screen_on || !q.iter().all(|v| v.is_finite()) {
            return (None, JointSpare::NONE);
        }
        if !self.spare_covered() {
            return (self.screen(q), JointSpare::NONE);
        }
        self.derive();
        let Some(Derived {
            screen: Some(screen),
            moving: Some(moving),
        }) = self.derived.as_mut()
        else {
            return (None, JointSpare::NONE);
        };
        let (verdict, mut spare) = screen.free_spare(q, caps);
        if verdict.is_some() {
            return (verdict, spare);
        }
        // The pairs the screen cannot decide, measured exactly: a contact counts below the
        // checker's margin, and MuJoCo reports none beyond the pair's own.
        moving.pose(q, &mut self.data);
        for u in screen.undecided() {
            let counts = self.margin.min(u.gap - PAD);
            let wanted = u.range.map_or(0.0, |r| caps.get(r.first, r.last));
            let d = self
                .data
                .geom_distance(u.geoms.0, u.geoms.1, u.gap + u.kappa * wanted, None);
            if d < counts {
                return (Some(false), JointSpare::NONE);
            }
            if let Some(r) = u.range {
                spare.tighten(r.first, r.last, (d - u.gap) / u.kappa);
            }
        }
        (Some(true), spare)
    }

    /// The least distance of the tested pairs (`least_distance`) up to `cap` metres beyond the
    /// margin, less the margin and `SPARE_TOLERANCE`, the same for every joint range; `None`
    /// when a pair is closer than that, and with a held block beyond `HELD_BLOCK_REACH` of the
    /// pinch (see the trait).
    fn exact_spare(&mut self, q: &[f64; 6], cap: f64) -> Option<JointSpare> {
        if !(q.iter().all(|v| v.is_finite()) && cap.is_finite() && cap > 0.0 && self.spare_covered()) {
            return None;
        }
        let wide = self.margin + cap.min(MAX_MARGIN);
        let (least, reach) = self.least_distance(q, wide)?;
        let spare = least - self.margin - SPARE_TOLERANCE;
        (spare >= 0.0).then(|| JointSpare::uniform(spare.min(cap)).with_reach(reach))
    }
}

impl SceneChecker {
    /// Turns the conservative screen on or off (on by default); off, the planner checks every
    /// configuration with MuJoCo alone, as it did before the screen existed.
    pub fn set_screen(&mut self, on: bool) {
        self.screen_on = on;
    }

    /// The screen of the current snapshot, built if needed; `None` when the cell has geometry it
    /// cannot bound.
    pub fn screen_model(&mut self) -> Option<&mut Screen> {
        self.derive().screen.as_mut()
    }

    /// What the checker derives from the current snapshot, built if needed.
    fn derive(&mut self) -> &mut Derived {
        if self.derived.is_none() {
            // Pose the private data at the snapshot's joints (a held block from the pinch).
            let q = self.snapshot_q;
            self.detect_pose(&q);
            let mut group = self.group.clone();
            if let Some(h) = &self.held {
                let [g0, g1] = self.scene.objects[h.object].geoms;
                for g in group.iter_mut().take(g1).skip(g0) {
                    *g = WRIST_3;
                }
            }
            let (bodies, joints) = self.arm_links;
            let chain = ArmChain::new(&self.data, bodies, joints);
            let screen = chain.as_ref().and_then(|chain| {
                Screen::build(&Build {
                    data: &self.data,
                    group: &group,
                    link_bodies: bodies,
                    chain,
                })
            });
            if screen.is_none() {
                tracing::debug!(target: "macrotree::plan", "no collision screen for this cell: MuJoCo checks every configuration");
            }
            let moving = chain.map(|chain| MovingGeoms::new(&self.data, chain, bodies, &group));
            self.derived = Some(Derived { screen, moving });
        }
        self.derived.as_mut().expect("derived above")
    }

    /// Poses the moving geoms at `q` (radians) for `mj_geomDistance`: from the arm's link
    /// frames ([`MovingGeoms`]), the screen's primitives with them ([`Screen::bound_at`]), or by
    /// `mj_kinematics` when the arm is not a chain. Returns how
    /// far the moving geoms reach from each joint's axis there, metres, through the screen's
    /// link spheres ([`Screen::reach`]); infinite when the cell has no screen.
    fn pose_moving(&mut self, q: &[f64; 6]) -> [f64; 6] {
        self.derive();
        match self.derived.as_mut() {
            Some(Derived {
                moving: Some(moving),
                screen,
            }) => {
                let frames = moving.frames(q);
                moving.pose_at(&frames, &mut self.data);
                screen.as_mut().map_or([f64::INFINITY; 6], |s| {
                    s.bound_at(&frames);
                    s.reach(&frames)
                })
            }
            _ => {
                self.detect_pose(q);
                [f64::INFINITY; 6]
            }
        }
    }

    fn group_of(&self, g: usize) -> u8 {
        match &self.held {
            Some(h)
                if (self.scene.objects[h.object].geoms[0]..self.scene.objects[h.object].geoms[1])
                    .contains(&g) =>
            {
                WRIST_3 + 1
            }
            _ => self.group[g],
        }
    }

    /// True when the planner's lever arms cover every moving part: no block held, or one within
    /// [`HELD_BLOCK_REACH`] of the pinch.
    fn spare_covered(&self) -> bool {
        self.held.as_ref().is_none_or(|h| h.within_arms)
    }

    /// The block's pose the checker uses at `q` if it is held (world frame), for tests and logs.
    pub fn held_pose(&self, q: &[f64; 6]) -> Option<Isometry3<f64>> {
        self.held.as_ref().map(|h| fk(q) * h.in_pinch)
    }
}

#[cfg(test)]
#[path = "collision_tests.rs"]
mod tests;
