//! The spare clearance by joint range, exact ([`SceneChecker::exact_spare`]) and the screen's,
//! against `mj_geomDistance` of every pair the checker tests, and the lever-arm bound that lets
//! it vouch for nearby configurations.

use nalgebra::{Isometry3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{SPARE_TOLERANCE, SceneChecker};
use crate::motion::plan::{Collision, CollisionChecker, FastChecks, JointSpare, SPARE_CAP};
use crate::motion::ur5e::LEVER_ARMS as UR5E_LEVER_ARMS;
use crate::motion::{HOME_Q, JOINT_LIMITS, down_pose, fk, ik};
use crate::scene::SceneSpec;
use crate::sim::chain::{ArmChain, Frame};
use crate::sim::pair_filter::PairFilter;
use crate::sim::screen::shapes::{Shape, separation};
use crate::sim::screen::{PairMove, TurnedBound};
use crate::sim::{Scene, Sim};

/// Posts, a bin and a shelf board close to the arm, a block to hold.
const CELL: &str = "objects:
  cube: {block: {size: 0.05}, pose: [0.3, -0.35]}
  post: {obstacle: {size: [0.06, 0.06, 0.30]}, pose: [0.45, 0.0]}
  bin: {container: {inner: [0.2, 0.2], wall_height: 0.12}, pose: [0.45, 0.3]}
  board: {obstacle: {size: [0.25, 0.30, 0.12]}, pose: [0.45, -0.35]}
";

/// The least `mj_geomDistance` over every geom pair MuJoCo tests in the checker's private
/// model at `q` (metres, at most 1 m).
fn truth(c: &mut SceneChecker, q: &[f64; 6]) -> f64 {
    c.detect_pose(q);
    let pairs: Vec<(usize, usize)> = {
        let m = c.data.model();
        let filter = PairFilter::new(m);
        let n = m.ffi().ngeom as usize;
        let (ct, ca) = (m.geom_contype(), m.geom_conaffinity());
        (0..n)
            .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
            .filter(|&(a, b)| (ct[a] != 0 || ca[a] != 0) && (ct[b] != 0 || ca[b] != 0) && filter.tested(a, b))
            .collect()
    };
    pairs
        .iter()
        .map(|&(a, b)| c.data.geom_distance(a, b, 1.0, None))
        .fold(1.0, f64::min)
}

/// A configuration near the scene: the pinch over the table, tool down, perturbed; or random.
fn drawn(r: &mut ChaCha8Rng) -> [f64; 6] {
    if r.random_bool(0.7) {
        let p = Vector3::new(
            r.random_range(0.2..0.7),
            r.random_range(-0.5..0.5),
            r.random_range(0.0..0.4),
        );
        if let Ok(mut q) = ik(&down_pose(&p, r.random_range(-3.0..3.0)), &HOME_Q) {
            for v in &mut q {
                *v += r.random_range(-0.3..0.3);
            }
            return q;
        }
    }
    std::array::from_fn(|j| r.random_range(JOINT_LIMITS[j].0.max(-3.5)..JOINT_LIMITS[j].1.min(3.5)))
}

/// The checker of [`CELL`]; holding the cube in the pinch (at the snapshot's pinch point) or
/// not.
fn checker(hold: bool) -> SceneChecker {
    let spec = SceneSpec::from_str(CELL, "spare.yaml").expect("valid scene");
    let scene = Scene::load_spec(&spec).expect("scene (run tools/bootstrap)");
    let mut sim = Sim::new(&scene);
    if hold {
        place_cube(&scene, &mut sim, &Isometry3::identity());
    }
    let mut c = SceneChecker::from_sim(&sim, 0.005).expect("checker");
    if hold {
        c.hold(0).expect("the cube is a block");
    }
    c
}

/// Puts the cube at `in_pinch` from the pinch of the arm's current joints.
fn place_cube(scene: &Scene, sim: &mut Sim, in_pinch: &Isometry3<f64>) {
    let q: [f64; 6] = scene.ids.arm_qpos.map(|a| sim.data().qpos()[a]);
    let pose = fk(&q) * in_pinch;
    let (t, r) = (pose.translation.vector, pose.rotation.quaternion());
    let adr = scene.objects[0].qpos.expect("the cube is a block");
    sim.data_mut().qpos_mut()[adr..adr + 7].copy_from_slice(&[t.x, t.y, t.z, r.w, r.i, r.j, r.k]);
}

/// Over seeded configurations near the obstacles, the exact spare clearance never exceeds the
/// exact distance of any tested pair less the margin, a measured spare means `is_free`, and every
/// configuration within its reach keeps the margin.
fn spare_is_conservative(hold: bool, seed: u64) {
    let mut c = checker(hold);
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let (mut measured, mut near, mut vouched, mut beyond_arms) = (0, 0, 0, 0);
    // The largest excess of a range's measured distance over the least `mj_geomDistance` of
    // every pair, metres.
    let mut worst = f64::NEG_INFINITY;
    for _ in 0..1200 {
        let q = drawn(&mut r);
        let spare = c.exact_spare(&q, SPARE_CAP);
        let exact = truth(&mut c, &q);
        let Some(spare) = spare else {
            // Not measured free: the planner asks `is_free`, which may still find it free.
            assert!(exact < c.margin() + 1e-3, "{q:?}: {exact} m apart, no spare");
            continue;
        };
        // Every pair is at least the least range's spare beyond the margin.
        let least = spare.least();
        worst = worst.max(least + c.margin() - exact + SPARE_TOLERANCE);
        assert!(
            least + c.margin() <= exact + 1e-6,
            "{q:?}: spare {least} m beyond the margin, but a pair is {exact} m apart"
        );
        for lo in 0..6 {
            for hi in lo..6 {
                assert!(
                    (0.0..=SPARE_CAP + 1e-12).contains(&spare.get(lo, hi)),
                    "{spare:?}"
                );
            }
        }
        assert!(c.is_free(&q), "{q:?}: spare {spare:?} but not free");
        measured += 1;
        near += usize::from(least < SPARE_CAP);
        // Configurations within the reach of the spare clearance keep the margin.
        for _ in 0..3 {
            if let Some((_, by_arms)) = vouched_step(&mut c, &mut r, &q, &spare) {
                vouched += 1;
                beyond_arms += usize::from(!by_arms);
            }
        }
    }
    eprintln!("spare clearance: worst excess over mj_geomDistance of every pair {worst:.2e} m");
    assert!(worst < SPARE_TOLERANCE);
    // Most vouched steps go beyond what the lever arms alone allow: the reach is tested.
    assert!(
        measured > 200 && near > 100 && vouched > 600 && beyond_arms > vouched / 2,
        "{measured} {near} {vouched} {beyond_arms}"
    );
}

#[test]
fn the_exact_spare_clearance_is_conservative() {
    spare_is_conservative(false, 31);
}

#[test]
fn the_exact_spare_clearance_is_conservative_with_a_held_block() {
    spare_is_conservative(true, 32);
}

/// Along seeded walks near the obstacles (steps of 0.3–6 cm in the lever-arm bound, as a
/// segment's measured configurations are; every other walk turns only the wrists, so the bounds
/// of the pairs the other joints move are carried unchanged), the exact spare of a checker that
/// carries its pairs' lower bounds from call to call equals that of a checker measuring the
/// same configuration afresh: the carried bounds skip only pairs that cannot be the closest.
fn carried_bounds_change_no_spare(hold: bool, seed: u64) {
    let mut walking = checker(hold);
    let mut fresh = checker(hold);
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let (mut compared, mut spared) = (0, 0);
    for walk in 0..40 {
        let mut q = drawn(&mut r);
        let first = if walk % 2 == 0 { 0 } else { 3 };
        for _ in 0..30 {
            let dir: [f64; 6] = std::array::from_fn(|j| {
                if j >= first {
                    r.random_range(-1.0..1.0)
                } else {
                    0.0
                }
            });
            let sweep: f64 = (0..6).map(|j| UR5E_LEVER_ARMS[j] * dir[j].abs()).sum();
            let step = r.random_range(0.003..0.06) / sweep;
            for j in 0..6 {
                q[j] += dir[j] * step;
            }
            let carried = walking.exact_spare(&q, SPARE_CAP);
            fresh.margin_pairs.0.forget();
            let afresh = fresh.exact_spare(&q, SPARE_CAP);
            assert_eq!(carried, afresh, "{q:?}");
            compared += 1;
            spared += usize::from(carried.is_some());
        }
    }
    assert!(
        compared == 1200 && spared > 300,
        "{spared} of {compared} with a spare"
    );
}

#[test]
fn carried_pair_bounds_change_no_exact_spare() {
    carried_bounds_change_no_spare(false, 31);
}

#[test]
fn carried_pair_bounds_change_no_exact_spare_with_a_held_block() {
    carried_bounds_change_no_spare(true, 32);
}

#[test]
fn the_spare_clearance_leaves_the_checker_as_it_was() {
    let mut c = checker(false);
    let mut r = ChaCha8Rng::seed_from_u64(33);
    let qs: Vec<[f64; 6]> = (0..200).map(|_| drawn(&mut r)).collect();
    let before: Vec<bool> = qs.iter().map(|q| c.is_free(q)).collect();
    for q in &qs {
        c.exact_spare(q, SPARE_CAP);
    }
    let after: Vec<bool> = qs.iter().map(|q| c.is_free(q)).collect();
    assert_eq!(before, after);
    assert!(before.iter().any(|f| *f) && before.iter().any(|f| !*f));
    // A zero margin has nothing to widen: not measured.
    c.set_margin(0.0).unwrap();
    assert_eq!(c.exact_spare(&qs[0], SPARE_CAP), None);
}

/// The longest step `s` along `dir` (radians per unit) whose displacements stay within every
/// joint range's spare, at the spare's reach from the joint axes ([`JointSpare::steps_along`]).
fn reach_within(spare: &JointSpare, dir: &[f64; 6]) -> f64 {
    spare.steps_along(&UR5E_LEVER_ARMS, dir)
}

/// A seeded step from `q` in a random direction, within the reach of `spare` (half to all of
/// it), asserted to keep the margin by `mj_geomDistance` and to be free by `is_free`: what each
/// joint turned the parts by (metres, [`JointSpare::levers`]) and whether the lever arms alone
/// (without the spare's reach from the axes) would have vouched for it; `None` when the spare
/// allows no step.
fn vouched_step(
    c: &mut SceneChecker,
    r: &mut ChaCha8Rng,
    q: &[f64; 6],
    spare: &JointSpare,
) -> Option<([f64; 6], bool)> {
    let dir: [f64; 6] = std::array::from_fn(|_| r.random_range(-1.0..1.0));
    let s = reach_within(spare, &dir);
    if !s.is_finite() || s <= 0.0 {
        return None;
    }
    let s = s * r.random_range(0.5..1.0);
    let q2: [f64; 6] = std::array::from_fn(|j| q[j] + dir[j] * s);
    let dq: [f64; 6] = std::array::from_fn(|j| q2[j] - q[j]);
    assert!(spare.after(&UR5E_LEVER_ARMS, &dq).is_some());
    let by_arms: [f64; 6] = std::array::from_fn(|j| UR5E_LEVER_ARMS[j] * dq[j].abs());
    let exact = truth(c, &q2);
    assert!(
        exact >= c.margin() - 1e-6,
        "{q2:?} within the spare of {q:?} ({spare:?}) is {exact} m from something"
    );
    assert!(c.is_free(&q2), "{q2:?} within the spare of {q:?} is not free");
    Some((spare.levers(&UR5E_LEVER_ARMS, &dq), spare.covers(&by_arms)))
}

/// Over seeded configurations near the obstacles, the verdict with the spare is the screen's,
/// or where the screen cannot tell, the full MuJoCo pass's (its undecided pairs measured
/// alone); and every configuration the spare clearance by joint range vouches for keeps the
/// margin: `is_free` finds it free, and every tested pair is at least the margin apart by
/// `mj_geomDistance`.
fn screen_spare_is_conservative(hold: bool, seed: u64) {
    let mut c = checker(hold);
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let (mut free, mut vouched, mut wide) = (0, 0, 0);
    let (mut settled_free, mut settled_blocked) = (0, 0);
    for _ in 0..1500 {
        let q = drawn(&mut r);
        let (verdict, spare) = c.screen_spare(&q, &JointSpare::uniform(SPARE_CAP));
        match c.screen(&q) {
            Some(v) => assert_eq!(verdict, Some(v), "{q:?}: the spare changes no verdict"),
            None => {
                assert_eq!(
                    verdict,
                    Some(c.is_free(&q)),
                    "{q:?}: settled unlike MuJoCo's pass"
                );
                settled_free += usize::from(verdict == Some(true));
                settled_blocked += usize::from(verdict == Some(false));
            }
        }
        if verdict != Some(true) {
            assert_eq!(spare, JointSpare::NONE);
            continue;
        }
        free += 1;
        for lo in 0..6 {
            for hi in lo..6 {
                assert!((0.0..=SPARE_CAP).contains(&spare.get(lo, hi)), "{spare:?}");
            }
        }
        for _ in 0..3 {
            let Some((moved, _)) = vouched_step(&mut c, &mut r, &q, &spare) else {
                continue;
            };
            vouched += 1;
            // The whole chain's reach is where the single-spare vouching ends: count the steps
            // that go beyond it (the per-range spares let the wrists move farther).
            let whole: f64 = moved.iter().sum();
            wide += usize::from(whole > spare.least());
        }
    }
    assert!(
        free > 300 && vouched > 600 && wide > 100,
        "{free} {vouched} {wide}"
    );
    // Both settled verdicts occur (near the obstacles most undecided pairs are blocked).
    assert!(
        settled_free > 10 && settled_blocked > 50,
        "settled free {settled_free}, blocked {settled_blocked}"
    );
}

#[test]
fn the_screen_spare_by_joint_range_is_conservative() {
    screen_spare_is_conservative(false, 41);
}

#[test]
fn the_screen_spare_by_joint_range_is_conservative_with_a_held_block() {
    screen_spare_is_conservative(true, 42);
}

#[test]
fn a_wrist_pair_inside_its_bounding_spheres_limited_the_spare_to_their_gap() {
    // The wrist 1 housing and the flange cylinder, 2–4 cm apart, sit well inside each other's
    // bounding spheres: where the spheres kept the pair's gap but not the spare wanted, the
    // spheres' gap (a few millimetres) was the spare of joints 5–6, and the bisection of a
    // wrist move asked twice as many configurations. The spare now takes each such pair's
    // primitive clearance: no range's spare is below its pairs' clearances, nor above them.
    for hold in [false, true] {
        let mut c = checker(hold);
        let mut r = ChaCha8Rng::seed_from_u64(43);
        let (mut free, mut beyond_spheres) = (0, 0);
        for _ in 0..600 {
            let q = drawn(&mut r);
            let screen = c.screen_model().expect("a screen");
            let (verdict, spare) = screen.free_spare(&q, &JointSpare::uniform(SPARE_CAP));
            if verdict != Some(true) {
                continue;
            }
            free += 1;
            let (low, high) = screen.pair_spares(&q, SPARE_CAP);
            for lo in 0..6 {
                for hi in lo..6 {
                    let s = spare.get(lo, hi);
                    assert!(
                        low.get(lo, hi) <= s + 1e-12 && s <= high.get(lo, hi) + 1e-12,
                        "{q:?}: range {lo}..={hi} spare {s} outside [{}, {}]",
                        low.get(lo, hi),
                        high.get(lo, hi)
                    );
                }
            }
            beyond_spheres += usize::from(spare.get(4, 5) > 0.02);
        }
        assert!(free > 200 && beyond_spheres > 50, "{free} {beyond_spheres}");
    }
}

#[test]
fn the_screen_spare_measured_up_to_what_a_move_wants_is_the_whole_spare_capped() {
    // A checker asked for the spare a move wants skips the pairs that surely keep it: the
    // verdict is the same, and every range's spare is the whole spare's, capped at what the
    // move wants of that range (so it holds the move wherever the whole spare does).
    for hold in [false, true] {
        let mut c = checker(hold);
        let mut r = ChaCha8Rng::seed_from_u64(44);
        let (mut free, mut capped) = (0, 0);
        for _ in 0..600 {
            let q = drawn(&mut r);
            let step: [f64; 6] = std::array::from_fn(|_| r.random_range(-0.01..0.01));
            let want = r.random_range(0.5..20.0);
            let caps = JointSpare::wanted(&UR5E_LEVER_ARMS, &step, want, SPARE_CAP);
            let (whole_verdict, whole) = c.screen_spare(&q, &JointSpare::uniform(SPARE_CAP));
            let (verdict, spare) = c.screen_spare(&q, &caps);
            assert_eq!(verdict, whole_verdict, "{q:?}");
            if verdict != Some(true) {
                continue;
            }
            free += 1;
            for lo in 0..6 {
                for hi in lo..6 {
                    let expected = whole.get(lo, hi).min(caps.get(lo, hi));
                    assert!(
                        (spare.get(lo, hi) - expected).abs() < 1e-12,
                        "{q:?}: range {lo}..={hi} {} against {expected}",
                        spare.get(lo, hi)
                    );
                    capped += usize::from(caps.get(lo, hi) < whole.get(lo, hi));
                }
            }
            let k = spare.steps_along(&UR5E_LEVER_ARMS, &step);
            assert!(k >= want.min(whole.steps_along(&UR5E_LEVER_ARMS, &step)) * (1.0 - 1e-9));
        }
        assert!(free > 200 && capped > 1000, "{free} {capped}");
    }
}

#[test]
fn the_chain_poses_the_links_as_mujoco_does() {
    // `ArmChain::link_poses` (each UR5e hinge a coordinate axis of its body: a turn mixes two
    // columns) against `mj_kinematics`, over whole swings of every joint.
    let mut c = checker(false);
    let (bodies, joints) = c.arm_links;
    c.detect_pose(&HOME_Q);
    let chain = ArmChain::new(&c.data, bodies, joints).expect("the arm is a chain");
    let mut r = ChaCha8Rng::seed_from_u64(46);
    for _ in 0..300 {
        let q = drawn(&mut r);
        c.detect_pose(&q);
        for (k, Frame { rot, pos: t }) in chain.link_poses(&q).iter().enumerate() {
            let (xpos, xmat) = (c.data.xpos()[bodies[k]], c.data.xmat()[bodies[k]]);
            for i in 0..3 {
                assert!(
                    (t[i] - xpos[i]).abs() < 1e-12,
                    "{q:?} link {k}: {t} against {xpos:?}"
                );
                for j in 0..3 {
                    assert!(
                        (rot[(i, j)] - xmat[3 * i + j]).abs() < 1e-12,
                        "{q:?} link {k}: {rot} against {xmat:?}"
                    );
                }
            }
        }
    }
}

/// An upper bound on the distance between two primitives, metres: exact where one is a
/// capsule; between two boxes, the least distance from a grid of points on the first box's
/// surface to the second box (every point of it is at least the distance away).
fn distance_at_most(x: &Shape, y: &Shape) -> f64 {
    let (Shape::Box { center, axes, half }, Shape::Box { .. }) = (x, y) else {
        return separation(x, y).clearance();
    };
    let mut least = f64::INFINITY;
    for face in 0..6 {
        let (i, sign) = (face / 2, if face % 2 == 0 { -1.0 } else { 1.0 });
        for u in 0..=8 {
            for v in 0..=8 {
                let mut s = Vector3::zeros();
                s[i] = sign * half[i];
                s[(i + 1) % 3] = half[(i + 1) % 3] * (u as f64 / 4.0 - 1.0);
                s[(i + 2) % 3] = half[(i + 2) % 3] * (v as f64 / 4.0 - 1.0);
                let p = Vector3::from_fn(|k, _| {
                    center[k] + axes[0][k] * s[0] + axes[1][k] * s[1] + axes[2][k] * s[2]
                });
                let point = Shape::Capsule {
                    a: p,
                    b: p,
                    radius: 0.0,
                };
                least = least.min(separation(&point, y).clearance());
            }
        }
    }
    least
}

#[test]
fn the_arms_own_pairs_keep_their_turned_bound_at_any_joints() {
    // The screen leaves out the arm's own pairs that keep their gap at any angles of the joints
    // between them (`turned_apart`): the bound taken at one configuration must hold at every
    // other. Whole swings of every joint, with and without a held block.
    for hold in [false, true] {
        let mut c = checker(hold);
        let mut r = ChaCha8Rng::seed_from_u64(45);
        let screen = c.screen_model().expect("a screen of this cell");
        let (mut bounded, mut tight) = (0, 0);
        for _ in 0..60 {
            let (q, q2) = (drawn(&mut r), drawn(&mut r));
            for TurnedBound { bound, x, y } in screen.turned_bounds(&q, &q2) {
                if bound <= 0.0 {
                    continue;
                }
                bounded += 1;
                let d = distance_at_most(&x, &y);
                assert!(d >= bound - 1e-9, "{bound} m bound, {d} m apart: {x:?} {y:?}");
                tight += usize::from(d < bound + 0.01);
            }
        }
        assert!(bounded > 1000 && tight > 50, "{bounded} {tight}");
    }
}

#[test]
fn a_block_held_away_from_the_pinch_was_vouched_for_beyond_the_lever_arms() {
    // Held 30 cm from the pinch, the cube's points lie farther from the joint axes than the
    // lever arms bound: a move within a measured spare carried it from 6.7 cm above the table
    // to 3.3 mm. Such a checker measures no spare, by either model.
    let spec = SceneSpec::from_str(CELL, "spare.yaml").expect("valid scene");
    let scene = Scene::load_spec(&spec).expect("scene (run tools/bootstrap)");
    let mut sim = Sim::new(&scene);
    place_cube(&scene, &mut sim, &Isometry3::translation(0.0, 0.0, 0.3));
    let mut c = SceneChecker::from_sim(&sim, 0.005).expect("checker");
    c.hold(0).expect("the cube is a block");
    let mut r = ChaCha8Rng::seed_from_u64(43);
    let (mut free, mut screened) = (0, 0);
    for _ in 0..300 {
        let q = drawn(&mut r);
        assert!(c.exact_spare(&q, SPARE_CAP).is_none(), "{q:?}");
        let (verdict, spare) = c.screen_spare(&q, &JointSpare::uniform(SPARE_CAP));
        assert_eq!(verdict, c.screen(&q));
        assert_eq!(spare, JointSpare::NONE);
        free += usize::from(c.is_free(&q));
        screened += usize::from(verdict == Some(true));
    }
    assert!(free > 50 && screened > 50, "{free} {screened}");
    // In the pinch, the same cube is measured.
    let mut c = checker(true);
    let mut r = ChaCha8Rng::seed_from_u64(43);
    assert!((0..300).any(|_| c.exact_spare(&drawn(&mut r), SPARE_CAP).is_some()));
}

#[test]
fn a_pairs_lever_ratio_bounds_how_far_its_parts_move_relative_to_each_other() {
    // Regression for the lever-arm ratios of the screen's pairs: a clearance vouches for
    // `1 / kappa` times the planner's lever-arm bound, so the pair's parts must never move
    // relative to each other more than `kappa` times that bound, for any joints and any step.
    for hold in [false, true] {
        let mut c = checker(hold);
        let mut r = ChaCha8Rng::seed_from_u64(77);
        let screen = c.screen_model().expect("a screen of this cell");
        let (mut short, mut tight) = (0, 0);
        for i in 0..400 {
            let q = drawn(&mut r);
            // Small steps and whole swings.
            let scale = if i % 2 == 0 { 0.05 } else { 2.0 };
            let q2: [f64; 6] = std::array::from_fn(|j| q[j] + scale * r.random_range(-1.0..1.0));
            for PairMove { kappa, moved, bound } in screen.pair_moves(&q, &q2) {
                assert!(kappa > 0.0 && kappa <= 1.0, "{kappa}");
                assert!(
                    moved <= bound + 1e-9,
                    "moved {moved} m, bound {bound} m (kappa {kappa})"
                );
                short += usize::from(kappa < 0.5);
                tight += usize::from(moved > 0.5 * bound);
            }
        }
        // Short chains (the forearm against wrist 2) move far less than the whole arm, and the
        // bound is not loose everywhere.
        assert!(short > 0 && tight > 0, "{short} {tight}");
    }
}

#[test]
fn a_coupler_within_the_margin_of_a_bin_wall_went_unreported_while_their_bodies_boxes_kept_apart() {
    // The gripper's right coupler 4.8 mm from the bin's wall with a 5 mm margin: MuJoCo's
    // broadphase grew each body's box by its compiled margin (none), not by the checker's, so
    // the pair was never tested and `is_free` said free.
    let mut c = checker(false);
    let q = [
        -3.108482044516199,
        -1.8411954563078488,
        2.438454926387847,
        -2.0640177064202962,
        -1.5542821248542857,
        -2.4237821435029545,
    ];
    assert!(!c.is_free(&q));
    let hits = c.collisions(&q);
    let coupler = hits
        .iter()
        .find(|h| h.a == "gripper/right_coupler" && h.b == "bin/wall_nx")
        .unwrap_or_else(|| panic!("{hits:?}"));
    assert!((0.0..0.005).contains(&coupler.distance), "{coupler:?}");
    assert!((truth(&mut c, &q) - coupler.distance).abs() < 1e-6);
}

/// The checker of [`CELL`] on `model` (the cell's collision model or its whole model), holding
/// the cube in the pinch or not.
fn checker_on(scene: &Scene, model: &mujoco_rs::prelude::MjModel, hold: bool) -> SceneChecker {
    let mut sim = Sim::new(scene);
    if hold {
        place_cube(scene, &mut sim, &Isometry3::identity());
    }
    let mut c = SceneChecker::on_model(scene, sim.data(), 0.005, model).expect("checker");
    if hold {
        c.hold(0).expect("the cube is a block");
    }
    c
}

#[test]
fn the_collision_model_keeps_every_id_and_collidable_geom_of_the_cell_in_a_fraction_of_the_memory() {
    let spec = SceneSpec::from_str(CELL, "spare.yaml").expect("valid scene");
    let scene = Scene::load_spec(&spec).expect("scene (run tools/bootstrap)");
    let (whole, lean) = (&scene.model, scene.collision_model().expect("collision model"));
    let (w, l) = (whole.ffi(), lean.ffi());
    let counts = |m: &mujoco_rs::mujoco_c::mjModel| {
        [
            m.nq, m.nv, m.nu, m.nbody, m.njnt, m.ngeom, m.nsite, m.ncam, m.nmocap, m.neq, m.nexclude,
        ]
    };
    assert_eq!(
        counts(w),
        counts(l),
        "nq nv nu nbody njnt ngeom nsite ncam nmocap neq nexclude"
    );
    let (mut collidable, mut meshes) = (0, 0);
    for g in 0..w.ngeom as usize {
        assert_eq!(whole.geom_bodyid()[g], lean.geom_bodyid()[g], "geom {g}'s body");
        assert_eq!(
            whole.geom_contype()[g],
            lean.geom_contype()[g],
            "geom {g}'s contype"
        );
        assert_eq!(
            whole.geom_conaffinity()[g],
            lean.geom_conaffinity()[g],
            "geom {g}'s conaffinity"
        );
        if whole.geom_contype()[g] == 0 && whole.geom_conaffinity()[g] == 0 {
            continue;
        }
        collidable += 1;
        assert_eq!(whole.geom_type()[g], lean.geom_type()[g], "geom {g}'s type");
        let (dw, dl) = (whole.geom_dataid()[g], lean.geom_dataid()[g]);
        assert_eq!(dw < 0, dl < 0, "geom {g} has a mesh in one model only");
        if dw < 0 {
            assert_eq!(whole.geom_size()[g], lean.geom_size()[g], "geom {g}'s size");
            assert_eq!(whole.geom_pos()[g], lean.geom_pos()[g], "geom {g}'s position");
            assert_eq!(
                whole.geom_quat()[g],
                lean.geom_quat()[g],
                "geom {g}'s orientation"
            );
        } else {
            // The mesh is its convex hull, recentred: as many hull vertices, fewer vertices.
            let hull = |m: &mujoco_rs::prelude::MjModel, d: i32| {
                m.mesh_graph()[m.mesh_graphadr()[d as usize] as usize]
            };
            assert_eq!(hull(whole, dw), hull(&lean, dl), "geom {g}'s hull vertices");
            meshes += 1;
        }
    }
    assert!(meshes >= 6, "{meshes} collidable meshes");
    assert!(collidable > 20, "{collidable} collidable geoms");
    // The meshes are most of the cell's model (44 MB; the collision model 1.1 MB).
    let (wb, lb) = (w.nbuffer as f64, l.nbuffer as f64);
    assert!(
        lb < wb / 20.0,
        "collision model {lb} bytes, whole model {wb} bytes"
    );
}

/// How far two distances of the same geoms may differ by rounding alone, metres: MuJoCo stores
/// mesh vertices as `f32` (7 digits, tens of nanometres at a gripper's size), and the hull's
/// vertices pass through two such roundings (out of the whole model, then recentred).
const ROUNDING: f64 = 1e-6;

/// Over seeded configurations near the obstacles, holding the cube and not, a checker on the
/// collision model reports the same collisions (pairs and distances) and the same exact spare
/// clearance as one on the whole model.
#[test]
fn a_checker_on_the_collision_model_answers_as_on_the_whole_model() {
    let spec = SceneSpec::from_str(CELL, "spare.yaml").expect("valid scene");
    let scene = Scene::load_spec(&spec).expect("scene (run tools/bootstrap)");
    let lean = scene.collision_model().expect("collision model");
    let mut r = ChaCha8Rng::seed_from_u64(17);
    let (mut touching, mut near) = (0, 0);
    for hold in [false, true] {
        let mut whole = checker_on(&scene, &scene.model, hold);
        let mut twin = checker_on(&scene, &lean, hold);
        for _ in 0..300 {
            let q = drawn(&mut r);
            let by_pair = |mut c: Vec<Collision>| {
                c.sort_by_key(Collision::pair);
                c
            };
            let (found, twin_found) = (by_pair(whole.collisions(&q)), by_pair(twin.collisions(&q)));
            touching += usize::from(!found.is_empty());
            let pairs = |c: &[Collision]| c.iter().map(Collision::pair).collect::<Vec<_>>();
            assert_eq!(
                pairs(&found),
                pairs(&twin_found),
                "pairs at {q:?} (holding: {hold})"
            );
            for (a, b) in found.iter().zip(&twin_found) {
                // A penetration's depth is MuJoCo's estimate, found from the shapes' centres,
                // which the recentred hull moves: both penetrate there. Apart (within the
                // margin) the distance is exact, so equal up to rounding.
                if a.distance < -ROUNDING {
                    assert!(b.distance < 0.0, "{a:?} and {b:?} at {q:?}");
                } else {
                    assert!(
                        (a.distance - b.distance).abs() < ROUNDING,
                        "{a:?} and {b:?} at {q:?}"
                    );
                    near += 1;
                }
            }
            assert_eq!(whole.is_free(&q), twin.is_free(&q), "free at {q:?}");
            match (whole.exact_spare(&q, SPARE_CAP), twin.exact_spare(&q, SPARE_CAP)) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    for lo in 0..6 {
                        for hi in lo..6 {
                            let (x, y) = (a.get(lo, hi), b.get(lo, hi));
                            assert!((x - y).abs() < ROUNDING, "spare {a:?} and {b:?} at {q:?}");
                        }
                    }
                }
                (a, b) => panic!("spare {a:?} and {b:?} at {q:?}"),
            }
        }
    }
    assert!(
        touching > 50,
        "only {touching} of 600 configurations touch something"
    );
    assert!(near > 10, "only {near} pairs within the margin and apart");
}
