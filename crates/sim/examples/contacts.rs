use dexcube_sim::{Pose, Scene, SceneKind, Sim, rotation};
use mujoco_rs::wrappers::mj_model::MjtObjBase;
use std::collections::BTreeMap;
fn main() {
    let scene = Scene::load(SceneKind::Cube).unwrap();
    let mut sim = Sim::new(scene.clone());
    sim.set_object_pose(&Pose {
        position: [1.3, 0.6, 0.3],
        orientation: rotation::IDENTITY,
    });
    sim.forward();
    for _ in 0..30 {
        sim.step().unwrap();
    }
    let m = scene.model();
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    let n = sim.data().ffi().ncon as usize;
    for c in sim.data().contact().iter().take(n) {
        let a = m
            .id_to_name(MjtObjBase::mjOBJ_GEOM, c.geom[0] as usize)
            .unwrap_or("?");
        let b = m
            .id_to_name(MjtObjBase::mjOBJ_GEOM, c.geom[1] as usize)
            .unwrap_or("?");
        *counts
            .entry(format!("{a}-{b} dist {:.4}", c.dist))
            .or_default() += 1;
    }
    for (k, v) in counts {
        println!("{v} {k}");
    }
}
