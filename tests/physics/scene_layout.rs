//! Cells with height and layout: objects raised with `z:`, blocks that start on or inside other
//! objects (`on:`, `random: {in|on: ..}`), named spots, keep-out and allowed regions, and overlap
//! on oriented footprints — located errors for each key, property checks of the sampler over
//! many seeds, the shipped layout scenes, and the heights on real MuJoCo.

use std::path::Path;

use macrotree::scene::{Placement, SceneSpec, load_scene_file, sample_placement, support_of};
use macrotree::sim::{Scene, Sim};
use macrotree::spec::Diagnostic;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn scene(text: &str) -> SceneSpec {
    SceneSpec::from_str(text, "cell.yaml").unwrap_or_else(|d| panic!("{}", d[0]))
}

fn scene_errors(text: &str) -> Vec<Diagnostic> {
    SceneSpec::from_str(text, "cell.yaml").expect_err("the scene is invalid")
}

/// The one diagnostic whose message contains `needle`.
fn find(diags: &[Diagnostic], needle: &str) -> Diagnostic {
    diags
        .iter()
        .find(|d| d.message.contains(needle))
        .cloned()
        .unwrap_or_else(|| panic!("no diagnostic with {needle:?} in {diags:#?}"))
}

fn shipped(name: &str) -> SceneSpec {
    load_scene_file(&Path::new(ROOT).join("scenes").join(name)).unwrap_or_else(|d| panic!("{}", d[0]))
}

/// Object `name`'s pose in `p`.
fn pose(s: &SceneSpec, p: &Placement, name: &str) -> macrotree::scene::Pose {
    p.poses[s.index_of(name).unwrap()]
}

const BIN_TEXT: &str = "objects:
  bin_a:
    container: {inner: [0.20, 0.20], wall_height: 0.06}
    random: {x: [0.40, 0.52], y: [-0.25, -0.15], clearance: 0.02}
  red:
    block: {size: 0.04}
    random: {in: bin_a, yaw: [deg(-45), deg(45)], clearance: 0.02}
  green:
    block: {size: 0.04}
    random: {in: bin_a, yaw: [deg(-45), deg(45)], clearance: 0.02}
  blue:
    block: {size: 0.04}
    random: {x: [0.3, 0.6], y: [-0.3, 0.3], clearance: 0.02}
";

#[test]
fn blocks_drawn_in_a_randomized_bin_lie_on_its_floor_inside_the_walls_for_every_seed() {
    let s = scene(BIN_TEXT);
    let bin = s.index_of("bin_a").unwrap();
    for k in 0..300 {
        let (_, p) = sample_placement(&s, 7, k).unwrap();
        p.check(&s).unwrap();
        let b = p.poses[bin];
        for name in ["red", "green"] {
            let q = pose(&s, &p, name);
            assert_eq!(q.z, b.z + 0.01, "{name} rests on the floor's top");
            // The block's corners stay 2 cm inside the 0.10 m half-width.
            let corners = (0..4).map(|c| {
                let a = q.yaw + c as f64 * std::f64::consts::FRAC_PI_2 + std::f64::consts::FRAC_PI_4;
                let r = 0.02 * 2f64.sqrt();
                [q.x + r * a.cos() - b.x, q.y + r * a.sin() - b.y]
            });
            for [dx, dy] in corners {
                assert!(
                    dx.abs() <= 0.08 + 1e-9 && dy.abs() <= 0.08 + 1e-9,
                    "scenario {k}: {name} corner at ({dx}, {dy})"
                );
            }
        }
        let (r, g) = (pose(&s, &p, "red"), pose(&s, &p, "green"));
        assert!(r.distance(&g) >= 2.0 * 0.02 * 2f64.sqrt() + 0.02 - 1e-9);
        assert_eq!(pose(&s, &p, "blue").z, 0.0);
    }
    // The draw is a pure function of (seed, scenario).
    assert_eq!(
        sample_placement(&s, 7, 11).unwrap(),
        sample_placement(&s, 7, 11).unwrap()
    );
}

