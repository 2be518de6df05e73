//! The physical cube's readout against the `cube` crate: kinematic turns, tumbling, pushes.

use dexcube_cube::{Face, Facelets, Move, parse_moves};
use dexcube_sim::cube::{
    CubeState, face_normal, face_toward, read_puzzle, turn_face, turn_face_by, turned_since,
};
use dexcube_sim::rotation::{self, about};
use dexcube_sim::{PhysicsScales, Pose, Scene, SceneKind, Sim};

fn cube_sim() -> Sim {
    let mut sim = Sim::new(Scene::load(SceneKind::Cube).expect("run scripts/setup first"));
    // Hold the cube in free space above the floor, away from the hand, so settling tests
    // see only the cube's own mechanics.
    let pose = Pose {
        position: [1.3, 0.6, 0.3],
        orientation: rotation::IDENTITY,
    };
    sim.set_object_pose(&pose);
    sim.forward();
    sim
}

fn read(sim: &Sim) -> CubeState {
    CubeState::read(sim).expect("a cube scene")
}

/// Checks that `seen` is the `expected` cube, held in some whole-cube orientation.
fn assert_held_differently(
    expected: &Facelets,
    seen: Result<Facelets, dexcube_cube::FaceletError>,
) {
    let seen = seen.expect("a valid cube");
    assert!(
        expected.orientations().contains(&seen),
        "{seen} is not {expected} turned"
    );
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
        assert!(
            state.is_aligned(),
            "{m}: misaligned by {}",
            state.misalignment()
        );
        assert_held_differently(&expected, state.facelets_in_cube_frame());
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
        assert!(
            state.is_aligned(),
            "misaligned by {} after settling",
            state.misalignment()
        );
        assert_held_differently(&expected, state.facelets_in_cube_frame());
        assert_held_differently(&expected, state.facelets_in_world());
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
    assert_held_differently(&expected, state.facelets_in_world());
}

#[test]
fn partial_turns_show_as_layer_angle_and_misalignment() {
    let mut sim = cube_sim();
    turn_face_by(&mut sim, Face::U, 0.3);
    sim.forward();
    let state = read(&sim);
    assert!(
        (state.layer_angle(Face::U) - 0.3).abs() < 1e-9,
        "{}",
        state.layer_angle(Face::U)
    );
    assert!(
        (state.layer_angle(Face::D) - 0.3).abs() < 1e-9,
        "D against U is the same turn"
    );
    assert!(state.layer_angle(Face::R).abs() < 1e-9);
    assert!(!state.is_aligned());
    assert!((state.misalignment() - 0.3).abs() < 1e-9);
    turn_face_by(&mut sim, Face::U, -0.3 + 0.05);
    sim.forward();
    assert!(read(&sim).is_aligned());
}

/// The mean frame is DBL's on a square cube, and halfway between the layers when one is
/// turned part-way, whether or not DBL's layer is the one that turned.
#[test]
fn the_mean_frame_splits_a_partial_turn_between_the_layers() {
    let mut sim = cube_sim();
    let tilted = rotation::normalise(&[0.8, 0.3, -0.4, 0.33]);
    let mut pose = sim.object_pose();
    pose.orientation = tilted;
    sim.set_object_pose(&pose);
    sim.forward();
    let angle = rotation::angle_between;
    assert!(angle(&read(&sim).mean_frame(), &tilted) < 1e-9);
    for face in [Face::R, Face::L] {
        // Turned as seen in the world; the layers are named in the cube's own frame.
        let own = face_toward(&tilted, face_normal(face));
        turn_face_by(&mut sim, face, 0.2);
        sim.forward();
        let state = read(&sim);
        let mean = state.mean_frame();
        // The two layers' frames, 0.2 apart; the one point 0.1 from each is halfway.
        let (stayed, turned) = (
            state.layer_behind(own).0,
            state.layer_behind(own.opposite()).0,
        );
        assert!((angle(&stayed, &turned) - 0.2).abs() < 1e-6, "{face:?}");
        for layer in [stayed, turned] {
            assert!((angle(&mean, &layer) - 0.1).abs() < 1e-6, "{face:?}");
        }
        turn_face_by(&mut sim, face, -0.2);
        sim.forward();
        assert!(angle(&read(&sim).mean_frame(), &tilted) < 1e-9, "{face:?}");
    }
}

