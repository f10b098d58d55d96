//! `carry`: lift the held block, move it above the goal at a height that clears everything under
//! its path, lower it onto the goal (a container's floor, the top of another block, or a point).
//! `place` runs the same controller ([`Carry::placing`]): to a point on whatever surface is under
//! it, turned to a yaw, lowered by the block's own size.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};

use super::cell::Cell;
use super::clearance::{
    MARGIN, SetDown, blocks_inside, closing_axis_in_pinch, closing_in_world, release_opening, tip_above_block,
};
use super::macro_action::{Arrival, MacroAction, Progress};
use super::packing::Lookahead;
use super::planning::{check_motion, check_straight, describe};
use super::side_set_down::{held_from_side, refuse_side_set_down};
use super::targets::{resolve, segment_distance, target_object, target_spot};
use crate::failure::{Failure, FailureKind};
use crate::kinds::Carry as CarrySpec;
use crate::motion::{CartesianMove, JointMove, MotionLimits, Trajectory};
use crate::scene::ObjectKind;
use crate::world::World;
use crate::world::conditions::Tolerances;

/// Consecutive ticks without a grasp before the carry fails (filters single-step contact flicker).
const LOST_TICKS: u32 = 3;

/// How far the goal may have moved during the transfer before the transfer is re-planned to its
/// new place (a bowl slid aside), metres.
const GOAL_MOVED: f64 = 0.005;

/// Least lift (block centre, metres) a carry takes when a straight lift to its own height would
/// leave the arm's workspace: the lift ends below that, where the line is still reachable.
const MIN_LIFT: f64 = 0.05;

/// Bisection steps finding how high a straight lift stays reachable (0.15 m / 2¹⁰: under 0.2 mm).
const LIFT_BISECTIONS: u32 = 10;

/// How far in front of its place a block that goes under something is brought before it is
/// slid in, along the hand's horizontal approach, metres (the stand-off of a side grasp).
const INSERT_STAND_OFF: f64 = 0.12;

/// How far above its place a block that goes under something slides in, metres: it is lowered
/// this last bit straight down.
const INSERT_LIFT: f64 = 0.01;

/// Re-plans of the transfer allowed in one carry.
const MAX_REPLANS: u32 = 3;

/// Gap kept between the carried block's bottom and the top of anything it passes over, metres.
pub const CLEARANCE: f64 = 0.03;

/// Tallest object top the carry lifts over, metres above the table: a taller fixture (a column
/// 0.80 m high) would need a transfer height the arm cannot reach with the tool pointing down, so
/// the transfer stays at its own height and the planner takes the held block around it.
pub const MAX_LIFT_OVER: f64 = 0.40;

/// Reach of the closed fingers beyond the held block's faces, in the table plane, metres (the
/// 2F-85's fingertips are about 2 cm wide and the pads 8 mm thick).
pub const FINGER_MARGIN: f64 = 0.025;

/// Steps of the grid of candidate spots across a container's floor, each way (odd: the centre
/// is one of them).
const SPOT_GRID: i32 = 9;

/// Steps of the finer grid the packing look-ahead searches when the first choice leaves too
/// little room for the blocks still to come (odd; every point of the [`SPOT_GRID`] is on it).
const FINE_GRID: i32 = 17;

/// A spot the packing search scored: where (world, metres), the tool's turn (radians), and how
/// many blocks still to come fit after it, the walls' gap and the room (metres).
type PackedSpot = (Vector2<f64>, f64, (usize, f64, f64));

/// The carry's phases, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Lift,
    Transfer,
    /// A place under something (a shelf's upper board): the block slides in horizontally, just
    /// above its place, from [`INSERT_STAND_OFF`] in front of it.
    Insert,
    Lower,
}

impl Phase {
    fn name(self) -> &'static str {
        match self {
            Phase::Lift => "lift",
            Phase::Transfer => "transfer",
            Phase::Insert => "insert",
            Phase::Lower => "lower",
        }
    }
}