#[test]
fn an_obstacle_the_arm_at_home_stands_in_is_refused_at_its_pose() {
    let pinch = macrotree::motion::fk(&macrotree::motion::HOME_Q)
        .translation
        .vector;
    let cell = |height: f64| {
        SceneSpec::from_str(
            &format!(
                "objects:\n  red: {{block: {{size: 0.04}}, pose: [0.45, 0.0]}}\n  post:\n    obstacle: {{size: [0.06, 0.06, {height}]}}\n    pose: [{:.3}, {:.3}]\n",
                pinch.x, pinch.y
            ),
            "cell.yaml",
        )
    };
    // A post under the gripper, up past its pinch point: every episode would start inside it.
    let d = cell(0.40).expect_err("the arm at home stands in the post");
    let e = find(&d, "stands where the arm rests at home");
    assert_eq!((e.line, e.column), (5, 11), "located at the post's pose: {e}");
    assert!(e.message.contains("its gripper"), "{e}");
    assert!(
        e.help.as_deref().unwrap().contains("clear of the arm at home"),
        "{e}"
    );
    // A low one under the hanging gripper is fine.
    cell(0.20).expect("a post below the gripper at home");
    // Randomized, the draws keep clear of the arm: every drawn pose of the post is outside it.
    let s = SceneSpec::from_str(
        &format!(
            "objects:\n  red: {{block: {{size: 0.04}}, pose: [0.45, 0.0]}}\n  post:\n    obstacle: {{size: [0.06, 0.06, 0.40]}}\n    random: {{x: [{:.3}, 0.30], y: [0.0, {:.3}]}}\n",
            pinch.x, pinch.y
        ),
        "cell.yaml",
    )
    .expect("the region has room clear of the arm");
    // (Without the check, about 1 draw in 60 would put the gripper's axis inside the post.)
    for k in 0..400 {
        let (_, p) = sample_placement(&s, 3, k).unwrap();
        let post = p.poses[1];
        assert!(
            (post.x - pinch.x).abs().max((post.y - pinch.y).abs()) >= 0.03,
            "scenario {k}: the post drawn around the gripper at ({}, {})",
            post.x,
            post.y
        );
    }
}

#[test]
fn overlapping_fixed_objects_are_told_to_move_one_not_to_widen_random_regions() {
    // Two fixed objects (no `random:`, no clearance) whose footprints meet.
    let d = scene_errors(
        "objects:\n  bowl: {container: {inner: [0.14, 0.14], wall_height: 0.05}, pose: [0.45, 0.05]}\n  wall: {obstacle: {size: [0.30, 0.02, 0.25]}, pose: [0.45, 0.0]}\n",
    );
    let e = find(&d, "overlap");
    let help = e.help.as_deref().unwrap();
    assert!(help.contains("both have fixed poses"), "{help}");
    assert!(!help.contains("random") && !help.contains("0.000 m"), "{help}");
    // A randomized block too close to a fixed wall keeps the advice about its region.
    let d = scene_errors(
        "objects:\n  wall: {obstacle: {size: [0.30, 0.02, 0.25]}, pose: [0.45, 0.0]}\n  red:\n    block: {size: 0.04}\n    pose: [0.45, 0.05]\n    random: {x: [0.44, 0.46], y: [0.04, 0.06], clearance: 0.08}\n",
    );
    let e = d
        .iter()
        .find(|d| d.help.as_deref().is_some_and(|h| h.contains("`red`")))
        .unwrap_or_else(|| panic!("{d:#?}"));
    assert!(
        e.help
            .as_deref()
            .unwrap()
            .contains("widen their `random:` regions"),
        "{e}"
    );
}

