//! Hand-built worlds for unit tests.

use std::sync::Arc;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use crate::scene::SceneSpec;
use crate::world::{ObjectState, World};

/// A still object at `pos`.
pub fn still(pos: Vector3<f64>) -> ObjectState {
    ObjectState {
        pos,
        quat: UnitQuaternion::identity(),
        linvel: Vector3::zeros(),
        angvel: Vector3::zeros(),
        left_pad_contact: false,
        right_pad_contact: false,
    }
}

/// Half the edge of the cube of the `cube_bowl` scene, metres.
pub const HALF: f64 = 0.022;

/// A cube resting on the table at (0.45, −0.18), open gripper far above it, bowl at (0.45, 0.08)
/// (the built-in `cube_bowl` scene: `objects[0]` is the cube, `objects[1]` the bowl).
pub fn resting() -> World {
    World {
        time: 0.0,
        arm_q: [0.0; 6],
        arm_qd: [0.0; 6],
        arm_cmd: [0.0; 6],
        gripper_width: 0.085,
        gripper_speed: 0.0,
        pinch_pos: Vector3::new(0.45, -0.18, 0.3),
        pinch_rot: Matrix3::identity(),
        left_pad_pos: Vector3::new(0.40, -0.18, 0.3),
        right_pad_pos: Vector3::new(0.50, -0.18, 0.3),
        home_q: [0.0; 6],
        scene: Arc::new(SceneSpec::builtin()),
        objects: vec![
            still(Vector3::new(0.45, -0.18, HALF)),
            still(Vector3::new(0.45, 0.08, 0.0)),
        ],
        touches: Vec::new(),
    }
}

/// The same cube held between the pads 10 cm above the table.
pub fn held() -> World {
    let mut w = resting();
    w.objects[0].pos = Vector3::new(0.45, -0.18, 0.10 + HALF);
    w.left_pad_pos = Vector3::new(0.45 - HALF - 0.004, -0.18, 0.125);
    w.right_pad_pos = Vector3::new(0.45 + HALF + 0.004, -0.18, 0.125);
    w.gripper_width = 2.0 * HALF;
    w.objects[0].left_pad_contact = true;
    w.objects[0].right_pad_contact = true;
    w
}

/// Two blocks `a` (at (0.40, −0.10)) and `b` (at (0.40, 0.10)), resting, with `goal`.
pub fn two_blocks(goal: &str) -> World {
    let mut w = resting();
    w.scene = Arc::new(
        SceneSpec::from_str(
            &format!(
                "objects:\n  a: {{block: {{size: 0.044}}, pose: [0.40, -0.10]}}\n  b: {{block: {{size: 0.044}}, pose: [0.40, 0.10]}}\ngoal:\n{goal}"
            ),
            "two.yaml",
        )
        .unwrap(),
    );
    w.objects[0].pos = Vector3::new(0.40, -0.10, HALF);
    w.objects[1].pos = Vector3::new(0.40, 0.10, HALF);
    w
}
