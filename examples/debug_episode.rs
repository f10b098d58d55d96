use macrotree::actions::Cell;
use macrotree::episode::{EpisodeConfig, EpisodeObserver, run_in_cell};
use macrotree::runtime::TreeRunner;
use macrotree::sim::{Layout, Scene};
use std::sync::Arc;
struct P(f64);
impl EpisodeObserver for P {
    fn on_tick(&mut self, cell: &Cell, _r: &mut TreeRunner) {
        let w = cell.world();
        if w.time >= self.0 {
            self.0 += 0.1;
            let m = &cell.sim().scene().model;
            println!(
                "qfrc_constraint {:.2?} act_force {:.1?} ncon {}",
                &cell.sim().data().qfrc_constraint()[..20],
                cell.sim().data().actuator_force(),
                cell.sim().data().contact().len()
            );
            for c in cell.sim().data().contact() {
                let n = |g: i32| {
                    m.id_to_name(mujoco_rs::prelude::MjtObjBase::mjOBJ_GEOM, g as usize)
                        .unwrap_or("?")
                        .to_string()
                };
                let (a, b) = (n(c.geom[0]), n(c.geom[1]));
                if !(a == "floor" && b == "cube") && !(a.starts_with("bowl") || b.starts_with("bowl")) {
                    print!("[{a}|{b} {:.4}] ", c.dist);
                }
            }
            println!(
                "q {:.4?} setpoint {:.4?} fk(q) {:.4?} fk(set) {:.4?}",
                w.arm_q,
                cell.arm_setpoint(),
                macrotree::motion::fk(&w.arm_q).translation.vector.as_slice(),
                macrotree::motion::fk(&cell.arm_setpoint())
                    .translation
                    .vector
                    .as_slice()
            );
            println!(
                "t {:.2} pinch {:.4?} cube {:.4?} width {:.4} contacts L{} R{} qd {:.3}",
                w.time,
                w.pinch_pos.as_slice(),
                w.cube_pos.as_slice(),
                w.gripper_width,
                w.left_pad_contact,
                w.right_pad_contact,
                w.arm_qd.iter().map(|v| v.abs()).fold(0.0, f64::max)
            );
        }
    }
}
fn main() {
    let a: Vec<f64> = std::env::args().skip(1).map(|s| s.parse().unwrap()).collect();
    let plan = Arc::new(macrotree::plan::load_plan(std::path::Path::new("trees/cube_to_bowl.yaml")).unwrap());
    let scene = Scene::load().unwrap();
    let cfg = EpisodeConfig {
        layout: Layout::new(a[0], a[1], a[2], a[3], a[4]),
        max_sim_time: a[5],
        ..Default::default()
    };
    let mut cell = Cell::new(&scene, &cfg.layout, cfg.control_period);
    let r = run_in_cell(&mut cell, plan, &cfg, &mut P(0.0));
    println!("{:?}", r.failure_reason);
}