/// Executes a [`CarrySpec`].
///
/// Each phase is planned when it starts, from the world as it is then: the transfer and the
/// lowering aim at where the goal is *now*, and a transfer whose goal moved meanwhile is re-planned.
pub struct Carry {
    spec: CarrySpec,
    /// The held block (index into the world's objects).
    held: usize,
    /// Half the held block's edge, metres.
    half: f64,
    /// Pinch position minus block centre when the carry started (kept, so the block goes where
    /// the pinch is sent), metres.
    pinch_from_block: Vector3<f64>,
    /// Tool orientation kept during the carry.
    rotation: UnitQuaternion<f64>,
    phase: Phase,
    /// Block centre the current phase ends at, metres.
    phase_end: Vector3<f64>,
    replans: u32,
    goal_q: [f64; 6],
    arrival: Arrival,
    lost: u32,
    /// The fingers' closing axis in the pinch frame (unit).
    closing: Vector3<f64>,
    /// Height of the fingertips above the held block's centre, metres.
    tip: f64,
    /// A point target is set down on whatever is under it (a block, an obstacle, a container's
    /// floor, else the table), not at the point's own height (`place`).
    surface: bool,
    /// The yaw the block should have when set down, radians (`place`); `None`: as held.
    turn_to: Option<f64>,
    /// The spot chosen in the destination container, in the container's frame (kept for the
    /// whole carry, so a container that moves carries the spot with it), metres.
    spot_local: Option<Vector2<f64>>,
    /// The spot chosen in the container takes the tool turned by this much about the vertical
    /// through the block (radians): turned when the lift ends.
    spot_turn: f64,
    /// The object a spot's block rests on (its `on:`), by name; `None`: whatever is under it.
    support: Option<String>,
    /// The hand's horizontal approach (unit, world) when the place is under something and the
    /// block is slid in along it; `None`: set down from above.
    insert: Option<Vector3<f64>>,
}

impl Carry {
    /// A carry controller for `spec`.
    pub fn new(spec: CarrySpec) -> Self {
        Self {
            spec,
            held: 0,
            half: 0.0,
            pinch_from_block: Vector3::zeros(),
            rotation: UnitQuaternion::identity(),
            phase: Phase::Lift,
            phase_end: Vector3::zeros(),
            replans: 0,
            goal_q: [0.0; 6],
            lost: 0,
            arrival: Arrival::default(),
            closing: Vector3::y(),
            tip: 0.0,
            surface: false,
            turn_to: None,
            spot_local: None,
            spot_turn: 0.0,
            support: None,
            insert: None,
        }
    }

    /// The hand's horizontal approach when the block must slide in under something to reach
    /// `place` (block centre): an object other than the block and its support is over the place
    /// (within the fingers' reach) with its underside above the set-down block's top and below
    /// the transfer height `above_z` (block centre, metres). `Ok(None)` when the place is open
    /// from above; `Err` when it is not and the block is held from above (the hand cannot go
    /// under).
    fn under(&self, w: &World, place: &Vector3<f64>, above_z: f64) -> Result<Option<Vector3<f64>>, Failure> {
        let dest = self.destination(w);
        let reach = self.finger_reach();
        let over = (0..w.objects.len()).find(|&j| {
            j != self.held
                && Some(j) != dest
                && w.from_footprint(j, place).norm() <= reach
                && w.bottom(j) > place.z + self.half
                && w.bottom(j) < above_z + self.half
        });
        let Some(j) = over else {
            return Ok(None);
        };
        if !held_from_side(&self.rotation) {
            return Err(Failure::new(
                FailureKind::GoalInCollision,
                format!(
                    "the place is under `{}`, and a block held from above cannot be set down under it; grasp the block from the side (`reach: {{approach: side}}`) to slide it in",
                    w.name(j)
                ),
            ));
        }
        let axis = self.rotation * Vector3::z();
        Ok(Some(Vector3::new(axis.x, axis.y, 0.0).normalize()))
    }

    /// Where a block slid in under something starts, in front of `place` along `along`, and
    /// where the slide ends, above the place (block centres, metres).
    fn insert_path(place: &Vector3<f64>, along: &Vector3<f64>) -> [Vector3<f64>; 2] {
        let end = place + Vector3::new(0.0, 0.0, INSERT_LIFT);
        [end - along * INSERT_STAND_OFF, end]
    }

    /// The controller `place` runs: `spec.to` is a point whose height is ignored, the block is
    /// set down on the surface under it (`spec.place_height` above it; on the object named
    /// `on` when given), turned to `yaw` (radians, modulo a quarter turn; `None`: as held).
    pub fn placing(spec: CarrySpec, yaw: Option<f64>, on: Option<String>) -> Self {
        Self {
            surface: true,
            turn_to: yaw,
            support: on,
            ..Self::new(spec)
        }
    }

    /// The held block (valid once started).
    pub fn held(&self) -> usize {
        self.held
    }

    /// The hand's horizontal approach (unit, world) when the block was slid in under something
    /// (a release retreats back out along its opposite); `None` when it was set down from above.
    pub fn slid_in_along(&self) -> Option<Vector3<f64>> {
        self.insert
    }

    /// The set-down at block centre `centre` with the tool as it is planned now.
    fn set_down(&self, centre: Vector3<f64>) -> SetDown {
        self.set_down_turned(centre, 0)
    }

    /// The set-down at `centre` with the tool turned `k` quarter turns from its planned
    /// orientation.
    fn set_down_turned(&self, centre: Vector3<f64>, k: usize) -> SetDown {
        SetDown {
            centre,
            closing: closing_in_world(&self.turned(k).0, &self.closing),
            half: self.half,
            tip: self.tip,
            opening: release_opening(self.half),
        }
    }