/// The bodies of the named cubelets.
fn cubelet_bodies(sim: &Sim, names: [&str; 4]) -> [usize; 4] {
    use mujoco_rs::wrappers::mj_model::MjtObjBase;
    let model = sim.scene().model();
    names.map(|c| {
        model
            .name_to_id(MjtObjBase::mjOBJ_BODY, &format!("cubelet:{c}"))
            .unwrap()
    })
}

/// Applies `wrench` (force, then torque, world frame) to `first` and its negative to
/// `second` for one control step.
fn push_apart(sim: &mut Sim, first: &[usize; 4], second: &[usize; 4], wrench: [f64; 6]) {
    for (bodies, sign) in [(first, 1.0), (second, -1.0)] {
        for &b in bodies {
            sim.data_mut().xfrc_applied_mut()[b] = wrench.map(|w| sign * w);
        }
    }
    sim.step().expect("stable under a hard push");
}

const TOP: [&str; 4] = ["URF", "UFL", "ULB", "UBR"];
const BOTTOM: [&str; 4] = ["DFR", "DLF", "DRB", "DBL"];
const RIGHT: [&str; 4] = ["URF", "UBR", "DFR", "DRB"];
const LEFT: [&str; 4] = ["UFL", "ULB", "DLF", "DBL"];

