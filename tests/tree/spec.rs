//! YAML format: valid trees, subtrees and includes, and located diagnostics for invalid ones.

use std::path::Path;

use macrotree::kinds::{Carry, Grasp, Leaf, MoveJoints, PathKind, Reach, Target, Yaw};
use macrotree::plan::Loader;
use macrotree::spec::Diagnostic;

fn errors(yaml: &str) -> Vec<Diagnostic> {
    match Loader::default().compile_str(yaml, "bad.yaml") {
        Ok(_) => panic!("expected errors for:\n{yaml}"),
        Err(d) => d,
    }
}

/// The one diagnostic whose message contains `needle`.
fn find<'a>(diags: &'a [Diagnostic], needle: &str) -> &'a Diagnostic {
    let found: Vec<&Diagnostic> = diags.iter().filter(|d| d.message.contains(needle)).collect();
    assert!(
        found.len() == 1,
        "expected one diagnostic containing {needle:?}, got:\n{}",
        diags
            .iter()
            .map(|d| d.to_string())
            .collect::<Vec<_>>()
            .join("\n\n")
    );
    found[0]
}

fn at(d: &Diagnostic) -> (u32, u32) {
    (d.line, d.column)
}

#[test]
fn fixture_with_include_and_subtrees_compiles() {
    let plan = Loader::default()
        .load(Path::new("tests/fixtures/trees/pick_place.yaml"))
        .unwrap_or_else(|d| {
            panic!(
                "{}",
                d.iter().map(|d| d.to_string()).collect::<Vec<_>>().join("\n")
            );
        });
    let paths: Vec<&str> = plan.leaves.iter().map(|l| l.path.as_str()).collect();
    assert_eq!(
        paths,
        [
            "main/sequence[pick and place]/home#1",
            "main/sequence[pick and place]/retry/sequence[attempt]/subtree[pick]/sequence[pick the cube]/reach#1",
            "main/sequence[pick and place]/retry/sequence[attempt]/subtree[pick]/sequence[pick the cube]/reach#2",
            "main/sequence[pick and place]/retry/sequence[attempt]/subtree[pick]/sequence[pick the cube]/grasp",
            "main/sequence[pick and place]/retry/sequence[attempt]/subtree[pick]/sequence[pick the cube]/cube_grasped",
            "main/sequence[pick and place]/retry/sequence[attempt]/subtree[place]/sequence[place]/guard/cube_grasped",
            "main/sequence[pick and place]/retry/sequence[attempt]/subtree[place]/sequence[place]/guard/carry",
            "main/sequence[pick and place]/retry/sequence[attempt]/subtree[place]/sequence[place]/release",
            "main/sequence[pick and place]/retry/sequence[attempt]/subtree[place]/sequence[place]/cube_in_bowl",
            "main/sequence[pick and place]/home#2",
        ]
    );
    let Some(r) = plan.leaves[1].kind.params::<Reach>() else {
        panic!("not a reach")
    };
    assert_eq!(r.offset, [0.0, 0.0, 0.12], "argument overrides the default");
    assert_eq!(r.yaw, Yaw::Object, "default argument");
    assert_eq!(r.speed, 0.5, "leaf default");
    let Some(r2) = plan.leaves[2].kind.params::<Reach>() else {
        panic!("not a reach")
    };
    assert_eq!(r2.path, PathKind::Cartesian);
    // Node sources point into the library file.
    let carry = plan.node_by_path(paths[6]).unwrap();
    assert!(
        plan.nodes[carry].source.ends_with("lib/pick_place.yaml:24:23"),
        "{}",
        plan.nodes[carry].source
    );
    assert!(plan.nodes.iter().all(|n| !n.path.is_empty()));
}

#[test]
fn includes_that_include_each_other_are_loaded_once() {
    let plan = Loader::default()
        .load(Path::new("tests/fixtures/trees/include_cycle.yaml"))
        .unwrap();
    assert_eq!(plan.leaves.len(), 1);
}

