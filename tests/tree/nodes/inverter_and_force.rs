//! `inverter`, `force_success` and `force_failure`.

use super::*;

#[test]
fn inverter_and_force_decorators() {
    for (yaml, leaf, expected) in [
        (
            "main: {inverter: {child: {cube_in_bowl: {}}}}",
            Success,
            TreeStatus::Failure,
        ),
        (
            "main: {inverter: {child: {cube_in_bowl: {}}}}",
            fail("x"),
            TreeStatus::Success,
        ),
        (
            "main: {force_success: {child: {cube_in_bowl: {}}}}",
            fail("x"),
            TreeStatus::Success,
        ),
        (
            "main: {force_success: {child: {cube_in_bowl: {}}}}",
            Success,
            TreeStatus::Success,
        ),
        (
            "main: {force_failure: {child: {cube_in_bowl: {}}}}",
            Success,
            TreeStatus::Failure,
        ),
        (
            "main: {force_failure: {child: {cube_in_bowl: {}}}}",
            fail("x"),
            TreeStatus::Failure,
        ),
    ] {
        let p = plan(yaml);
        let mut d = ScriptedDriver::new(&p);
        d.set("cube_in_bowl", leaf.clone());
        let mut r = TreeRunner::new(p);
        assert_eq!(run(&mut r, &mut d, 5), (expected, 1), "{yaml} with {leaf:?}");
    }
}