#[test]
fn a_shearing_push_leaves_a_valid_cube() {
    let mut sim = cube_sim();
    let (top, bottom) = (cubelet_bodies(&sim, TOP), cubelet_bodies(&sim, BOTTOM));
    // 2 N on each cubelet, top layer one way and bottom layer the other, for 0.2 s: twice
    // what a fingertip's actuator can push, sheared across the layers. Then let go.
    for step in 0..30 {
        let force = if step < 5 { 2.0 } else { 0.0 };
        push_apart(
            &mut sim,
            &top,
            &bottom,
            [force, 0.5 * force, 0.0, 0.0, 0.0, 0.0],
        );
    }
    let state = read(&sim);
    assert!(
        state.facelets_in_cube_frame().is_ok(),
        "not a valid cube after the push"
    );
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

/// Twists the R layer against the L layer with `torque` N·m per cubelet for `steps` control
/// steps, after turning U by `u_angle`; returns how far URF turned about x.
fn twist_r_against_l(u_angle: f64, torque: f64, steps: usize) -> f64 {
    let mut sim = cube_sim();
    turn_face_by(&mut sim, Face::U, u_angle);
    sim.forward();
    let start = read(&sim).cubelet_rotation(0);
    let (right, left) = (cubelet_bodies(&sim, RIGHT), cubelet_bodies(&sim, LEFT));
    for _ in 0..steps {
        push_apart(&mut sim, &right, &left, [0.0, 0.0, 0.0, -torque, 0.0, 0.0]);
    }
    let now = read(&sim).cubelet_rotation(0);
    rotation::twist_about(
        &rotation::mul(&now, &rotation::conj(&start)),
        [1.0, 0.0, 0.0],
    )
    .abs()
}

#[test]
fn only_aligned_layers_turn() {
    let free = twist_r_against_l(0.0, 0.01, 6);
    assert!(free > 0.3, "an aligned cube's R layer turns: {free}");
    // The paper's cube tolerates about 5° of misalignment; ours turns at 5° and jams at 8°.
    let nearly = twist_r_against_l(5f64.to_radians(), 0.01, 6);
    assert!(nearly > 0.3, "5° of misalignment is tolerated: {nearly}");
    for degrees in [8.0, 15.0, 45.0] {
        let blocked = twist_r_against_l(f64::to_radians(degrees), 0.01, 6);
        assert!(blocked < 0.1, "U turned {degrees}° blocks R: {blocked}");
    }
}

/// The open-hand action drives every joint back towards the model's zero pose (the flat hand
/// that episodes start from), or to its actuator's nearest limit, from a clenched hand.
#[test]
fn the_open_hand_action_flattens_a_clenched_hand() {
    let mut sim = cube_sim();
    sim.set_action(&[1.0; dexcube_sim::HAND_ACTUATORS]);
    settle(&mut sim, 25);
    let clenched = sim.hand_angles();
    sim.set_action(&sim.scene().open_hand_action());
    settle(&mut sim, 25);
    let open = sim.hand_angles();
    let far = |angles: &[f64]| angles.iter().map(|a| a.abs()).fold(0.0, f64::max);
    assert!(far(&clenched) > 1.0, "clenched: {clenched:?}");
    assert!(
        open.iter()
            .zip(&clenched)
            .all(|(o, c)| o.abs() <= c.abs() + 0.05),
        "every joint nearer zero: {clenched:?} then {open:?}"
    );
    assert!(far(&open) < 0.5, "open: {open:?}");
}

/// A physics state taken mid-motion and restored into a fresh simulation of the scene goes
/// on exactly as the original did: what lets an episode start where an operator's stage did.
#[test]
fn a_restored_physics_state_continues_exactly() {
    let scene = Scene::load(SceneKind::Cube).expect("run scripts/setup first");
    let mut original = Sim::new(scene.clone());
    let action = |k: usize| {
        std::array::from_fn::<f64, { dexcube_sim::HAND_ACTUATORS }, _>(|j| {
            ((k * 7 + j * 3) as f64 * 0.37).sin()
        })
    };
    let run = |sim: &mut Sim, from: usize, to: usize| {
        for k in from..to {
            sim.set_action(&action(k));
            sim.step().expect("stable");
        }
    };
    run(&mut original, 0, 10);
    let saved = original.physics_state();
    assert_eq!(saved.len(), original.scene().physics_state_size());
    run(&mut original, 10, 25);

    let mut restored = Sim::new(scene);
    assert_ne!(restored.physics_state(), saved);
    restored.restore_physics_state(&saved).expect("same scene");
    assert_eq!(restored.physics_state(), saved);
    run(&mut restored, 10, 25);
    assert_eq!(restored.physics_state(), original.physics_state());
    assert_eq!(restored.object_pose(), original.object_pose());

    let before = restored.physics_state();
    let error = restored
        .restore_physics_state(&saved[1..])
        .expect_err("a state one number short");
    assert!(
        error.to_string().contains("does not fit this scene"),
        "{error}"
    );
    assert_eq!(restored.physics_state(), before, "left as it was");
}

/// The cube's weight, newtons, in the physics the simulation now runs on.
fn cube_weight(sim: &Sim) -> f64 {
    let model = sim.data().model();
    let body = model
        .name_to_id(
            mujoco_rs::wrappers::mj_model::MjtObjBase::mjOBJ_BODY,
            "cubelet:DBL",
        )
        .expect("the cube's root body");
    model.body_subtreemass()[body] * 9.81
}

/// Scaled physics: a heavier cube weighs more on the palm, by its scale; friction and damping
/// follow theirs; the nominal scales give the scene's own physics back.
#[test]
fn scaled_physics_weighs_on_the_palm_and_goes_back() {
    let scene = Scene::load(SceneKind::Cube).expect("run scripts/setup first");
    let scaled = PhysicsScales {
        friction: 0.5,
        object_mass: 1.5,
        damping: 2.0,
    };
    let borne = |scales: PhysicsScales| {
        let mut sim = Sim::new(scene.clone());
        sim.set_physics_scales(scales);
        sim.set_action(&[0.0; dexcube_sim::HAND_ACTUATORS]);
        settle(&mut sim, 10);
        (sim.grip().iter().sum::<f64>(), cube_weight(&sim))
    };
    let (nominal_force, nominal_weight) = borne(PhysicsScales::NOMINAL);
    let (heavy_force, heavy_weight) = borne(PhysicsScales {
        object_mass: 1.5,
        ..PhysicsScales::NOMINAL
    });
    assert!(
        (heavy_weight / nominal_weight - 1.5).abs() < 1e-9,
        "the subtree mass follows: {heavy_weight} against {nominal_weight}"
    );
    assert!(
        (1.35..1.65).contains(&(heavy_force / nominal_force)),
        "the palm bears half as much again: {heavy_force} N against {nominal_force} N"
    );
    let mut sim = Sim::new(scene.clone());
    sim.set_physics_scales(scaled);
    let nominal = scene.model();
    let model = sim.data().model();
    for (now, was) in model.geom_friction().iter().zip(nominal.geom_friction()) {
        assert_eq!(*now, was.map(|f| 0.5 * f));
    }
    for (now, was) in model.dof_damping().iter().zip(nominal.dof_damping()) {
        assert_eq!(*now, 2.0 * was);
    }
    sim.set_physics_scales(PhysicsScales::NOMINAL);
    let model = sim.data().model();
    assert_eq!(model.geom_friction(), nominal.geom_friction());
    assert_eq!(model.dof_damping(), nominal.dof_damping());
    assert_eq!(model.body_mass(), nominal.body_mass());
}

/// The grip readout: the palm bears a cube resting on it, a closed hand presses with its
/// fingers too, and a cube away from the hand has no grip at all.
#[test]
fn the_grip_shows_what_of_the_hand_presses_on_the_cube() {
    let mut sim = Sim::new(Scene::load(SceneKind::Cube).expect("run scripts/setup first"));
    let weight = cube_weight(&sim);
    sim.set_action(&[0.0; dexcube_sim::HAND_ACTUATORS]);
    settle(&mut sim, 10);
    let resting = sim.grip();
    let palm = dexcube_sim::GRIP_PARTS.len() - 1;
    let borne: f64 = resting.iter().sum();
    assert!(resting[palm] > 0.0, "the palm bears it: {resting:?}");
    assert!(
        (0.5 * weight..2.0 * weight).contains(&borne),
        "about its weight, {weight} N: {resting:?}"
    );
    sim.set_action(&[1.0; dexcube_sim::HAND_ACTUATORS]);
    settle(&mut sim, 10);
    let closed = sim.grip();
    assert!(
        closed.iter().all(|&force| force > 0.0),
        "every part presses: {closed:?}"
    );
    assert!(
        closed.iter().sum::<f64>() > 5.0 * borne,
        "harder than resting: {closed:?}"
    );
    let away = cube_sim().grip();
    assert_eq!(
        away,
        [0.0; dexcube_sim::GRIP_PARTS.len()],
        "away from the hand"
    );
}

/// A re-posed cube is the same puzzle; a turned layer is another, whichever way the cube is
/// held; a start that could not be read, or a scene without the cube, counts no turn.
#[test]
fn a_turned_layer_is_told_from_a_turned_cube() {
    let mut sim = cube_sim();
    let start = read_puzzle(&sim).expect("a solved cube reads");
    assert!(!turned_since(Some(&start), &sim));
    let mut pose = read(&sim).pose();
    pose.orientation = about([1.0, 0.0, 0.0], std::f64::consts::FRAC_PI_2);
    sim.set_object_pose(&pose);
    sim.forward();
    assert!(!turned_since(Some(&start), &sim));
    assert!(turn_face(&mut sim, Move::QUARTER_TURNS[0]));
    sim.forward();
    assert!(turned_since(Some(&start), &sim));
    assert!(!turned_since(None, &sim));
    let rigid = Sim::new(Scene::load(SceneKind::Rot).unwrap());
    assert!(!turned_since(Some(&start), &rigid));
}