    /// The object the carry goes to, if its target is one; for a `place` at a point, the
    /// object the block would come down on (the one with the highest support under the point).
    fn destination(&self, w: &World) -> Option<usize> {
        match (&self.spec.to, self.surface) {
            (crate::kinds::Target::Point(_), true) if self.support.is_some() => {
                self.support.as_deref().and_then(|n| w.index_of(n))
            }
            (crate::kinds::Target::Point(p), true) => {
                let at = Vector3::new(p[0], p[1], 0.0);
                (0..w.objects.len())
                    .filter(|&j| j != self.held && w.from_footprint(j, &at).norm() == 0.0)
                    .max_by(|&a, &b| w.support_height(a).total_cmp(&w.support_height(b)))
            }
            _ => target_object(&self.spec.to, w),
        }
    }

    /// How far the held block's corners and the closed fingers reach from its centre in the table
    /// plane, metres.
    fn finger_reach(&self) -> f64 {
        self.half * std::f64::consts::SQRT_2 + FINGER_MARGIN
    }

    /// Where the block's centre ends up when placed at the goal as it is now, metres: on a
    /// container's floor, on top of a block, or at a point, `place_height` above it.
    fn place(&mut self, w: &World) -> Result<Vector3<f64>, Failure> {
        let goal = resolve(&self.spec.to, w)?;
        let dest = self.destination(w);
        let base = match dest {
            Some(d) if w.spec(d).kind() == ObjectKind::Block => w.top(d),
            Some(d) if self.surface => w.support_height(d),
            None if self.surface => 0.0,
            _ => goal.z,
        };
        let z = base + self.spec.place_height + self.half;
        let spot = match dest {
            Some(c) if w.spec(c).kind() == ObjectKind::Container && !self.surface => {
                let local = match self.spot_local {
                    Some(l) => l,
                    None => {
                        let (p, turn) = self.free_spot(w, c, z)?;
                        self.spot_turn = turn;
                        let l = w.local_xy(c, &Vector3::new(p.x, p.y, 0.0));
                        self.spot_local = Some(l);
                        l
                    }
                };
                let (s, co) = crate::world::angles::yaw_of(&w.objects[c].quat).sin_cos();
                w.objects[c].pos.xy() + Vector2::new(co * local.x - s * local.y, s * local.x + co * local.y)
            }
            _ => goal.xy(),
        };
        Ok(Vector3::new(spot.x, spot.y, z))
    }

