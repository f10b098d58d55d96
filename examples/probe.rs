use macrotree::sim::{Scene, Sim};
fn main() {
    let scene = Scene::load().unwrap();
    let sim = Sim::new(&scene);
    let w = sim.observe();
    println!(
        "left {:?} right {:?} pinch {:?} yaw {}",
        w.left_pad_pos,
        w.right_pad_pos,
        w.pinch_pos,
        macrotree::actions::tool_yaw(&w.pinch_rot)
    );
}
