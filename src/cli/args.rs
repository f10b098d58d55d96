//! Parsers for the layout arguments `--cube X,Y[,YAW_DEG]` and `--bowl X,Y`.

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

#[cfg(test)]
mod tests {
    use super::*;

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
