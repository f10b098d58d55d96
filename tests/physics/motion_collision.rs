//! The planner's MuJoCo collision checker (`sim::collision::SceneChecker`) and the planner on it,
//! on the real cell: the unmodified Menagerie UR5e + 2F-85, the table, a tall post.

use std::sync::OnceLock;

use macrotree::motion::plan::{CollisionChecker, GoalSet, PlanFailure, PlannerConfig, check_segment, plan};
use macrotree::motion::{Trajectory, down_pose, fk, ik};
use macrotree::scene::SceneSpec;
use macrotree::sim::{DEFAULT_MARGIN, HOME_Q, Scene, SceneChecker, Sim};
use nalgebra::Vector3;

fn cube_bowl() -> &'static Scene {
    static SCENE: OnceLock<Scene> = OnceLock::new();
    SCENE.get_or_init(|| Scene::load().expect("scene (run tools/bootstrap)"))
}

/// A cell with a 30 cm post at (0.45, 0) between a cube on the right and a bin on the left.
fn post_scene() -> &'static Scene {
    static SCENE: OnceLock<Scene> = OnceLock::new();
    SCENE.get_or_init(|| {
        let yaml = "
objects:
  cube:
    block: {size: 0.044}
    pose: [0.45, -0.25]
  bin:
    container: {inner: [0.12, 0.12], wall_height: 0.06}
    pose: [0.45, 0.27]
  post:
    obstacle: {size: [0.06, 0.06, 0.30]}
    pose: [0.45, 0.0]
goal:
  - in: {object: cube, container: bin}
";
        let spec = SceneSpec::from_str(yaml, "post.yaml").expect("valid scene");
        Scene::load_spec(&spec).expect("scene (run tools/bootstrap)")
    })
}

fn checker(scene: &Scene, margin: f64) -> SceneChecker {
    let sim = Sim::new(scene);
    SceneChecker::from_sim(&sim, margin).unwrap()
}

/// The pinch pointing down at (x, y, z), nearest branch to home.
fn down(x: f64, y: f64, z: f64) -> [f64; 6] {
    ik(&down_pose(&Vector3::new(x, y, z), 0.0), &HOME_Q).unwrap()
}

#[test]
fn home_is_free_with_and_without_margin() {
    for scene in [cube_bowl(), post_scene()] {
        for margin in [0.0, DEFAULT_MARGIN, 0.02] {
            let mut c = checker(scene, margin);
            assert!(c.is_free(&HOME_Q), "margin {margin}: {:?}", c.collisions(&HOME_Q));
            assert!(c.collisions(&HOME_Q).is_empty());
        }
    }
}

#[test]
fn the_arm_pushed_into_the_table_collides_and_names_the_pair() {
    let mut c = checker(cube_bowl(), 0.0);
    // Shoulder lifted 0.4 rad below the horizontal, elbow straight: the forearm and the wrist
    // go through the table top.
    let q = [
        -std::f64::consts::FRAC_PI_2,
        0.4,
        0.0,
        -std::f64::consts::FRAC_PI_2,
        -std::f64::consts::FRAC_PI_2,
        0.0,
    ];
    assert!(!c.is_free(&q));
    let hits = c.collisions(&q);
    assert!(!hits.is_empty());
    let table: Vec<_> = hits.iter().filter(|h| h.b == "table").collect();
    assert!(!table.is_empty(), "{hits:?}");
    assert!(
        table
            .iter()
            .all(|h| h.a.starts_with("ur5e/") || h.a.starts_with("gripper/")),
        "{hits:?}"
    );
    assert!(table.iter().all(|h| h.distance < 0.0), "{hits:?}");
}

#[test]
fn a_configuration_through_the_tall_post_collides_and_names_the_post() {
    let mut c = checker(post_scene(), 0.0);
    let q = down(0.45, 0.0, 0.15);
    assert!(!c.is_free(&q));
    let hits = c.collisions(&q);
    assert!(
        hits.iter().any(|h| h.b == "post" && h.a.starts_with("gripper/")),
        "{hits:?}"
    );
    // The same pose in the cell without the post is free.
    let mut open = checker(cube_bowl(), 0.0);
    let q_open = down(0.45, -0.02, 0.25);
    assert!(open.is_free(&q_open), "{:?}", open.collisions(&q_open));
}

