use dexcube_cube::Move;
use dexcube_sim::cube::{CubeState, turn_face};
use dexcube_sim::{Pose, Scene, SceneKind, Sim, rotation};
fn main() {
    let scene = Scene::load(SceneKind::Cube).unwrap();
    for (name, moves) in [
        ("solved", vec![]),
        ("R", vec![Move::QUARTER_TURNS[2]]),
        ("D", vec![Move::QUARTER_TURNS[6]]),
        ("RU", vec![Move::QUARTER_TURNS[2], Move::QUARTER_TURNS[0]]),
    ] {
        let mut sim = Sim::new(scene.clone());
        sim.set_object_pose(&Pose {
            position: [1.3, 0.6, 0.3],
            orientation: rotation::IDENTITY,
        });
        for m in &moves {
            turn_face(&mut sim, *m);
        }
        sim.forward();
        print!("{name}: ");
        for i in 0..30 {
            if let Err(e) = sim.step() {
                print!("ERR {e}");
                break;
            }
            if i % 3 == 0 {
                let s = CubeState::read(&sim).unwrap();
                print!("{:.3}/{} ", s.misalignment(), sim.data().ffi().ncon);
            }
        }
        println!();
    }
}
