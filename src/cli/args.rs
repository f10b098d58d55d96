//! Parsers for the layout arguments `--cube X,Y[,YAW]` and `--bowl X,Y`, yaws in degrees (or with
//! their unit: `30deg`, `0.5236rad`), and for `plan`'s
//! joint configurations (`home` or `J1,…,J6`) and points (`X,Y,Z`).

use std::str::FromStr;

/// `--cube X,Y[,YAW]`: cube centre on the table (metres) and yaw (degrees; or with its unit, `30deg`, `0.5236rad`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubeArg {
    /// x, metres.
    pub x: f64,
    /// y, metres.
    pub y: f64,
    /// Yaw, degrees.
    pub yaw_deg: f64,
}

/// `--bowl X,Y`: bowl centre on the table, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct XyArg {
    /// x, metres.
    pub x: f64,
    /// y, metres.
    pub y: f64,
}

fn numbers(s: &str, min: usize, max: usize, what: &str) -> Result<Vec<f64>, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() < min || parts.len() > max {
        return Err(format!("expected {what}, got {s:?}"));
    }
    parts
        .iter()
        .map(|p| match p.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("{p:?} is not a finite number (expected {what})")),
        })
        .collect()
}

/// Largest yaw the command line takes either way, degrees (one turn).
pub const MAX_YAW_DEG: f64 = 360.0;

/// A yaw on the command line, in degrees: a plain number is degrees (as every report prints
/// them), and an explicit unit is accepted, `30deg` or `0.5236rad`; within ±360°. A plain number
/// that looks like radians (`0.785`, near a multiple of π/12: [`looks_like_radians`]) is refused
/// with both readings, so a slip between the conventions never runs silently.
///
/// [`looks_like_radians`]: crate::yaml::units::looks_like_radians
pub fn yaw_degrees(text: &str) -> Result<f64, String> {
    let t = text.trim();
    let (number, unit) = if let Some(n) = t.strip_suffix("deg") {
        (n, Some(1.0))
    } else if let Some(n) = t.strip_suffix("rad") {
        (n, Some(180.0 / std::f64::consts::PI))
    } else {
        (t, None)
    };
    let form = "degrees (`30`, `30deg`) or radians with their unit (`0.5236rad`)";
    let x = match number.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => x,
        _ => return Err(format!("{t:?} is not a yaw: write {form}")),
    };
    if unit.is_none()
        && let Some(deg) = crate::yaml::units::looks_like_radians(x)
    {
        return Err(format!(
            "the yaw `{x}` is read as {x}° (plain numbers on the command line are degrees), but it looks like radians ({deg}°): write {deg} for {deg}°, `{x}rad` for radians, or `{x}deg` to keep {x}°"
        ));
    }
    let deg = x * unit.unwrap_or(1.0);
    if deg.abs() > MAX_YAW_DEG {
        return Err(format!(
            "the yaw {t} is {deg:.1}°, more than a full turn: write {form} within ±{MAX_YAW_DEG}°"
        ));
    }
    Ok(deg)
}

impl FromStr for CubeArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let form = "X,Y or X,Y,YAW (metres; the yaw in degrees, or with its unit: 30deg, 0.5236rad), e.g. 0.45,-0.18,30";
        let parts: Vec<&str> = s.split(',').collect();
        if !(2..=3).contains(&parts.len()) {
            return Err(format!("expected {form}, got {s:?}"));
        }
        let v = numbers(&parts[..2].join(","), 2, 2, form)?;
        let yaw_deg = match parts.get(2) {
            Some(y) => yaw_degrees(y)?,
            None => 0.0,
        };
        Ok(Self {
            x: v[0],
            y: v[1],
            yaw_deg,
        })
    }
}

impl FromStr for XyArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let v = numbers(s, 2, 2, "X,Y in metres, e.g. 0.45,0.08")?;
        Ok(Self { x: v[0], y: v[1] })
    }
}

/// A joint configuration on the command line: `home` or six angles J1,…,J6 (radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointsArg {
    /// The arm's home configuration ([`crate::sim::HOME_Q`]).
    Home,
    /// Six joint angles, radians.
    Joints([f64; 6]),
}

impl FromStr for JointsArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s.trim() == "home" {
            return Ok(Self::Home);
        }
        let v = numbers(s, 6, 6, "`home` or six joint angles J1,…,J6 in radians")?;
        Ok(Self::Joints(std::array::from_fn(|k| v[k])))
    }
}