    /// Where in container `c` to set the block down, its centre at height `z`: of a grid over
    /// the container's floor, the spots whose set-down the descent check accepts (the same
    /// [`SetDown::obstruction`] as [`Self::check_descent`], the fingers' closing axis as the tool
    /// is now), preferring those where the fingers fully open (as a `release` opens them by
    /// default) clear its walls by [`MARGIN`] (or come nearest to), and among them the one with
    /// the most room to the blocks already in it (ties go to the spot nearest the centre; the
    /// centre when it is empty), world frame, metres; with the tool as held, else turned about
    /// the vertical by the angle returned (radians).
    ///
    /// That spot stands unless it leaves too little room: when the scene's goal sends more
    /// blocks into the container, the spot must leave room for as many of them as any spot
    /// does ([`Lookahead::capacity`]: bottom-left fill of the blocks still to come, largest
    /// first); otherwise the spot, of a finer grid and any of the turns, that leaves room for
    /// the most of them is taken (ties as above). A container with no spot that takes the block
    /// any way fails with `container_full`, before anything moves.
    fn free_spot(&self, w: &World, c: usize, z: f64) -> Result<(Vector2<f64>, f64), Failure> {
        let centre = w.objects[c].pos.xy();
        let crate::scene::Shape::Container { .. } = w.spec(c).shape else {
            return Ok((centre, 0.0));
        };
        let inside = blocks_inside(w, c, self.held);
        let candidates = self.grid(w, c, SPOT_GRID);
        // The tool as held first. Only when no spot takes it so (a deep bin, where the opened
        // hand reaches far along its closing axis), the block goes square to the container, its
        // fingers along one of the container's axes, then the other, then a quarter turn from
        // the hold.
        let closing = self.set_down(Vector3::zeros()).closing;
        let bin_x = crate::world::angles::yaw_of(&w.objects[c].quat);
        let square = crate::world::angles::fold_quarter_turn(bin_x - closing.y.atan2(closing.x));
        let quarter = std::f64::consts::FRAC_PI_2;
        let turns = [0.0, square, square + quarter, quarter];
        let first = turns.iter().find_map(|&turn| {
            self.best_spot(w, c, z, &candidates, &inside, turn)
                .map(|p| (p, turn))
        });
        let floor = z - self.spec.place_height - self.half;
        let ahead = Lookahead::new(
            w,
            c,
            self.held,
            floor,
            self.spec.place_height,
            self.tip,
            FINE_GRID,
        );
        let room_after = |p: Vector2<f64>, turn: f64| {
            let down = SetDown {
                closing: nalgebra::Rotation2::new(turn) * closing,
                ..self.set_down(Vector3::new(p.x, p.y, z))
            };
            ahead.capacity(ahead.planned(&down))
        };
        let kept = first.map(|(p, turn)| (p, turn, room_after(p, turn)));
        if kept.is_some_and(|(_, _, n)| n == ahead.total()) {
            return Ok(first.unwrap_or((centre, 0.0)));
        }
        // Packing: the spot (finer grid, any turn) that leaves room for the most blocks still to
        // come; the first turn, then the walls and the room, as above, on ties.
        let fine = self.grid(w, c, FINE_GRID);
        let mut best: Option<PackedSpot> = None;
        for &turn in &turns {
            for &p in &fine {
                let Some((walls, room)) = self.spot_score(w, c, z, p, &inside, turn) else {
                    continue;
                };
                let n = room_after(p, turn);
                let better = best.is_none_or(|(_, _, (bn, bw, br))| {
                    n > bn || (n == bn && (walls > bw + 1e-9 || (walls > bw - 1e-9 && room > br + 1e-9)))
                });
                if better {
                    best = Some((p, turn, (n, walls, room)));
                }
            }
            if best.is_some_and(|(_, _, (n, _, _))| n == ahead.total()) || ahead.spent() {
                break;
            }
        }
        tracing::debug!(target: "macrotree::actions", "carry: packing look-ahead made {} spot tests", ahead.work());
        match (kept, best) {
            (Some((p, turn, n)), Some((_, _, (bn, _, _)))) if n >= bn => return Ok((p, turn)),
            (_, Some((p, turn, (n, _, _)))) => {
                tracing::debug!(target: "macrotree::actions", "carry: spot ({:.3}, {:.3}) turned {:.0}° leaves room for {n} of the {} blocks still to come", p.x, p.y, turn.to_degrees(), ahead.total());
                return Ok((p, turn));
            }
            (Some((p, turn, _)), None) => return Ok((p, turn)),
            (None, None) => {}
        }
        let names: Vec<&str> = inside.iter().map(|&j| w.name(j)).collect();
        let holding = if names.is_empty() {
            "it is empty, but too small for the block and the opened fingers".to_string()
        } else {
            format!("it holds {}", names.join(", "))
        };
        Err(Failure::new(
            FailureKind::ContainerFull,
            format!(
                "{} cannot take {}: no spot on its floor where the block and the fingers (opened to {:.0} mm, turned any way) clear its walls and the blocks in it; {holding}",
                w.name(c),
                w.name(self.held),
                self.set_down(Vector3::zeros()).opening * 1e3
            ),
        ))
    }

    /// A `steps` × `steps` grid of spots for the held block's centre over container `c`'s floor
    /// (`steps` odd: the centre is one of them), world frame, nearest the centre first, metres.
    fn grid(&self, w: &World, c: usize, steps: i32) -> Vec<Vector2<f64>> {
        let centre = w.objects[c].pos.xy();
        let crate::scene::Shape::Container { inner_half, .. } = w.spec(c).shape else {
            return vec![centre];
        };
        let usable = inner_half.map(|h| (h - self.half).max(0.0));
        let (s, co) = crate::world::angles::yaw_of(&w.objects[c].quat).sin_cos();
        let n = steps / 2;
        let mut candidates: Vec<Vector2<f64>> = Vec::with_capacity((steps * steps) as usize);
        for i in -n..=n {
            for k in -n..=n {
                let (lx, ly) = (
                    usable[0] * f64::from(i) / f64::from(n),
                    usable[1] * f64::from(k) / f64::from(n),
                );
                candidates.push(centre + Vector2::new(co * lx - s * ly, s * lx + co * ly));
            }
        }
        candidates.sort_by(|a, b| (a - centre).norm().total_cmp(&(b - centre).norm()));
        candidates
    }

    /// Of `candidates` in container `c` (block centre at height `z`), the spot [`Self::free_spot`]
    /// prefers with the tool turned by `turn` radians about the vertical; `None` when the
    /// descent check refuses all.
    fn best_spot(
        &self,
        w: &World,
        c: usize,
        z: f64,
        candidates: &[Vector2<f64>],
        inside: &[usize],
        turn: f64,
    ) -> Option<Vector2<f64>> {
        let mut best: Option<(Vector2<f64>, (f64, f64))> = None;
        for &p in candidates {
            let Some((walls, room)) = self.spot_score(w, c, z, p, inside, turn) else {
                continue;
            };
            let better =
                best.is_none_or(|(_, (bw, br))| walls > bw + 1e-9 || (walls > bw - 1e-9 && room > br + 1e-9));
            if better {
                best = Some((p, (walls, room)));
            }
        }
        best.map(|(p, _)| p)
    }

