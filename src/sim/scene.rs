//! Composing the task scene: our `assets/scene.xml` (floor, cube, bowl, light, camera, physics
//! options) with the **unmodified** Menagerie UR5e (prefix `ur5e/`) and Robotiq 2F-85 (prefix
//! `gripper/`, attached at `ur5e/attachment_site`) through MuJoCo's MjSpec API.
//!
//! The compiled model is kept in memory and shared (`Arc`); layouts are applied by writing the
//! cube's free joint and the bowl's mocap position, never by recompiling.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_editing::{Attach, MjSpec};

use super::error::SimError;

/// The task scene XML (without the robot), embedded at build time.
pub const SCENE_XML: &str = include_str!("../../assets/scene.xml");

/// Environment variable that points at a Menagerie checkout holding
/// `universal_robots_ur5e/` and `robotiq_2f85/`.
pub const MENAGERIE_ENV: &str = "MACROTREE_MENAGERIE";

/// The Menagerie folder to use: `$MACROTREE_MENAGERIE`, else `third_party/menagerie` of this
/// source tree (filled by `tools/bootstrap`).
pub fn menagerie_dir() -> PathBuf {
    match std::env::var_os(MENAGERIE_ENV) {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("third_party/menagerie"),
    }
}

pub use crate::motion::ARM_JOINTS;

/// Indices into the compiled model that the simulator reads every step.
#[derive(Debug, Clone)]
pub struct SceneIds {
    /// `qpos` address of each arm joint.
    pub arm_qpos: [usize; 6],
    /// `qvel` (dof) address of each arm joint.
    pub arm_dof: [usize; 6],
    /// Actuator id of each arm position servo.
    pub arm_act: [usize; 6],
    /// Actuator id of `gripper/fingers_actuator` (ctrl 0 = open … 255 = closed).
    pub gripper_act: usize,
    /// `qpos` address of the right driver joint (the gripper's closure, rad).
    pub gripper_driver_qpos: usize,
    /// `qvel` (dof) address of the right driver joint.
    pub gripper_driver_dof: usize,
    /// `qpos` address of the cube's free joint (x, y, z, qw, qx, qy, qz).
    pub cube_qpos: usize,
    /// `qvel` address of the cube's free joint (vx, vy, vz, wx, wy, wz).
    pub cube_dof: usize,
    /// Body id of the cube.
    pub cube_body: usize,
    /// Geom id of the cube.
    pub cube_geom: usize,
    /// Geom ids of the two left pad boxes.
    pub left_pads: [usize; 2],
    /// Geom ids of the two right pad boxes.
    pub right_pads: [usize; 2],
    /// Site id of the 2F-85 pinch point (the tool point).
    pub pinch_site: usize,
    /// Site id of the bowl target.
    pub bowl_target_site: usize,
    /// Mocap index of the bowl body.
    pub bowl_mocap: usize,
    /// Body id of the bowl.
    pub bowl_body: usize,
    /// First and one-past-last geom id that belong to the bowl.
    pub bowl_geoms: [usize; 2],
    /// Geom id of the floor.
    pub floor_geom: usize,
}

/// The compiled task scene, shareable between threads.
#[derive(Clone)]
pub struct Scene {
    /// The compiled MuJoCo model (UR5e + 2F-85 + cube + bowl).
    pub model: Arc<MjModel>,
    /// Ids looked up once at load time.
    pub ids: SceneIds,
    /// Position-servo gains (kp in N·m/rad, kv in N·m·s/rad) of each arm actuator.
    pub arm_gains: [(f64, f64); 6],
    /// Control range of each arm actuator, radians.
    pub arm_ctrlrange: [[f64; 2]; 6],
}

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scene")
            .field("ids", &self.ids)
            .finish_non_exhaustive()
    }
}

impl Scene {
    /// Loads and compiles the scene with the Menagerie models from [`menagerie_dir`].
    pub fn load() -> Result<Self, SimError> {
        Self::load_from(&menagerie_dir())
    }

