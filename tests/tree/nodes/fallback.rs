//! `fallback`: children tried in order until one succeeds.

use super::*;

#[test]
fn fallback_tries_children_until_one_succeeds() {
    let p = plan("main: {fallback: {children: [{cube_in_bowl: {}}, {home: {}}, {release: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    d.set("cube_in_bowl", fail("no"));
    d.script("home", [Running, Success]);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Success, 2));
    assert_eq!(
        d.ticks("cube_in_bowl"),
        1,
        "fallback has memory: the failed check is not re-run"
    );
    assert_eq!(d.ticks("release"), 0);

    let mut d = ScriptedDriver::new(&p);
    d.set_default(fail("nope"));
    let mut r = TreeRunner::new(p);
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Failure, 1));
    assert_eq!(ticked_paths(&d), ["cube_in_bowl", "home", "release"]);
}