#[test]
fn the_margin_reports_near_misses_with_their_distance() {
    let mut exact = checker(post_scene(), 0.0);
    // Lower the pinch over the post until the gripper touches it.
    let mut z = 0.6;
    while exact.is_free(&down(0.45, 0.0, z)) {
        z -= 0.002;
        assert!(z > 0.2, "the gripper never met the post");
    }
    let free_z = z + 0.012; // about a centimetre above the first touch
    let q = down(0.45, 0.0, free_z);
    assert!(exact.is_free(&q));
    let mut wide = checker(post_scene(), 0.03);
    assert!(!wide.is_free(&q));
    let hits = wide.collisions(&q);
    let post = hits
        .iter()
        .find(|h| h.b == "post")
        .expect("the post within the margin");
    assert!(post.distance > 0.0 && post.distance < 0.03, "{post:?}");
    let mut narrow = checker(post_scene(), 0.0);
    narrow.set_margin(0.005).unwrap();
    assert!(narrow.is_free(&q), "{:?}", narrow.collisions(&q));
    assert!(narrow.set_margin(-1.0).is_err() && narrow.set_margin(f64::NAN).is_err());
    assert_eq!(narrow.margin(), 0.005);
}

#[test]
fn a_held_block_moves_with_the_pinch_and_collides_with_the_table() {
    let scene = cube_bowl();
    let mut sim = Sim::new(scene);
    let cube = scene.spec.objects.iter().position(|o| o.name == "cube").unwrap();
    let qpos = scene.objects[cube].qpos.unwrap();
    // The cube between the open fingers at home.
    let pinch = fk(&HOME_Q).translation.vector;
    sim.data_mut().qpos_mut()[qpos..qpos + 3].copy_from_slice(&[pinch.x, pinch.y, pinch.z]);
    sim.data_mut().forward();
    let mut c = SceneChecker::from_sim(&sim, 0.0).unwrap();
    c.hold(cube).unwrap();
    assert_eq!(c.held(), Some(cube));
    assert!(c.is_free(&HOME_Q), "{:?}", c.collisions(&HOME_Q));
    // Pinch 1 cm above the table: the held cube (22 mm half edge) is in the table.
    let low = down(0.45, 0.2, 0.01);
    let held = c.held_pose(&low).unwrap();
    assert!((held.translation.vector - fk(&low).translation.vector).norm() < 1e-9);
    let hits = c.collisions(&low);
    assert!(hits.iter().any(|h| h.a == "cube" && h.b == "table"), "{hits:?}");
    // Let go: the cube stays at its snapshot pose (between the fingers at home), out of the way.
    c.release();
    let hits = c.collisions(&low);
    assert!(!hits.iter().any(|h| h.a == "cube" || h.b == "cube"), "{hits:?}");
    assert!(c.hold(999).is_err());
}

#[test]
fn the_planner_goes_around_the_post_and_every_configuration_on_the_way_is_free() {
    let scene = post_scene();
    let mut c = checker(scene, 0.01);
    let start = down(0.45, -0.2, 0.15);
    let goal_pos = Vector3::new(0.45, 0.2, 0.15);
    let goals = GoalSet::down(&goal_pos, 0.0, false, &start);
    assert!(goals.len() >= 4);
    // The direct joint motion to the nearest goal hits the post.
    assert!(
        check_segment(
            &mut c,
            &start,
            &goals.configs[0],
            &PlannerConfig::default().edge_resolution()
        )
        .is_err()
    );
    // The default resolution (0.05 rad, 1 cm of displacement) with a 1 cm margin: nothing
    // touches between checks.
    let config = PlannerConfig::default();
    let m = plan(&mut c, &start, &goals, &config).unwrap();
    eprintln!("{}", m.stats.summary());
    let end = fk(&m.trajectory.end()).translation.vector;
    assert!((end - goal_pos).norm() < 1e-6);
    // Every 2 ms of the timed motion, checked without margin: nothing touches.
    let mut exact = checker(scene, 0.0);
    let n = (m.trajectory.duration() / 0.002).ceil() as usize;
    for k in 0..=n {
        let q = m.trajectory.sample(k as f64 * 0.002).0;
        assert!(
            exact.is_free(&q),
            "t = {} s: {:?}",
            k as f64 * 0.002,
            exact.collisions(&q)
        );
    }
    // Same seed, same path.
    let again = plan(&mut c, &start, &goals, &config).unwrap();
    assert_eq!(again.raw_path, m.raw_path);
    assert_eq!(again.trajectory.waypoints(), m.trajectory.waypoints());
}

