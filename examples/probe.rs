use macrotree::sim::{HOME_Q, Scene, Sim};
fn main() {
    let scene = Scene::load().unwrap();
    println!("gains {:?}", scene.arm_gains);
    let mut sim = Sim::new(&scene);
    for _ in 0..1000 {
        sim.command_arm(&HOME_Q, &[0.0; 6]);
        sim.step();
    }
    let w = sim.observe();
    println!(
        "after 2s with ff: pinch {:?} err {:?}",
        w.pinch_pos,
        macrotree::world::conditions::home_error(&w)
    );
}
