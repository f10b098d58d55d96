//! How wide a `release` may open the fingers around the block it lets go: the widest opening,
//! up to the one asked for, whose finger envelope ([`SetDown`]) clears the walls of the container
//! the block is in and the objects beside it by [`super::clearance::MARGIN`] — never narrower
//! than the block plus [`RELEASE_GAP`](super::clearance::RELEASE_GAP) a side, the opening the
//! carry's set-down check cleared.

use nalgebra::Vector2;

use super::clearance::{SetDown, release_opening, tip_above_block};
use crate::world::World;
use crate::world::conditions::Tolerances;

/// Largest gap between the block's bottom and the top of what it stands on, metres.
const SUPPORT_SLACK: f64 = 0.005;

/// Step by which the opening is narrowed from the one asked for, metres.
const STEP: f64 = 0.001;

/// The opening (pad faces apart, metres) a release asked to open to `wanted` metres should open
/// to in `w`: `wanted` when no block is between the pads or the envelope at `wanted` is clear;
/// otherwise the widest clear opening down to the block's width plus the release gap (that
/// opening when none is clear, or `wanted` if it is narrower).
pub fn room_to_open(w: &World, wanted: f64) -> f64 {
    let Some(b) = w.held_block(Tolerances::GRASP_OFF_AXIS) else {
        return wanted;
    };
    let d = (w.right_pad_pos - w.left_pad_pos).xy();
    let closing = if d.norm() < 1e-9 {
        Vector2::x()
    } else {
        d.normalize()
    };
    let half = w.half(b);
    let least = release_opening(half);
    if wanted <= least {
        return wanted;
    }
    // What the block stands on: the container it is in, else a block or obstacle right under
    // it (a stack), which the fingers come down beside, not onto.
    let centre = w.objects[b].pos;
    let support = w.container_of(b).or_else(|| {
        (0..w.objects.len()).find(|&j| {
            j != b
                && w.from_footprint(j, &centre).norm() == 0.0
                && (w.top(j) - w.bottom(b)).abs() <= SUPPORT_SLACK
        })
    });
    let clear = |opening: f64| {
        SetDown {
            centre: w.objects[b].pos,
            closing,
            half,
            tip: tip_above_block(w, b),
            opening,
        }
        .obstruction(w, b, support)
        .is_none()
    };
    let mut opening = wanted;
    while opening > least {
        if clear(opening) {
            return opening;
        }
        opening -= STEP;
    }
    least
}