    /// How spot `p` of container `c` (block centre at height `z`, the tool turned by `turn`
    /// radians) suits the set-down: `None` when the descent check refuses it; else how far the
    /// fully opened fingers stay inside the walls (capped at [`MARGIN`]) and the room to the
    /// blocks `inside`, metres.
    fn spot_score(
        &self,
        w: &World,
        c: usize,
        z: f64,
        p: Vector2<f64>,
        inside: &[usize],
        turn: f64,
    ) -> Option<(f64, f64)> {
        let down = SetDown {
            closing: nalgebra::Rotation2::new(turn) * self.set_down(Vector3::zeros()).closing,
            ..self.set_down(Vector3::new(p.x, p.y, z))
        };
        if down.obstruction(w, self.held, Some(c)).is_some() {
            return None;
        }
        // First the walls: the fingers fully open (a `release` after the carry opens them
        // fully by default) clear them by the margin where they can; then the most room to
        // the blocks in it.
        let open = SetDown {
            opening: crate::motion::gripper::width_for_ctrl(crate::motion::gripper::OPEN_CTRL),
            ..down
        };
        let walls = open.wall_gap(w, c).unwrap_or(f64::INFINITY).min(MARGIN);
        Some((walls, down.room(w, inside)))
    }

    /// Height of the block's centre for a transfer from `from` to `to` (table plane), metres:
    /// `lift` above the table, or higher when something under the path (any object but the held
    /// block, the goal's own walls included) needs it to clear its top by [`CLEARANCE`]; an
    /// object taller than [`MAX_LIFT_OVER`] is not lifted over (the transfer's check sees it
    /// and the planner goes around it).
    fn transfer_z(&self, w: &World, from: Vector2<f64>, to: Vector2<f64>) -> f64 {
        let mut z = self.spec.lift + self.half;
        let reach = self.finger_reach();
        for j in 0..w.objects.len() {
            if j == self.held {
                continue;
            }
            let c = w.objects[j].pos.xy();
            let near = segment_distance(c, from, to) <= w.spec(j).shape.footprint_radius() + reach;
            if near && w.top(j) <= MAX_LIFT_OVER {
                z = z.max(w.top(j) + CLEARANCE + self.half);
            }
        }
        z
    }

    /// Checks that the block and the fingers (opened to let go, along their closing axis) can
    /// come down to `place` (block centre): [`SetDown::check`].
    fn check_descent(&self, w: &World, place: &Vector3<f64>) -> Result<(), Failure> {
        self.set_down(*place).check(w, self.held, self.destination(w))
    }

    /// Moves the block centre to `end` in a straight line: the phase `phase` starts.
    fn start_phase(&mut self, cell: &mut Cell, phase: Phase, end: Vector3<f64>) -> Result<(), Failure> {
        let pose = Isometry3::from_parts(Translation3::from(end + self.pinch_from_block), self.rotation);
        let limits = MotionLimits {
            tool_speed: self.spec.speed,
            ..MotionLimits::default()
        };
        let from = cell.arm_setpoint();
        let mv: Box<dyn Trajectory> = match CartesianMove::new(from, pose, &limits) {
            Ok(mv) => Box::new(mv),
            // The transfer runs at a height that clears everything: when its straight line
            // crosses a wrist singularity or a branch flip, a joint move to the same pose does.
            Err(line) if phase == Phase::Transfer => {
                let goal = crate::motion::ik(&pose, &from).map_err(|e| {
                    Failure::new(
                        FailureKind::Unreachable,
                        format!(
                            "unreachable carry path ({}): {line}; and by a joint move: {e}",
                            phase.name()
                        ),
                    )
                })?;
                tracing::debug!(target: "macrotree::actions", "carry: straight transfer impossible ({line}); joint move instead");
                Box::new(JointMove::new(from, goal, &limits))
            }
            Err(e) => {
                return Err(Failure::new(
                    FailureKind::Unreachable,
                    format!("unreachable carry path ({}): {e}", phase.name()),
                ));
            }
        };
        if phase == Phase::Transfer {
            let blocked = check_motion(cell, &[mv.as_ref()], &[], false);
            let place = self.place(cell.world())?;
            // The set-down that follows stays straight: when it would hit something from where
            // the transfer ends (the wrist on a post beside the goal), the transfer is planned to
            // a pre-place configuration whose set-down is free.
            let lower_blocked = blocked.is_none() && self.set_down_hits(cell, &mv.end(), &place, 0);
            if blocked.is_some() || lower_blocked {
                match &blocked {
                    Some((_, pairs)) => {
                        tracing::debug!(target: "macrotree::actions", "carry: the transfer would touch {}; planning", describe(pairs))
                    }
                    None => {
                        tracing::debug!(target: "macrotree::actions", "carry: the set-down from the transfer's end would touch something or cannot be made straight; planning the transfer to another arm configuration")
                    }
                }
                let motion = self.plan_transfer(cell, &from, &end, &place)?;
                self.goal_q = motion.trajectory.end();
                cell.track(Box::new(motion.trajectory));
                self.phase = phase;
                self.phase_end = end;
                return Ok(());
            }
        } else {
            // Lift and set-down stay straight; only real contact counts, with the destination
            // intended (its floor, the block it goes on).
            let intended: Vec<String> = match phase {
                Phase::Lower | Phase::Insert => self.set_down_intended(cell.world()),
                _ => Vec::new(),
            };
            let what = match phase {
                Phase::Lift => "lift",
                Phase::Insert => "insert",
                _ => "set-down",
            };
            check_straight(cell, what, mv.as_ref(), &intended);
        }
        self.goal_q = mv.end();
        cell.track(mv);
        self.phase = phase;
        self.phase_end = end;
        Ok(())
    }