#[test]
fn missing_include_is_located_at_the_include_entry() {
    let d = Loader::default()
        .load(Path::new("tests/fixtures/trees/bad/missing_include.yaml"))
        .unwrap_err();
    let e = find(&d, "cannot include");
    assert_eq!(at(e), (1, 11));
    assert!(e.file.ends_with("missing_include.yaml"));
}

#[test]
fn duplicate_subtree_across_files_is_an_error() {
    let d = Loader::default()
        .load(Path::new("tests/fixtures/trees/bad/dup_subtree.yaml"))
        .unwrap_err();
    let e = find(&d, "defined twice");
    assert!(e.file.ends_with("bad/lib/dup.yaml"), "{e}");
    assert_eq!(at(e), (2, 3));
    assert!(e.note.as_deref().unwrap().contains("dup_subtree.yaml:4:3"), "{e}");
}

#[test]
fn angles_in_degrees_and_radians() {
    let plan = Loader::default().compile_str(
        "main:\n  sequence:\n    children:\n      - move_joints: {joints: [0, deg(-90), rad(1.5), -1.57, deg(90), 0]}\n      - reach: {target: [0.5, 0, 0.3], yaw: deg(45)}\n      - at_home: {tolerance: deg(2)}\n",
        "t.yaml",
    )
    .unwrap();
    let Some(m) = plan.leaves[0].kind.params::<MoveJoints>() else {
        panic!()
    };
    assert!((m.joints[1] + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert_eq!(m.joints[2], 1.5);
    assert_eq!(m.joints[3], -1.57);
    let Some(r) = plan.leaves[1].kind.params::<Reach>() else {
        panic!()
    };
    assert_eq!(r.target, Target::Point([0.5, 0.0, 0.3]));
    assert!(matches!(r.yaw, Yaw::Angle(a) if (a - std::f64::consts::FRAC_PI_4).abs() < 1e-12));
}

#[test]
fn defaults_are_filled_in() {
    let plan = Loader::default()
        .compile_str(
            "main: {sequence: {children: [{carry: {}}, {grasp: }, {release: {retreat: 0.05}}]}}",
            "t.yaml",
        )
        .unwrap();
    let Some(c) = plan.leaves[0].kind.params::<Carry>() else {
        panic!()
    };
    assert_eq!(
        (c.to, c.lift, c.place_height, c.speed, c.timeout),
        (Target::Bowl, 0.20, 0.03, 0.5, 10.0)
    );
    let Some(g) = plan.leaves[1].kind.params::<Grasp>() else {
        panic!()
    };
    assert_eq!((g.width, g.timeout), (None, 2.0));
}

#[test]
fn unknown_node_kind_suggests_the_closest() {
    let d = errors("main:\n  sequnce:\n    children: [{home: {}}]\n");
    let e = find(&d, "unknown node kind `sequnce`");
    assert_eq!(at(e), (2, 3));
    assert_eq!(e.help.as_deref(), Some("did you mean `sequence`?"));
}

#[test]
fn unknown_leaf_parameter_is_located_at_the_key() {
    let d = errors("main:\n  sequence:\n    children:\n      - reach: {targt: cube}\n");
    let e = find(&d, "unknown parameter `targt`");
    assert_eq!(at(e), (4, 17));
    assert_eq!(e.help.as_deref(), Some("did you mean `target`?"));
    assert!(e.message.ends_with("in `reach`"), "{}", e.message);
}

#[test]
fn every_bad_parameter_of_one_leaf_is_reported_at_once() {
    // Three mistakes in one `reach`, one in the next: four diagnostics, in source order, and no
    // spurious "missing parameter `target`" for the misspelled target value.
    let d = errors(
        "main:\n  sequence:\n    children:\n      - reach: {target: cubee, ofset: [0, 0, 0.1], speed: .nan}\n      - grasp: {force: 1}\n",
    );
    let found: Vec<(u32, u32)> = d.iter().map(at).collect();
    assert_eq!(found, [(4, 25), (4, 32), (4, 59), (5, 17)], "{d:?}");
    find(&d, "unknown target `cubee`");
    assert_eq!(
        find(&d, "unknown parameter `ofset`").help.as_deref(),
        Some("did you mean `offset`?")
    );
    find(&d, "must be a finite number");
    find(&d, "unknown parameter `force`");
    assert!(
        !d.iter().any(|e| e.message.contains("missing parameter")),
        "{d:?}"
    );
}

#[test]
fn a_missing_parameter_is_reported_with_the_bad_ones() {
    let d = errors("main:\n  reach: {ofset: [0, 0, 0.1], sped: 1}\n");
    let messages: Vec<&str> = d.iter().map(|e| e.message.as_str()).collect();
    assert_eq!(
        messages,
        [
            "missing parameter `target` in `reach`",
            "unknown parameter `ofset` in `reach`",
            "unknown parameter `sped` in `reach`",
        ]
    );
}

#[test]
fn a_duplicate_key_is_named_and_located_at_the_second() {
    let d = errors("main:\n  sequence:\n    name: top\n    name: again\n    children: [home: {}]\n");
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0].message, "`name` is given twice in this mapping");
    assert_eq!(at(&d[0]), (4, 5));
}

