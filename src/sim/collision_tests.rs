//! The exact spare clearance ([`SceneChecker::exact_spare`]) against `mj_geomDistance` of every
//! pair the checker tests, and the lever-arm bound that lets it vouch for nearby configurations.

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{SPARE_TOLERANCE, SceneChecker};
use crate::motion::plan::config::UR5E_LEVER_ARMS;
use crate::motion::plan::{CollisionChecker, SPARE_CAP};
use crate::motion::{HOME_Q, JOINT_LIMITS, down_pose, ik};
use crate::scene::SceneSpec;
use crate::sim::pair_filter::PairFilter;
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

fn checker(hold: bool) -> SceneChecker {
    let spec = SceneSpec::from_str(CELL, "spare.yaml").expect("valid scene");
    let scene = Scene::load_spec(&spec).expect("scene (run tools/bootstrap)");
    let sim = Sim::new(&scene);
    let mut c = SceneChecker::from_sim(&sim, 0.005).expect("checker");
    if hold {
        c.hold(0).expect("the cube is a block");
    }
    c
}

/// Over seeded configurations near the obstacles, the spare clearance never exceeds the exact
/// distance of any tested pair less the margin, it is free exactly when `is_free` says so
/// where both answer, and every configuration within the lever-arm reach of it keeps the margin.
fn spare_is_conservative(hold: bool, seed: u64) {
    let mut c = checker(hold);
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let (mut measured, mut near, mut vouched) = (0, 0, 0);
    // The largest excess of the measured distance over `mj_geomDistance` of every pair, metres.
    let mut worst = f64::NEG_INFINITY;
    for _ in 0..1200 {
        let q = drawn(&mut r);
        let Some(spare) = c.exact_spare(&q, SPARE_CAP) else {
            panic!("the MuJoCo checker measures its spare clearance")
        };
        let exact = truth(&mut c, &q);
        if spare < 0.0 {
            assert!(exact < c.margin() + 1e-3, "{q:?}: {exact} m apart, spare {spare}");
            continue;
        }
        worst = worst.max(spare + c.margin() - exact + SPARE_TOLERANCE);
        assert!(
            spare + c.margin() <= exact + 1e-6,
            "{q:?}: spare {spare} m beyond the margin, but a pair is {exact} m apart"
        );
        assert!(spare <= SPARE_CAP + 1e-12);
        if spare >= 0.0 {
            assert!(c.is_free(&q), "{q:?}: spare {spare} m but not free");
            measured += 1;
            near += usize::from(spare < SPARE_CAP);
            // Configurations within the reach of the spare clearance keep the margin.
            for _ in 0..3 {
                let dir: [f64; 6] = std::array::from_fn(|_| r.random_range(-1.0..1.0));
                let reach: f64 = (0..6).map(|j| UR5E_LEVER_ARMS[j] * dir[j].abs()).sum();
                let s = spare / reach * r.random_range(0.0..1.0);
                let q2: [f64; 6] = std::array::from_fn(|j| q[j] + dir[j] * s);
                let exact2 = truth(&mut c, &q2);
                assert!(
                    exact2 >= c.margin() - 1e-6,
                    "{q2:?} within the reach of {q:?} (spare {spare} m) is {exact2} m from something"
                );
                assert!(c.is_free(&q2), "{q2:?} within the reach of {q:?} is not free");
                vouched += 1;
            }
        } else {
            // Maybe not free: the planner asks `is_free`, which may still find it free.
            assert!(exact < c.margin() + 1e-3, "{q:?}: {exact} m apart, spare {spare}");
        }
    }
    eprintln!("spare clearance: worst excess over mj_geomDistance of every pair {worst:.2e} m");
    assert!(worst < SPARE_TOLERANCE);
    assert!(
        measured > 200 && near > 100 && vouched > 600,
        "{measured} {near} {vouched}"
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
