//! Faults injected through real physics (never by faking the state), to rehearse what a real
//! cell meets: see [`FaultKind`] and `docs/faults.md`. A fault is a [`StepObserver`] installed
//! in the cell for one episode; it fires at most once, and its timing, direction and magnitude
//! come from the episode seed (the same seed gives the same fault, bit for bit).
//!
//! Every fault acts through MuJoCo: an external force on the cube body (`xfrc_applied`) for a
//! few physics steps, or a kinematic move of the bowl's mocap body. The model (shared between
//! workers through an `Arc`) is never modified.

mod bump;
mod late_bowl;
mod noise;
mod nudge;
mod push;
mod slip;

use std::sync::{Arc, Mutex};

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{RngCore, SeedableRng};

use crate::actions::StepObserver;
use crate::kinds::ActionRole;
use crate::sim::Sim;
use crate::world::World;

pub use bump::Bump;
pub use late_bowl::LateBowl;
pub use noise::{ActionNoise, MAX_GRIPPER_SIGMA, MAX_JOINT_SIGMA, NOISE_HOLD_S};
pub use nudge::Nudge;
pub use slip::Slip;

/// The faults `run --fault` and `sweep --fault` can inject.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultKind {
    /// During the first carry, shortly after the cube is lifted, a downward blow knocks it out
    /// of the fingers and it falls to the table.
    Slip,
    /// Just before the gripper first closes, the cube is pushed 2–4 cm along the table.
    Nudge,
    /// While the arm makes its first approach, the cube is knocked 3–6 cm along the table, away
    /// from the bowl (a bumped table).
    Bump,
    /// During the first carry, the bowl slides 3–6 cm to a new place (a tray on a conveyor).
    LateBowl,
}

impl FaultKind {
    /// Every fault.
    pub const ALL: [FaultKind; 4] = [
        FaultKind::Slip,
        FaultKind::Nudge,
        FaultKind::Bump,
        FaultKind::LateBowl,
    ];

    /// The name used on the command line (`slip`, `nudge`, `bump`, `late_bowl`).
    pub fn name(self) -> &'static str {
        match self {
            FaultKind::Slip => "slip",
            FaultKind::Nudge => "nudge",
            FaultKind::Bump => "bump",
            FaultKind::LateBowl => "late_bowl",
        }
    }

    /// The generator a fault of this kind draws from in an episode seeded with `seed`: ChaCha8
    /// seeded with `seed`, on a stream of its own per kind.
    pub fn rng(self, seed: u64) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(0xfa17_0000 + self as u64);
        rng
    }
}

impl std::str::FromStr for FaultKind {
    type Err = String;

    /// Reads a fault's command-line name (`slip`, `nudge`, `bump`, `late_bowl`).
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.into_iter().find(|k| k.name() == s).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|k| k.name()).collect();
            format!("unknown fault `{s}`: expected one of {}", names.join(", "))
        })
    }
}

impl std::fmt::Display for FaultKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What an injected fault did, for tests and logs.
#[derive(Debug, Clone, PartialEq)]
pub struct FaultEvent {
    /// The fault.
    pub kind: FaultKind,
    /// Simulated time it fired, seconds.
    pub time: f64,
    /// What it did, in words.
    pub detail: String,
}

/// A shared record of the fault's firing: read it after the episode.
pub type FaultLog = Arc<Mutex<Option<FaultEvent>>>;

/// The observer that injects `kind` in an episode seeded with `seed`.
pub fn injector(kind: FaultKind, seed: u64) -> Box<dyn StepObserver> {
    injector_with_log(kind, seed).0
}

/// The observer that injects `kind` in an episode seeded with `seed`, and a log that says
/// whether and when it fired.
pub fn injector_with_log(kind: FaultKind, seed: u64) -> (Box<dyn StepObserver>, FaultLog) {
    let log = FaultLog::default();
    let mut rng = kind.rng(seed);
    let fault: Box<dyn Fault> = match kind {
        FaultKind::Slip => Box::new(Slip::new(&mut rng)),
        FaultKind::Nudge => Box::new(Nudge::new(&mut rng)),
        FaultKind::Bump => Box::new(Bump::new(&mut rng)),
        FaultKind::LateBowl => Box::new(LateBowl::new(&mut rng)),
    };
    let injector = Injector {
        kind,
        fault,
        log: log.clone(),
    };
    (Box::new(injector), log)
}

/// One fault's behaviour: the hooks of [`StepObserver`], returning a description when it fires.
trait Fault: Send {
    /// Before a physics step; `Some(detail)` on the step the fault fires.
    fn before_step(&mut self, sim: &mut Sim) -> Option<String>;
    /// A macro action playing `role` starts.
    fn on_action_start(&mut self, role: ActionRole, world: &World);
}

/// Wraps a [`Fault`]: logs its firing (tracing target `macrotree::fault`) and records it.
struct Injector {
    kind: FaultKind,
    fault: Box<dyn Fault>,
    log: FaultLog,
}

impl StepObserver for Injector {
    fn before_step(&mut self, sim: &mut Sim) {
        if let Some(detail) = self.fault.before_step(sim) {
            let time = sim.time();
            tracing::info!(target: "macrotree::fault", fault = self.kind.name(), sim_time = time, "fault {}: {detail}", self.kind);
            let mut log = self.log.lock().unwrap_or_else(|e| e.into_inner());
            log.get_or_insert(FaultEvent {
                kind: self.kind,
                time,
                detail,
            });
        }
    }

    fn on_action_start(&mut self, _kind: &str, role: ActionRole, world: &World) {
        self.fault.on_action_start(role, world);
    }
}

/// A uniform float in `[lo, hi)` from the top 53 bits of a draw (the same on every platform).
fn uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * ((rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64))
}