#[test]
fn a_random_region_inside_a_bin_is_refused_with_help_to_start_the_block_in_it() {
    // The old way: an x/y region inside the bin, without saying the block starts in it. It still
    // is refused (the block would stand in the bin's walls' footprint as if on the table), but the
    // message names the pair and the help says how to start a block inside.
    let d = scene_errors(
        "objects:\n  bin: {container: {inner: [0.20, 0.20]}, pose: [0.45, 0.0]}\n  red:\n    block: {size: 0.04}\n    random: {x: [0.42, 0.48], y: [-0.03, 0.03]}\n",
    );
    let e = find(&d, "the randomization cannot be met");
    assert!(e.message.contains("`red` and `bin`"), "{e}");
    assert!(e.message.contains("100 %"), "every draw failed on that pair: {e}");
    let help = e.help.as_deref().unwrap();
    assert!(
        help.contains("random: {in: bin}") && !help.contains("widen"),
        "{help}"
    );
    assert_eq!(e.line, 5, "located at red's `random:`: {e}");
    // The new way works.
    let s = scene(
        "objects:\n  bin: {container: {inner: [0.20, 0.20]}, pose: [0.45, 0.0]}\n  red:\n    block: {size: 0.04}\n    random: {in: bin}\n",
    );
    let (_, p) = sample_placement(&s, 0, 0).unwrap();
    assert_eq!(p.poses[1].z, 0.01);
}

#[test]
fn a_fixed_pose_inside_a_bin_needs_on_and_is_refused_with_that_help() {
    // Without `on:` the fixed pose is refused with the way to say it…
    let d = scene_errors(
        "objects:\n  bin: {container: {inner: [0.20, 0.20]}, pose: [0.45, 0.0]}\n  red: {block: {size: 0.04}, pose: [0.47, 0.02]}\n",
    );
    let e = find(&d, "overlap");
    assert!(e.help.as_deref().unwrap().contains("on: bin"), "{e}");
    // …and with it, the block starts on the floor.
    let s = scene(
        "objects:\n  bin: {container: {inner: [0.20, 0.20]}, pose: [0.45, 0.0]}\n  red: {block: {size: 0.04}, pose: [0.47, 0.02], on: bin}\n",
    );
    let p = Placement::fixed(&s).unwrap();
    assert_eq!(p.poses[1].z, 0.01);
    // A fixed pose on the bin that pokes through its wall names the support.
    let d = scene_errors(
        "objects:\n  bin: {container: {inner: [0.20, 0.20]}, pose: [0.45, 0.0]}\n  red: {block: {size: 0.04}, pose: [0.54, 0.0], on: bin}\n",
    );
    let e = find(&d, "does not lie on `bin`");
    assert_eq!(e.line, 3);
}

#[test]
fn an_unmeetable_randomization_names_the_constraint_most_draws_broke() {
    // Three blocks with 5 cm clearance cannot share a 0.12 m bin.
    let d = scene_errors(
        "objects:\n  bin: {container: {inner: [0.12, 0.12]}, pose: [0.45, 0.0]}\n  a: {block: {size: 0.04}, random: {in: bin, clearance: 0.05}}\n  b: {block: {size: 0.04}, random: {in: bin, clearance: 0.005}}\n  c: {block: {size: 0.04}, random: {in: bin, clearance: 0.005}}\n",
    );
    let e = find(&d, "does not fit");
    assert!(e.message.contains("`a`") && e.message.contains("`bin`"), "{e}");
    assert_eq!(e.line, 3);
    let d = scene_errors(
        "objects:\n  bin: {container: {inner: [0.08, 0.08]}, pose: [0.45, 0.0]}\n  a: {block: {size: 0.04}, random: {in: bin, clearance: 0.005}}\n  b: {block: {size: 0.04}, random: {in: bin, clearance: 0.005}}\n",
    );
    let e = find(&d, "the randomization cannot be met");
    assert!(
        e.message.contains("`a` and `b`") || e.message.contains("`b` and `a`"),
        "{e}"
    );
    assert!(e.help.as_deref().unwrap().contains("clearance"), "{e}");
}

