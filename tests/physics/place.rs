//! `place` and `carry`'s set-down on real MuJoCo: a block set down at a point with a yaw, on top
//! of another block, refused or accepted by the finger-envelope check depending on which way the
//! fingers point, and `carry` into a container choosing spots its own descent check accepts (or
//! saying the container is full before it moves).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use macrotree::FailureKind;
use macrotree::actions::Cell;
use macrotree::episode::{EpisodeReport, Goal};
use macrotree::plan::Loader;
use macrotree::world::World;
use nalgebra::Vector2;

use crate::support::cell_run;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// Half a 44 mm block, metres.
const HALF: f64 = 0.022;

fn tempdir(name: &str) -> PathBuf {
    let dir = Path::new(ROOT)
        .join("target")
        .join(format!("place_action_{name}"));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `main` (the tree's body, YAML) on a scene whose `objects:` are `objects` (YAML), with
/// the tree's own outcome as success; the report and the cell in its final state.
fn run(name: &str, objects: &str, main: &str) -> (EpisodeReport, Cell) {
    run_with_spots(name, objects, main, &[])
}

/// [`run`], with `spots` written into the scene file's `spots:`.
fn run_with_spots(
    name: &str,
    objects: &str,
    main: &str,
    spots: &[macrotree::scene::Spot],
) -> (EpisodeReport, Cell) {
    let dir = tempdir(name);
    let spots: String = spots
        .iter()
        .map(|s| format!("  {}: [{}, {}, {}]\n", s.name, s.x, s.y, s.yaw))
        .collect();
    let spots = if spots.is_empty() {
        spots
    } else {
        format!("spots:\n{spots}")
    };
    let scene = format!("description: {name}\nobjects:\n{objects}{spots}");
    let tree = cell_run::write_cell_tree(&dir, &scene, main);
    let plan = Arc::new(
        Loader::default()
            .load(&tree)
            .unwrap_or_else(|d| panic!("{}", d[0])),
    );
    cell_run::run_plan(plan, Goal::Tree, 60.0, name)
}

/// The steps that pick `block` up (pre-shape, above, straight down, close), as sequence children
/// indented for `children:` at depth 3.
fn pick(block: &str) -> String {
    format!(
        "      - release: {{width: 0.065, retreat: 0}}\n      - reach: {{target: {block}, offset: [0, 0, 0.12]}}\n      - reach: {{target: {block}, path: cartesian}}\n      - grasp: {{object: {block}}}\n"
    )
}

fn sequence(children: &str) -> String {
    format!("  sequence:\n    children:\n{children}")
}

fn block(name: &str, x: f64, y: f64, yaw_deg: f64) -> String {
    format!("  {name}:\n    block: {{size: 0.044, color: red}}\n    pose: [{x}, {y}, deg({yaw_deg})]\n")
}

fn index(w: &World, name: &str) -> usize {
    w.index_of(name).unwrap()
}

/// Yaw error modulo a quarter turn, degrees.
fn yaw_error_deg(w: &World, i: usize, want_deg: f64) -> f64 {
    let q = 90.0;
    let d = w.yaw(i).to_degrees() - want_deg;
    ((d + q / 2.0).rem_euclid(q) - q / 2.0).abs()
}

fn assert_success(r: &EpisodeReport, what: &str) {
    assert!(
        r.outcome.success,
        "{what}: {:?} ({:?}) at {:?}",
        r.outcome.failure_reason, r.outcome.failure_kind, r.outcome.failed_node
    );
}

#[test]
fn place_at_a_point_with_a_yaw_lands_within_5_mm_and_3_degrees() {
    let objects = block("red", 0.45, -0.15, 0.0);
    let main = sequence(&format!(
        "{}      - place: {{point: [0.50, 0.10], yaw: deg(30)}}\n",
        pick("red")
    ));
    let (r, cell) = run("point_yaw", &objects, &main);
    assert_success(&r, "place at a point");
    let w = cell.world();
    let red = index(w, "red");
    let p = w.objects[red].pos;
    let off = (p.xy() - Vector2::new(0.50, 0.10)).norm();
    assert!(off < 0.005, "{:.1} mm from the point", off * 1e3);
    assert!((p.z - HALF).abs() < 0.003, "on the table: z {:.4} m", p.z);
    let e = yaw_error_deg(w, red, 30.0);
    assert!(e < 3.0, "yaw off by {e:.2}°");
    assert!(w.released(red), "the fingers let go");
    assert!(
        w.gripper_width > 0.05,
        "opened to let go: {:.3} m",
        w.gripper_width
    );
}

#[test]
fn place_at_a_spot_takes_its_point_and_its_yaw() {
    let spot = macrotree::scene::Spot {
        name: "kit_a".into(),
        x: 0.42,
        y: 0.14,
        yaw: (-20.0f64).to_radians(),
        on: None,
    };
    let objects = block("red", 0.45, -0.15, 10.0);
    let main = sequence(&format!("{}      - place: {{spot: kit_a}}\n", pick("red")));
    let (r, cell) = run_with_spots("spot", &objects, &main, &[spot]);
    assert_success(&r, "place at a spot");
    let w = cell.world();
    let red = index(w, "red");
    let off = (w.objects[red].pos.xy() - Vector2::new(0.42, 0.14)).norm();
    assert!(off < 0.005, "{:.1} mm from the spot", off * 1e3);
    let e = yaw_error_deg(w, red, -20.0);
    assert!(e < 3.0, "yaw off by {e:.2}°");
}

#[test]
fn place_on_another_block_builds_a_tower() {
    let objects = format!(
        "{}{}",
        block("red", 0.45, -0.15, 0.0),
        block("blue", 0.50, 0.10, 10.0)
    );
    let main = sequence(&format!(
        "{}      - place: {{point: [0.50, 0.10]}}\n",
        pick("red")
    ));
    let (r, cell) = run("tower", &objects, &main);
    assert_success(&r, "place on a block");
    let w = cell.world();
    let (red, blue) = (index(w, "red"), index(w, "blue"));
    let (p, b) = (w.objects[red].pos, w.objects[blue].pos);
    assert!(
        (p.xy() - b.xy()).norm() < 0.005,
        "centred on blue: {:.1} mm",
        (p.xy() - b.xy()).norm() * 1e3
    );
    assert!(
        (p.z - (w.top(blue) + HALF)).abs() < 0.003,
        "on blue's top: z {:.4} m, blue's top {:.4} m",
        p.z,
        w.top(blue)
    );
    assert!(w.released(red));
}

#[test]
fn place_at_a_point_over_a_container_sets_the_block_on_its_floor() {
    let objects = format!(
        "{}  bin:\n    container: {{inner: [0.15, 0.15], wall_height: 0.05, color: gray}}\n    pose: [0.50, 0.10]\n",
        block("red", 0.45, -0.15, 0.0)
    );
    let main = sequence(&format!(
        "{}      - place: {{point: [0.51, 0.09]}}\n",
        pick("red")
    ));
    let (r, cell) = run("into_bin", &objects, &main);
    assert_success(&r, "place over a bin");
    let w = cell.world();
    let (red, bin) = (index(w, "red"), index(w, "bin"));
    let p = w.objects[red].pos;
    assert!(w.inside(red, bin), "in the bin: {p:?}");
    assert!(
        (p.z - (w.support_height(bin) + HALF)).abs() < 0.003,
        "on its floor: z {:.4} m",
        p.z
    );
    assert!((p.xy() - Vector2::new(0.51, 0.09)).norm() < 0.005, "{p:?}");
}

/// Halted during its transfer, `place` leaves the arm where it is and the block in the closed
/// fingers (like `carry`).
#[test]
fn a_place_halted_mid_transfer_keeps_the_block_in_the_fingers() {
    let objects = block("red", 0.45, -0.15, 0.0);
    let main = sequence(&format!(
        "{}      - force_success: {{child: {{timeout: {{seconds: 1.1, child: {{place: {{point: [0.50, 0.10]}}}}}}}}}}\n      - wait: {{seconds: 1.0}}\n",
        pick("red")
    ));
    let (r, cell) = run("halted", &objects, &main);
    assert_success(&r, "the halted place is forced to success");
    let w = cell.world();
    let red = index(w, "red");
    assert!(w.holds(red, 0.03), "still held after the halt and 1 s of waiting");
    let p = w.objects[red].pos;
    assert!(p.z > HALF + 0.05, "still up in the air: {p:?}");
    assert!(
        (p.xy() - Vector2::new(0.50, 0.10)).norm() > 0.03
            && (p.xy() - Vector2::new(0.45, -0.15)).norm() > 0.03,
        "stopped on the way (the lift takes 0.75 s, then the transfer): {p:?}"
    );
}

/// The fingers' closing axis, world table plane, with `block` grasped as `pick` grasps it (the
/// tool's yaw follows the block's, so this is the axis a `place` with `yaw: keep` sets down with).
fn closing_axis_after_pick(block_yaw_deg: f64) -> Vector2<f64> {
    let objects = block("red", 0.45, -0.15, block_yaw_deg);
    let (r, cell) = run("closing_axis", &objects, &sequence(&pick("red")));
    assert_success(&r, "pick");
    let w = cell.world();
    (w.right_pad_pos - w.left_pad_pos).xy().normalize()
}

/// Blocks whose footprints are 41 mm from the place, on the lines through it along each of
/// `dirs`, and `red` placed there keeping the grasp's yaw (modulo a quarter turn); the report and
/// the fingers' closing axis at the end.
fn place_beside(name: &str, dirs: &[Vector2<f64>]) -> (EpisodeReport, Vector2<f64>) {
    let target = Vector2::new(0.50, 0.05);
    let mut objects = block("red", 0.45, -0.15, 0.0);
    for (i, d) in dirs.iter().enumerate() {
        let n = target + d * (0.041 + HALF);
        objects += &block(&format!("n{i}"), n.x, n.y, 0.0);
    }
    let main = sequence(&format!(
        "{}      - place: {{point: [{}, {}], yaw: keep}}\n",
        pick("red"),
        target.x,
        target.y
    ));
    let (r, cell) = run(name, &objects, &main);
    let w = cell.world();
    (r, (w.right_pad_pos - w.left_pad_pos).xy().normalize())
}

#[test]
fn place_is_refused_when_the_opened_fingers_would_hit_a_neighbour_in_every_quarter_turn() {
    let closing = closing_axis_after_pick(0.0);
    let across = Vector2::new(-closing.y, closing.x);
    let (r, _) = place_beside("refused", &[closing, across]);
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::Blocked),
        "{:?}",
        r.outcome.failure_reason
    );
    let reason = r.outcome.failure_reason.unwrap_or_default();
    assert!(
        reason.contains("no clear way down") && reason.contains("would hit n"),
        "{reason}"
    );
    assert_eq!(r.outcome.failed_node.as_deref(), Some("main/sequence/place"));
}

