//! Faults injected through real physics (never by faking the state), to rehearse what a real
//! cell meets: see [`FaultKind`]. A fault is a [`StepObserver`] installed in the cell for one
//! episode; its randomness comes from the episode seed.

use crate::actions::StepObserver;

/// The faults `run --fault` and `sweep --fault` can inject.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultKind {
    /// During the first carry the cube is knocked out of the grasp (placeholder: not yet injected).
    Slip,
}

/// The observer that injects `kind` in an episode seeded with `seed`.
pub fn injector(kind: FaultKind, seed: u64) -> Box<dyn StepObserver> {
    let _ = (kind, seed);
    Box::new(NoFault)
}

struct NoFault;
impl StepObserver for NoFault {
    fn before_step(&mut self, _sim: &mut crate::sim::Sim) {}
}
