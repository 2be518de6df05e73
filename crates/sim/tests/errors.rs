//! Bad set-ups fail with messages that name the file and the fix; blow-ups are values.

use std::path::Path;

use dexcube_sim::{Scene, SceneKind, Sim, SimError, assets_dir};

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

#[test]
fn a_missing_hand_model_names_the_file_and_the_set_up() {
    let empty = std::env::temp_dir().join("dexcube-no-assets");
    std::fs::create_dir_all(empty.join("rot")).unwrap();
    std::fs::write(empty.join("rot/scene.xml"), "<mujoco/>").unwrap();
    let err = Scene::load_from(SceneKind::Rot, &empty).err().unwrap();
    assert!(matches!(err, SimError::MissingAsset { .. }), "{err}");
    let message = err.to_string();
    assert!(
        message.contains("shadow_hand/hand/robot.xml") && message.contains("scripts/setup"),
        "{message}"
    );
}

#[test]
fn a_broken_scene_reports_mujocos_reason_and_the_path() {
    let assets = std::env::temp_dir().join("dexcube-broken-assets");
    let _ = std::fs::remove_dir_all(&assets);
    copy_dir(&assets_dir(), &assets);
    std::fs::write(
        assets.join("cube/scene.xml"),
        "<mujoco><worldbody><geom type='nonsense'/></worldbody></mujoco>",
    )
    .unwrap();
    let err = Scene::load_from(SceneKind::Cube, &assets).err().unwrap();
    let message = err.to_string();
    assert!(matches!(err, SimError::Load { .. }), "{message}");
    assert!(
        message.contains("cube/scene.xml") && message.contains("nonsense"),
        "{message}"
    );
}

#[test]
fn a_blown_up_state_is_an_error_value_and_reset_recovers() {
    let mut sim = Sim::new(Scene::load(SceneKind::Rot).unwrap());
    let dof = sim.scene().object().free().dof;
    sim.data_mut().qvel_mut()[dof] = f64::NAN;
    let err = sim.step().expect_err("a NaN velocity is caught");
    assert!(matches!(err, SimError::Diverged { .. }), "{err}");
    sim.reset();
    sim.step().expect("a reset simulation steps again");
}