#[test]
fn a_thin_wall_is_an_oriented_footprint_not_a_disc() {
    // A 0.30 × 0.02 m wall and a block 4 cm beside it: the old circle test (0.15 m disc) refused
    // it; the footprints are 0.03 m apart.
    let s = scene(
        "objects:\n  wall: {obstacle: {size: [0.30, 0.02, 0.25]}, pose: [0.45, 0.0]}\n  red: {block: {size: 0.04}, pose: [0.45, -0.05]}\n",
    );
    Placement::fixed(&s).unwrap().check(&s).unwrap();
    // Turned 90° the wall runs through the block.
    let d = scene_errors(
        "objects:\n  wall: {obstacle: {size: [0.30, 0.02, 0.25]}, pose: [0.45, 0.0, deg(90)]}\n  red: {block: {size: 0.04}, pose: [0.45, -0.05]}\n",
    );
    find(&d, "overlap");
    // Random blocks beside the wall keep their clearance to its rectangle, over many seeds.
    let s = shipped("wall_cell.yaml");
    let (w, c) = (s.index_of("wall").unwrap(), s.index_of("cube").unwrap());
    // The scene keeps the block 0.08 m from the wall's rectangle (room for the wrist); the old
    // 0.15 m disc around the wall's centre would have kept it at least 0.15 m + its own radius
    // away.
    let mut closest = f64::INFINITY;
    for k in 0..500 {
        let (_, p) = sample_placement(&s, 3, k).unwrap();
        let gap = s.objects[w]
            .shape
            .footprint(&p.poses[w])
            .gap(&s.objects[c].shape.footprint(&p.poses[c]));
        assert!(gap >= 0.08 - 1e-9, "scenario {k}: {gap}");
        let (dx, dy) = (p.poses[c].x - p.poses[w].x, p.poses[c].y - p.poses[w].y);
        closest = closest.min(dx.hypot(dy));
    }
    assert!(
        closest < 0.15,
        "blocks are drawn near the wall (closest centre {closest} m from the wall's), inside its old 0.15 m disc"
    );
}

#[test]
fn keep_out_regions_stay_empty_and_allowed_regions_hold_their_objects() {
    let s = scene(
        "objects:
  a: {block: {size: 0.04}, random: {x: [0.3, 0.6], y: [-0.3, 0.3], clearance: 0.01}}
  b: {block: {size: 0.04}, random: {region: left, yaw: [deg(-45), deg(45)]}}
  c: {block: {size: 0.04}, random: {region: [left, right]}}
regions:
  middle: {x: [0.35, 0.55], y: [-0.1, 0.1], role: keep_out}
  left: {x: [0.30, 0.45], y: [0.15, 0.30], role: allowed}
  right: {x: [0.30, 0.45], y: [-0.30, -0.15], role: allowed}
",
    );
    let middle = s.region("middle").unwrap().rect();
    let left = s.region("left").unwrap().rect();
    let right = s.region("right").unwrap().rect();
    for k in 0..400 {
        let (_, p) = sample_placement(&s, 1, k).unwrap();
        for (i, o) in s.objects.iter().enumerate() {
            assert!(
                !middle.overlaps(&o.shape.footprint(&p.poses[i])),
                "scenario {k}: {} in middle",
                o.name
            );
        }
        assert!(left.margin_inside(&s.objects[1].shape.footprint(&p.poses[1])) >= -1e-9);
        let fc = s.objects[2].shape.footprint(&p.poses[2]);
        assert!(left.margin_inside(&fc) >= -1e-9 || right.margin_inside(&fc) >= -1e-9);
    }
}

