//! The cell's MjSpec before compiling: the task scene's MJCF with the unmodified Menagerie UR5e
//! (prefix [`ARM_PREFIX`]) and Robotiq 2F-85 attached and the [`WRIST_CAMERA`] added — what both
//! the cell's model and its collision model ([`super::collision_model`]) are compiled from.

use std::path::Path;

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_editing::{Attach, MjSpec};

use super::error::SimError;

/// The prefix of every name the UR5e brings into a cell's model (`ur5e/wrist_1_link`).
pub const ARM_PREFIX: &str = "ur5e/";

/// A [`SimError::Scene`] for a failed MjSpec step.
pub(super) fn spec_err(what: &str, e: MjEditError) -> SimError {
    SimError::Scene(format!("{what}: {e:?}"))
}

/// The cell's specification: `xml` with the UR5e and the 2F-85 attached and the wrist camera
/// added, not yet compiled.
pub(super) fn cell_spec(xml: &str, ur5e: &Path, gripper: &Path) -> Result<MjSpec, SimError> {
    let mut scene = MjSpec::from_xml_string(xml).map_err(|e| spec_err("the scene's MJCF", e))?;
    let mut arm = MjSpec::from_xml(ur5e).map_err(|e| spec_err("ur5e.xml", e))?;
    let mut hand = MjSpec::from_xml(gripper).map_err(|e| spec_err("2f85.xml", e))?;
    scene
        .world_body_mut()
        .attach_by_deep_copy(&mut arm, ARM_PREFIX, "")
        .map_err(|e| spec_err("attaching the UR5e", e))?;
    scene
        .site_mut("ur5e/attachment_site")
        .ok_or_else(|| SimError::Scene("ur5e/attachment_site not found in ur5e.xml".into()))?
        .attach_by_deep_copy(&mut hand, "gripper/", "")
        .map_err(|e| spec_err("attaching the 2F-85", e))?;
    add_wrist_camera(&mut scene)?;
    Ok(scene)
}

/// Name of the wrist camera on the 2F-85's base, added when the scene is compiled.
pub const WRIST_CAMERA: &str = "wrist";

/// Adds the camera [`WRIST_CAMERA`] to the attached 2F-85's `gripper/base` body (Menagerie's
/// file stays unmodified): 10 cm to the side of the tool axis (across the fingers' travel),
/// 2 cm below the base, looking down the fingers at a point 1.5 cm past the pinch point, fingers
/// opening left–right in the image, 75° vertical field of view. Cameras do not take part in the
/// physics.
fn add_wrist_camera(spec: &mut MjSpec) -> Result<(), SimError> {
    use nalgebra::{Rotation3, UnitQuaternion, Vector3};
    // In the base's frame z runs from the base to the pinch point (0, 0, 0.145) and the fingers
    // open along y; a MuJoCo camera looks along its -z with +y up in the image.
    let pos = Vector3::new(0.1, 0.0, 0.02);
    let look_at = Vector3::new(0.0, 0.0, 0.16);
    let z = (pos - look_at).normalize();
    let x = Vector3::y();
    let y = z.cross(&x);
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_basis_unchecked(&[x, y, z]));
    spec.body_mut("gripper/base")
        .ok_or_else(|| SimError::Scene("gripper/base not found in 2f85.xml".into()))?
        .add_camera()
        .with_name(WRIST_CAMERA)
        .with_pos([pos.x, pos.y, pos.z])
        .with_quat([q.w, q.i, q.j, q.k])
        .with_fovy(75.0);
    Ok(())
}