#[test]
fn place_is_accepted_with_the_same_neighbour_beside_the_fingers_open_side() {
    let closing = closing_axis_after_pick(0.0);
    let across = Vector2::new(-closing.y, closing.x);
    let (r, end) = place_beside("accepted", &[across]);
    assert_success(&r, "neighbour across the closing axis, 41 mm away");
    assert!(
        end.dot(&across).abs() < 0.1,
        "the fingers still close across the neighbour's line"
    );
}

/// With the neighbour on the fingers' closing axis the transfer is planned with the tool a
/// quarter turn round (a cube looks the same), and the set-down is made with the neighbour
/// beside the fingers' open side.
#[test]
fn a_neighbour_on_the_closing_axis_turns_the_fingers_a_quarter_turn() {
    let closing = closing_axis_after_pick(0.0);
    let (r, end) = place_beside("turned", &[closing]);
    assert_success(&r, "neighbour along the closing axis, 41 mm away");
    assert!(
        end.dot(&closing).abs() < 0.1,
        "the fingers turned: closing axis {end:?}, neighbour along {closing:?}"
    );
}

/// The bug: in a 0.20 m bin `carry` chose a free spot that its own descent check then refused.
/// Three blocks carried into one, one after the other: each carry's spot is one its descent
/// check accepts, and all three end up in the bin.
#[test]
fn carry_chose_a_free_spot_in_a_020_m_bin_that_its_own_descent_check_refused() {
    let objects = format!(
        "{}{}{}  bin:\n    container: {{inner: [0.20, 0.20], wall_height: 0.05, color: gray}}\n    pose: [0.50, 0.12]\n",
        block("a", 0.40, -0.20, 0.0),
        block("b", 0.50, -0.20, 20.0),
        block("c", 0.60, -0.20, -15.0),
    );
    let mut steps = String::new();
    for b in ["a", "b", "c"] {
        steps += &pick(b);
        steps += "      - carry: {to: bin, lift: 0.15}\n      - release: {retreat: 0.10}\n";
    }
    let (r, cell) = run("bin_020", &objects, &sequence(&steps));
    assert_success(&r, "three blocks into a 0.20 m bin");
    let w = cell.world();
    let bin = index(w, "bin");
    for b in ["a", "b", "c"] {
        assert!(
            w.inside(index(w, b), bin),
            "{b} in the bin: {:?}",
            w.objects[index(w, b)].pos
        );
    }
}