#[test]
fn the_check_budget_is_a_hard_deterministic_cap_ending_in_no_path_naming_the_post() {
    let scene = post_scene();
    let mut c = checker(scene, DEFAULT_MARGIN);
    let start = down(0.45, -0.2, 0.15);
    let goals = GoalSet::down(&Vector3::new(0.45, 0.2, 0.15), 0.0, false, &start);
    // The direct segments are blocked by the post (see above): a search is needed, and 120
    // checks (the start, the goals and the direct segments' first checks) leave none for it.
    let config = PlannerConfig {
        max_checks: 120,
        ..PlannerConfig::default()
    };
    let e = plan(&mut c, &start, &goals, &config).unwrap_err();
    match &e.reason {
        PlanFailure::SearchExhausted {
            spent,
            checks,
            blocking,
            ..
        } => {
            assert!(*checks <= 120, "{checks} checks past the budget");
            assert!(blocking.iter().any(|(h, _)| h.b == "post"), "{e}");
            // The message says the check budget ran out, not that the motion cannot exist.
            assert_eq!(*spent, macrotree::motion::plan::SearchBudget::Checks(120));
            assert!(
                e.to_string()
                    .contains("collision-check budget (120, `max_checks`) ran out"),
                "{e}"
            );
        }
        r => panic!("expected search_exhausted, got {r}"),
    }
    assert!(e.stats.collision_checks <= 120);
    // The same query ends the same way (no clock in the outcome).
    let again = plan(&mut c, &start, &goals, &config).unwrap_err();
    assert_eq!(again.reason, e.reason);
    // Through the cell's planning entry point it is a typed `no_path` failure.
    let e = macrotree::sim::plan_in_cell(&mut c, &start, &goals, &config).unwrap_err();
    let f = macrotree::sim::plan_failure(&e);
    assert_eq!(f.kind, macrotree::FailureKind::NoPath);
    assert!(f.message.contains("post"), "{}", f.message);
    // With the default budget the same query plans.
    assert!(plan(&mut c, &start, &goals, &PlannerConfig::default()).is_ok());
}

#[test]
fn each_reason_on_the_real_cell() {
    let mut c = checker(post_scene(), DEFAULT_MARGIN);
    let config = PlannerConfig::default();
    let into_table = [
        -std::f64::consts::FRAC_PI_2,
        0.4,
        0.0,
        -std::f64::consts::FRAC_PI_2,
        -std::f64::consts::FRAC_PI_2,
        0.0,
    ];
    let e = plan(&mut c, &into_table, &GoalSet::configs(vec![HOME_Q]), &config).unwrap_err();
    assert!(
        matches!(&e.reason, PlanFailure::StartInCollision { collisions } if collisions.iter().any(|h| h.b == "table")),
        "{e}"
    );
    // Inside the post: every IK branch of the pose is blocked by it.
    let goals = GoalSet::down(&Vector3::new(0.45, 0.0, 0.15), 0.0, false, &HOME_Q);
    let e = plan(&mut c, &HOME_Q, &goals, &config).unwrap_err();
    match &e.reason {
        PlanFailure::GoalInCollision {
            goals: n,
            in_collision,
            collisions,
            ..
        } => {
            assert_eq!(n, in_collision);
            assert!(collisions.iter().any(|(h, _)| h.b == "post"), "{e}");
        }
        r => panic!("{r}"),
    }
    assert!(e.to_string().contains("post"), "{e}");
    let far = GoalSet::down(&Vector3::new(1.2, 0.0, 0.15), 0.0, false, &HOME_Q);
    let e = plan(&mut c, &HOME_Q, &far, &config).unwrap_err();
    assert_eq!(e.reason.name(), "no_goal");
}

