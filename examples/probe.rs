use macrotree::sim::{Scene, Sim};
fn main() {
    let t = std::time::Instant::now();
    let scene = Scene::load().unwrap();
    println!("load {:?}", t.elapsed());
    let m = &scene.model;
    println!(
        "nq {} nv {} nu {} nbody {} ngeom {}",
        m.ffi().nq,
        m.ffi().nv,
        m.ffi().nu,
        m.ffi().nbody,
        m.ffi().ngeom
    );
    let mut sim = Sim::new(&scene);
    let w = sim.observe();
    println!(
        "pinch {:?}\nrot {:?}\nwidth {}",
        w.pinch_pos, w.pinch_rot, w.gripper_width
    );
    for _ in 0..500 {
        sim.step();
    }
    let w = sim.observe();
    println!(
        "after 1s: pinch {:?} cube {:?} q {:?} width {}",
        w.pinch_pos, w.cube_pos, w.arm_q, w.gripper_width
    );
    for u in [0.0, 50.0, 100.0, 150.0, 200.0, 230.0, 255.0] {
        sim.set_gripper_ctrl(u);
        for _ in 0..1000 {
            sim.step();
        }
        let w = sim.observe();
        println!(
            "ctrl {u}: width {:.5} speed {:.4}",
            w.gripper_width, w.gripper_speed
        );
    }
    let t = std::time::Instant::now();
    for _ in 0..10000 {
        sim.step();
    }
    println!("10k steps {:?}", t.elapsed());
}