    /// Loads and compiles the scene with the Menagerie models found in `menagerie`.
    pub fn load_from(menagerie: &Path) -> Result<Self, SimError> {
        let ur5e = menagerie.join("universal_robots_ur5e/ur5e.xml");
        let gripper = menagerie.join("robotiq_2f85/2f85.xml");
        for file in [&ur5e, &gripper] {
            if !file.is_file() {
                return Err(SimError::MissingAsset {
                    path: file.clone(),
                    help: format!(
                        "run tools/bootstrap to fetch the pinned Menagerie models, or point {MENAGERIE_ENV} at a Menagerie checkout"
                    ),
                });
            }
            if file.to_str().is_none_or(|s| s.contains('\0')) {
                return Err(SimError::Scene(format!(
                    "{} is not a valid UTF-8 path without NUL bytes",
                    file.display()
                )));
            }
        }
        let spec_err = |what: &str, e: MjEditError| SimError::Scene(format!("{what}: {e:?}"));
        let mut scene = MjSpec::from_xml_string(SCENE_XML).map_err(|e| spec_err("assets/scene.xml", e))?;
        let mut arm = MjSpec::from_xml(&ur5e).map_err(|e| spec_err("ur5e.xml", e))?;
        let mut hand = MjSpec::from_xml(&gripper).map_err(|e| spec_err("2f85.xml", e))?;
        scene
            .world_body_mut()
            .attach_by_deep_copy(&mut arm, "ur5e/", "")
            .map_err(|e| spec_err("attaching the UR5e", e))?;
        scene
            .site_mut("ur5e/attachment_site")
            .ok_or_else(|| SimError::Scene("ur5e/attachment_site not found in ur5e.xml".into()))?
            .attach_by_deep_copy(&mut hand, "gripper/", "")
            .map_err(|e| spec_err("attaching the 2F-85", e))?;
        let model = scene.compile().map_err(|e| spec_err("compiling the scene", e))?;
        let ids = SceneIds::lookup(&model)?;
        let gain = model.actuator_gainprm();
        let bias = model.actuator_biasprm();
        let range = model.actuator_ctrlrange();
        let arm_gains = ids.arm_act.map(|a| (gain[a][0], -bias[a][2]));
        let arm_ctrlrange = ids.arm_act.map(|a| range[a]);
        Ok(Self {
            model: Arc::new(model),
            ids,
            arm_gains,
            arm_ctrlrange,
        })
    }
}

impl SceneIds {
    fn lookup(m: &MjModel) -> Result<Self, SimError> {
        let id = |kind: MjtObjBase, name: &str| {
            m.name_to_id(kind, name)
                .ok_or_else(|| SimError::Scene(format!("the compiled scene has no {kind:?} named {name}")))
        };
        let jnt_qposadr = m.jnt_qposadr();
        let jnt_dofadr = m.jnt_dofadr();
        let mut arm_qpos = [0; 6];
        let mut arm_dof = [0; 6];
        let mut arm_act = [0; 6];
        for (i, name) in ARM_JOINTS.iter().enumerate() {
            let j = id(MjtObjBase::mjOBJ_JOINT, &format!("ur5e/{name}_joint"))?;
            arm_qpos[i] = jnt_qposadr[j] as usize;
            arm_dof[i] = jnt_dofadr[j] as usize;
            arm_act[i] = id(MjtObjBase::mjOBJ_ACTUATOR, &format!("ur5e/{name}"))?;
        }
        let cube_joint = id(MjtObjBase::mjOBJ_JOINT, "cube_freejoint")?;
        let bowl_body = id(MjtObjBase::mjOBJ_BODY, "bowl")?;
        let bowl_mocap = m.body_mocapid()[bowl_body];
        if bowl_mocap < 0 {
            return Err(SimError::Scene("the bowl body must be a mocap body".into()));
        }
        let geom_body = m.geom_bodyid();
        let bowl_first = geom_body.iter().position(|&b| b as usize == bowl_body);
        let bowl_count = geom_body.iter().filter(|&&b| b as usize == bowl_body).count();
        let bowl_first = bowl_first.ok_or_else(|| SimError::Scene("the bowl has no geoms".into()))?;
        Ok(Self {
            arm_qpos,
            arm_dof,
            arm_act,
            gripper_act: id(MjtObjBase::mjOBJ_ACTUATOR, "gripper/fingers_actuator")?,
            gripper_driver_qpos: jnt_qposadr[id(MjtObjBase::mjOBJ_JOINT, "gripper/right_driver_joint")?]
                as usize,
            gripper_driver_dof: jnt_dofadr[id(MjtObjBase::mjOBJ_JOINT, "gripper/right_driver_joint")?]
                as usize,
            cube_qpos: jnt_qposadr[cube_joint] as usize,
            cube_dof: jnt_dofadr[cube_joint] as usize,
            cube_body: id(MjtObjBase::mjOBJ_BODY, "cube")?,
            cube_geom: id(MjtObjBase::mjOBJ_GEOM, "cube")?,
            left_pads: [
                id(MjtObjBase::mjOBJ_GEOM, "gripper/left_pad1")?,
                id(MjtObjBase::mjOBJ_GEOM, "gripper/left_pad2")?,
            ],
            right_pads: [
                id(MjtObjBase::mjOBJ_GEOM, "gripper/right_pad1")?,
                id(MjtObjBase::mjOBJ_GEOM, "gripper/right_pad2")?,
            ],
            pinch_site: id(MjtObjBase::mjOBJ_SITE, "gripper/pinch")?,
            bowl_target_site: id(MjtObjBase::mjOBJ_SITE, "bowl_target")?,
            bowl_mocap: bowl_mocap as usize,
            bowl_body,
            bowl_geoms: [bowl_first, bowl_first + bowl_count],
            floor_geom: id(MjtObjBase::mjOBJ_GEOM, "floor")?,
        })
    }
}
