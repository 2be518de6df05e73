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
    let mut sim = Sim::new(scene.clone());
    sim.set_object_pose(&Pose {
        position: [1.3, 0.6, 0.5],
        orientation: rotation::IDENTITY,
    });
    turn_face_by(&mut sim, Face::U, std::f64::consts::FRAC_PI_4);
    sim.forward();
    let start: Vec<_> = (0..8)
        .map(|i| CubeState::read(&sim).unwrap().cubelet_rotation(i))
        .collect();
    for step in 0..6 {
        for (bodies, sign) in [(&right, -1.0), (&left, 1.0)] {
            for &b in bodies.iter() {
                sim.data_mut().xfrc_applied_mut()[b] = [0.0, 0.0, 0.0, sign * 0.01, 0.0, 0.0];
            }
        }
        sim.step().unwrap();
        let s = CubeState::read(&sim).unwrap();
        let moved: Vec<String> = (0..8)
            .map(|i| {
                format!(
                    "{:.0}",
                    rotation::angle_between(&s.cubelet_rotation(i), &start[i]).to_degrees()
                )
            })
            .collect();
        println!(
            "step {step}: cubelets moved (deg) {:?}, ncon {}",
            moved,
            sim.data().ffi().ncon
        );
    }
}
