//! `repeat`: the child run N times, one tick apart.

use super::*;

#[test]
fn repeat_runs_child_n_times_one_tick_apart() {
    let p = plan("main: {repeat: {times: 3, child: {grasp: {}}}}");
    let mut d = ScriptedDriver::new(&p);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 20), (TreeStatus::Success, 3));
    assert_eq!(d.starts("grasp"), 3);

    let mut d = ScriptedDriver::new(&p);
    d.script("grasp", [Success, fail("dropped")]);
    let mut r = TreeRunner::new(p);
    assert_eq!(run(&mut r, &mut d, 20), (TreeStatus::Failure, 2));
    assert_eq!(d.starts("grasp"), 2);
}
