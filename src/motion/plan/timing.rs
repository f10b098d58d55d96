//! Timing: the smoothed path followed exactly, as fast as the per-joint speed and acceleration
//! limits allow, from rest to rest.
//!
//! The path is cut into cells of at most [`CELL`] radians of arc length. Each piece bounds the
//! path speed `ṡ` (joint-space radians per second): on a line with unit direction `u`,
//! `ṡ ≤ min_j v_j/|u_j|` and `|s̈| ≤ min_j a_j/|u_j|`; on a corner arc of radius `r` the speed is
//! constant (`s̈ = 0`) and `ṡ ≤ min_j min(v_j/w_j, √(a_j r / w_j))` with `w_j = √(x_j² + y_j²)`,
//! which bounds both the joint speed and the centripetal joint acceleration `|q''_j| ṡ²`. A
//! forward pass (accelerate as allowed) and a backward pass (brake as needed) over the cell
//! boundaries give a speed with constant acceleration inside each cell, so every limit holds
//! everywhere, not only at samples. The arm stops at the start, the end and every unblended corner.
//! With a tool speed (a carry's, for the held block), the speed at each cell boundary is also
//! capped so the pinch point moves at most that fast (by the pinch's displacement per radian of
//! path over the cell, through forward kinematics).

use super::blend::{Piece, Smoothed};
use crate::motion::trajectory::Trajectory;

use super::config::JointLimits;

/// Longest cell of the speed profile, radians of joint-space arc length.
pub const CELL: f64 = 0.01;

/// One cell: a stretch of one piece with constant path acceleration.
#[derive(Clone, Debug, PartialEq)]
struct Cell {
    piece: u32,
    /// Arc length into the piece where the cell starts, and its length, radians.
    s0: f64,
    ds: f64,
    /// Time at the cell's start, seconds; path speed at its ends, rad/s.
    t0: f64,
    v0: f64,
    v1: f64,
}

/// A planned motion: the smoothed path timed within the joint limits. Implements
/// [`Trajectory`], so the cell's trajectory tracking runs it like any other motion.
#[derive(Clone, Debug, PartialEq)]
pub struct PathTrajectory {
    pieces: Vec<Piece>,
    cells: Vec<Cell>,
    start: [f64; 6],
    end: [f64; 6],
    duration: f64,
    waypoints: Vec<[f64; 6]>,
}

fn caps(piece: &Piece, limits: &JointLimits) -> (f64, f64) {
    let (mut v, mut a) = (f64::INFINITY, f64::INFINITY);
    match piece {
        Piece::Line { dir, .. } => {
            for ((d, vl), al) in dir.iter().zip(&limits.velocity).zip(&limits.acceleration) {
                let u = d.abs();
                if u > 0.0 {
                    v = v.min(vl / u);
                    a = a.min(al / u);
                }
            }
        }
        Piece::Arc { x, y, r, .. } => {
            a = 0.0;
            for j in 0..6 {
                let w = x[j].hypot(y[j]);
                if w > 0.0 {
                    v = v
                        .min(limits.velocity[j] / w)
                        .min((limits.acceleration[j] * r / w).sqrt());
                }
            }
        }
    }
    (v, a)
}

/// Caps `cap` (the path speed at each cell boundary, rad/s) so the pinch point moves at most
/// `tool_speed` m/s: over each cell, the pinch's displacement per radian of path (the chord
/// between its ends, by forward kinematics) bounds the speed at both ends.
fn cap_tool_speed(pieces: &[Piece], cells: &[(u32, f64, f64, f64)], cap: &mut [f64], tool_speed: f64) {
    let pinch = |piece: u32, s: f64| {
        crate::motion::fk(&pieces[piece as usize].eval(s).0)
            .translation
            .vector
    };
    // The end of a cell is usually the next one's start: its pinch is computed once.
    let mut last: Option<(u32, f64, nalgebra::Vector3<f64>)> = None;
    for (k, &(piece, s0, ds, _)) in cells.iter().enumerate() {
        let start = match last {
            Some((p, s, at)) if p == piece && s.to_bits() == s0.to_bits() => at,
            _ => pinch(piece, s0),
        };
        let end = pinch(piece, s0 + ds);
        last = Some((piece, s0 + ds, end));
        let gain = (end - start).norm() / ds;
        if gain > 0.0 {
            let v = tool_speed / gain;
            cap[k] = cap[k].min(v);
            cap[k + 1] = cap[k + 1].min(v);
        }
    }
}