/// The bug: a deep bin (0.12 m walls, the scene format's maximum) holding one block "could not
/// take" a second one held at 40° to it: the opened hand, diagonal across the bin, reached a wall
/// or the first block from every spot. Set down square to the bin, both fit. (Found in a
/// 0.21 m bin; there, since the servos' inertia feed-forward, the first block lands 0.4 mm from
/// where it did and one diagonal spot just fits, so the test uses 0.20 m, where none does.)
#[test]
fn a_deep_bin_could_not_take_a_second_block_held_diagonally() {
    let objects = format!(
        "{}{}  bin:\n    container: {{inner: [0.20, 0.20], wall_height: 0.12, color: gray}}\n    pose: [0.50, 0.14]\n",
        block("a", 0.40, -0.20, 0.0),
        block("b", 0.55, -0.20, 40.0),
    );
    let mut steps = String::new();
    for b in ["a", "b"] {
        steps += &pick(b);
        steps += "      - carry: {to: bin, lift: 0.20}\n      - release: {width: 0.08, retreat: 0.15}\n";
    }
    let (r, cell) = run("deep_bin_square", &objects, &sequence(&steps));
    assert_success(&r, "two blocks into a deep 0.20 m bin");
    assert!(r.outcome.collisions.is_empty(), "{:?}", r.outcome.collisions);
    let w = cell.world();
    let bin = index(w, "bin");
    for b in ["a", "b"] {
        assert!(
            w.inside(index(w, b), bin),
            "{b} in the bin: {:?}",
            w.objects[index(w, b)].pos
        );
    }
    let e = yaw_error_deg(w, index(w, "b"), 0.0);
    assert!(e < 5.0, "b set down square to the bin: {e:.1}° off");
}

