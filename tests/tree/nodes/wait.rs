//! `wait`: simulated time counted, leftover time passed on.

use super::*;

#[test]
fn wait_counts_simulated_time_and_passes_leftover_dt_on() {
    let p = plan("main: {sequence: {children: [{wait: {seconds: 0.25}}, {home: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    let mut r = TreeRunner::new(p.clone());
    // 0.1 + 0.1 + 0.1 ≥ 0.25: done on tick 3, and `home` runs in that same tick.
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Success, 3));
    assert_eq!(d.ticks("home"), 1);
}
