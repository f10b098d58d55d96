//! Parsers for the layout arguments `--cube X,Y[,YAW_DEG]` and `--bowl X,Y`, and for `plan`'s
//! joint configurations (`home` or `J1,…,J6`) and points (`X,Y,Z`).

use std::str::FromStr;

/// `--cube X,Y[,YAW_DEG]`: cube centre on the table (metres) and yaw (degrees).
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

impl FromStr for CubeArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let v = numbers(
            s,
            2,
            3,
            "X,Y or X,Y,YAW_DEG (metres, degrees), e.g. 0.45,-0.18,30",
        )?;
        Ok(Self {
            x: v[0],
            y: v[1],
            yaw_deg: v.get(2).copied().unwrap_or(0.0),
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
    fn bad_layouts_are_rejected_with_the_expected_form() {
        assert!("0.4".parse::<CubeArg>().unwrap_err().contains("X,Y"));
        assert!("0.4,nan".parse::<CubeArg>().unwrap_err().contains("finite"));
        assert!("1,2,3".parse::<XyArg>().is_err());
    }
}