    /// The tool orientations a cube allows at the goal: the carry's, turned by `k` quarter turns
    /// about the vertical, and the block's offset from the pinch turned with it.
    fn turned(&self, k: usize) -> (UnitQuaternion<f64>, Vector3<f64>) {
        let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), k as f64 * std::f64::consts::FRAC_PI_2);
        (r * self.rotation, r * self.pinch_from_block)
    }

    /// What the set-down may touch, as the collision checker names it: a container
    /// destination's floor (`bin/floor`: the held block comes down on it) but not its walls (the
    /// arm or the fingers on a wall is a collision), or the whole destination otherwise (the block
    /// it goes on, the surface of a `place`).
    fn set_down_intended(&self, w: &World) -> Vec<String> {
        let Some(d) = self.destination(w) else {
            return Vec::new();
        };
        if w.spec(d).kind() == ObjectKind::Container {
            vec![format!("{}/floor", w.name(d))]
        } else {
            vec![w.name(d).to_string()]
        }
    }

    /// True when the straight set-down from `q` (the arm above the place, tool turned `k`
    /// quarter turns) to the block centre `place` would touch something other than the
    /// destination, or cannot be made at all (the line crosses a wrist singularity or a branch
    /// flip from this arm configuration).
    fn set_down_hits(&self, cell: &mut Cell, q: &[f64; 6], place: &Vector3<f64>, k: usize) -> bool {
        let (rotation, offset) = self.turned(k);
        let pose = Isometry3::from_parts(Translation3::from(place + offset), rotation);
        let limits = MotionLimits {
            tool_speed: self.spec.speed,
            ..MotionLimits::default()
        };
        let Ok(lower) = CartesianMove::new(*q, pose, &limits) else {
            return true;
        };
        let intended = self.set_down_intended(cell.world());
        check_motion(cell, &[&lower], &intended, true).is_some()
    }

    /// Plans the transfer from `from` to above the place, the held block's centre at `end`
    /// (metres): every IK branch of the tool turned by quarter turns about the vertical (a cube
    /// looks the same), each with the block's offset turned with it, keeping those from which
    /// the straight set-down to `place` is free (all of them when none is). The tool orientation
    /// and the block's offset follow the goal reached, so the set-down stays consistent with
    /// the grasp.
    fn plan_transfer(
        &mut self,
        cell: &mut Cell,
        from: &[f64; 6],
        end: &Vector3<f64>,
        place: &Vector3<f64>,
    ) -> Result<crate::motion::plan::PlannedMotion, Failure> {
        let mut all: Vec<(f64, usize, [f64; 6])> = Vec::new();
        // A block slid in under something keeps the hand's approach: no quarter turns.
        let turns = if self.insert.is_some() { 1 } else { 4 };
        for k in 0..turns {
            let (rotation, offset) = self.turned(k);
            let pose = Isometry3::from_parts(Translation3::from(end + offset), rotation);
            for q in crate::motion::plan::GoalSet::pose(&pose, from).configs {
                all.push((crate::motion::plan::stats::distance2(&q, from), k, q));
            }
        }
        all.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Quarter turns whose fingers the descent check refuses at the place are left out
        // (unless every turn is refused: the check then says why when the set-down starts).
        let w = cell.world();
        let dest = self.destination(w);
        let clear: Vec<bool> = (0..4)
            .map(|k| {
                self.set_down_turned(*place, k)
                    .obstruction(w, self.held, dest)
                    .is_none()
            })
            .collect();
        if clear.iter().any(|&c| c) {
            all.retain(|(_, k, _)| clear[*k]);
        }
        let mut free: Vec<[f64; 6]> = Vec::new();
        for (_, k, q) in &all {
            if !self.set_down_hits(cell, q, place, *k) {
                free.push(*q);
            }
        }
        // The block stays on the elbow branch it was picked on when a goal there is free: a
        // transfer across the branches swings the forearm through the stretched arm with the
        // tool far from pointing down, and the block falls out of the fingers.
        if free.iter().any(|q| same_elbow(q, from)) {
            free.retain(|q| same_elbow(q, from));
        }
        let goals = if free.is_empty() {
            // Every pre-place configuration's set-down touches: plan to any (the goal's own
            // reasons, if any, name why) and let the set-down run as the leaf asks.
            let poses: Vec<Isometry3<f64>> = (0..4)
                .filter(|&k| clear[k] || !clear.iter().any(|&c| c))
                .map(|k| {
                    let (rotation, offset) = self.turned(k);
                    Isometry3::from_parts(Translation3::from(end + offset), rotation)
                })
                .collect();
            crate::motion::plan::GoalSet::poses(&poses, from)
        } else {
            crate::motion::plan::GoalSet::configs(free)
        };
        let motion = super::planning::plan_motion(
            cell,
            super::plan_help::PlanFor::Transfer { lift: self.spec.lift },
            from,
            &goals,
            self.spec.plan_budget(),
            Some(self.spec.speed),
        )?;
        let reached = crate::motion::fk(&motion.trajectory.end()).rotation;
        let k = (0..4)
            .min_by(|&a, &b| {
                reached
                    .angle_to(&self.turned(a).0)
                    .total_cmp(&reached.angle_to(&self.turned(b).0))
            })
            .unwrap_or(0);
        (self.rotation, self.pinch_from_block) = self.turned(k);
        Ok(motion)
    }

    /// Turns the planned tool orientation (and the block's offset from the pinch with it) about
    /// the vertical through the block's centre so the block ends at the yaw `place` asks for,
    /// by the smallest turn modulo a quarter turn (a cube looks the same).
    fn turn(&mut self, w: &World) {
        let Some(yaw) = self.turn_to else {
            return;
        };
        let now = w.yaw(self.held);
        let by = crate::world::angles::fold_quarter_turn(yaw - now);
        let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), by);
        self.rotation = r * self.rotation;
        self.pinch_from_block = r * self.pinch_from_block;
        self.turn_to = None;
    }

    /// The current phase's motion has ended: start the next one (or re-plan the transfer).
    fn next_phase(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        let w = cell.world();
        let place = self.place(w)?;
        let from = w.objects[self.held].pos.xy();
        let above_z = self.transfer_z(w, from, place.xy()).max(place.z);
        let above = Vector3::new(place.x, place.y, above_z);
        match self.phase {
            Phase::Lift => {
                self.turn(w);
                let turn = std::mem::take(&mut self.spot_turn);
                if turn != 0.0 {
                    let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), turn);
                    self.rotation = r * self.rotation;
                    self.pinch_from_block = r * self.pinch_from_block;
                }
                let place = self.place(w)?;
                self.insert = self.under(w, &place, above_z)?;
                let end = match &self.insert {
                    Some(along) => Self::insert_path(&place, along)[0],
                    None => Vector3::new(place.x, place.y, above_z.max(place.z)),
                };
                self.start_phase(cell, Phase::Transfer, end)
            }
            Phase::Transfer if let Some(along) = self.insert => {
                self.start_phase(cell, Phase::Insert, Self::insert_path(&place, &along)[1])
            }
            Phase::Insert => self.start_phase(cell, Phase::Lower, place),
            Phase::Transfer if (above.xy() - self.phase_end.xy()).norm() > GOAL_MOVED => {
                self.replans += 1;
                if self.replans > MAX_REPLANS {
                    return Err(Failure::new(
                        FailureKind::GoalMoved,
                        format!("the goal kept moving: re-planned the transfer {MAX_REPLANS} times"),
                    ));
                }
                tracing::debug!(target: "macrotree::actions", replans = self.replans, "carry: goal moved, re-planning the transfer");
                self.start_phase(cell, Phase::Transfer, above)
            }
            Phase::Transfer => {
                self.check_descent(w, &place)?;
                self.start_phase(cell, Phase::Lower, place)
            }
            Phase::Lower => Ok(()),
        }
    }
}

