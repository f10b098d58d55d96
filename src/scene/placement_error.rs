//! Why a placement is not allowed: which constraint, between which objects (or which region),
//! and what to change.

use super::types::{Pose, ROBOT_BASE_RADIUS, reach_limits};

/// Half-width of the table the objects stand on (the floor plane), metres.
pub(super) const TABLE_HALF: f64 = 1.0;

/// Why a placement is not allowed.
#[derive(Clone, Debug, PartialEq)]
pub enum PlacementError {
    /// A coordinate is not a finite number, or lies off the table.
    OffTable {
        /// The object.
        object: String,
        /// Its pose.
        pose: Pose,
    },
    /// The yaw is not a finite angle within one turn either way.
    BadYaw {
        /// The object.
        object: String,
        /// Its yaw as given, radians.
        yaw: f64,
    },
    /// The object's footprint comes too close to the robot's base.
    OnRobotBase {
        /// The object.
        object: String,
        /// Distance from the base axis to the nearest point of its footprint, metres.
        distance: f64,
    },
    /// A fixed object stands where the arm rests at home: a link of the arm at home (as
    /// [`crate::motion::body::arm_capsules`] models it) comes into its box.
    InArmAtHome {
        /// The object.
        object: String,
        /// The link (`forearm`, `gripper`, …).
        link: &'static str,
        /// How far the link comes into the object, metres.
        depth: f64,
    },
    /// A block lies where the arm cannot pick it from above.
    OutOfReach {
        /// The block.
        object: String,
        /// Its distance from the base axis, metres.
        distance: f64,
    },
    /// Two objects' footprints overlap (or come closer than the clearance asked for) at heights
    /// where both stand.
    TooClose {
        /// The first object.
        a: String,
        /// The second object.
        b: String,
        /// Their distance, metres: between the centres when `centres` (two blocks, compared
        /// as footprint circles), else the smallest gap between the footprints (0: overlap).
        distance: f64,
        /// The smallest distance allowed, metres.
        min: f64,
        /// The distance is between centres (two blocks), not between footprints.
        centres: bool,
        /// `a` is a block whose centre lies over `b`'s top or inside its walls: it was probably
        /// meant to start on `b`.
        on_b: bool,
        /// `a` or `b` is drawn from a `random:` region (else both have fixed poses, and only
        /// moving one helps).
        randomized: bool,
    },
    /// A block does not lie on what it is declared to rest on (`on:`, `random: {in: ..}`):
    /// its footprint sticks out of the support's top, or comes closer to a container's walls
    /// than its clearance.
    OffSupport {
        /// The block.
        object: String,
        /// What it rests on.
        support: String,
        /// How far the footprint lies inside the support's area, metres (negative: sticks out).
        margin: f64,
        /// The margin needed, metres (the clearance to a container's walls, else 0).
        min: f64,
    },
    /// A randomized object's footprint enters a `keep_out` region.
    InKeepOut {
        /// The object.
        object: String,
        /// The region.
        region: String,
    },
    /// A randomized object's footprint is not inside any of the `allowed` regions it names.
    OutsideRegions {
        /// The object.
        object: String,
        /// The regions it names.
        regions: Vec<String>,
    },
    /// No draw met the constraints.
    Unsatisfiable {
        /// Draws tried.
        draws: usize,
        /// How many of them failed on the most common problem.
        count: usize,
        /// The most common problem (the first of its kind met).
        most_common: Box<PlacementError>,
    },
    /// The placement does not have one pose per object.
    WrongCount {
        /// Poses given.
        given: usize,
        /// Objects in the scene.
        objects: usize,
    },
}

impl PlacementError {
    /// The object the problem is about (the first of a pair), when there is one.
    pub fn object(&self) -> Option<&str> {
        match self {
            PlacementError::OffTable { object, .. }
            | PlacementError::BadYaw { object, .. }
            | PlacementError::OnRobotBase { object, .. }
            | PlacementError::InArmAtHome { object, .. }
            | PlacementError::OutOfReach { object, .. }
            | PlacementError::OffSupport { object, .. }
            | PlacementError::InKeepOut { object, .. }
            | PlacementError::OutsideRegions { object, .. } => Some(object),
            PlacementError::TooClose { a, .. } => Some(a),
            PlacementError::Unsatisfiable { most_common, .. } => most_common.object(),
            PlacementError::WrongCount { .. } => None,
        }
    }