#[test]
fn wrong_type_is_located_at_the_value() {
    let d = errors("main:\n  reach:\n    target: cube\n    speed: fast\n");
    let e = find(&d, "wrong type");
    assert_eq!(at(e), (4, 12));
    assert_eq!(e.label.as_deref(), Some("expected a number"), "{e}");
}

#[test]
fn missing_leaf_parameter_is_reported() {
    let d = errors("main:\n  reach: {offset: [0, 0, 0.1]}\n");
    let e = find(&d, "missing parameter `target`");
    assert_eq!(at(e), (2, 10));
}

#[test]
fn invalid_numbers_are_errors() {
    let d = errors(
        "main:\n  sequence:\n    children:\n      - retry: {attempts: 0, child: {home: {}}}\n      - timeout: {seconds: -1, child: {home: {}}}\n      - reach: {target: cube, speed: 0}\n      - wait: {seconds: .inf}\n      - repeat: {times: 2.5, child: {home: {}}}\n      - reach: {target: [0.1, 0.2]}\n",
    );
    assert_eq!(at(find(&d, "`attempts` must be between 1")), (4, 27));
    assert_eq!(at(find(&d, "time limit (s) must be > 0")), (5, 28));
    assert_eq!(at(find(&d, "speed (m/s) must be > 0")), (6, 38));
    assert_eq!(at(find(&d, "must be a finite number")), (7, 25));
    assert_eq!(at(find(&d, "`times` must be an integer")), (8, 25));
    assert_eq!(at(find(&d, "wrong number of items")), (9, 25));
    assert_eq!(d.len(), 6, "all errors of the file are reported at once");
}

#[test]
fn empty_composite_is_an_error() {
    let d = errors("main:\n  sequence:\n    children: []\n");
    let e = find(&d, "`sequence` has no children");
    assert_eq!(at(e), (3, 15));
}

#[test]
fn node_with_two_kinds_is_an_error() {
    let d = errors("main:\n  sequence:\n    children:\n      - home: {}\n        name: x\n");
    let e = find(&d, "exactly one kind");
    assert_eq!(at(e), (4, 9));
    assert!(e.help.as_deref().unwrap().contains("put `name:` inside"));
}

#[test]
fn subtree_argument_errors_are_located() {
    let src = "subtrees:\n  pick:\n    params: {approach: ~, speed: 0.5}\n    root: {reach: {target: cube, offset: [0, 0, $approach], speed: $speed}}\nmain:\n  sequence:\n    children:\n      - subtree: {ref: pick}\n      - subtree: {ref: pick, args: {approach: 0.1, sped: 1}}\n      - subtree: {ref: pick, args: {approach: 0.1, speed: -2}}\n      - subtree: {ref: pikc, args: {approach: 0.1}}\n";
    let d = errors(src);
    let e = find(&d, "missing argument `approach`");
    assert_eq!(at(e), (8, 9));
    let e = find(&d, "unknown argument `sped`");
    assert_eq!(at(e), (9, 52));
    assert_eq!(e.help.as_deref(), Some("did you mean `speed`?"));
    let e = find(&d, "speed (m/s) must be > 0");
    assert_eq!(at(e), (10, 59), "points at the argument value");
    assert!(e.note.as_deref().unwrap().contains("bad.yaml:4:68"), "{e}");
    let e = find(&d, "undefined subtree `pikc`");
    assert_eq!(at(e), (11, 24));
    assert_eq!(e.help.as_deref(), Some("did you mean `pick`?"));
}

