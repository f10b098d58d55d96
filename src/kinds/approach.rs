//! How a `reach` comes to a block: from above, from the side, or whichever is free.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The direction a `reach` approaches its target from.
///
/// YAML: `top` (default), `side` or `auto`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema, Default)]
#[serde(rename_all = "snake_case")]
pub enum Approach {
    /// Tool pointing straight down at the target (the top-down grasp); `offset` is in the world
    /// frame.
    #[default]
    Top,
    /// Tool horizontal, along the normal of one of the target block's four vertical faces, the
    /// pinch at the block's centre height and the fingers closing across the two faces beside
    /// it; `offset` is in the approach frame (z: stand-off back out along the face normal, y:
    /// up, x: along the face). Needs a block target.
    Side,
    /// `top` when a top-down pre-grasp at the stand-off and the straight descent from it are
    /// collision-free, else `side`; `offset` must be a stand-off `[0, 0, s]`.
    Auto,
}

impl Approach {
    /// True for the default, [`Approach::Top`] (left out when a `reach` is written back).
    pub fn is_top(&self) -> bool {
        *self == Approach::Top
    }

    /// The YAML name: `top`, `side` or `auto`.
    pub fn name(self) -> &'static str {
        match self {
            Approach::Top => "top",
            Approach::Side => "side",
            Approach::Auto => "auto",
        }
    }
}

/// The checks a `reach`'s `approach` puts on its other parameters: `side` and `auto` need a
/// block to approach (not a point or the legacy `bowl`), a stand-off that is not negative, and
/// `side` takes no `yaw` (the face decides the tool's turn); `auto` takes only a stand-off
/// `[0, 0, s]` (it means the same for both approaches).
pub(crate) fn check_reach(
    approach: Approach,
    target: &super::Target,
    offset: &[f64; 3],
    yaw: &super::Yaw,
) -> Result<(), super::ParamError> {
    use super::{ParamError, Target, Yaw};
    if approach.is_top() {
        return Ok(());
    }
    let name = approach.name();
    match target {
        Target::Point(_) => {
            return Err(ParamError::at(
                "approach",
                format!(
                    "`{name}` needs a block to approach (a point has no faces); use `approach: top` for a point"
                ),
            ));
        }
        Target::Bowl => {
            return Err(ParamError::at(
                "approach",
                format!("`{name}` needs a block to approach, not the bowl; use `approach: top`"),
            ));
        }
        Target::Cube | Target::Object(_) => {}
    }
    if offset[2] < 0.0 {
        return Err(ParamError::at(
            "offset",
            format!(
                "with `approach: {name}` the offset's z is the stand-off back from the block along the approach, \
                 so it cannot be negative (found {} m)",
                offset[2]
            ),
        ));
    }
    if approach == Approach::Auto && (offset[0] != 0.0 || offset[1] != 0.0) {
        return Err(ParamError::at(
            "offset",
            format!(
                "with `approach: auto` the offset must be a stand-off `[0, 0, s]` (it means the same from above and \
                 from the side), found [{}, {}, {}]",
                offset[0], offset[1], offset[2]
            ),
        ));
    }
    if approach == Approach::Side && !matches!(yaw, Yaw::Object) {
        return Err(ParamError::at(
            "yaw",
            "with `approach: side` the face approached decides the tool's turn: leave `yaw` out",
        ));
    }
    Ok(())
}
