//! `VecEnv`: N environments on worker threads give, per environment, exactly what one
//! `MacroEnv` gives for the same resets and actions; `send`/`recv` return whichever finish.

use macrotree::App;
use macrotree::env::{Action, Duration, EnvConfig, MacroEnv, Primitive, Reset, StepResult, VecEnv};

use crate::support::flagship;

fn actions(i: usize) -> Vec<Action> {
    let reach = format!(
        "{{\"reach\": {{\"target\": \"cube\", \"offset\": [0, 0, {}]}}}}",
        0.10 + 0.02 * i as f64
    );
    vec![
        Action::Leaf(reach),
        Action::Primitive(Primitive::CloseGripper {
            command: Some(40.0 * i as f64),
            width: None,
            duration: Duration::Seconds(0.2),
        }),
        Action::Setpoint([-1.5, -1.5, 1.5, -1.6, -1.5, 0.1 * i as f64, 10.0]),
    ]
}

fn key(r: &StepResult) -> (Vec<u64>, u64) {
    let o = &r.observation;
    let mut v: Vec<f64> = o
        .joint_pos
        .iter()
        .chain(&o.joint_vel)
        .chain(&o.pinch_pos)
        .copied()
        .collect();
    for b in &o.objects {
        v.extend(b.pos.iter().chain(&b.quat).chain(&b.linvel));
    }
    (v.into_iter().map(f64::to_bits).collect(), r.physics_steps)
}

fn single(i: usize) -> Vec<(Vec<u64>, u64)> {
    let mut env = MacroEnv::new(&App::new(), flagship::scene().clone(), None, EnvConfig::default()).unwrap();
    env.reset(&Reset::Seed(100 + i as u64)).unwrap();
    actions(i).iter().map(|a| key(&env.step(a).unwrap())).collect()
}

#[test]
fn each_sub_environment_matches_a_single_environment_bit_for_bit() {
    let n = 3;
    let mut v = VecEnv::with_threads(
        &App::new(),
        flagship::scene().clone(),
        None,
        EnvConfig::default(),
        n,
        2,
    )
    .unwrap();
    assert_eq!((v.num_envs(), v.threads()), (3, 2));
    let resets: Vec<Reset> = (0..n).map(|i| Reset::Seed(100 + i as u64)).collect();
    let obs = v.reset(&resets).unwrap();
    assert_ne!(
        obs[0].objects[0].pos, obs[1].objects[0].pos,
        "independent placements"
    );
    let mut got: Vec<Vec<(Vec<u64>, u64)>> = vec![Vec::new(); n];
    for k in 0..3 {
        let batch: Vec<Action> = (0..n).map(|i| actions(i)[k].clone()).collect();
        for (i, r) in v.step(&batch).unwrap().into_iter().enumerate() {
            got[i].push(key(&r.unwrap()));
        }
    }
    for (i, g) in got.iter().enumerate() {
        assert_eq!(g, &single(i), "sub-environment {i}");
    }
}