impl JointsArg {
    /// The configuration, each joint checked against `bounds` (radians); out of bounds is bad
    /// input naming `flag`, the joint and its range.
    pub fn resolve(&self, flag: &str, bounds: &[(f64, f64); 6]) -> Result<[f64; 6], super::CliError> {
        let q = match self {
            Self::Home => crate::sim::HOME_Q,
            Self::Joints(q) => *q,
        };
        for (k, (v, (lo, hi))) in q.iter().zip(bounds).enumerate() {
            if !(lo..=hi).contains(&v) {
                return Err(super::CliError::Input(format!(
                    "error: {flag}: joint {} is {v} rad, outside its limits {lo:.4} … {hi:.4} rad",
                    k + 1
                )));
            }
        }
        Ok(q)
    }
}

/// Farthest a `plan --to-point` coordinate may be from the robot's base, metres (the UR5e
/// reaches 0.85 m; farther is refused before IK is asked).
pub const MAX_POINT_DISTANCE: f64 = 2.0;

/// `--to-point X,Y,Z`: a point in the world frame, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointArg {
    /// x, metres.
    pub x: f64,
    /// y, metres.
    pub y: f64,
    /// z, metres.
    pub z: f64,
}

impl FromStr for PointArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let v = numbers(s, 3, 3, "X,Y,Z in metres, e.g. 0.45,0.1,0.2")?;
        if v.iter().any(|c| c.abs() > MAX_POINT_DISTANCE) {
            return Err(format!(
                "each coordinate must be within ±{MAX_POINT_DISTANCE} m of the robot's base, got {s:?}"
            ));
        }
        Ok(Self {
            x: v[0],
            y: v[1],
            z: v[2],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joints_take_home_or_six_finite_angles() {
        assert_eq!("home".parse::<JointsArg>().unwrap(), JointsArg::Home);
        assert_eq!(
            "0, -1.5, 1.5, -1.5, -1.5, 0".parse::<JointsArg>().unwrap(),
            JointsArg::Joints([0.0, -1.5, 1.5, -1.5, -1.5, 0.0])
        );
        assert!("0,1,2,3,4".parse::<JointsArg>().is_err());
        assert!("0,1,2,3,4,nan".parse::<JointsArg>().is_err());
        let bounds = [(-1.0, 1.0); 6];
        assert!(JointsArg::Joints([0.0; 6]).resolve("--from", &bounds).is_ok());
        assert!(
            JointsArg::Joints([0.0, 0.0, 1.5, 0.0, 0.0, 0.0])
                .resolve("--from", &bounds)
                .is_err()
        );
    }

    #[test]
    fn points_are_three_finite_coordinates_near_the_base() {
        assert_eq!(
            "0.45,-0.1,0.2".parse::<PointArg>().unwrap(),
            PointArg {
                x: 0.45,
                y: -0.1,
                z: 0.2
            }
        );
        assert!("0.45,0.1".parse::<PointArg>().is_err());
        assert!("0.45,0.1,inf".parse::<PointArg>().is_err());
        assert!("0.45,0.1,1e9".parse::<PointArg>().is_err());
    }

    #[test]
    fn cube_with_and_without_yaw() {
        assert_eq!(
            "0.4,-0.1".parse::<CubeArg>().unwrap(),
            CubeArg {
                x: 0.4,
                y: -0.1,
                yaw_deg: 0.0
            }
        );
        assert_eq!(
            "0.4, -0.1, 30".parse::<CubeArg>().unwrap(),
            CubeArg {
                x: 0.4,
                y: -0.1,
                yaw_deg: 30.0
            }
        );
    }

    #[test]
    fn a_command_line_yaw_is_degrees_takes_an_explicit_unit_and_refuses_a_radian_look() {
        assert_eq!(yaw_degrees("30"), Ok(30.0));
        assert_eq!(yaw_degrees("30deg"), Ok(30.0));
        assert_eq!(yaw_degrees("-45.5 deg"), Ok(-45.5));
        assert!((yaw_degrees("0.785rad").unwrap() - 0.785f64.to_degrees()).abs() < 1e-12);
        assert_eq!(yaw_degrees("0.785deg"), Ok(0.785));
        let e = yaw_degrees("0.785").unwrap_err();
        assert!(
            e.contains("looks like radians (45°)") && e.contains("`0.785rad`"),
            "{e}"
        );
        for bad in ["361", "7rad", "x", "30 degrees", "nan", ""] {
            assert!(yaw_degrees(bad).is_err(), "{bad}");
        }
        assert_eq!(
            "0.45,-0.1,0.785rad".parse::<CubeArg>().unwrap().yaw_deg,
            0.785f64.to_degrees()
        );
        assert!(
            "0.45,-0.1,0.785"
                .parse::<CubeArg>()
                .unwrap_err()
                .contains("radians")
        );
    }

    #[test]
    fn bad_layouts_are_rejected_with_the_expected_form() {
        assert!("0.4".parse::<CubeArg>().unwrap_err().contains("X,Y"));
        assert!("0.4,nan".parse::<CubeArg>().unwrap_err().contains("finite"));
        assert!("1,2,3".parse::<XyArg>().is_err());
    }
}