impl PathTrajectory {
    /// Times `smoothed` (the path through `waypoints`, radians) within `limits`, the pinch
    /// point at most `tool_speed` m/s (`f64::INFINITY`: no such bound).
    pub(crate) fn new(
        smoothed: Smoothed,
        waypoints: Vec<[f64; 6]>,
        limits: &JointLimits,
        tool_speed: f64,
    ) -> Self {
        let start = waypoints[0];
        let end = waypoints[waypoints.len() - 1];
        let pieces: Vec<Piece> = smoothed.pieces.iter().map(|(p, _)| p.clone()).collect();
        // Nodes at cell boundaries: speed cap; cells: piece, s0, ds, acceleration cap.
        let mut cap: Vec<f64> = vec![0.0];
        let mut cells: Vec<(u32, f64, f64, f64)> = Vec::new();
        for (pi, (piece, stop)) in smoothed.pieces.iter().enumerate() {
            let (v, a) = caps(piece, limits);
            let last = cap.len() - 1;
            cap[last] = if *stop || pi == 0 { 0.0 } else { cap[last].min(v) };
            let len = piece.len();
            let n = ((len / CELL).ceil() as usize).max(2);
            let ds = len / n as f64;
            for k in 0..n {
                cells.push((pi as u32, ds * k as f64, ds, a));
                cap.push(v);
            }
        }
        let last = cap.len() - 1;
        cap[last] = 0.0;
        if tool_speed.is_finite() {
            cap_tool_speed(&pieces, &cells, &mut cap, tool_speed);
        }
        // Forward then backward pass.
        let mut vel = cap.clone();
        vel[0] = 0.0;
        for (k, &(_, _, ds, a)) in cells.iter().enumerate() {
            vel[k + 1] = vel[k + 1].min((vel[k] * vel[k] + 2.0 * a * ds).sqrt());
        }
        for (k, &(_, _, ds, a)) in cells.iter().enumerate().rev() {
            vel[k] = vel[k].min((vel[k + 1] * vel[k + 1] + 2.0 * a * ds).sqrt());
        }
        let mut t = 0.0;
        let mut out = Vec::with_capacity(cells.len());
        for (k, &(piece, s0, ds, _)) in cells.iter().enumerate() {
            let (v0, v1) = (vel[k], vel[k + 1]);
            out.push(Cell {
                piece,
                s0,
                ds,
                t0: t,
                v0,
                v1,
            });
            if v0 + v1 > 0.0 {
                t += 2.0 * ds / (v0 + v1);
            }
        }
        Self {
            pieces,
            cells: out,
            start,
            end,
            duration: t,
            waypoints,
        }
    }

    /// The shortcut path's waypoints the trajectory passes by (it cuts their corners by at most
    /// the blend deviation), radians, start and goal included.
    pub fn waypoints(&self) -> &[[f64; 6]] {
        &self.waypoints
    }

    /// Start configuration, radians.
    pub fn start(&self) -> [f64; 6] {
        self.start
    }

    /// Joints (radians), velocities (rad/s) and accelerations (rad/s²) at time `t` seconds.
    pub fn sample_full(&self, t: f64) -> ([f64; 6], [f64; 6], [f64; 6]) {
        if self.cells.is_empty() || t >= self.duration {
            return (self.end, [0.0; 6], [0.0; 6]);
        }
        let t = t.max(0.0);
        let k = self.cells.partition_point(|c| c.t0 <= t).saturating_sub(1);
        let c = &self.cells[k];
        let acc = (c.v1 * c.v1 - c.v0 * c.v0) / (2.0 * c.ds);
        let tau = t - c.t0;
        let s = (c.v0 * tau + 0.5 * acc * tau * tau).clamp(0.0, c.ds);
        let sd = (c.v0 + acc * tau).max(0.0);
        let (q, d1, d2) = self.pieces[c.piece as usize].eval(c.s0 + s);
        let mut qd = [0.0; 6];
        let mut qdd = [0.0; 6];
        for j in 0..6 {
            qd[j] = d1[j] * sd;
            qdd[j] = d1[j] * acc + d2[j] * sd * sd;
        }
        (q, qd, qdd)
    }
}

impl Trajectory for PathTrajectory {
    fn sample(&self, t: f64) -> ([f64; 6], [f64; 6]) {
        let (q, qd, _) = self.sample_full(t);
        (q, qd)
    }
    fn duration(&self) -> f64 {
        self.duration
    }
    fn end(&self) -> [f64; 6] {
        self.end
    }
    fn name(&self) -> &'static str {
        "planned path"
    }
}