#[test]
fn blocks_on_a_shelf_board_start_on_its_top() {
    let s = shipped("shelf.yaml");
    let low = s.index_of("shelf_low").unwrap();
    let top = s.index_of("shelf_top").unwrap();
    for k in 0..200 {
        let (_, p) = sample_placement(&s, 0, k).unwrap();
        for name in ["low_a", "low_b"] {
            let i = s.index_of(name).unwrap();
            assert_eq!(support_of(&s, i), Some(low));
            assert!((p.poses[i].z - 0.12).abs() < 1e-12, "{name} at {}", p.poses[i].z);
            let m = s.objects[low]
                .shape
                .footprint(&p.poses[low])
                .margin_inside(&s.objects[i].shape.footprint(&p.poses[i]));
            assert!(
                m >= -1e-9,
                "scenario {k}: {name} hangs over the board's edge by {m}"
            );
        }
        assert!((pose(&s, &p, "top_a").z - 0.24).abs() < 1e-12);
        assert!((p.poses[top].z - 0.22).abs() < 1e-12);
        assert_eq!(pose(&s, &p, "table_a").z, 0.0);
    }
    // The lower board's blocks are under the upper board: a top-down grasp is blocked.
    let p = Placement::fixed(&s).unwrap();
    let a = pose(&s, &p, "low_a");
    assert!(
        s.objects[top]
            .shape
            .footprint(&p.poses[top])
            .distance_to_point([a.x, a.y])
            == 0.0
    );
    assert!(
        p.poses[top].z - (a.z + 0.04) < 0.1,
        "less than 10 cm above the block's top"
    );
}

#[test]
fn every_new_key_has_a_located_error() {
    // `z:` on a block, out of range on an obstacle.
    let e = find(
        &scene_errors("objects:\n  red: {block: {size: 0.04}, pose: [0.45, 0], z: 0.1}\n"),
        "takes no `z",
    );
    assert_eq!((e.line, e.column), (2, 50));
    let e = find(
        &scene_errors(
            "objects:\n  red: {block: {size: 0.04}, pose: [0.45, 0.2]}\n  board: {obstacle: {size: [0.1, 0.1, 0.02]}, pose: [0.45, 0], z: 0.9}\n",
        ),
        "height of a base",
    );
    assert_eq!(e.line, 3);
    // `on:` an unknown object, on a container, on itself, in a cycle.
    let e = find(
        &scene_errors(
            "objects:\n  red: {block: {size: 0.04}, pose: [0.45, 0], on: shelff}\n  shelf: {obstacle: {size: [0.1, 0.1, 0.02]}, pose: [0.45, 0.2]}\n",
        ),
        "unknown object `shelff`",
    );
    assert_eq!(e.help.as_deref(), Some("did you mean `shelf`?"));
    find(
        &scene_errors(
            "objects:\n  red: {block: {size: 0.04}, pose: [0.45, 0.2]}\n  bin: {container: {inner: [0.1, 0.1]}, pose: [0.45, 0], on: red}\n",
        ),
        "only blocks take `on:`",
    );
    find(
        &scene_errors("objects:\n  red: {block: {size: 0.04}, pose: [0.45, 0], on: red}\n"),
        "cannot rest on itself",
    );
    find(
        &scene_errors(
            "objects:\n  a: {block: {size: 0.04}, pose: [0.45, 0], on: b}\n  b: {block: {size: 0.04}, pose: [0.45, 0], on: a}\n",
        ),
        "through others, on itself",
    );
    // `random: {in: ..}` with x/y, both in and on, a fixed block on a randomized bin.
    let e = find(
        &scene_errors(
            "objects:\n  bin: {container: {inner: [0.2, 0.2]}, pose: [0.45, 0]}\n  red: {block: {size: 0.04}, random: {in: bin, x: [0.4, 0.5]}}\n",
        ),
        "drawn over `bin`",
    );
    assert_eq!(e.line, 3);
    find(
        &scene_errors(
            "objects:\n  bin: {container: {inner: [0.2, 0.2]}, pose: [0.45, 0]}\n  red: {block: {size: 0.04}, random: {in: bin, on: bin}}\n",
        ),
        "not both",
    );
    find(
        &scene_errors(
            "objects:\n  bin: {container: {inner: [0.2, 0.2]}, random: {x: [0.4, 0.5], y: [0, 0.1]}}\n  red: {block: {size: 0.04}, pose: [0.45, 0.05], on: bin}\n",
        ),
        "which sweeps place at random",
    );
    find(
        &scene_errors("objects:\n  red: {block: {size: 0.04}, random: {x: [0.4, 0.5]}}\n"),
        "has no `y:` range",
    );
    // Spots: out of reach, bad shape, a name taken by an object.
    let base = "objects:\n  red: {block: {size: 0.04}, pose: [0.45, 0]}\n";
    let e = find(
        &scene_errors(&format!("{base}spots:\n  far: [0.9, 0.0]\n")),
        "spot `far`",
    );
    assert_eq!(e.line, 4);
    find(
        &scene_errors(&format!("{base}spots:\n  p: [0.4]\n")),
        "2 or 3 numbers",
    );
    find(
        &scene_errors(&format!("{base}spots:\n  red: [0.4, 0.1]\n")),
        "already used",
    );
    // Regions: bad range, unknown role, unknown or keep-out region named by a random.
    let e = find(
        &scene_errors(&format!(
            "{base}regions:\n  r: {{x: [0.5, 0.4], y: [0, 0.1], role: keep_out}}\n"
        )),
        "lo < hi",
    );
    assert_eq!(e.line, 4);
    scene_errors(&format!(
        "{base}regions:\n  r: {{x: [0.4, 0.5], y: [0, 0.1], role: keepout}}\n"
    ));
    find(
        &scene_errors(
            "objects:\n  red: {block: {size: 0.04}, random: {region: lft}}\nregions:\n  left: {x: [0.3, 0.5], y: [0.1, 0.3], role: allowed}\n",
        ),
        "unknown region `lft`",
    );
    find(
        &scene_errors(
            "objects:\n  red: {block: {size: 0.04}, random: {region: no}}\nregions:\n  no: {x: [0.3, 0.5], y: [0.1, 0.3], role: keep_out}\n",
        ),
        "keep-out region, not an allowed one",
    );
    // A keep-out region that covers the whole random range: the region is named.
    let e = find(
        &scene_errors(
            "objects:\n  red: {block: {size: 0.04}, random: {x: [0.4, 0.5], y: [0.0, 0.1]}}\nregions:\n  no: {x: [0.3, 0.6], y: [-0.1, 0.2], role: keep_out}\n",
        ),
        "keep-out region `no`",
    );
    assert!(e.help.as_deref().unwrap().contains("`no`"));
}

