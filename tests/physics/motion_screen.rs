//! The collision screen (`sim::screen::Screen`, asked through `FastChecks::screen`)
//! against MuJoCo on the real cell: whatever MuJoCo finds in contact the screen never calls
//! free, and what it calls blocked MuJoCo finds in contact, over thousands of seeded configurations drawn near the
//! obstacles (on the boundary between free and blocked), with and without a held block, at
//! several margins; and the planner with the screen gives the same paths as without it.

use macrotree::motion::plan::{CollisionChecker, FastChecks, GoalSet, PlannerConfig, plan};
use macrotree::motion::{JOINT_LIMITS, down_pose, fk, ik};
use macrotree::scene::SceneSpec;
use macrotree::sim::{DEFAULT_MARGIN, HOME_Q, Scene, SceneChecker, Sim};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const BIN: &str = "objects:
  cube: {block: {size: 0.044}, pose: [0.35, -0.25]}
  other: {block: {size: 0.05}, pose: [0.25, 0.05]}
  bin: {container: {inner: [0.24, 0.24], wall_height: 0.12}, pose: [0.45, 0.22]}
";

const POST: &str = "objects:
  cube: {block: {size: 0.044}, pose: [0.3, -0.35]}
  post: {obstacle: {size: [0.06, 0.06, 0.30]}, pose: [0.45, 0.0]}
";

const CLUTTER: &str = "objects:
  cube: {block: {size: 0.044}, pose: [0.3, -0.38]}
  p1: {obstacle: {size: [0.05, 0.05, 0.25]}, pose: [0.40, -0.05]}
  p2: {obstacle: {size: [0.05, 0.05, 0.25]}, pose: [0.55, 0.05]}
  p3: {obstacle: {size: [0.05, 0.05, 0.20]}, pose: [0.35, 0.15]}
  wall: {obstacle: {size: [0.30, 0.02, 0.12]}, pose: [0.50, -0.25]}
";

/// A shelf opening: the top board is moved over the bottom one in the simulation.
const SHELF: &str = "objects:
  cube: {block: {size: 0.044}, pose: [0.3, -0.4]}
  bottom: {obstacle: {size: [0.25, 0.40, 0.12]}, pose: [0.675, 0.0]}
  top: {obstacle: {size: [0.25, 0.40, 0.02]}, pose: [0.3, 0.45]}
";