    /// The constraint broken, as a stable key (`too_close a b`), so that many draws failing on
    /// the same constraint can be counted together.
    pub fn constraint(&self) -> String {
        match self {
            PlacementError::OffTable { object, .. } => format!("off_table {object}"),
            PlacementError::BadYaw { object, .. } => format!("bad_yaw {object}"),
            PlacementError::OnRobotBase { object, .. } => format!("on_robot_base {object}"),
            PlacementError::InArmAtHome { object, .. } => format!("in_arm_at_home {object}"),
            PlacementError::OutOfReach { object, .. } => format!("out_of_reach {object}"),
            PlacementError::TooClose { a, b, .. } => format!("too_close {a} {b}"),
            PlacementError::OffSupport { object, support, .. } => format!("off_support {object} {support}"),
            PlacementError::InKeepOut { object, region } => format!("keep_out {object} {region}"),
            PlacementError::OutsideRegions { object, .. } => format!("outside_regions {object}"),
            PlacementError::Unsatisfiable { most_common, .. } => most_common.constraint(),
            PlacementError::WrongCount { .. } => "wrong_count".into(),
        }
    }

    /// What to change in the scene so that the problem goes away.
    pub fn hint(&self) -> String {
        match self {
            PlacementError::OffTable { .. } => "keep x and y within ±1 m of the robot".into(),
            PlacementError::BadYaw { .. } => {
                "give the yaw in radians within one turn (±2π), e.g. its value modulo 2π".into()
            }
            PlacementError::OnRobotBase { object, .. } => {
                format!("move `{object}` (or its `random:` region) away from the robot's base at the origin")
            }
            PlacementError::InArmAtHome { object, .. } => {
                let pinch = crate::motion::fk(&crate::motion::HOME_Q).translation.vector;
                format!(
                    "move `{object}` (or its `random:` region) clear of the arm at home, or make it lower: at home the upper arm rises beside the base to {:.2} m and the forearm reaches over to the gripper, which hangs down to ({:.2}, {:.2}, {:.2}) m",
                    crate::motion::ur5e::SHOULDER_HEIGHT + crate::motion::ur5e::UPPER_ARM,
                    pinch.x,
                    pinch.y,
                    pinch.z
                )
            }
            PlacementError::OutOfReach { object, .. } => {
                let [lo, hi] = reach_limits();
                format!(
                    "keep block `{object}` {lo} … {hi} m from the base (its `pose:` or `random:` x and y)"
                )
            }
            PlacementError::TooClose { a, b, on_b: true, .. } => format!(
                "to start `{a}` on or inside `{b}`, declare it: `on: {b}` with a fixed pose, or `random: {{in: {b}}}` (`{{on: {b}}}` for a top)"
            ),
            PlacementError::TooClose {
                a,
                b,
                min,
                randomized: true,
                ..
            } if *min > 0.0 => format!(
                "move `{a}` and `{b}` apart, widen their `random:` regions, or lower their `clearance` ({min:.3} m needed)"
            ),
            PlacementError::TooClose {
                a,
                b,
                randomized: true,
                ..
            } => format!("move `{a}` and `{b}` apart, or widen their `random:` regions"),
            PlacementError::TooClose { a, b, min, .. } if *min > 0.0 => format!(
                "move `{a}` or `{b}` (both have fixed poses) so that {min:.3} m lies between them, or lower their `clearance`"
            ),
            PlacementError::TooClose { a, b, .. } => {
                format!("move `{a}` or `{b}`: both have fixed poses, and their footprints must not meet")
            }
            PlacementError::OffSupport { object, support, .. } => format!(
                "put `{object}` over `{support}`'s top (inside its walls), make `{support}` larger or `{object}` smaller, or lower `{object}`'s clearance"
            ),
            PlacementError::InKeepOut { object, region } => {
                format!("move `{object}`'s `random:` region out of `{region}`, or shrink the region")
            }
            PlacementError::OutsideRegions { object, .. } => format!(
                "make `{object}`'s `random:` x and y ranges lie inside its regions, or widen the regions"
            ),
            PlacementError::Unsatisfiable { most_common, .. } => most_common.hint(),
            PlacementError::WrongCount { .. } => {
                "give one pose per object of the scene, in scene order".into()
            }
        }
    }
}

