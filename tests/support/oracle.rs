//! An independent judge of physics outcomes for tests, built only from the compiled MuJoCo model
//! and MuJoCo's own state — never from `macrotree::world` predicates or hand-copied constants:
//!
//! - "block B is in container C": MuJoCo reports a contact between B's geom and C's floor geom;
//!   B's centre is within ±1 mm of the floor's top face + B's half-size; B's centre is at most
//!   (inner half-width − B's half-size) from C's centre along each of C's axes, the inner
//!   half-width being read off the wall geoms (their inner faces); and B is at rest after an extra
//!   settling period (the controls held as they are).
//! - "MuJoCo raised no warning": every one of MuJoCo's warning counters (`mjData.warning`) is 0.

#![allow(dead_code)]

use macrotree::scene::OBJECT_PREFIX;
use macrotree::sim::Sim;
use mujoco_rs::prelude::*;

/// Largest distance of the block's centre from floor top + half-size, metres.
pub const HEIGHT_TOLERANCE: f64 = 0.001;
/// Extra simulated time the oracle lets the cell settle before judging, seconds.
pub const SETTLE_S: f64 = 0.5;
/// At rest: the block's centre moves at most this far over the last half of the settling, metres.
pub const REST_DRIFT: f64 = 0.0005;

/// What the oracle measured for one block and one container.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// MuJoCo lists a contact between the block and the container's floor.
    pub floor_contact: bool,
    /// Block centre height − (floor top + half-size), metres.
    pub height_error: f64,
    /// Block centre − container centre, along the container's x and y axes, metres.
    pub offset: [f64; 2],
    /// Largest allowed |offset| along each axis: inner half-width − half-size, metres.
    pub allowed: [f64; 2],
    /// How far the block moved over the last half of the settling period, metres.
    pub drift: f64,
}

impl Verdict {
    /// Every criterion holds.
    pub fn inside(&self) -> bool {
        self.floor_contact
            && self.height_error.abs() <= HEIGHT_TOLERANCE
            && self.offset[0].abs() <= self.allowed[0]
            && self.offset[1].abs() <= self.allowed[1]
            && self.drift <= REST_DRIFT
    }
}

fn geom(sim: &Sim, name: &str) -> usize {
    sim.scene()
        .model
        .name_to_id(MjtObjBase::mjOBJ_GEOM, name)
        .unwrap_or_else(|| panic!("the compiled model has no geom `{name}`"))
}

/// The block geom's centre, world frame, metres.
fn centre(sim: &Sim, g: usize) -> [f64; 3] {
    sim.data().geom_xpos()[g]
}

/// Judges block `block` in container `container` (scene object names) as they are now, with
/// `drift` supplied by the caller.
fn judge_now(sim: &Sim, block: &str, container: &str, drift: f64) -> Verdict {
    let m = &sim.scene().model;
    let b = geom(sim, &format!("{OBJECT_PREFIX}{block}"));
    let floor = geom(sim, &format!("{OBJECT_PREFIX}{container}/floor"));
    let wall_x = geom(sim, &format!("{OBJECT_PREFIX}{container}/wall_px"));
    let wall_y = geom(sim, &format!("{OBJECT_PREFIX}{container}/wall_py"));
    let size = m.geom_size();
    let pos = m.geom_pos();
    assert_eq!(
        m.geom_type()[b],
        MjtGeomBase::mjGEOM_BOX,
        "`{block}` is not a box"
    );
    let half = size[b][0];
    // Inner faces of the walls, in the container's frame.
    let inner = [pos[wall_x][0] - size[wall_x][0], pos[wall_y][1] - size[wall_y][1]];
    let d = sim.data();
    let p = centre(sim, b);
    let f = d.geom_xpos()[floor];
    let r = d.geom_xmat()[floor]; // row-major: column k is the floor's axis k in world
    let rel = [p[0] - f[0], p[1] - f[1], p[2] - f[2]];
    let along = |k: usize| rel[0] * r[k] + rel[1] * r[3 + k] + rel[2] * r[6 + k];
    let floor_top = f[2] + size[floor][2];
    let floor_contact = d.contact().iter().any(|c| {
        let (g0, g1) = (c.geom[0] as usize, c.geom[1] as usize);
        (g0 == b && g1 == floor) || (g0 == floor && g1 == b)
    });
    Verdict {
        floor_contact,
        height_error: p[2] - (floor_top + half),
        offset: [along(0), along(1)],
        allowed: [inner[0] - half, inner[1] - half],
        drift,
    }
}

/// Lets the cell settle for [`SETTLE_S`] with the controls as they are, then judges whether
/// `block` rests in `container`. Asserts that MuJoCo raised no warning while settling.
pub fn settle_and_judge(sim: &mut Sim, block: &str, container: &str) -> Verdict {
    let b = geom(sim, &format!("{OBJECT_PREFIX}{block}"));
    let steps = (SETTLE_S / macrotree::sim::TIMESTEP).round() as usize;
    let mut mid = centre(sim, b);
    for k in 0..steps {
        sim.step();
        if k + 1 == steps / 2 {
            mid = centre(sim, b);
        }
    }
    assert_no_warning(sim, "while the oracle let the cell settle");
    let end = centre(sim, b);
    let drift = ((end[0] - mid[0]).powi(2) + (end[1] - mid[1]).powi(2) + (end[2] - mid[2]).powi(2)).sqrt();
    judge_now(sim, block, container, drift)
}

/// Asserts `block` rests in `container` (see [`settle_and_judge`]), naming `what` on failure.
pub fn assert_in(sim: &mut Sim, block: &str, container: &str, what: &str) -> Verdict {
    let v = settle_and_judge(sim, block, container);
    assert!(
        v.inside(),
        "{what}: the oracle does not see `{block}` in `{container}`: {v:?}"
    );
    v
}

/// Asserts that MuJoCo raised no warning (any kind) since the simulation's last reset.
pub fn assert_no_warning(sim: &Sim, what: &str) {
    let w = &sim.data().ffi().warning;
    let raised: Vec<String> = w
        .iter()
        .enumerate()
        .filter(|(_, s)| s.number > 0)
        .map(|(k, s)| format!("warning kind {k} ×{} (last info {})", s.number, s.lastinfo))
        .collect();
    assert!(raised.is_empty(), "{what}: MuJoCo raised {}", raised.join(", "));
}
