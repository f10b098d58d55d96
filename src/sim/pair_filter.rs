//! [`PairFilter`]: which geom pairs MuJoCo's collision detection tests in a model — its contact
//! bitmasks and its body filters (two geoms of the same weld body never; a weld body and its
//! weld parent not unless the parent filter is disabled, the world excepted; `<exclude>`d body
//! pairs never). The collision screen and the margin completion both list pairs with it, so they
//! agree with `mj_collision` and with each other.

use mujoco_rs::prelude::*;

/// MuJoCo's pair filter of one model (see the module docs).
pub(crate) struct PairFilter<'m> {
    contype: &'m [i32],
    conaffinity: &'m [i32],
    body: &'m [i32],
    weld: &'m [i32],
    parent: &'m [i32],
    filter_parent: bool,
    excluded: &'m [i32],
}

impl<'m> PairFilter<'m> {
    /// The filter of `m`.
    pub(crate) fn new(m: &'m MjModel) -> Self {
        Self {
            contype: m.geom_contype(),
            conaffinity: m.geom_conaffinity(),
            body: m.geom_bodyid(),
            weld: m.body_weldid(),
            parent: m.body_parentid(),
            filter_parent: m.ffi().opt.disableflags & MjtDisableBit::mjDSBL_FILTERPARENT as i32 == 0,
            excluded: m.exclude_signature(),
        }
    }

    /// True when `mj_collision` tests geoms `g1` and `g2` (geom ids of the model).
    pub(crate) fn tested(&self, g1: usize, g2: usize) -> bool {
        let (ct, ca) = (self.contype, self.conaffinity);
        if ct[g1] & ca[g2] == 0 && ct[g2] & ca[g1] == 0 {
            return false;
        }
        let (b1, b2) = (self.body[g1] as usize, self.body[g2] as usize);
        let (w1, w2) = (self.weld[b1] as usize, self.weld[b2] as usize);
        if w1 == w2 {
            return false;
        }
        let (wp1, wp2) = (
            self.weld[self.parent[w1] as usize] as usize,
            self.weld[self.parent[w2] as usize] as usize,
        );
        if self.filter_parent && w1 != 0 && w2 != 0 && (w1 == wp2 || w2 == wp1) {
            return false;
        }
        let sig = ((b1.min(b2) as i32) << 16) + b1.max(b2) as i32;
        !self.excluded.contains(&sig)
    }
}