#[test]
fn recv_returns_whichever_steps_finish_and_each_once() {
    let n = 4;
    let mut v = VecEnv::with_threads(
        &App::new(),
        flagship::scene().clone(),
        None,
        EnvConfig::default(),
        n,
        2,
    )
    .unwrap();
    let resets: Vec<Reset> = (0..n).map(|i| Reset::Seed(100 + i as u64)).collect();
    v.reset(&resets).unwrap();
    // Environment 0 reaches (hundreds of control periods), the others hold for one period.
    let ids = [0, 1, 2, 3];
    let mut batch = vec![actions(0)[0].clone()];
    batch.extend((1..n).map(|i| actions(i)[2].clone()));
    v.send(&ids, &batch).unwrap();
    assert_eq!(v.pending(), 4);
    // Refused while they run: a second step on a busy environment, a synchronous step, bad recv.
    let busy = v.send(&[1], &[actions(1)[2].clone()]).unwrap_err();
    assert!(busy.to_string().contains("still running"), "{busy}");
    assert!(
        v.step(&batch).is_err(),
        "a synchronous step while steps are pending"
    );
    assert_eq!(v.recv(0).unwrap_err().kind(), "invalid_action");
    assert!(v.recv(5).is_err());
    let mut seen = Vec::new();
    let mut reach = None;
    while v.pending() > 0 {
        let got = v.recv(1).unwrap();
        assert!(!got.is_empty());
        for (i, r) in got {
            let r = r.unwrap();
            assert!(r.success(), "{i}: {:?}", r.failure);
            seen.push((i, r.physics_steps));
            if i == 0 {
                reach = Some(key(&r));
            }
        }
    }
    seen.sort();
    assert_eq!(seen.iter().map(|s| s.0).collect::<Vec<_>>(), ids);
    assert!(seen[0].1 > 100 && seen[1..].iter().all(|s| s.1 == 2), "{seen:?}");
    assert_eq!(
        reach.unwrap(),
        single(0)[0],
        "the same result as a single environment"
    );
    // Invalid ids and lengths.
    assert!(v.send(&[7], &[actions(0)[2].clone()]).is_err());
    assert!(
        v.send(&[1, 1], &[actions(0)[2].clone(), actions(0)[2].clone()])
            .is_err()
    );
    assert!(v.step(&[actions(0)[2].clone()]).is_err());
    // An invalid action refuses the whole batch before any environment moves.
    let before: Vec<u64> = (0..n)
        .map(|i| v.with_env(i, |e| e.cell().sim().steps()).unwrap())
        .collect();
    let bad = Action::Setpoint([f64::NAN; 7]);
    let e = v
        .step(&[
            actions(1)[2].clone(),
            bad,
            actions(2)[2].clone(),
            actions(3)[2].clone(),
        ])
        .unwrap_err();
    assert_eq!(e.kind(), "invalid_action");
    assert!(e.to_string().contains("environment 1"), "{e}");
    let after: Vec<u64> = (0..n)
        .map(|i| v.with_env(i, |e| e.cell().sim().steps()).unwrap())
        .collect();
    assert_eq!(before, after, "no environment moved");
    assert_eq!(v.pending(), 0);
    let ok = v
        .step(&(0..n).map(|i| actions(i)[2].clone()).collect::<Vec<_>>())
        .unwrap();
    assert!(ok.iter().all(|r| r.is_ok()), "the vector environment steps on");
}

#[test]
fn an_interrupt_stops_every_running_step_and_asks_for_a_reset() {
    let mut v = VecEnv::with_threads(
        &App::new(),
        flagship::scene().clone(),
        None,
        EnvConfig::default(),
        2,
        2,
    )
    .unwrap();
    v.reset(&[Reset::Seed(1), Reset::Seed(2)]).unwrap();
    let long = Action::Primitive(Primitive::Wait {
        duration: Duration::Seconds(30.0),
        gripper: None,
    });
    let mut asked = 0;
    let e = v
        .step_each_with(&[0, 1], &[long.clone(), long.clone()], &mut || {
            asked += 1;
            asked > 3
        })
        .unwrap_err();
    assert_eq!(e.kind(), "interrupted");
    for i in 0..2 {
        let t = v.with_env(i, |e| e.cell().world().time).unwrap();
        assert!(t < 30.0, "environment {i} stopped early, at {t} s");
    }
    assert!(
        v.step(&[long.clone(), long.clone()])
            .unwrap_err()
            .to_string()
            .contains("reset")
    );
    v.reset(&[Reset::Seed(1), Reset::Seed(2)]).unwrap();
    let short = Action::Primitive(Primitive::Wait {
        duration: Duration::Seconds(0.1),
        gripper: None,
    });
    assert!(v.step(&[short.clone(), short]).unwrap().iter().all(|r| r.is_ok()));
}