#[test]
fn undefined_and_misplaced_params_are_errors() {
    let src = "subtrees:\n  pick:\n    params: {approach: 0.1}\n    root: {reach: {target: cube, offset: [0, 0, $aproach]}}\nmain:\n  sequence:\n    children:\n      - subtree: {ref: pick}\n      - wait: {seconds: $delay}\n";
    let d = errors(src);
    let e = find(&d, "undefined parameter `$aproach`");
    assert_eq!(at(e), (4, 49));
    assert_eq!(e.help.as_deref(), Some("did you mean `$approach`?"));
    let e = find(&d, "`$delay` is used outside a subtree");
    assert_eq!(at(e), (9, 25));
    // Regression: the `$name` left in place was reported a second time, as a wrong type.
    assert_eq!(d.len(), 2, "{d:#?}");
}

#[test]
fn whole_offset_can_be_a_parameter() {
    let src = "subtrees:\n  above:\n    params: {off: [0, 0, 0.2]}\n    root: {reach: {target: bowl, offset: $off}}\nmain: {subtree: {ref: above, args: {off: [0.1, 0, 0.3]}}}\n";
    let plan = Loader::default().compile_str(src, "t.yaml").unwrap();
    let Some(r) = plan.leaves[0].kind.params::<Reach>() else {
        panic!()
    };
    assert_eq!(r.offset, [0.1, 0.0, 0.3]);
}

#[test]
fn recursive_subtrees_are_errors() {
    let src = "subtrees:\n  a: {root: {sequence: {children: [{home: {}}, {subtree: {ref: b}}]}}}\n  b: {root: {subtree: {ref: a}}}\nmain: {subtree: {ref: a}}\n";
    let d = errors(src);
    assert!(
        d.iter()
            .any(|e| e.message.contains("recursive subtree: a → b → a")),
        "{d:?}"
    );
}

#[test]
fn reactive_sequence_needs_conditions_before_the_last_child() {
    let d = errors("main:\n  reactive_sequence:\n    children: [{home: {}}, {carry: {}}]\n");
    let e = find(&d, "only the last child may be `home`");
    assert_eq!(at(e), (3, 17));
}

#[test]
fn guard_condition_must_be_a_condition() {
    let d = errors("main:\n  guard:\n    condition: {home: {}}\n    child: {carry: {}}\n");
    let e = find(&d, "guard's condition must be a condition leaf");
    assert_eq!(at(e), (3, 17));
}

#[test]
fn unknown_target_and_yaw_are_explained() {
    let d = errors(
        "main:\n  sequence:\n    children:\n      - reach: {target: cub}\n      - reach: {target: cube, yaw: objet}\n",
    );
    let e = find(&d, "unknown target `cub`");
    assert_eq!(at(e), (4, 25));
    assert!(e.message.contains("did you mean `cube`?"));
    let e = find(&d, "unknown yaw `objet`");
    assert_eq!(at(e), (5, 36));
}

#[test]
fn yaml_syntax_error_is_located() {
    let d = errors("main:\n  sequence: {children: [{home: {}}\n");
    assert_eq!(d.len(), 1);
    assert!(d[0].message.starts_with("invalid YAML"), "{}", d[0]);
    assert!(d[0].line >= 2, "{}", d[0]);
}

#[test]
fn missing_main_and_unknown_top_level_keys() {
    let d = errors("subtree:\n  x: {root: {home: {}}}\n");
    let e = find(&d, "unknown top-level key `subtree`");
    assert_eq!(at(e), (1, 1));
    assert_eq!(e.help.as_deref(), Some("did you mean `subtrees`?"));
    find(&d, "no `main:` tree");
}

