//! The physical cube's readout against the `cube` crate: kinematic turns, tumbling, pushes.

use dexcube_cube::{Face, Facelets, Move, parse_moves};
use dexcube_sim::cube::{CubeState, turn_face, turn_face_by};
use dexcube_sim::rotation::{self, about};
use dexcube_sim::{Pose, Scene, SceneKind, Sim};

fn cube_sim() -> Sim {
    let mut sim = Sim::new(Scene::load(SceneKind::Cube).expect("run scripts/setup first"));
    // Hold the cube in free space above the floor, away from the hand, so settling tests
    // see only the cube's own mechanics.
    let pose = Pose { position: [1.3, 0.6, 0.3], orientation: rotation::IDENTITY };
    sim.set_object_pose(&pose);
    sim.forward();
    sim
}

fn read(sim: &Sim) -> CubeState {
    CubeState::read(sim).expect("a cube scene")
}

/// Lets the physics run for `steps` control steps with the hand idle.
fn settle(sim: &mut Sim, steps: usize) {
    for _ in 0..steps {
        sim.step().expect("the cube stays stable");
    }
}

#[test]
fn each_quarter_turn_reads_back_as_the_cube_crate_says() {
    for m in Move::QUARTER_TURNS {
        let mut sim = cube_sim();
        assert!(turn_face(&mut sim, m));
        sim.forward();
        let state = read(&sim);
        let expected = Facelets::SOLVED.apply(m);
        assert_eq!(state.facelets_in_world().unwrap(), expected, "{m}");
        assert!(state.is_aligned(), "{m}: misaligned by {}", state.misalignment());
        assert!(expected.orientations().contains(&state.facelets_in_cube_frame().unwrap()));
    }
}

#[test]
fn random_sequences_read_back_after_settling() {
    let mut seed = 0x9e3779b97f4a7c15u64;
    for _ in 0..6 {
        let mut sim = cube_sim();
        let mut expected = Facelets::SOLVED;
        for _ in 0..20 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let m = Move::QUARTER_TURNS[(seed % 12) as usize];
            turn_face(&mut sim, m);
            expected = expected.apply(m);
        }
        sim.forward();
        assert_eq!(read(&sim).facelets_in_world().unwrap(), expected);
        settle(&mut sim, 25);
        let state = read(&sim);
        assert!(state.is_aligned(), "misaligned by {} after settling", state.misalignment());
        assert!(expected.orientations().contains(&state.facelets_in_cube_frame().unwrap()));
        assert!(expected.orientations().contains(&state.facelets_in_world().unwrap()));
    }
}

#[test]
fn a_tumbled_cube_still_reads_correctly() {
    let mut sim = cube_sim();
    let scramble = parse_moves("R U F' R2 U'").unwrap();
    for &m in &scramble {
        turn_face(&mut sim, m);
    }
    let expected = Facelets::SOLVED.apply_all(&scramble);
    // A quarter turn of the whole cube about x, like R: the world view changes exactly so.
    let mut pose = read(&sim).pose();
    pose.orientation = about([1.0, 0.0, 0.0], -std::f64::consts::FRAC_PI_2);
    sim.set_object_pose(&pose);
    sim.forward();
    let turned = expected.apply_all(&parse_moves("R L'").unwrap());
    assert_eq!(read(&sim).facelets_in_world().unwrap(), turned);
    // An arbitrary tilt: the cube's own view is unchanged, the world's is a whole-cube turn.
    let own_view = read(&sim).facelets_in_cube_frame().unwrap();
    pose.orientation = rotation::normalise(&[0.8, 0.3, -0.4, 0.33]);
    sim.set_object_pose(&pose);
    sim.forward();
    let state = read(&sim);
    assert_eq!(state.facelets_in_cube_frame().unwrap(), own_view);
    assert!(expected.orientations().contains(&state.facelets_in_world().unwrap()));
}

#[test]
fn partial_turns_show_as_layer_angle_and_misalignment() {
    let mut sim = cube_sim();
    turn_face_by(&mut sim, Face::U, 0.3);
    sim.forward();
    let state = read(&sim);
    assert!((state.layer_angle(Face::U) - 0.3).abs() < 1e-9, "{}", state.layer_angle(Face::U));
    assert!((state.layer_angle(Face::D) - 0.3).abs() < 1e-9, "D against U is the same turn");
    assert!(state.layer_angle(Face::R).abs() < 1e-9);
    assert!(!state.is_aligned());
    assert!((state.misalignment() - 0.3).abs() < 1e-9);
    turn_face_by(&mut sim, Face::U, -0.3 + 0.05);
    sim.forward();
    assert!(read(&sim).is_aligned());
}

#[test]
fn a_shearing_push_leaves_a_valid_cube() {
    let mut sim = cube_sim();
    let urf = sim
        .scene()
        .model()
        .name_to_id(mujoco_rs::wrappers::mj_model::MjtObjBase::mjOBJ_BODY, "cubelet:URF")
        .unwrap();
    // 20 N sideways on one corner cubelet for 0.2 s: far more than a finger applies.
    for step in 0..30 {
        sim.data_mut().xfrc_applied_mut()[urf] = if step < 5 { [0.0, 20.0, 0.0, 0.0, 0.0, 0.0] } else { [0.0; 6] };
        sim.step().expect("stable under a hard push");
    }
    let state = read(&sim);
    assert!(state.facelets_in_cube_frame().is_ok(), "not a valid cube after the push");
}

#[test]
fn a_dropped_cube_holds_together() {
    let mut sim = cube_sim();
    settle(&mut sim, 40); // falls 0.3 m to the floor
    let state = read(&sim);
    assert!(state.pose().position[2] < 0.05, "it fell to the floor");
    assert_eq!(state.facelets_in_cube_frame().unwrap(), Facelets::SOLVED);
    assert!(state.is_aligned(), "misaligned by {}", state.misalignment());
}