#[test]
fn the_lever_arms_bound_every_robot_geom_at_random_joints() {
    use macrotree::motion::ur5e::LEVER_ARMS as UR5E_LEVER_ARMS;
    use rand::{Rng, SeedableRng};
    let scene = cube_bowl();
    let m = &scene.model;
    let mut sim = Sim::new(scene);
    let joints: Vec<usize> = macrotree::motion::ARM_JOINTS
        .iter()
        .map(|n| {
            m.name_to_id(
                mujoco_rs::prelude::MjtObjBase::mjOBJ_JOINT,
                &format!("ur5e/{n}_joint"),
            )
            .unwrap()
        })
        .collect();
    let (parent, jbody, gbody, rbound) = (
        m.body_parentid(),
        m.jnt_bodyid(),
        m.geom_bodyid(),
        m.geom_rbound(),
    );
    let below = |mut b: usize, top: usize| {
        while b != 0 {
            if b == top {
                return true;
            }
            b = parent[b] as usize;
        }
        false
    };
    // Geoms moved by each joint: those of its body and every body below it.
    let moved: Vec<Vec<usize>> = joints
        .iter()
        .map(|&j| {
            (0..gbody.len())
                .filter(|&g| below(gbody[g] as usize, jbody[j] as usize))
                .collect()
        })
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut worst = [0.0f64; 6];
    // The arm stretched out (every wrist pose of it), then random joints.
    let half = std::f64::consts::FRAC_PI_2;
    let mut configs: Vec<[f64; 6]> = Vec::new();
    for w1 in [-half, 0.0, half] {
        for w2 in [-half, 0.0, half] {
            configs.push([0.0, 0.0, 0.0, w1, w2, 0.0]);
        }
    }
    configs.extend((0..400).map(|_| std::array::from_fn(|_| rng.random_range(-3.1..3.1))));
    for q in configs {
        {
            let ids = scene.ids.arm_qpos;
            let qpos = sim.data_mut().qpos_mut();
            for (i, &a) in ids.iter().enumerate() {
                qpos[a] = q[i];
            }
        }
        sim.data_mut().kinematics();
        let d = sim.data();
        for (k, &j) in joints.iter().enumerate() {
            let (a, u) = (Vector3::from(d.xanchor()[j]), Vector3::from(d.xaxis()[j]));
            for &g in &moved[k] {
                let p = Vector3::from(d.geom_xpos()[g]) - a;
                let r = (p - u * p.dot(&u)).norm() + rbound[g];
                worst[k] = worst[k].max(r);
            }
        }
    }
    // Room for a held block (half diagonal of a 7 cm cube, 6.1 cm, centred on the pinch) beyond
    // the robot's own geoms; on wrist 3's own axis the block only reaches its half diagonal.
    for k in 0..5 {
        assert!(
            worst[k] + 0.061 <= UR5E_LEVER_ARMS[k],
            "joint {}: a geom reaches {:.3} m from the axis",
            k + 1,
            worst[k]
        );
    }
    assert!(
        worst[5].max(0.061) <= UR5E_LEVER_ARMS[5],
        "wrist 3: {:.3} m",
        worst[5]
    );
    eprintln!("largest radius of a robot geom about each joint: {worst:.3?} m");
}

