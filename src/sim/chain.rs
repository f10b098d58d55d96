//! [`ArmChain`]: the six arm link frames at any joints, computed from the model's own body
//! offsets and joint axes (the same products as `mj_kinematics`, without posing the rest of the
//! cell); [`MovingGeoms`]: the geoms the arm moves, posed from those frames into an `MjData`.

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;
use nalgebra::{Matrix3, Quaternion, Unit, UnitQuaternion, Vector3};

/// A body's pose in the world: the rotation from its frame to the world's (MuJoCo's row-major
/// `xmat` read as a matrix) and its origin (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Rotation, body to world.
    pub rot: Matrix3<f64>,
    /// Origin, world frame (metres).
    pub pos: Vector3<f64>,
}

impl Frame {
    /// The pose of body `body` in `data` (posed by `mj_kinematics`).
    pub(crate) fn of_body<M: ModelType>(data: &MjData<M>, body: usize) -> Self {
        Self {
            rot: mat(&data.xmat()[body]),
            pos: Vector3::from(data.xpos()[body]),
        }
    }
}

/// A joint's axis in the world: a point on it and its unit direction (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct JointAxis {
    /// A point of the axis, world frame (metres).
    pub(crate) point: Vector3<f64>,
    /// The axis's unit direction, world frame.
    pub(crate) direction: Vector3<f64>,
}

/// A moving geom: fixed in its link's frame.
#[derive(Clone, Copy, Debug)]
struct LinkedGeom {
    /// MuJoCo geom id.
    geom: usize,
    /// The arm link (0..6) that carries it.
    link: usize,
    /// Its pose in the link's frame.
    in_link: Frame,
}

/// One arm link: its body's offset from its parent (rotation, translation, metres) and its
/// hinge (unit axis and anchor in the body frame, the joint's reference angle in radians).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Link {
    pub(crate) rot: Matrix3<f64>,
    pub(crate) pos: Vector3<f64>,
    pub(crate) axis: Vector3<f64>,
    pub(crate) anchor: Vector3<f64>,
    pub(crate) qpos0: f64,
    /// The hinge's axis when it is a coordinate axis of the body frame (index, and the sign
    /// of the turn), as for every UR5e joint: a turn then mixes two columns of the frame.
    coordinate: Option<(usize, f64)>,
}

impl Link {
    /// This link's frame from its parent's (`r`, `t`: rotation and origin, world) with the
    /// joint `angle` radians past its reference.
    #[inline]
    fn frame(&self, r: &mut Matrix3<f64>, t: &mut Vector3<f64>, angle: f64) {
        *t += *r * self.pos;
        if self.rot != Matrix3::identity() {
            *r *= self.rot;
        }
        match self.coordinate {
            Some((i, sign)) if self.anchor == Vector3::zeros() => {
                // r · R_i(angle): columns a and b turn into each other.
                let (s, c) = angle.sin_cos();
                let s = sign * s;
                let (a, b) = ((i + 1) % 3, (i + 2) % 3);
                let (ca, cb) = (r.column(a).into_owned(), r.column(b).into_owned());
                r.set_column(a, &(ca * c + cb * s));
                r.set_column(b, &(cb * c - ca * s));
            }
            _ => {
                let j = axis_angle(&self.axis, angle);
                // Rotation about the axis through the anchor: x ↦ anchor + J (x − anchor).
                *t += *r * (self.anchor - j * self.anchor);
                *r *= j;
            }
        }
    }
}

/// Rotation by `angle` radians about the unit `axis` (Rodrigues).
fn axis_angle(a: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    Matrix3::new(
        c + t * a.x * a.x,
        t * a.x * a.y - s * a.z,
        t * a.x * a.z + s * a.y,
        t * a.x * a.y + s * a.z,
        c + t * a.y * a.y,
        t * a.y * a.z - s * a.x,
        t * a.x * a.z - s * a.y,
        t * a.y * a.z + s * a.x,
        c + t * a.z * a.z,
    )
}

/// Rotation matrix of MuJoCo's row-major `xmat`.
pub(crate) fn mat(x: &[f64; 9]) -> Matrix3<f64> {
    Matrix3::new(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], x[8])
}

/// The six arm links as a kinematic chain from the first link's parent body.
#[derive(Clone, Debug)]
pub struct ArmChain {
    /// World pose of the first arm link's parent body.
    base: Frame,
    pub(crate) links: [Link; 6],
}

