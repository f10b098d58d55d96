//! How far a pair's parts move relative to each other, as a fraction of the planner's lever-arm
//! bound.

use super::posed::MovingShape;
use crate::motion::ur5e::LEVER_ARMS;
use crate::sim::chain::Link;

/// The lever-arm ratio of the pair of shapes `a` (moving) and `b` (moving or fixed, index past
/// `moving`): the largest, over the joints that move the two relative to each other, of how far
/// the distal shape's points can lie from the joint's axis over the planner's lever arm for
/// that joint ([`LEVER_ARMS`], an upper bound for the whole moving robot and a held
/// block), at most 1.
///
/// Joint `j` moves the distal shape's points by at most their distance from its axis times the
/// angle, and that distance is bounded through the chain, whatever the joints between: the
/// shape lies within its reach of its centre in its link's frame, each link's origin within
/// `|pos| + 2 |anchor|` of its parent's (the body offset, and the rotation about the anchor),
/// and joint `j`'s axis passes within `|anchor_j|` of link `j`'s origin. A short chain (the
/// forearm against wrist 2) then moves far less than the whole arm's lever arm allows, and a
/// clearance vouches for proportionally more.
pub(super) fn lever_ratio(links: &[Link; 6], moving: &[MovingShape], a: usize, b: usize) -> f64 {
    let (range, far) = if b < moving.len() {
        let (ka, kb) = (moving[a].link, moving[b].link);
        let far = if ka >= kb { a } else { b };
        (ka.min(kb) + 1..=ka.max(kb), far)
    } else {
        (0..=moving[a].link, a)
    };
    let distal = &moving[far];
    let mut chain = distal.local.centre().norm() + distal.reach;
    let mut ratio: f64 = 0.0;
    for j in (0..=distal.link).rev() {
        let anchor = links[j].anchor.norm();
        if range.contains(&j) {
            ratio = ratio.max((chain + anchor) / LEVER_ARMS[j]);
        }
        chain += links[j].pos.norm() + 2.0 * anchor;
    }
    if ratio > 0.0 { ratio.min(1.0) } else { 1.0 }
}