/// The true distance, metres, from capsule geom `cap` to box geom `bx` as `data` poses them
/// (positive apart, 0 when the segment is inside the box): the segment's distance to the box
/// is convex along it, so a ternary search finds its minimum; minus the radius.
fn capsule_box_distance(
    data: &mujoco_rs::prelude::MjData<std::sync::Arc<mujoco_rs::prelude::MjModel>>,
    cap: usize,
    bx: usize,
) -> f64 {
    let m = data.model();
    let mat = |g: usize| nalgebra::Matrix3::from_row_slice(&data.geom_xmat()[g]);
    let pos = |g: usize| Vector3::from(data.geom_xpos()[g]);
    let (cs, bs) = (m.geom_size()[cap], m.geom_size()[bx]);
    let (rb, cb) = (mat(bx), pos(bx));
    let axis = mat(cap).column(2).into_owned();
    let to_box = |t: f64| {
        let local = rb.transpose() * (pos(cap) + axis * t - cb);
        Vector3::from_fn(|i, _| (local[i].abs() - bs[i]).max(0.0)).norm()
    };
    let (mut lo, mut hi) = (-cs[1], cs[1]);
    for _ in 0..200 {
        let (a, b) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if to_box(a) <= to_box(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    to_box(0.5 * (lo + hi)) - cs[0]
}

/// MuJoCo 3.17's capsule–box collider reports every penetration but not every pair closer than
/// the margin: `go_around`'s planned reach "kept 5 mm" while the forearm's capsule passed 1.5 mm
/// from the 0.80 m fixture, and the servos' few millimetres of tracking error put the forearm on
/// it (scenarios 127, 174, 195 of seed 1). Near the configuration that reach passed through,
/// every arm capsule closer to the fixture than the margin (measured here from the geoms' own
/// poses) must be reported by the checker.
#[test]
fn the_checker_missed_capsules_within_its_margin_of_a_box() {
    use mujoco_rs::prelude::*;
    let spec =
        macrotree::scene::load_scene_file(std::path::Path::new("scenes/go_around.yaml")).expect("scene file");
    let scene = Scene::load_spec(&spec).expect("scene (run tools/bootstrap)");
    let mut sim = Sim::new(&scene);
    let mut c = SceneChecker::from_sim(&sim, DEFAULT_MARGIN).unwrap();
    c.set_screen(false);
    let m = scene.model.clone();
    let body = |g: usize| {
        m.id_to_name(MjtObjBase::mjOBJ_BODY, m.geom_bodyid()[g] as usize)
            .unwrap_or_default()
            .to_string()
    };
    let ngeom = m.ffi().ngeom as usize;
    let capsules: Vec<usize> = (0..ngeom)
        .filter(|&g| {
            m.geom_type()[g] == MjtGeomBase::mjGEOM_CAPSULE
                && m.geom_contype()[g] != 0
                && body(g).starts_with("ur5e/")
        })
        .filter(|&g| body(g) != "ur5e/shoulder_link")
        .collect();
    let fixture = (0..ngeom)
        .find(|&g| body(g).ends_with("fixture") && m.geom_type()[g] == MjtGeomBase::mjGEOM_BOX)
        .expect("the fixture's box");
    // Where scenario 127's planned reach was commanded when the forearm touched (1.5 mm apart).
    let q0 = [
        -0.1762,
        -2.1244,
        -1.3366,
        -4.3768,
        -std::f64::consts::FRAC_PI_2,
        -2.0856,
    ];
    let mut rng = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    let arm = scene.ids.arm_qpos;
    let (mut near, mut missed) = (0, Vec::new());
    for _ in 0..1500 {
        let q: [f64; 6] = std::array::from_fn(|i| q0[i] + (next() - 0.5) * 0.06);
        let data = sim.data_mut();
        for (i, &a) in arm.iter().enumerate() {
            data.qpos_mut()[a] = q[i];
        }
        data.kinematics();
        let hits = c.collisions(&q);
        for &g in &capsules {
            let d = capsule_box_distance(sim.data(), g, fixture);
            if d > 2e-4 && d < DEFAULT_MARGIN - 2e-4 {
                near += 1;
                if !hits.iter().any(|h| h.a == body(g) && h.b == "fixture") {
                    missed.push((body(g), d, hits.clone()));
                }
            }
        }
    }
    assert!(
        near >= 50,
        "only {near} capsules within the margin: the test no longer probes it"
    );
    assert!(
        missed.is_empty(),
        "{} of {near} capsules within the margin not reported, e.g. {:?}",
        missed.len(),
        missed.first()
    );
}
