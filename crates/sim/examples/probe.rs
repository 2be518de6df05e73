use dexcube_sim::{Scene, SceneKind, Sim};
fn main() {
    for kind in SceneKind::ALL {
        let scene = match Scene::load(kind) {
            Ok(s) => s,
            Err(e) => {
                println!("{kind}: {e}");
                continue;
            }
        };
        let m = scene.model().ffi();
        println!(
            "{kind}: nq {} nv {} nu {} nbody {} ngeom {} njnt {} ntendon {}",
            m.nq, m.nv, m.nu, m.nbody, m.ngeom, m.njnt, m.ntendon
        );
        let mut sim = Sim::new(scene);
        let t = std::time::Instant::now();
        let mut ncon = 0;
        for i in 0..200 {
            let a = [((i as f64) * 0.1).sin(); 20];
            sim.set_action(&a);
            if let Err(e) = sim.step() {
                println!("  {e}");
                sim.reset();
            }
            ncon += sim.data().ffi().ncon;
        }
        println!(
            "  {:.0} control steps/s, {:.1} contacts/step, object {:?}",
            200.0 / t.elapsed().as_secs_f64(),
            ncon as f64 / 200.0,
            sim.object_pose().position
        );
    }
}