impl MacroAction for Carry {
    fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        let w = cell.world();
        // A spot is a place on the table: the block is set down there as `place` would, on
        // whatever is under the spot, turned to the spot's yaw.
        if let Some(spot) = target_spot(&self.spec.to, &w.scene) {
            self.spec.to = crate::kinds::Target::Point([spot.x, spot.y, 0.0]);
            self.surface = true;
            self.turn_to = Some(spot.yaw);
            self.support = spot.on.clone();
        }
        let Some(held) = w.held_block(Tolerances::GRASP_OFF_AXIS) else {
            return Err(Failure::new(
                FailureKind::NotHeld,
                "carry needs a block in the gripper, but none is grasped",
            ));
        };
        self.held = held;
        self.half = w.half(held);
        let pos = w.objects[held].pos;
        // Keep the pinch where it holds the block: move the pinch by as much as the block should move.
        self.pinch_from_block = w.pinch_pos - pos;
        self.rotation = UnitQuaternion::from_matrix(&w.pinch_rot);
        self.closing = closing_axis_in_pinch(w);
        self.tip = tip_above_block(w, held);
        self.spot_local = None;
        self.spot_turn = 0.0;
        let place = self.place(w)?;
        let lift_z = self.transfer_z(w, pos.xy(), place.xy()).max(pos.z);
        let lift = Vector3::new(pos.x, pos.y, lift_z);
        // A place under something that a hand from above cannot reach is refused before
        // anything moves.
        self.under(w, &place, lift_z.max(place.z))?;
        if held_from_side(&self.rotation) {
            let held_name = w.name(held).to_string();
            let surface = self
                .destination(w)
                .map_or_else(|| "table".to_string(), |d| w.name(d).to_string());
            let poses: Vec<Isometry3<f64>> = (0..4)
                .map(|k| {
                    let (rotation, offset) = self.turned(k);
                    Isometry3::from_parts(Translation3::from(place + offset), rotation)
                })
                .collect();
            let from = cell.arm_setpoint();
            if let Some(checker) = cell.checker() {
                refuse_side_set_down(checker, &poses, &from, &held_name, &surface)?;
            }
        }
        self.replans = 0;
        self.lost = 0;
        let base_z = (self.spec.lift + self.half).max(pos.z);
        let e = match self.start_phase(cell, Phase::Lift, lift) {
            Err(e) if e.kind == FailureKind::Unreachable => e,
            started => return started,
        };
        // High over a tall post, far out, the straight line up can cross a branch flip: lift
        // to the carry's own height, and the transfer (checked, planned when it would touch)
        // takes the block on from there.
        if lift_z > base_z {
            tracing::debug!(target: "macrotree::actions", "carry: the lift to {lift_z:.3} m is impossible ({}); lifting to {base_z:.3} m", e.message);
            match self.start_phase(cell, Phase::Lift, Vector3::new(pos.x, pos.y, base_z)) {
                Err(e) if e.kind == FailureKind::Unreachable => {}
                started => return started,
            }
        }
        // At the edge of the workspace even that line leaves it (the elbow straightens): lift as
        // high as the line stays reachable, at least `MIN_LIFT`; the transfer, which comes in
        // towards the goal, takes the block on.
        let from = cell.arm_setpoint();
        let reachable = |z: f64| {
            let pose = Isometry3::from_parts(
                Translation3::from(Vector3::new(pos.x, pos.y, z) + self.pinch_from_block),
                self.rotation,
            );
            CartesianMove::new(from, pose, &MotionLimits::default()).is_ok()
        };
        let (mut lo, mut hi) = (pos.z + MIN_LIFT, base_z.min(lift_z));
        if lo >= hi || !reachable(lo) {
            return Err(e);
        }
        for _ in 0..LIFT_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if reachable(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        tracing::debug!(target: "macrotree::actions", "carry: the straight lift leaves the workspace ({}); lifting to {lo:.3} m", e.message);
        self.start_phase(cell, Phase::Lift, Vector3::new(pos.x, pos.y, lo))
    }

