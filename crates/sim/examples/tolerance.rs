use dexcube_cube::Face;
use dexcube_sim::cube::{CubeState, turn_face_by};
use dexcube_sim::{Pose, Scene, SceneKind, Sim, rotation};
use mujoco_rs::wrappers::mj_model::MjtObjBase;
fn main() {
    let scene = Scene::load(SceneKind::Cube).unwrap();
    let body = |c: &str| {
        scene
            .model()
            .name_to_id(MjtObjBase::mjOBJ_BODY, &format!("cubelet:{c}"))
            .unwrap()
    };
    let right: Vec<usize> = ["URF", "UBR", "DFR", "DRB"]
        .iter()
        .map(|c| body(c))
        .collect();
    let left: Vec<usize> = ["UFL", "ULB", "DLF", "DBL"]
        .iter()
        .map(|c| body(c))
        .collect();
    for deg in [0.0, 3.0, 5.0, 6.0, 7.0, 8.0, 10.0, 20.0, 45.0] {
        let mut sim = Sim::new(scene.clone());
        sim.set_object_pose(&Pose {
            position: [1.3, 0.6, 0.5],
            orientation: rotation::IDENTITY,
        });
        turn_face_by(&mut sim, Face::U, (deg as f64).to_radians());
        sim.forward();
        let start = CubeState::read(&sim).unwrap().cubelet_rotation(0);
        let t = std::time::Instant::now();
        for _ in 0..8 {
            for (bodies, sign) in [(&right, -1.0), (&left, 1.0)] {
                for &b in bodies.iter() {
                    sim.data_mut().xfrc_applied_mut()[b] = [0.0, 0.0, 0.0, sign * 0.01, 0.0, 0.0];
                }
            }
            if let Err(e) = sim.step() {
                println!("{e}");
                break;
            }
        }
        let s = CubeState::read(&sim).unwrap();
        let turned = rotation::twist_about(
            &rotation::mul(&s.cubelet_rotation(0), &rotation::conj(&start)),
            [1.0, 0.0, 0.0],
        );
        println!(
            "U off by {deg:>4}°: URF turned {:>6.1}° about x, {:.0} steps/s",
            turned.to_degrees(),
            8.0 / t.elapsed().as_secs_f64()
        );
    }
}