/// Obstacles moved after the scene is built: (name, position of the bottom centre, metres).
type Placed<'a> = &'a [(&'a str, [f64; 3])];

fn cell(yaml: &str, placed: &[(&str, [f64; 3])]) -> (Scene, Sim) {
    let spec = SceneSpec::from_str(yaml, "screen.yaml").expect("valid scene");
    let scene = Scene::load_spec(&spec).expect("scene (run tools/bootstrap)");
    let mut sim = Sim::new(&scene);
    for (name, at) in placed {
        let i = spec.objects.iter().position(|o| o.name == *name).unwrap();
        let m = scene.objects[i].mocap.expect("a mocap obstacle");
        sim.data_mut().mocap_pos_mut()[m] = *at;
    }
    (scene, sim)
}

fn random_q(r: &mut ChaCha8Rng) -> [f64; 6] {
    // Mostly the half-space in front of the arm, where the obstacles are, with wide wrists.
    let mut q = [0.0; 6];
    for (j, v) in q.iter_mut().enumerate() {
        let (lo, hi) = JOINT_LIMITS[j];
        *v = r.random_range(lo.max(-3.5)..hi.min(3.5));
    }
    q
}

/// A configuration near the scene: the pinch somewhere over the table, tool down, or random.
fn drawn(r: &mut ChaCha8Rng) -> [f64; 6] {
    if r.random_bool(0.6) {
        let p = Vector3::new(
            r.random_range(0.2..0.8),
            r.random_range(-0.5..0.5),
            r.random_range(-0.02..0.4),
        );
        if let Ok(mut q) = ik(&down_pose(&p, r.random_range(-3.0..3.0)), &HOME_Q) {
            for v in &mut q {
                *v += r.random_range(-0.3..0.3);
            }
            return q;
        }
    }
    random_q(r)
}

struct Tally {
    /// Configurations MuJoCo found free, and how many of them the screen vouched for.
    free: usize,
    vouched: usize,
    /// Configurations MuJoCo found blocked, and how many of them the screen called blocked.
    blocked: usize,
    proven: usize,
}

/// Draws pairs (free, blocked) by MuJoCo and bisects between them to the boundary, asking the
/// screen and MuJoCo at every point; panics at the first configuration the screen calls free
/// and MuJoCo blocked.
fn compare(checker: &mut SceneChecker, r: &mut ChaCha8Rng, pairs: usize, what: &str) -> Tally {
    let mut t = Tally {
        free: 0,
        vouched: 0,
        blocked: 0,
        proven: 0,
    };
    let ask = |c: &mut SceneChecker, q: &[f64; 6], t: &mut Tally| -> bool {
        let screen = FastChecks::screen(c, q);
        let exact = c.is_free(q);
        assert!(
            screen != Some(true) || exact,
            "{what}: the screen calls {q:?} free, MuJoCo finds {:?}",
            c.collisions(q)
        );
        assert!(
            screen != Some(false) || !exact,
            "{what}: the screen calls {q:?} blocked ({:?}), MuJoCo finds it free",
            c.screen_model().unwrap().decide(q)
        );
        if exact {
            t.free += 1;
            t.vouched += usize::from(screen == Some(true));
        } else {
            t.blocked += 1;
            t.proven += usize::from(screen == Some(false));
        }
        exact
    };
    let mut done = 0;
    while done < pairs {
        let (a, b) = (drawn(r), drawn(r));
        let (fa, fb) = (ask(checker, &a, &mut t), ask(checker, &b, &mut t));
        if fa == fb {
            continue;
        }
        done += 1;
        let (mut free, mut blocked) = if fa { (a, b) } else { (b, a) };
        for _ in 0..14 {
            let mut mid = [0.0; 6];
            for j in 0..6 {
                mid[j] = 0.5 * (free[j] + blocked[j]);
            }
            if ask(checker, &mid, &mut t) {
                free = mid;
            } else {
                blocked = mid;
            }
        }
    }
    t
}

fn report(what: &str, t: &Tally) {
    println!(
        "{what}: {} free (screen vouched for {:.0} %), {} blocked (screen proved {:.0} %)",
        t.free,
        100.0 * t.vouched as f64 / t.free.max(1) as f64,
        t.blocked,
        100.0 * t.proven as f64 / t.blocked.max(1) as f64,
    );
}

#[test]
fn the_screen_never_calls_free_what_mujoco_finds_in_contact() {
    let cells: [(&str, &str, Placed); 3] = [
        ("bin", BIN, &[]),
        ("clutter", CLUTTER, &[]),
        ("shelf", SHELF, &[("top", [0.675, 0.0, 0.30])]),
    ];
    let mut r = ChaCha8Rng::seed_from_u64(0x5C4EE7);
    for (name, yaml, placed) in cells {
        let (_scene, sim) = cell(yaml, placed);
        for margin in [0.0, DEFAULT_MARGIN, 0.02] {
            let mut c = SceneChecker::from_sim(&sim, margin).unwrap();
            assert!(c.screen_model().is_some(), "{name}: the cell has a screen");
            let what = format!("{name}, margin {margin} m");
            let t = compare(&mut c, &mut r, 150, &what);
            report(&what, &t);
            // Useful: a third or more of the free configurations, most of them within millimetres of
            // contact (the bisection), are vouched for.
            assert!(t.blocked > 500 && t.free > 500, "{what}");
            assert!(t.vouched * 3 > t.free, "{what}: the screen vouched for too few");
        }
    }
}

#[test]
fn the_screen_never_calls_free_what_mujoco_finds_in_contact_with_a_held_block() {
    let (scene, mut sim) = cell(BIN, &[]);
    // The cube in the pinch at home, then held: it moves with the gripper.
    let pinch = fk(&HOME_Q);
    let qa = scene.objects[0].qpos.expect("a block");
    {
        let qpos = sim.data_mut().qpos_mut();
        let t = pinch.translation.vector;
        let rq = pinch.rotation.quaternion();
        qpos[qa..qa + 7].copy_from_slice(&[t.x, t.y, t.z, rq.w, rq.i, rq.j, rq.k]);
    }
    let arm = scene.ids.arm_qpos;
    for (j, &a) in arm.iter().enumerate() {
        sim.data_mut().qpos_mut()[a] = HOME_Q[j];
    }
    let mut r = ChaCha8Rng::seed_from_u64(0xB10C);
    for margin in [0.0, DEFAULT_MARGIN] {
        let mut c = SceneChecker::from_sim(&sim, margin).unwrap();
        c.hold(0).unwrap();
        let what = format!("held block, margin {margin} m");
        let t = compare(&mut c, &mut r, 150, &what);
        report(&what, &t);
        assert!(t.blocked > 500 && t.free > 500, "{what}");
        assert!(t.vouched * 3 > t.free, "{what}: the screen vouched for too few");
        // Released, the block is part of the scene again.
        c.release();
        let t = compare(&mut c, &mut r, 50, "released block");
        assert!(t.vouched > 0);
    }
}

#[test]
fn the_planner_with_the_screen_plans_the_same_paths_as_without_it() {
    let (_scene, sim) = cell(POST, &[]);
    let mut fast = SceneChecker::from_sim(&sim, DEFAULT_MARGIN).unwrap();
    let mut exact = SceneChecker::from_sim(&sim, DEFAULT_MARGIN).unwrap();
    exact.set_screen(false);
    let start = ik(&down_pose(&Vector3::new(0.45, -0.25, 0.2), 0.0), &HOME_Q).unwrap();
    let goals = GoalSet::down(&Vector3::new(0.45, 0.25, 0.2), 0.0, false, &start);
    let mut searched = 0;
    for seed in 0..6 {
        let config = PlannerConfig {
            seed,
            ..PlannerConfig::default()
        };
        let a = plan(&mut fast, &start, &goals, &config).unwrap();
        let b = plan(&mut exact, &start, &goals, &config).unwrap();
        // Again with the screen: the same path, bit for bit.
        let c = plan(&mut fast, &start, &goals, &config).unwrap();
        assert_eq!(a.raw_path, b.raw_path, "seed {seed}");
        assert_eq!(a.trajectory.waypoints(), b.trajectory.waypoints(), "seed {seed}");
        assert_eq!(a.raw_path, c.raw_path);
        // The start, the goals and the direct segments are checked exactly either way. (The
        // search's count of a blocked segment depends on where its bisection met the block,
        // which the screen's spare moves: paths stay the same unless the budget binds.)
        assert_eq!(a.stats.stage_checks[0], b.stats.stage_checks[0]);
        assert_eq!(
            a.stats.screened > 0,
            !a.stats.direct,
            "the screen helps searches only"
        );
        assert_eq!(b.stats.screened, 0);
        assert!(!a.stats.screen_fallback);
        searched += usize::from(!a.stats.direct);
    }
    assert!(searched > 0, "some query searched");
}
