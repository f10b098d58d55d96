//! A synthetic collision model: named axis-aligned boxes in joint space. For tests and
//! benchmarks of the planner without physics; a configuration collides when it lies inside a box.

use super::checker::{Collision, CollisionChecker, FastChecks};

/// An obstacle in joint space: every configuration with `lo ≤ q ≤ hi` (radians, per joint) is
/// in collision.
#[derive(Clone, Debug, PartialEq)]
pub struct JointBox {
    /// Its name, reported as the second member of a [`Collision`] (the first is `arm`).
    pub name: String,
    /// Lower corner, radians.
    pub lo: [f64; 6],
    /// Upper corner, radians.
    pub hi: [f64; 6],
}

impl JointBox {
    /// A box named `name` from `lo` to `hi` (radians).
    pub fn new(name: &str, lo: [f64; 6], hi: [f64; 6]) -> Self {
        Self {
            name: name.to_string(),
            lo,
            hi,
        }
    }

    /// How deep `q` is inside the box grown by `margin` on every side, radians (the smallest
    /// distance to a face of the grown box, minus the margin: negative when only within the
    /// margin), or `None` if outside.
    pub fn depth(&self, q: &[f64; 6], margin: f64) -> Option<f64> {
        let mut d = f64::INFINITY;
        for ((v, lo), hi) in q.iter().zip(&self.lo).zip(&self.hi) {
            if *v < lo - margin || *v > hi + margin {
                return None;
            }
            d = d.min(v - lo).min(hi - v);
        }
        Some(d)
    }
}

/// A checker made of [`JointBox`]es, each grown by a clearance `margin`; counts the
/// configurations it is asked about.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointBoxes {
    /// The obstacles.
    pub boxes: Vec<JointBox>,
    /// Clearance, radians: a configuration closer than this to a box (in every joint) collides.
    /// With a margin of half the planner's edge resolution, every configuration *between* the
    /// checked ones is free of the boxes themselves.
    pub margin: f64,
    /// Configurations checked so far.
    pub checks: u64,
}

impl JointBoxes {
    /// A checker with these obstacles and no margin.
    pub fn new(boxes: Vec<JointBox>) -> Self {
        Self {
            boxes,
            margin: 0.0,
            checks: 0,
        }
    }

    /// The same obstacles with a clearance margin of `margin` radians.
    pub fn with_margin(mut self, margin: f64) -> Self {
        self.margin = margin;
        self
    }
}

impl CollisionChecker for JointBoxes {
    fn is_free(&mut self, q: &[f64; 6]) -> bool {
        self.checks += 1;
        self.boxes.iter().all(|b| b.depth(q, self.margin).is_none())
    }

    fn collisions(&mut self, q: &[f64; 6]) -> Vec<Collision> {
        self.boxes
            .iter()
            .filter_map(|b| {
                b.depth(q, self.margin).map(|d| Collision {
                    a: "arm".into(),
                    b: b.name.clone(),
                    distance: -d,
                })
            })
            .collect()
    }
}

impl FastChecks for JointBoxes {}