impl std::fmt::Display for PlacementError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [rmin, rmax] = reach_limits();
        match self {
            PlacementError::OffTable { object, pose } => write!(
                f,
                "`{object}` at ({}, {}) is off the table: x and y must be finite and within ±{TABLE_HALF} m",
                crate::yaml::short_number(pose.x),
                crate::yaml::short_number(pose.y)
            ),
            PlacementError::BadYaw { object, yaw } => write!(
                f,
                "`{object}`'s yaw is {}: a yaw must be a finite angle within ±{:.4} rad (one turn)",
                crate::yaml::short_number(*yaw),
                crate::yaml::units::MAX_BARE_ANGLE
            ),
            PlacementError::OnRobotBase { object, distance } => write!(
                f,
                "`{object}` overlaps the robot's base: its footprint comes within {distance:.3} m of the base axis (keep it clear of {ROBOT_BASE_RADIUS} m)"
            ),
            PlacementError::InArmAtHome { object, link, depth } => write!(
                f,
                "`{object}` stands where the arm rests at home: its {link} would be {depth:.3} m inside it, and every episode starts at home"
            ),
            PlacementError::OutOfReach { object, distance } => write!(
                f,
                "block `{object}` is {distance:.3} m from the robot's base: blocks must be {rmin} … {rmax} m away to be picked from above"
            ),
            PlacementError::TooClose {
                a,
                b,
                distance,
                min,
                centres: true,
                ..
            } => write!(
                f,
                "`{a}` and `{b}` are {distance:.3} m apart (centres); at least {min:.3} m is needed so they do not overlap"
            ),
            PlacementError::TooClose {
                a, b, distance, min, ..
            } => {
                if *distance <= 0.0 {
                    write!(
                        f,
                        "`{a}` and `{b}` overlap: their footprints meet at heights where both stand{}",
                        if *min > 0.0 {
                            format!(" (at least {min:.3} m is needed between them)")
                        } else {
                            String::new()
                        }
                    )
                } else {
                    write!(
                        f,
                        "`{a}` and `{b}` are {distance:.3} m apart (footprints); at least {min:.3} m is needed"
                    )
                }
            }
            PlacementError::OffSupport {
                object,
                support,
                margin,
                min,
            } => {
                if *margin < 0.0 {
                    write!(
                        f,
                        "`{object}` does not lie on `{support}`: its footprint sticks out of `{support}`'s top (inside its walls) by {:.3} m",
                        -margin
                    )
                } else {
                    write!(
                        f,
                        "`{object}` comes {margin:.3} m from `{support}`'s walls; its clearance asks for {min:.3} m"
                    )
                }
            }
            PlacementError::InKeepOut { object, region } => {
                write!(f, "`{object}`'s footprint enters the keep-out region `{region}`")
            }
            PlacementError::OutsideRegions { object, regions } => write!(
                f,
                "`{object}`'s footprint is not inside its allowed region{} `{}`",
                if regions.len() == 1 { "" } else { "s" },
                regions.join("`, `")
            ),
            PlacementError::Unsatisfiable {
                draws,
                count,
                most_common,
            } => write!(
                f,
                "no placement found in {draws} draws; {count} of them ({:.0} %) failed because {most_common}",
                100.0 * *count as f64 / (*draws).max(1) as f64
            ),
            PlacementError::WrongCount { given, objects } => {
                write!(f, "{given} poses given for {objects} objects")
            }
        }
    }
}

impl std::error::Error for PlacementError {}
