//! The pairs the screen tests, and their groups of one arm link against one partner.

/// The arm joints `first..=last` (0..6, base to wrist 3) that move two parts relative to each
/// other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JointRange {
    /// The first joint of the range.
    pub first: usize,
    /// The last joint of the range (at least `first`).
    pub last: usize,
}

impl JointRange {
    /// The joints `first..=last`; `None` when the range is empty (`first > last`).
    #[inline]
    pub(super) fn new(first: usize, last: usize) -> Option<Self> {
        (first <= last).then_some(Self { first, last })
    }
}

/// One pair to test: two shape indices (moving shapes first, then fixed ones), the distance
/// they must keep for "free" (the pair's margin plus [`PAD`](super::PAD), metres), and the
/// distance below which exact shapes are "blocked": [`PAD`](super::PAD) of penetration (MuJoCo
/// reports every penetration, but not every pair closer than a margin: its plane–box and
/// capsule–box contacts within a margin were found missing in `tests/physics/motion_screen.rs`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Pair {
    /// The first shape (always a moving one).
    pub(super) a: u16,
    /// The second shape, after `a`.
    pub(super) b: u16,
    /// The distance the pair keeps for "free", metres.
    pub(super) gap: f64,
    /// The distance below which two exact shapes are "blocked" (negative: a depth), metres.
    pub(super) block: f64,
    /// The pair's lever-arm ratio ([`lever_ratio`](super::lever::lever_ratio)): its parts move
    /// relative to each other at most this fraction of the planner's lever-arm bound, so a
    /// clearance `c` beyond the gap vouches for `c / kappa` of that bound. In (0, 1].
    pub(super) kappa: f64,
}

/// The partner of an arm link in a [`Group`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Partner {
    /// A fixed shape (index into the screen's fixed shapes).
    Fixed(usize),
    /// Another arm link (0..6).
    Link(usize),
}

/// Consecutive pairs (`pairs[start..end]`) between the shapes of arm link `link` and one
/// partner. When the link's bounding sphere keeps `gap` (the largest of the pairs' gaps, metres)
/// from the partner's (a fixed shape's bounding sphere or half-space, or the other link's
/// sphere), every pair of the group does, and none needs testing.
#[derive(Clone, Copy, Debug)]
pub(super) struct Group {
    /// The arm link, 0..6.
    pub(super) link: usize,
    /// What its shapes are tested against.
    pub(super) partner: Partner,
    /// The largest gap of the group's pairs, metres.
    pub(super) gap: f64,
    /// The largest lever-arm ratio of the group's pairs.
    pub(super) kappa: f64,
    /// The group's first pair.
    pub(super) start: u32,
    /// One past the group's last pair.
    pub(super) end: u32,
}

impl Group {
    /// The joints that move the group's pairs relative to each other: every joint up to the
    /// link against a fixed shape, those after the nearer link up to the farther one against
    /// another link; `None` when none does (two shapes of one link).
    #[inline]
    pub(super) fn joints(&self) -> Option<JointRange> {
        match self.partner {
            Partner::Fixed(_) => JointRange::new(0, self.link),
            Partner::Link(m) => JointRange::new(self.link.min(m) + 1, self.link.max(m)),
        }
    }
}