    fn waiting_for(&self, cell: &Cell) -> String {
        format!(
            "{} phase: {}",
            self.phase.name(),
            self.arrival.waiting_for(cell, &self.goal_q)
        )
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        let w = cell.world();
        if w.holds(self.held, Tolerances::GRASP_OFF_AXIS) {
            self.lost = 0;
        } else {
            self.lost += 1;
            if self.lost >= LOST_TICKS {
                let c = w.objects[self.held].pos;
                return Progress::Failed(Failure::new(
                    FailureKind::GraspLost,
                    format!(
                        "grasp lost during {}: {} at ({:.3}, {:.3}, {:.3}) m",
                        self.phase.name(),
                        w.name(self.held),
                        c.x,
                        c.y,
                        c.z
                    ),
                ));
            }
        }
        if self.phase != Phase::Lower {
            if cell.arm_motion_finished()
                && let Err(e) = self.next_phase(cell)
            {
                return Progress::Failed(e);
            }
            return Progress::Running;
        }
        self.arrival.progress(cell, &self.goal_q)
    }
}

/// True when joints `a` and `b` (radians) put the elbow on the same side: the elbow joint's
/// sign, which changes only through the stretched arm.
fn same_elbow(a: &[f64; 6], b: &[f64; 6]) -> bool {
    (a[2] >= 0.0) == (b[2] >= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn distance_to_a_segment() {
        let (a, b) = (Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0));
        assert!((segment_distance(Vector2::new(0.5, 0.2), a, b) - 0.2).abs() < 1e-12);
        assert!((segment_distance(Vector2::new(-0.3, 0.4), a, b) - 0.5).abs() < 1e-12);
        assert!((segment_distance(Vector2::new(2.0, 0.0), a, a) - 2.0).abs() < 1e-12);
    }
}