/// A 0.12 m bin with one block in it cannot take another with the fingers opened beside it:
/// the carry says so before the block leaves the table, naming the bin and what is in it.
#[test]
fn carry_into_a_full_container_fails_before_moving() {
    let objects = format!(
        "{}{}  bin:\n    container: {{inner: [0.12, 0.12], wall_height: 0.05, color: gray}}\n    pose: [0.50, 0.12]\n",
        block("a", 0.40, -0.20, 0.0),
        block("b", 0.55, -0.20, 0.0),
    );
    let steps = format!(
        "{}      - carry: {{to: bin, lift: 0.15}}\n      - release: {{retreat: 0.10}}\n{}      - carry: {{to: bin, lift: 0.15}}\n",
        pick("a"),
        pick("b")
    );
    let (r, cell) = run("bin_full", &objects, &sequence(&steps));
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::ContainerFull),
        "{:?}",
        r.outcome.failure_reason
    );
    let reason = r.outcome.failure_reason.clone().unwrap_or_default();
    assert!(
        reason.contains("bin cannot take b") && reason.contains("it holds a"),
        "{reason}"
    );
    assert!(
        r.outcome
            .failed_node
            .as_deref()
            .is_some_and(|n| n.contains("carry")),
        "{:?}",
        r.outcome.failed_node
    );
    let w = cell.world();
    let b = w.objects[index(w, "b")].pos;
    assert!(
        (b.xy() - Vector2::new(0.55, -0.20)).norm() < 0.01 && b.z < HALF + 0.005,
        "b never left the table: {b:?}"
    );
    assert!(w.inside(index(w, "a"), index(w, "bin")));
}

/// `place` takes a point or a spot (not both, not neither) and an angle or `keep` for its yaw;
/// each mistake is a located error that says what to write.
#[test]
fn place_parameters_are_checked_where_they_are_written() {
    let cases = [
        (
            "main:\n  place: {point: [0.5, 0.1], spot: kit_a}\n",
            "not both",
            2,
        ),
        ("main:\n  place: {yaw: deg(30)}\n", "`place` needs where", 2),
        (
            "main:\n  place: {point: [0.5, 0.1], yaw: object}\n",
            "not a place yaw",
            2,
        ),
        (
            "main:\n  place: {spot: Kit-A}\n",
            "not a name of an object or a spot",
            2,
        ),
        ("main:\n  place: {point: [0.5]}\n", "wrong number of items", 2),
        (
            "main:\n  place: {point: [0.5, 0.1], lift: -1}\n",
            "must be ≥ 0",
            2,
        ),
    ];
    for (yaml, needle, line) in cases {
        let Err(diags) = Loader::default().compile_str(yaml, "bad.yaml") else {
            panic!("accepted:\n{yaml}");
        };
        let d = diags
            .iter()
            .find(|d| d.message.contains(needle))
            .unwrap_or_else(|| panic!("no diagnostic with {needle:?} for {yaml}: {diags:?}"));
        assert_eq!(d.line, line, "{d}");
    }
    let dir = tempdir("params_ok");
    std::fs::write(
        dir.join("cell.yaml"),
        format!(
            "objects:\n{}spots:\n  kit_a: [0.45, 0.1]\n",
            block("red", 0.45, -0.15, 0.0)
        ),
    )
    .unwrap();
    let tree = dir.join("ok.yaml");
    std::fs::write(
        &tree,
        "scene: cell.yaml\nmain:\n  place: {spot: kit_a, yaw: keep, retreat: 0.05}\n",
    )
    .unwrap();
    Loader::default()
        .load(&tree)
        .expect("a place at a spot, keeping the yaw, compiles");
}
