//! `place`: set the held block down at a point or a named spot, turned to a yaw, on whatever
//! surface is under it (or the spot's `on:`), then open the fingers just enough to let go and
//! retreat straight up — or back out the way the hand came, when the block was slid in under
//! something.
//!
//! The transfer and the set-down are `carry`'s ([`Carry::placing`]: the same lift, planned
//! transfer, clearance check and straight set-down); the letting go is `release`'s, opened to
//! the width the clearance check was made for.

use super::carry::Carry;
use super::cell::Cell;
use super::clearance::release_opening;
use super::macro_action::{MacroAction, Progress};
use super::release::Release;
use crate::failure::Failure;
use crate::kinds::{Carry as CarrySpec, Place as PlaceSpec, Release as ReleaseSpec, Target, Yaw};
use crate::scene::SceneSpec;

/// Gap left under the block when the set-down ends, metres: the block drops this much when the
/// fingers open (a set-down aimed exactly at the surface would press the arm into it).
pub const DROP: f64 = 0.002;

/// Time the fingers get to open and the arm to retreat after the set-down, seconds.
const RELEASE_TIME: f64 = 3.0;

/// Where a `place` goes.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaceTarget {
    /// The point `[x, y]`, world frame, metres.
    pub point: [f64; 2],
    /// The block's yaw there, radians; `None`: as held.
    pub yaw: Option<f64>,
    /// What the block rests on there, by name (a spot's `on:`); `None`: whatever is under the
    /// point with the highest top.
    pub on: Option<String>,
}

/// Where a `place` goes. A spot the scene does not have is a failure of kind `other` that lists
/// the spots it has.
pub fn place_target(scene: &SceneSpec, spec: &PlaceSpec) -> Result<PlaceTarget, Failure> {
    let explicit = match spec.yaw {
        Some(Yaw::Angle(a)) => Some(Some(a)),
        Some(Yaw::Keep) | Some(Yaw::Object) => Some(None),
        None => None,
    };
    if let Some(point) = spec.point {
        return Ok(PlaceTarget {
            point,
            yaw: explicit.flatten(),
            on: None,
        });
    }
    let Some(named) = &spec.spot else {
        return Err(Failure::other("`place` has neither a point nor a spot"));
    };
    let spot = super::targets::spot(named, scene)?;
    Ok(PlaceTarget {
        point: [spot.x, spot.y],
        yaw: explicit.unwrap_or(Some(spot.yaw)),
        on: spot.on.clone(),
    })
}

/// Executes a [`PlaceSpec`]: a carry to the place, then a release to the checked opening.
pub struct Place {
    spec: PlaceSpec,
    carry: Option<Carry>,
    release: Option<Release>,
}

impl Place {
    /// A place controller for `spec`.
    pub fn new(spec: PlaceSpec) -> Self {
        Self {
            spec,
            carry: None,
            release: None,
        }
    }

    /// The set-down has ended: open to the width the clearance check allowed for, and retreat.
    fn let_go(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        let half = self.carry.as_ref().map_or(0.0, |c| cell.world().half(c.held()));
        let spec = ReleaseSpec {
            width: Some(release_opening(half)),
            retreat: self.spec.retreat,
            timeout: RELEASE_TIME,
        };
        // Slid in under something, the hand backs out the way it came.
        let mut release = match self.carry.as_ref().and_then(Carry::slid_in_along) {
            Some(along) => Release::retreating_along(spec, -along),
            None => Release::new(spec),
        };
        release.start(cell)?;
        self.release = Some(release);
        Ok(())
    }
}