/// `breakpoints:` is a list of text entries, each located when malformed (its patterns are
/// matched against the tree by `validate` and `run --view`).
#[test]
fn breakpoints_are_a_list_of_located_text_entries() {
    let plan = macrotree::plan::Loader::default()
        .compile_str(
            "main: {home: {}}\nbreakpoints: [\"main/home\", \"main/home@after\"]\n",
            "bp.yaml",
        )
        .unwrap();
    let written: Vec<(&str, u32, u32)> = plan
        .breakpoints
        .iter()
        .map(|b| (b.text.as_str(), b.line, b.column))
        .collect();
    assert_eq!(written, [("main/home", 2, 15), ("main/home@after", 2, 28)]);
    let d = errors("main: {home: {}}\nbreakpoints: 3\n");
    assert_eq!(at(find(&d, "`breakpoints` must be a list")), (2, 14));
    let d = errors("main: {home: {}}\nbreakpoints: [main/home, {a: 1}]\n");
    assert_eq!(at(find(&d, "a breakpoint must be text")), (2, 26));
}

#[test]
fn calling_a_subtree_by_its_name_as_a_kind_gets_help() {
    let d = errors("subtrees:\n  pick: {root: {home: {}}}\nmain: {pick: {}}\n");
    let e = find(&d, "unknown node kind `pick`");
    assert_eq!(
        e.help.as_deref(),
        Some("`pick` is a subtree: call it with `subtree: {ref: pick}`")
    );
}

#[test]
fn unused_subtrees_with_defaults_are_checked_too() {
    let d = errors("subtrees:\n  unused: {root: {grasp: {widht: 0.1}}}\nmain: {home: {}}\n");
    let e = find(&d, "unknown parameter `widht`");
    assert_eq!(at(e), (2, 27));
}

#[test]
fn diagnostic_display_is_rustc_like() {
    let d = errors("main:\n  sequence:\n    children:\n      - reach: {targt: cube}\n");
    assert_eq!(
        d[0].to_string(),
        "error: unknown parameter `targt` in `reach`\n --> bad.yaml:4:17\n  |\n4 |       - reach: {targt: cube}\n  |                 ^^^^^ expected one of `target`, `offset`, `yaw`, `path`, `approach`, `speed`, `timeout`, `max_checks`, `plan_time_cap` or `name`\n  = help: did you mean `target`?"
    );
}

/// Regression: with YAML 1.1 booleans, a parameter named `off` (or `on`, `yes`, `no`) was read as
/// the boolean `false` and rejected as "invalid parameter name".
#[test]
fn regression_yaml11_boolean_words_are_plain_names() {
    let src = "subtrees:\n  s:\n    params: {off: 0.1, on: 0.2, yes: 0.3, no: 0.4}\n    root: {reach: {target: cube, offset: [$off, $on, $yes]}}\nmain: {subtree: {ref: s, args: {no: 1}}}\n";
    let plan = Loader::default().compile_str(src, "t.yaml").unwrap();
    let Some(r) = plan.leaves[0].kind.params::<Reach>() else {
        panic!()
    };
    assert_eq!(r.offset, [0.1, 0.2, 0.3]);
}

/// Regression: `.inf` was rejected by the YAML reader with a misleading "fix the YAML syntax"
/// help; it must reach the parameter check, which explains the problem.
#[test]
fn regression_non_finite_numbers_reach_the_parameter_check() {
    let d = errors("main: {timeout: {seconds: .nan, child: {home: {}}}}\n");
    let e = find(&d, "must be a finite number");
    assert_eq!(at(e), (1, 27));
}

#[test]
fn condition_tolerances_are_overridable_and_checked() {
    use macrotree::kinds::{CubeGrasped, CubeInBowl};
    let yaml = "main:\n  sequence:\n    children:\n      - cube_grasped: {off_axis: 0.01}\n      - cube_in_bowl: {rest_speed: 0.02}\n      - cube_in_bowl: {}\n";
    let plan = Loader::default().compile_str(yaml, "t.yaml").unwrap();
    let conds: Vec<&Leaf> = plan
        .leaves
        .iter()
        .map(|l| &l.kind)
        .filter(|l| l.is_condition())
        .collect();
    assert!(matches!(conds[0].params::<CubeGrasped>(), Some(c) if c.off_axis == 0.01));
    assert!(matches!(conds[1].params::<CubeInBowl>(), Some(c) if c.rest_speed == 0.02));
    // Omitted tolerances are the condition module's defaults.
    let default = macrotree::world::conditions::Tolerances::REST_SPEED;
    assert!(matches!(conds[2].params::<CubeInBowl>(), Some(c) if c.rest_speed == default));

    let diags = errors("main:\n  cube_in_bowl: {rest_speed: 0}\n");
    let d = find(&diags, "speed");
    assert_eq!(at(d), (2, 30), "{d}");
}

