//! An episode observer that records every control period's command and the physics state
//! after it (for replays that must match bit for bit).

#![allow(dead_code)]

use macrotree::actions::Cell;
use macrotree::episode::EpisodeObserver;
use macrotree::motion::CellCommand;
use macrotree::runtime::TreeRunner;

/// Every control period's command (in full precision) and the physics state after it.
#[derive(Default)]
pub struct Commands {
    /// The command of each control period, in order.
    pub commands: Vec<CellCommand>,
    /// The state fingerprint after each control period.
    pub states: Vec<Vec<u64>>,
}

impl EpisodeObserver for Commands {
    fn on_period_start(&mut self, _cell: &Cell, command: &CellCommand, _runner: &mut TreeRunner) {
        self.commands.push(*command);
    }
    fn on_tick(&mut self, cell: &Cell, _runner: &mut TreeRunner) {
        self.states.push(cell.sim().state_fingerprint());
    }
}