impl MacroAction for Place {
    fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        let PlaceTarget {
            point: [x, y],
            yaw,
            on,
        } = place_target(&cell.world().scene, &self.spec)?;
        let spec = CarrySpec {
            to: Target::Point([x, y, 0.0]),
            lift: self.spec.lift,
            place_height: DROP,
            speed: self.spec.speed,
            timeout: self.spec.timeout,
            max_checks: self.spec.max_checks,
            plan_time_cap: self.spec.plan_time_cap,
        };
        let mut carry = Carry::placing(spec, yaw, on);
        self.release = None;
        let started = carry.start(cell);
        self.carry = Some(carry);
        started
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        if let Some(release) = &mut self.release {
            return release.update(cell);
        }
        let Some(carry) = &mut self.carry else {
            return Progress::Failed(Failure::other("place updated before it started"));
        };
        match carry.update(cell) {
            Progress::Done => match self.let_go(cell) {
                Ok(()) => Progress::Running,
                Err(e) => Progress::Failed(e),
            },
            other => other,
        }
    }

    fn halt(&mut self, cell: &mut Cell) {
        match (&mut self.release, &mut self.carry) {
            (Some(r), _) => r.halt(cell),
            (None, Some(c)) => c.halt(cell),
            (None, None) => {}
        }
    }

    fn waiting_for(&self, cell: &Cell) -> String {
        match (&self.release, &self.carry) {
            (Some(r), _) => format!("letting go: {}", r.waiting_for(cell)),
            (None, Some(c)) => c.waiting_for(cell),
            (None, None) => "not started".to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Spot;

    fn spec(point: Option<[f64; 2]>, spot: Option<&str>, yaw: Option<Yaw>) -> PlaceSpec {
        PlaceSpec {
            point,
            spot: spot.map(|n| crate::kinds::ObjectRef::name(n).unwrap()),
            yaw,
            lift: 0.2,
            retreat: 0.1,
            speed: 0.5,
            timeout: 15.0,
            max_checks: None,
            plan_time_cap: None,
        }
    }

    fn scene_with_spot() -> SceneSpec {
        let mut s = SceneSpec::builtin();
        s.spots.push(Spot {
            name: "kit_a".into(),
            x: 0.45,
            y: -0.1,
            yaw: 0.3,
            on: None,
        });
        s
    }

    fn at(point: [f64; 2], yaw: Option<f64>) -> PlaceTarget {
        PlaceTarget { point, yaw, on: None }
    }

    #[test]
    fn a_spot_gives_its_point_and_its_yaw_unless_the_node_says_otherwise() {
        let s = scene_with_spot();
        assert_eq!(
            place_target(&s, &spec(None, Some("kit_a"), None)).unwrap(),
            at([0.45, -0.1], Some(0.3))
        );
        assert_eq!(
            place_target(&s, &spec(None, Some("kit_a"), Some(Yaw::Keep))).unwrap(),
            at([0.45, -0.1], None)
        );
        assert_eq!(
            place_target(&s, &spec(None, Some("kit_a"), Some(Yaw::Angle(1.0)))).unwrap(),
            at([0.45, -0.1], Some(1.0))
        );
    }

    #[test]
    fn a_point_keeps_the_yaw_unless_given() {
        let s = scene_with_spot();
        assert_eq!(
            place_target(&s, &spec(Some([0.5, 0.1]), None, None)).unwrap(),
            at([0.5, 0.1], None)
        );
        assert_eq!(
            place_target(&s, &spec(Some([0.5, 0.1]), None, Some(Yaw::Angle(-0.2)))).unwrap(),
            at([0.5, 0.1], Some(-0.2))
        );
    }

    #[test]
    fn an_unknown_spot_names_the_spots_the_scene_has() {
        let s = scene_with_spot();
        let e = place_target(&s, &spec(None, Some("kit_b"), None)).unwrap_err();
        assert_eq!(e.kind, crate::failure::FailureKind::Other);
        assert!(
            e.message.contains("no spot `kit_b`") && e.message.contains("kit_a"),
            "{e}"
        );
    }

    #[test]
    fn a_spot_variable_left_unresolved_is_a_failure_not_a_panic() {
        let s = scene_with_spot();
        let mut p = spec(None, None, None);
        p.spot = Some(crate::kinds::ObjectRef::parse("{where}").unwrap());
        let e = place_target(&s, &p).unwrap_err();
        assert!(e.message.contains("`{where}` was not resolved"), "{e}");
    }
}