#[test]
fn out_of_range_numbers_are_located_errors() {
    // Each coordinate and joint angle is in range on its own (a single one out of range is
    // reported at itself, see tests/tree/common_mistakes.rs); the whole is not.
    let yaml = "main:\n  sequence:\n    children:\n      - release: {width: 0.2}\n      - move_joints: {joints: [0, 0, 3.5, 0, 0, 0]}\n      - carry: {lift: 15}\n      - reach: {target: [1.0, 0.9, 0.5]}\n      - reach: {target: cube, offset: [0.9, 0.9, 0.9]}\n      - reach: {target: [0.4, 0, -0.1]}\n";
    let diags = errors(yaml);
    assert_eq!(diags.len(), 6, "one error per bad value, all at once");
    assert_eq!(at(find(&diags, "gripper opening")), (4, 26));
    assert!(find(&diags, "gripper opening").message.contains("0.08513"));
    assert_eq!(at(find(&diags, "joint 3 (`elbow`)")), (5, 31));
    assert_eq!(at(find(&diags, "a distance of 15 m")), (6, 23));
    assert_eq!(at(find(&diags, "from the shoulder")), (7, 25));
    assert_eq!(at(find(&diags, "an offset of 1.559 m")), (8, 39));
    assert_eq!(at(find(&diags, "below the table top")), (9, 25));
    // A value written as a one-line list is underlined whole: `[0.9, 0.9, 0.9]`, `[0.4, 0, -0.1]`.
    assert_eq!(find(&diags, "an offset of 1.559 m").width, 15);
    assert_eq!(find(&diags, "below the table top").width, 14);
    for d in &diags {
        assert!(d.to_string().contains("bad.yaml:"), "{d}");
    }
}

#[test]
fn control_nodes_read_their_typed_parameters_with_located_errors() {
    let d = errors(
        "main:\n  sequence:\n    children:\n      - retry: {attempts: 3}\n      - timeout: {seconds: 0, child: {hom: {}}}\n      - inverter: {children: [home: {}]}\n      - for_each: {as: 3b, max_iterations: 2, child: {home: {}}}\n",
    );
    let e = find(&d, "missing parameter `child` in `retry`");
    assert_eq!(at(e), (4, 16));
    assert_eq!(
        e.help.as_deref(),
        Some("e.g. `retry: {attempts: 3, child: {subtree: {ref: pick}}}`"),
        "the help is the kind's documented example"
    );
    assert_eq!(at(find(&d, "a time limit (s) must be > 0")), (5, 28));
    // A bad parameter does not hide the mistakes of the node's child.
    assert_eq!(at(find(&d, "unknown node kind `hom`")), (5, 39));
    let e = find(&d, "unknown parameter `children` in `inverter`");
    assert_eq!(e.help.as_deref(), Some("did you mean `child`?"));
    assert_eq!(at(find(&d, "`3b` is not a variable name")), (7, 24));
    assert_eq!(
        d.len(),
        5,
        "no second error for the `child` the misspelled key was suggested as: {d:#?}"
    );
}

#[test]
fn a_node_name_with_the_dataset_label_separator_is_refused_at_the_name() {
    // A dataset joins the paths of leaves running at once with ` | `: a name holding `|` would
    // make such a label ambiguous.
    let d = errors(
        "main:\n  parallel:\n    children:\n      - wait: {seconds: 1, name: a | b}\n      - wait: {seconds: 1}\n",
    );
    let e = find(&d, "invalid node name `a | b`");
    assert_eq!((e.line, e.column), (4, 34), "{e}");
    assert!(e.label.as_deref().unwrap_or("").contains('|'), "{e}");
}