#[test]
fn spots_load_in_file_order_with_their_yaw() {
    let s = shipped("kitting.yaml");
    let names: Vec<&str> = s.spots.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["kit_1", "kit_2", "kit_3", "kit_4"]);
    let k = s.spot("kit_4").unwrap();
    assert_eq!((k.x, k.y), (0.52, 0.22));
    assert!((k.yaw - 30f64.to_radians()).abs() < 1e-12);
}

#[test]
fn every_layout_scene_loads_and_draws_200_valid_placements() {
    for name in [
        "shelf.yaml",
        "go_around.yaml",
        "bin_to_bin.yaml",
        "kitting.yaml",
        "swap.yaml",
        "tower_four.yaml",
        "wall_cell.yaml",
    ] {
        let s = shipped(name);
        if let Some(p) = Placement::fixed(&s) {
            p.check(&s).unwrap();
        }
        if !s.randomized() {
            continue;
        }
        for k in 0..200 {
            let (_, p) = sample_placement(&s, 0, k).unwrap_or_else(|e| panic!("{name} scenario {k}: {e}"));
            p.check(&s).unwrap_or_else(|e| panic!("{name} scenario {k}: {e}"));
        }
    }
}

/// Object `name`'s body position in the simulation, metres.
fn body_pos(sim: &Sim, name: &str) -> [f64; 3] {
    let i = sim.scene().spec.index_of(name).unwrap();
    sim.data().xpos()[sim.scene().objects[i].body]
}