impl ArmChain {
    /// The chain of `link_bodies` (base to wrist 3, each the parent of the next) and their
    /// hinges `joints`, its base posed as in `data` (posed by `mj_kinematics`); `None` when the
    /// bodies are not a chain.
    pub(crate) fn new<M: ModelType>(
        data: &MjData<M>,
        link_bodies: [usize; 6],
        joints: [usize; 6],
    ) -> Option<Self> {
        let m = data.model();
        let parent = m.body_parentid();
        for k in 1..6 {
            if parent[link_bodies[k]] as usize != link_bodies[k - 1] {
                return None;
            }
        }
        let p0 = parent[link_bodies[0]] as usize;
        let base = Frame::of_body(data, p0);
        let links = std::array::from_fn(|k| {
            let (body, j) = (link_bodies[k], joints[k]);
            let (p, q) = (m.body_pos()[body], m.body_quat()[body]);
            let (ax, an) = (m.jnt_axis()[j], m.jnt_pos()[j]);
            let offset = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
            let axis = Unit::new_normalize(Vector3::new(ax[0], ax[1], ax[2])).into_inner();
            let coordinate = (0..3).find_map(|i| {
                let along = axis[i];
                let unit = along.abs() == 1.0 && (0..3).all(|k| k == i || axis[k] == 0.0);
                unit.then_some((i, along))
            });
            Link {
                rot: offset.to_rotation_matrix().into_inner(),
                pos: Vector3::new(p[0], p[1], p[2]),
                axis,
                anchor: Vector3::new(an[0], an[1], an[2]),
                qpos0: m.qpos0()[m.jnt_qposadr()[j] as usize],
                coordinate,
            }
        });
        Some(Self { base, links })
    }

    /// World poses of the six arm links at joints `q` (radians), as `mj_kinematics` computes
    /// them: parent pose · body offset · rotation about the joint axis through its anchor.
    pub fn link_poses(&self, q: &[f64; 6]) -> [Frame; 6] {
        let Frame { mut rot, mut pos } = self.base;
        std::array::from_fn(|k| {
            let l = &self.links[k];
            l.frame(&mut rot, &mut pos, q[k] - l.qpos0);
            Frame { rot, pos }
        })
    }

    /// The axis of joint `j` at the link frames `frames` ([`ArmChain::link_poses`]).
    #[inline]
    pub(crate) fn joint_axis(&self, frames: &[Frame; 6], j: usize) -> JointAxis {
        // The axis is fixed in link j's frame: through the anchor, along the axis.
        let Frame { rot, pos } = &frames[j];
        JointAxis {
            point: rot * self.links[j].anchor + pos,
            direction: rot * self.links[j].axis,
        }
    }
}

/// The collidable geoms the arm moves (every one of arm group 1..=6: on a link, the gripper at
/// its opening, a held block), each fixed in its link's frame, posed at any joints without
/// `mj_kinematics`: what `mj_geomDistance` reads of them is their world pose alone, and it is
/// asked of no other geom.
#[derive(Clone, Debug)]
pub(crate) struct MovingGeoms {
    chain: ArmChain,
    /// Each moving geom and where its link holds it.
    geoms: Vec<LinkedGeom>,
}

impl MovingGeoms {
    /// The moving collidable geoms of `data` (posed by `mj_kinematics` at any joints; a geom
    /// with a contact type or affinity), `group` giving each geom's arm group (0 fixed, `k` in
    /// 1..=6 moved by arm joint `k − 1`).
    pub(crate) fn new<M: ModelType>(
        data: &MjData<M>,
        chain: ArmChain,
        link_bodies: [usize; 6],
        group: &[u8],
    ) -> Self {
        let (ct, ca) = (data.model().geom_contype(), data.model().geom_conaffinity());
        let geoms = group
            .iter()
            .enumerate()
            .filter(|&(g, &k)| k != 0 && (ct[g] != 0 || ca[g] != 0))
            .map(|(g, &k)| {
                let link = k as usize - 1;
                let body = Frame::of_body(data, link_bodies[link]);
                let lr = body.rot.transpose();
                let (gr, gt) = (mat(&data.geom_xmat()[g]), Vector3::from(data.geom_xpos()[g]));
                LinkedGeom {
                    geom: g,
                    link,
                    in_link: Frame {
                        rot: lr * gr,
                        pos: lr * (gt - body.pos),
                    },
                }
            })
            .collect();
        Self { chain, geoms }
    }

    /// Writes the world pose of every moving geom at joints `q` (radians) into `data`'s
    /// `geom_xpos` and `geom_xmat`; nothing else of `data` changes.
    pub(crate) fn pose<M: ModelType>(&self, q: &[f64; 6], data: &mut MjData<M>) {
        self.pose_at(&self.frames(q), data);
    }

    /// The six link frames at joints `q` (radians).
    pub(crate) fn frames(&self, q: &[f64; 6]) -> [Frame; 6] {
        self.chain.link_poses(q)
    }

    /// [`MovingGeoms::pose`] at the link frames `frames` ([`MovingGeoms::frames`]).
    pub(crate) fn pose_at<M: ModelType>(&self, frames: &[Frame; 6], data: &mut MjData<M>) {
        for &LinkedGeom {
            geom: g,
            link,
            in_link,
        } in &self.geoms
        {
            let Frame { rot: r, pos: t } = &frames[link];
            let (x, p) = (r * in_link.rot, r * in_link.pos + t);
            data.geom_xpos_mut()[g] = [p.x, p.y, p.z];
            // `geom_xmat` is row-major.
            data.geom_xmat_mut()[g] = [
                x[(0, 0)],
                x[(0, 1)],
                x[(0, 2)],
                x[(1, 0)],
                x[(1, 1)],
                x[(1, 2)],
                x[(2, 0)],
                x[(2, 1)],
                x[(2, 2)],
            ];
        }
    }
}
