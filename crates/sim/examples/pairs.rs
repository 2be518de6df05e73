use dexcube_cube::{Facelets, Move};
use dexcube_sim::cube::{CubeState, turn_face};
use dexcube_sim::{Scene, SceneKind, Sim};
fn main() {
    let scene = Scene::load(SceneKind::Cube).unwrap();
    for a in Move::QUARTER_TURNS {
        for b in Move::QUARTER_TURNS {
            let mut sim = Sim::new(scene.clone());
            turn_face(&mut sim, a);
            turn_face(&mut sim, b);
            sim.forward();
            let got = CubeState::read(&sim).unwrap().facelets_in_world().unwrap();
            let want = Facelets::SOLVED.apply(a).apply(b);
            if got != want {
                print!("{a} {b}; ");
            }
        }
    }
    println!();
}