#[test]
fn raised_objects_and_blocks_on_a_shelf_start_where_declared_and_stay_at_rest_on_mujoco() {
    let mut spec = shipped("shelf.yaml");
    // Add a raised bin with a block in it, to cover containers with height.
    let extra = scene(
        "objects:
  stand: {obstacle: {size: [0.12, 0.12, 0.08]}, pose: [0.32, -0.26]}
  high_bin: {container: {inner: [0.10, 0.10], wall_height: 0.05}, pose: [0.32, -0.26, deg(20)], z: 0.08}
  in_high: {block: {size: 0.03}, pose: [0.33, -0.25, deg(20)], on: high_bin}
",
    );
    spec.objects.retain(|o| o.name != "table_a");
    spec.objects.extend(extra.objects);
    let spec = SceneSpec::from_str(&serde_yaml_text(&spec), "shelf_plus.yaml")
        .unwrap_or_else(|d| panic!("{}", d[0]));
    let scene = Scene::load_spec(&spec).expect("compiles");
    let mut sim = Sim::new(&scene);
    let placement = Placement::fixed(&spec).unwrap();
    placement.check(&spec).unwrap();
    sim.reset_placement(&placement);
    let expect = |name: &str| {
        let p = pose(&spec, &placement, name);
        let o = spec.object(name).unwrap();
        let dz = match o.shape {
            macrotree::scene::Shape::Block { half, .. } => half,
            _ => 0.0,
        };
        [p.x, p.y, p.z + dz]
    };
    let names = [
        "shelf_low",
        "shelf_top",
        "high_bin",
        "low_a",
        "low_b",
        "top_a",
        "in_high",
    ];
    for n in names {
        let got = body_pos(&sim, n);
        let want = expect(n);
        for k in 0..3 {
            assert!(
                (got[k] - want[k]).abs() < 1e-9,
                "{n} starts at {got:?}, declared {want:?}"
            );
        }
    }
    assert!((expect("in_high")[2] - (0.08 + 0.01 + 0.015)).abs() < 1e-12);
    for _ in 0..1000 {
        sim.step(); // 2 s
    }
    assert!(sim.instability().is_none());
    for n in ["low_a", "low_b", "top_a", "in_high"] {
        let got = body_pos(&sim, n);
        let want = expect(n);
        let moved =
            ((got[0] - want[0]).powi(2) + (got[1] - want[1]).powi(2) + (got[2] - want[2]).powi(2)).sqrt();
        assert!(
            moved < 0.002,
            "{n} moved {moved} m in 2 s: from {want:?} to {got:?}"
        );
    }
    let w = sim.observe();
    let (b, c) = (w.index_of("in_high").unwrap(), w.index_of("high_bin").unwrap());
    assert_eq!(w.container_of(b), Some(c), "the block is in the raised bin");
    assert!(w.at_rest(b, 0.01));
}

/// `spec` written back as scene YAML (objects with their poses, heights and supports).
fn serde_yaml_text(spec: &SceneSpec) -> String {
    use macrotree::scene::Shape;
    let mut t = String::from("objects:\n");
    for o in &spec.objects {
        let kind = match &o.shape {
            Shape::Block { half, .. } => format!("block: {{size: {}}}", 2.0 * half),
            Shape::Container {
                inner_half,
                wall_height,
            } => format!(
                "container: {{inner: [{}, {}], wall_height: {wall_height}}}",
                2.0 * inner_half[0],
                2.0 * inner_half[1]
            ),
            Shape::Obstacle { half } => format!(
                "obstacle: {{size: [{}, {}, {}]}}",
                2.0 * half[0],
                2.0 * half[1],
                2.0 * half[2]
            ),
        };
        let p = o.pose.unwrap();
        t += &format!("  {}: {{{kind}, pose: [{}, {}, {}]", o.name, p.x, p.y, p.yaw);
        if o.z != 0.0 {
            t += &format!(", z: {}", o.z);
        }
        if let Some(s) = &o.on {
            t += &format!(", on: {s}");
        }
        t += "}\n";
    }
    t
}
