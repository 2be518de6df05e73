//! The goal-env contract of CubeRotEnv and LayerOpEnv, with real physics.

use dexcube_env::layer::LayerGoals;
use dexcube_env::random::uniform_rotation;
use dexcube_env::rot::PAPER_TARGETS;
use dexcube_env::{
    ControlRate, CubeLayer, CubeRotEnv, EpisodeSettings, Goal, GoalEnv, GoalLead, LayerGoal,
    LayerMove, LayerOpEnv, OBJECT_POSITION, ObjectKind, RecordedStart, RotGoal, RotMode,
    SimulatedEnv, StartMix, StartPick, VecEnv, View, in_object_frame, pose_goal,
};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

use dexcube_cube::Face;
use dexcube_sim::cube::{ALIGNED_TOLERANCE, CubeState, face_toward, turn_face_by};
use dexcube_sim::rotation::{self, Quat, about};
use dexcube_sim::{Pose, Scene};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_action(rng: &mut ChaCha8Rng) -> Vec<f64> {
    (0..20).map(|_| rng.random_range(-1.0..=1.0)).collect()
}

#[test]
fn spaces_have_the_papers_sizes() {
    let rot = CubeRotEnv::new(RotMode::Paper).unwrap();
    assert_eq!(
        (
            rot.spaces().observation,
            rot.spaces().goal,
            rot.spaces().action
        ),
        (61, 7, 20)
    );
    let mut layer =
        LayerOpEnv::new(ObjectKind::Block, LayerMove::UPrime, LayerGoals::Training).unwrap();
    assert_eq!((layer.spaces().observation, layer.spaces().goal), (62, 1));
    let (obs, _) = layer.reset(Some(1));
    assert_eq!(
        (
            obs.observation.len(),
            obs.achieved_goal.len(),
            obs.desired_goal.len()
        ),
        (62, 1, 1)
    );
}

/// Steps `env` with random actions for `episodes` episodes and checks every reward against
/// the pure functions, also on goals relabelled to achieved ones (HER's view).
fn rewards_agree(env: &mut dyn GoalEnv, episodes: u64) -> usize {
    let goal = env.goal();
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let mut checked = 0;
    for episode in 0..episodes {
        env.reset(Some(episode));
        let mut achieved_before = None;
        for _ in 0..dexcube_env::EPISODE_STEPS {
            let t = env.step(&random_action(&mut rng));
            let (a, d) = (&t.observation.achieved_goal, &t.observation.desired_goal);
            assert_eq!(t.reward, goal.compute_reward(a, d));
            assert_eq!(t.info.is_success, goal.is_success(a, d));
            assert_eq!(t.reward == 0.0, t.info.is_success);
            assert_eq!(
                goal.compute_reward(a, a),
                0.0,
                "an achieved goal is a success"
            );
            if let Some(before) = achieved_before.replace(a.clone()) {
                let r = goal.compute_reward(a, &before);
                assert!(r == 0.0 || r == -1.0);
            }
            checked += 1;
            if t.terminated || t.truncated {
                break;
            }
        }
    }
    checked
}

#[test]
fn compute_reward_agrees_with_step_on_thousands_of_transitions() {
    let mut rot = CubeRotEnv::new(RotMode::Paper).unwrap();
    let mut block =
        LayerOpEnv::new(ObjectKind::Block, LayerMove::UPrime, LayerGoals::Training).unwrap();
    let mut cube =
        LayerOpEnv::new(ObjectKind::Cube, LayerMove::UPrime, LayerGoals::Training).unwrap();
    let checked =
        rewards_agree(&mut rot, 12) + rewards_agree(&mut block, 12) + rewards_agree(&mut cube, 6);
    assert!(checked > 1000, "{checked}");
}

#[test]
fn rot_success_is_detected_just_inside_and_not_just_outside_the_thresholds() {
    for mode in [RotMode::Paper, RotMode::Axis, RotMode::Pair] {
        let mut env = CubeRotEnv::new(mode).unwrap();
        env.reset(Some(3));
        let target_q = rotation::about([0.0, 1.0, 0.0], -std::f64::consts::FRAC_PI_2);
        let rest = env.resting_point();
        let desired: Vec<f64> = rest.iter().chain(target_q.iter()).copied().collect();
        env.set_desired_goal(&desired);
        let goal = env.goal();
        let judge = |position: [f64; 3], orientation: [f64; 4], env: &mut CubeRotEnv| {
            env.sim_mut().set_object_pose(&Pose {
                position,
                orientation,
            });
            env.sim_mut().forward();
            let obs = env.sim().object_pose();
            let achieved: Vec<f64> = obs
                .position
                .iter()
                .chain(obs.orientation.iter())
                .copied()
                .collect();
            goal.is_success(&achieved, &desired)
        };
        let shifted = |d: f64| [rest[0] + d, rest[1], rest[2]];
        let tilted = |a: f64| rotation::mul(&about([1.0, 0.0, 0.0], a), &target_q);
        assert!(
            judge(rest, target_q, &mut env),
            "{mode:?}: exactly at the goal"
        );
        assert!(
            judge(shifted(0.009), tilted(0.09), &mut env),
            "{mode:?}: just inside"
        );
        assert!(
            !judge(shifted(0.011), target_q, &mut env),
            "{mode:?}: 11 mm off"
        );
        assert!(
            !judge(rest, tilted(0.11), &mut env),
            "{mode:?}: tilted 0.11 rad"
        );
        let yawed = rotation::mul(&about([0.0, 0.0, 1.0], 1.0), &target_q);
        assert_eq!(
            judge(rest, yawed, &mut env),
            mode != RotMode::Paper,
            "{mode:?}: turned about the vertical"
        );
        let flipped = rotation::mul(&about([1.0, 0.0, 0.0], std::f64::consts::PI), &target_q);
        assert_eq!(
            judge(rest, flipped, &mut env),
            mode == RotMode::Pair,
            "{mode:?}: the opposite face up"
        );
        let sideways = rotation::mul(&about([1.0, 0.0, 0.0], 1.5), &target_q);
        assert!(!judge(rest, sideways, &mut env), "{mode:?}: on its side");
    }
}

/// A goal led on shows the error still to go, as the test reads it, `1 + share` times as
/// large, on the far side of the goal, and leaves the goal as it is further off than `within`
/// or where the test reads nothing more (the misalignment).
#[test]
fn a_goal_led_on_lies_further_on_by_its_share_of_the_error() {
    let lead = GoalLead {
        share: 0.5,
        within: 0.5,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(40);
    let unit = |rng: &mut ChaCha8Rng| {
        let v: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        v.map(|x| x / n)
    };
    for mode in [RotMode::Paper, RotMode::Axis, RotMode::Pair] {
        let test = RotGoal::paper(mode).left_square();
        for case in 0..50 {
            let target = rotation::about(unit(&mut rng), rng.random_range(0.0..3.0));
            // In pair mode, also a cube turned upside down from the target, then tilted.
            let flip = if mode == RotMode::Pair && case % 2 == 1 {
                about([1.0, 0.0, 0.0], std::f64::consts::PI)
            } else {
                rotation::IDENTITY
            };
            let off = about(unit(&mut rng), rng.random_range(0.02..0.45));
            let now = rotation::mul(&off, &rotation::mul(&flip, &target));
            let at =
                |position: [f64; 3], q: rotation::Quat| test.achieved(&pose_goal(position, q), 0.3);
            let achieved = at([0.01, -0.004, 0.003], now);
            let desired = test.desired(&pose_goal([0.0; 3], target));
            let (distance, angle) = test.errors(&achieved, &desired);
            let led = test.led(&achieved, &desired, lead);
            let (led_distance, led_angle) = test.errors(&achieved, &led);
            assert!(
                (led_angle - 1.5 * angle).abs() < 1e-9
                    && (led_distance - 1.5 * distance).abs() < 1e-12,
                "{mode:?}: {angle} and {distance} to go shown as {led_angle} and {led_distance}"
            );
            let (_, beyond) = test.errors(&desired, &led);
            assert!(
                (beyond - 0.5 * angle).abs() < 1e-9,
                "{mode:?}: {beyond} past the goal"
            );
            assert_eq!(led[7], desired[7], "the desired misalignment stays");
        }
        let far = at_angle(&test, 0.6);
        assert_eq!(
            test.led(&far.0, &far.1, lead),
            far.1,
            "{mode:?}: 0.6 rad off"
        );
    }
    let layer = LayerGoal::square();
    let led = layer.led(&[1.3, 0.2], &[FRAC_PI_2, 0.0], lead);
    assert!((led[0] - (FRAC_PI_2 + 0.5 * (FRAC_PI_2 - 1.3))).abs() < 1e-12);
    assert_eq!(led[1], 0.0);
    assert_eq!(
        layer.led(&[0.9, 0.0], &[FRAC_PI_2, 0.0], lead),
        [FRAC_PI_2, 0.0]
    );
}

/// Of the cube's rotations onto itself, the nearest frame chooses among those the test reads
/// alike (in pair mode the turns about the target's up axis and the flips, in axis mode the
/// turns, in the paper's none), found here by the test's own errors, the one that leaves the
/// whole orientation nearest the goal's; the test reads the pose there as it did.
#[test]
fn the_nearest_frame_reads_the_pose_alike_and_nearest_the_goal() {
    let mut rng = ChaCha8Rng::seed_from_u64(62);
    for (mode, frames) in [(RotMode::Pair, 8), (RotMode::Axis, 4)] {
        let test = RotGoal::paper(mode).left_square();
        let mut relabelled = 0;
        for case in 0..200 {
            let now = uniform_rotation(&mut rng);
            let at = |q: Quat| test.achieved(&pose_goal([0.01, -0.004, 0.003], q), 0.03);
            let achieved = at(now);
            let desired = test.desired(&pose_goal([0.0; 3], PAPER_TARGETS[case % 3]));
            let errors = test.errors(&achieved, &desired);
            let alike: Vec<Quat> = (rotation::cube_rotations().into_iter())
                .filter(|g| {
                    let there = test.errors(&at(rotation::mul(&now, g)), &desired);
                    (there.0 - errors.0).abs() < 1e-12 && (there.1 - errors.1).abs() < 1e-9
                })
                .collect();
            assert_eq!(alike.len(), frames, "{mode:?}");
            let (g, reached) = test.nearest_frame(&achieved, &desired).unwrap();
            assert!(alike.contains(&g), "{mode:?}: {g:?}");
            let quat = |goal: &[f64]| [goal[3], goal[4], goal[5], goal[6]];
            let target = quat(&desired);
            assert!(reached[3] >= 0.0);
            assert!(rotation::angle_between(&quat(&reached), &rotation::mul(&now, &g)) < 1e-6);
            let off = rotation::angle_between(&quat(&reached), &target);
            for h in &alike {
                let other = rotation::angle_between(&rotation::mul(&now, h), &target);
                assert!(
                    off <= other + 1e-7,
                    "{mode:?}: {off} from the goal, {other} in another frame"
                );
            }
            let (position, angle) = test.errors(&reached, &desired);
            assert!((position - errors.0).abs() < 1e-12 && (angle - errors.1).abs() < 1e-9);
            assert_eq!(
                test.is_success(&reached, &desired),
                test.is_success(&achieved, &desired)
            );
            assert_eq!(reached[7], achieved[7], "the misalignment stays");
            relabelled += usize::from(g != rotation::IDENTITY);
        }
        assert!(
            relabelled > 100,
            "{mode:?}: {relabelled} of 200 read in another frame"
        );
    }
    let paper = RotGoal::paper(RotMode::Paper);
    let (achieved, desired) = at_angle(&paper, 0.3);
    assert_eq!(paper.nearest_frame(&achieved, &desired), None);
    assert_eq!(
        LayerGoal::square().nearest_frame(&[1.3, 0.2], &[FRAC_PI_2, 0.0]),
        None
    );
}

/// An observation read in another frame of the cube has the orientation q·g (w ≥ 0) and the
/// same angular velocity in the world (the observation's is in the cube's frame); the rest
/// is unchanged.
#[test]
fn an_observation_read_in_another_frame_keeps_the_cubes_motion() {
    let mut rng = ChaCha8Rng::seed_from_u64(63);
    let frames = rotation::cube_rotations();
    for case in 0..50 {
        let mut observation: Vec<f64> = (0..62).map(|_| rng.random_range(-1.0..1.0)).collect();
        let q = uniform_rotation(&mut rng);
        let (orientation, angular) = (OBJECT_POSITION + 3, OBJECT_POSITION + 10);
        observation[orientation..orientation + 4].copy_from_slice(&q);
        let g = frames[case % 24];
        let seen = in_object_frame(&observation, &g);
        let part = |v: &[f64], at: usize| [v[at], v[at + 1], v[at + 2]];
        let seen_q = [
            seen[orientation],
            seen[orientation + 1],
            seen[orientation + 2],
            seen[orientation + 3],
        ];
        assert!(seen_q[0] >= 0.0);
        assert!(rotation::angle_between(&seen_q, &rotation::mul(&q, &g)) < 1e-6);
        let world = rotation::rotate(&q, part(&observation, angular));
        let seen_world = rotation::rotate(&seen_q, part(&seen, angular));
        assert!(
            world
                .iter()
                .zip(seen_world)
                .all(|(a, b)| (a - b).abs() < 1e-12)
        );
        let relabelled = |k: &usize| {
            (orientation..orientation + 4).contains(k) || (angular..angular + 3).contains(k)
        };
        for k in (0..62).filter(|k| !relabelled(k)) {
            assert_eq!(seen[k], observation[k], "entry {k}");
        }
    }
}

/// An achieved and a desired pose `angle` apart by a tilt about x, as `test` has them.
fn at_angle(test: &RotGoal, angle: f64) -> (Vec<f64>, Vec<f64>) {
    let target = about([0.0, 1.0, 0.0], FRAC_PI_2);
    let now = rotation::mul(&about([1.0, 0.0, 0.0], angle), &target);
    (
        test.achieved(&pose_goal([0.0; 3], now), 0.0),
        test.desired(&pose_goal([0.0; 3], target)),
    )
}

#[test]
fn layer_success_is_detected_within_a_tenth_of_a_radian() {
    for object in [ObjectKind::Block, ObjectKind::Cube] {
        let mut env = LayerOpEnv::new(object, LayerMove::UPrime, LayerGoals::Evaluation).unwrap();
        let (obs, _) = env.reset(Some(5));
        assert_eq!(obs.desired_goal, [FRAC_PI_2]);
        for (offset, success) in [
            (0.0, true),
            (0.09, true),
            (-0.09, true),
            (0.11, false),
            (-0.11, false),
        ] {
            env.set_layer_angle(FRAC_PI_2 + offset);
            let t = env.step(&[0.0; 20]);
            let (a, d) = (&t.observation.achieved_goal, &t.observation.desired_goal);
            // One step of physics moves the layer a little, and on the cube the detent may
            // pull a layer within its capture back to the quarter turn: judge what was read.
            let read = a[0] - FRAC_PI_2;
            assert!(
                (read - offset).abs() < 0.05 || (object == ObjectKind::Cube && read.abs() < 0.02),
                "{object:?}: set {offset} past a quarter turn, read {read}"
            );
            assert_eq!(env.goal().is_success(a, d), (a[0] - d[0]).abs() < 0.1);
            let exact = env.goal().is_success(&[FRAC_PI_2 + offset], d);
            assert_eq!(exact, success, "{object:?}: offset {offset}");
        }
    }
    assert_eq!(
        LayerMove::U.direction(),
        -1.0,
        "U is clockwise: a negative angle"
    );
}

/// On the physical cube any face may start on top, and the free joint's cubelet (DBL) may be
/// in the turning layer or the one that stays. Either way Stage 2 sees the layer that stays,
/// in the frame nearest upright, and the angle turned counts on past the ±45° where the
/// cube's own reading wraps.
#[test]
fn the_cube_is_seen_through_the_layer_that_stays_whichever_face_is_up() {
    let mut env =
        LayerOpEnv::new(ObjectKind::Cube, LayerMove::UPrime, LayerGoals::Evaluation).unwrap();
    let orientation = |o: &[f64]| [o[51], o[52], o[53], o[54]];
    let (mut frame_carried_by_the_turn, mut frame_kept) = (0, 0);
    for seed in 0..12 {
        env.reset(Some(seed));
        let mut view = CubeLayer::start(env.sim(), [0.0, 0.0, 1.0], rotation::IDENTITY).unwrap();
        let seen = orientation(&view.observe(env.sim()));
        assert!(
            rotation::angle_between(&seen, &rotation::IDENTITY) < FRAC_PI_4 + 0.3,
            "seed {seed}: the frame is kept near upright"
        );
        let frame_before = env.sim().object_pose().orientation;
        let mut turned = 0.0;
        for angle in [0.5, 1.0, FRAC_PI_2, 2.0] {
            turn_face_by(env.sim_mut(), Face::U, angle - turned);
            env.sim_mut().forward();
            turned = angle;
            let observation = view.observe(env.sim());
            assert!(
                (observation[61] - angle).abs() < 1e-6,
                "seed {seed}: turned to {angle}, read {}",
                observation[61]
            );
            let now = orientation(&observation);
            assert!(
                rotation::angle_between(&now, &seen) < 1e-6,
                "seed {seed}: the layer that stays is seen to stay: {seen:?}, then {now:?} at {angle}"
            );
        }
        if rotation::angle_between(&env.sim().object_pose().orientation, &frame_before) > 1.0 {
            frame_carried_by_the_turn += 1;
        } else {
            frame_kept += 1;
        }
    }
    assert!(
        frame_carried_by_the_turn > 0 && frame_kept > 0,
        "both cases drawn: {frame_carried_by_the_turn} carried, {frame_kept} kept"
    );
}

#[test]
fn same_seed_same_trajectory_on_any_number_of_threads() {
    let run = |threads: usize| {
        let envs = (0..3)
            .map(|_| CubeRotEnv::new(RotMode::Paper).unwrap())
            .collect();
        let mut vec_env = VecEnv::new(envs, threads);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut trace = vec![];
        for (obs, _) in vec_env.reset(42) {
            trace.extend(obs.observation);
        }
        for _ in 0..30 {
            let actions: Vec<Vec<f64>> = (0..3).map(|_| random_action(&mut rng)).collect();
            for step in vec_env.step(&actions) {
                trace.extend(step.transition.observation.observation);
            }
        }
        trace
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(1));
}

#[test]
fn a_dropped_cube_ends_the_episode_as_a_failure() {
    let mut env = CubeRotEnv::new(RotMode::Paper).unwrap();
    env.reset(Some(0));
    let rest = env.resting_point();
    env.sim_mut().set_object_pose(&Pose {
        position: [rest[0] + 0.3, rest[1], rest[2]],
        orientation: rotation::IDENTITY,
    });
    let mut ended = false;
    for _ in 0..20 {
        let t = env.step(&[0.0; 20]);
        if t.terminated {
            assert!(t.info.dropped && !t.info.is_success && t.reward == -1.0);
            ended = true;
            break;
        }
    }
    assert!(ended, "a cube that falls off the hand ends the episode");
}

#[test]
fn a_blown_up_simulation_resets_that_env_only() {
    let envs = (0..2)
        .map(|_| {
            LayerOpEnv::new(ObjectKind::Block, LayerMove::UPrime, LayerGoals::Training).unwrap()
        })
        .collect();
    let mut vec_env = VecEnv::new(envs, 2);
    vec_env.reset(7);
    let dof = vec_env.envs()[0].sim().scene().object().free().dof;
    vec_env.envs_mut()[0].sim_mut().data_mut().qvel_mut()[dof] = f64::NAN;
    let steps = vec_env.step(&[vec![0.0; 20], vec![0.0; 20]]);
    assert!(steps[0].transition.terminated && steps[0].transition.info.physics_error.is_some());
    assert!(
        steps[0].reset.is_some(),
        "the broken env starts a new episode"
    );
    assert!(
        !steps[1].transition.terminated && steps[1].reset.is_none(),
        "its neighbour goes on"
    );
    let again = vec_env.step(&[vec![0.0; 20], vec![0.0; 20]]);
    assert!(
        again
            .iter()
            .all(|s| s.transition.info.physics_error.is_none())
    );
}

/// With the good state in the success test, the goal carries the cube's misalignment: a
/// quarter turn with the cube square succeeds, and the same turn with a side layer pushed
/// out of line does not, though the paper's test (the turned layer's angle) would pass it.
#[test]
fn a_layer_turn_left_square_needs_the_cube_in_its_good_state() {
    let mut env = LayerOpEnv::new(ObjectKind::Cube, LayerMove::UPrime, LayerGoals::Evaluation)
        .unwrap()
        .with_goal(LayerGoal::square());
    assert_eq!(env.spaces().goal, 2);
    let (obs, _) = env.reset(Some(5));
    assert_eq!(obs.desired_goal, [FRAC_PI_2, 0.0]);
    assert!(obs.achieved_goal[1] < ALIGNED_TOLERANCE, "starts square");
    env.set_layer_angle(FRAC_PI_2);
    let t = env.step(&[0.0; 20]);
    let (a, d) = (&t.observation.achieved_goal, &t.observation.desired_goal);
    assert!(t.info.is_success, "turned and square: {a:?}");
    assert_eq!(t.reward, 0.0);
    let misalignment = CubeState::read(env.sim()).unwrap().misalignment();
    assert!(
        (a[1] - misalignment).abs() < 1e-12,
        "the goal reads the cube's misalignment"
    );
    assert!(LayerGoal::default().is_success(&a[..1], &d[..1]));

    let a = skew_a_side_layer(&mut env);
    assert!(env.goal().is_success(&[a[0], 0.05], &a));
}

/// With the misalignment seen, Stage 2's observation gains one last number: the achieved
/// goal's misalignment in units of the good state's tolerance (see
/// [`assert_the_last_observation_is_the_misalignment`]). The block refuses to show what it
/// cannot have.
#[test]
fn a_layer_op_env_that_sees_the_misalignment_observes_the_achieved_one() {
    let make = |sees| {
        LayerOpEnv::new(ObjectKind::Cube, LayerMove::UPrime, LayerGoals::Evaluation)
            .unwrap()
            .with_goal(LayerGoal::square())
            .with_view(seeing(sees, false))
    };
    assert_views_told_by_size(CubeLayer::PAPER_OBSERVATION, 62);
    assert_the_last_observation_is_the_misalignment(&mut make(false), &mut make(true), 62);
    let block = std::panic::catch_unwind(|| {
        LayerOpEnv::new(ObjectKind::Block, LayerMove::UPrime, LayerGoals::Evaluation)
            .unwrap()
            .with_view(seeing(true, false))
    });
    assert!(block.is_err(), "the block has no misalignment to show");
}

/// A view of `misalignment` and `grip` or not.
fn seeing(misalignment: bool, grip: bool) -> View {
    View { misalignment, grip }
}

/// A stage whose paper observation has `stage_paper` numbers, `paper` of them, tells each view
/// from that and what the view adds (one for the misalignment, six for the grip), and no view
/// from any other size near them.
fn assert_views_told_by_size(stage_paper: usize, paper: usize) {
    assert_eq!(stage_paper, paper);
    let told = (paper - 2..paper + 10)
        .filter_map(|size| View::after(stage_paper, size).map(|view| (size - paper, view)))
        .collect::<Vec<_>>();
    assert_eq!(
        told,
        [
            (0, View::PAPER),
            (1, seeing(true, false)),
            (6, seeing(false, true)),
            (7, seeing(true, true)),
        ]
    );
}

/// A view leads a wider one ([`View::leads`], what lets an ensemble's narrower members read
/// the first member's observation) exactly when its observation is the leading part of the
/// wider one's, from the same start.
#[test]
fn a_view_leads_another_when_its_observation_is_the_start_of_the_other() {
    let views = [
        View::PAPER,
        seeing(true, false),
        seeing(false, true),
        seeing(true, true),
    ];
    let observation = |view| {
        let mut env = LayerOpEnv::new(ObjectKind::Cube, LayerMove::UPrime, LayerGoals::Evaluation)
            .unwrap()
            .with_goal(LayerGoal::square())
            .with_view(view);
        env.reset(Some(3));
        env.step(&[0.3; 20]).observation.observation
    };
    let seen = views.map(observation);
    for (narrow, narrow_seen) in views.iter().zip(&seen) {
        for (wide, wide_seen) in views.iter().zip(&seen) {
            if narrow_seen.len() > wide_seen.len() {
                continue;
            }
            let leading = wide_seen[..narrow_seen.len()] == narrow_seen[..];
            assert_eq!(narrow.leads(*wide), leading, "{narrow:?} within {wide:?}");
        }
    }
    assert!(seeing(true, false).leads(seeing(true, true)));
    assert!(!seeing(false, true).leads(seeing(true, true)));
}

/// Stage 1 may see the misalignment as Stage 2 does: its 61 observations gain the same last
/// number. The rigid cube, always square, refuses to show it.
#[test]
fn a_cube_rot_env_that_sees_the_misalignment_observes_the_achieved_one() {
    let scene = Scene::load(ObjectKind::Cube.scene()).unwrap();
    let make = |sees| {
        CubeRotEnv::with_scene(scene.clone(), RotGoal::paper(RotMode::Pair).left_square())
            .with_view(seeing(sees, false))
    };
    assert_views_told_by_size(CubeRotEnv::PAPER_OBSERVATION, 61);
    assert_the_last_observation_is_the_misalignment(&mut make(false), &mut make(true), 61);
    let rigid = std::panic::catch_unwind(|| {
        CubeRotEnv::new(RotMode::Paper)
            .unwrap()
            .with_view(seeing(true, false))
    });
    assert!(rigid.is_err(), "the rigid cube has no misalignment to show");
}

/// Either stage may be shown the hand's grip: six numbers after the paper's (and after the
/// misalignment, if that is shown too), the forces the physics reads for the thumb, the
/// fingers and the palm, which rise as the hand closes on the cube.
#[test]
fn an_env_that_sees_the_grip_observes_the_forces_on_the_cube() {
    let scene = Scene::load(ObjectKind::Cube.scene()).unwrap();
    let rot = |view| {
        Box::new(
            CubeRotEnv::with_scene(scene.clone(), RotGoal::paper(RotMode::Pair).left_square())
                .with_view(view),
        ) as Box<dyn SimulatedEnv>
    };
    let layer = |view| {
        Box::new(
            LayerOpEnv::new(ObjectKind::Cube, LayerMove::UPrime, LayerGoals::Evaluation)
                .unwrap()
                .with_view(view),
        ) as Box<dyn SimulatedEnv>
    };
    for (make, paper) in [
        (&rot as &dyn Fn(View) -> Box<dyn SimulatedEnv>, 61),
        (&layer, 62),
    ] {
        let (mut plain, mut gripping, mut both) = (
            make(View::PAPER),
            make(seeing(false, true)),
            make(seeing(true, true)),
        );
        assert_eq!(gripping.spaces().observation, paper + 6);
        assert_eq!(both.spaces().observation, paper + 7);
        let (without, _) = plain.reset(Some(5));
        let (with, _) = gripping.reset(Some(5));
        let (with_both, _) = both.reset(Some(5));
        assert_eq!(with.observation[..paper], without.observation[..]);
        assert_eq!(with.observation[paper..], gripping.sim().grip());
        assert_eq!(
            with_both.observation[paper + 1..],
            with.observation[paper..]
        );
        let resting: f64 = with.observation[paper..].iter().sum();
        assert!(resting > 0.0, "the hand bears the cube: {with:?}");
        let closing = [1.0; 20];
        let t = (0..5).map(|_| gripping.step(&closing)).last().unwrap();
        assert_eq!(t.observation.observation[paper..], gripping.sim().grip());
        let pressed: f64 = t.observation.observation[paper..].iter().sum();
        assert!(
            pressed > 2.0 * resting,
            "a closing hand presses harder: {resting} then {pressed}"
        );
    }
}

/// `seeing` observes what `plain` does (`paper` numbers, from the same reset) and then the
/// achieved goal's misalignment (its last part) in units of the good state's tolerance:
/// under 1 on the square cube at the start, past 1 once a side layer is out of line.
fn assert_the_last_observation_is_the_misalignment(
    plain: &mut dyn SimulatedEnv,
    seeing: &mut dyn SimulatedEnv,
    paper: usize,
) {
    assert_eq!(
        (plain.spaces().observation, seeing.spaces().observation),
        (paper, paper + 1)
    );
    let (without, _) = plain.reset(Some(5));
    let (with, _) = seeing.reset(Some(5));
    assert_eq!(with.observation.len(), paper + 1);
    assert_eq!(with.observation[..paper], without.observation[..]);
    let seen = |o: &dexcube_env::Observation| o.observation[paper] * ALIGNED_TOLERANCE;
    let achieved = |o: &dexcube_env::Observation| *o.achieved_goal.last().unwrap();
    assert!(
        (seen(&with) - achieved(&with)).abs() < 1e-12 && seen(&with) < ALIGNED_TOLERANCE,
        "square at the start: {with:?}"
    );
    let skewed = skew_a_side_layer(seeing);
    let t = seeing.step(&[0.0; 20]);
    assert!(
        (seen(&t.observation) - achieved(&t.observation)).abs() < 1e-12,
        "the last observation is the achieved misalignment: {:?}",
        t.observation
    );
    assert!(
        skewed[skewed.len() - 1] > ALIGNED_TOLERANCE && t.observation.observation[paper] > 1.0,
        "skewed: {skewed:?}"
    );
}

/// Pushes the layer facing +x (a side layer for either stage's goal) 0.35 rad out of line
/// and steps: checks that the goal reads the misalignment (its last part), that the step is
/// no success, and that the same achieved goal relabelled as desired (HER) is none either.
/// Returns the achieved goal.
fn skew_a_side_layer(env: &mut dyn SimulatedEnv) -> Vec<f64> {
    let side = face_toward(&env.sim().object_pose().orientation, [1.0, 0.0, 0.0]);
    turn_face_by(env.sim_mut(), side, 0.35);
    env.sim_mut().forward();
    let t = env.step(&[0.0; 20]);
    let a = t.observation.achieved_goal;
    assert!(
        a[a.len() - 1] > ALIGNED_TOLERANCE,
        "a side layer pushed out of line: {a:?}"
    );
    assert!(
        !t.info.is_success && t.reward == -1.0,
        "not a success while skewed: {a:?}"
    );
    assert!(
        !env.goal().is_success(&a, &a),
        "a skewed cube is never a goal reached"
    );
    a
}

/// Stage 1 with the good state in its test: the goal gains the cube's misalignment; the cube
/// at the target pose succeeds when square, and not with a side layer out of line, though
/// the paper's test (the pose alone) would pass it.
#[test]
fn a_pose_reached_left_square_needs_the_cube_in_its_good_state() {
    let scene = Scene::load(ObjectKind::Cube.scene()).unwrap();
    let mut env = CubeRotEnv::with_scene(scene, RotGoal::paper(RotMode::Pair).left_square());
    assert_eq!(env.spaces().goal, 8);
    let (obs, _) = env.reset(Some(5));
    let desired = obs.desired_goal;
    assert_eq!((desired.len(), desired[7]), (8, 0.0));
    let target = Pose {
        position: env.resting_point(),
        orientation: [desired[3], desired[4], desired[5], desired[6]],
    };
    env.sim_mut().set_object_pose(&target);
    env.sim_mut().forward();
    let t = env.step(&[0.0; 20]);
    let a = &t.observation.achieved_goal;
    assert!(t.info.is_success, "at the pose and square: {a:?}");
    let misalignment = CubeState::read(env.sim()).unwrap().misalignment();
    assert!(
        (a[7] - misalignment).abs() < 1e-12,
        "the goal reads the cube's misalignment"
    );
    let a = skew_a_side_layer(&mut env);
    let paper = RotGoal::paper(RotMode::Pair);
    assert!(
        paper.is_success(&a[..7], &desired[..7]),
        "the pose alone still passes: {a:?}"
    );
}

/// Stage 1 with the cube kept intact in its test: at the target pose and square it succeeds;
/// with a side layer turned a whole quarter round, square again, it does not, and its
/// achieved misalignment carries the turn (so a relabelled goal is judged alike), though the
/// square test alone would pass it. A new episode starts from the puzzle it finds.
#[test]
fn a_pose_reached_intact_needs_no_layer_turned() {
    let scene = Scene::load(ObjectKind::Cube.scene()).unwrap();
    let intact = RotGoal::paper(RotMode::Pair).left_intact();
    let mut env = CubeRotEnv::with_scene(scene, intact);
    assert_eq!(
        env.spaces().goal,
        8,
        "the same goal vector as the square test"
    );
    let at_target = |env: &mut CubeRotEnv, desired: &[f64]| {
        let target = Pose {
            position: env.resting_point(),
            orientation: [desired[3], desired[4], desired[5], desired[6]],
        };
        env.sim_mut().set_object_pose(&target);
        env.sim_mut().forward();
        env.step(&[0.0; 20])
    };
    let (obs, _) = env.reset(Some(5));
    let desired = obs.desired_goal;
    let t = at_target(&mut env, &desired);
    assert!(t.info.is_success, "at the pose, square and intact");
    let side = face_toward(&env.sim().object_pose().orientation, [1.0, 0.0, 0.0]);
    turn_face_by(env.sim_mut(), side, FRAC_PI_2);
    let t = at_target(&mut env, &desired);
    let a = &t.observation.achieved_goal;
    let misalignment = CubeState::read(env.sim()).unwrap().misalignment();
    assert!(
        misalignment < ALIGNED_TOLERANCE,
        "square again: {misalignment}"
    );
    assert!(
        (a[7] - misalignment - FRAC_PI_2).abs() < 1e-12,
        "the turn in the goal: {a:?}"
    );
    assert!(
        !t.info.is_success && t.reward == -1.0,
        "a layer turned: {a:?}"
    );
    assert!(
        !env.goal().is_success(a, a),
        "a turned cube is never a goal reached"
    );
    let square = RotGoal::paper(RotMode::Pair).left_square();
    let mut a_square = a.clone();
    a_square[7] = misalignment;
    assert!(
        square.is_success(&a_square, &desired),
        "square alone passes it"
    );
    // The next episode's start is its own: a cube with that layer turned is intact there.
    let (obs, _) = env.reset(Some(6));
    assert!(
        obs.achieved_goal[7] < ALIGNED_TOLERANCE,
        "{:?}",
        obs.achieved_goal
    );
}

/// Asked to, CubeRotEnv ends the episode when a layer turns, as it does at a drop: the
/// intact goal alone goes on, and neither ends a step with no layer turned.
#[test]
fn a_turned_layer_ends_the_episode_only_when_asked() {
    let scene = Scene::load(ObjectKind::Cube.scene()).unwrap();
    for (goal, ends) in [
        (RotGoal::paper(RotMode::Pair).left_intact(), false),
        (RotGoal::paper(RotMode::Pair).ending_on_turn(), true),
    ] {
        let mut env = CubeRotEnv::with_scene(scene.clone(), goal);
        env.reset(Some(5));
        let still = env.step(&[0.0; 20]);
        assert!(!still.terminated, "no layer turned yet");
        let side = face_toward(&env.sim().object_pose().orientation, [1.0, 0.0, 0.0]);
        turn_face_by(env.sim_mut(), side, FRAC_PI_2);
        env.sim_mut().forward();
        let turned = env.step(&[0.0; 20]);
        assert!(!turned.info.dropped, "the cube is still on the palm");
        assert_eq!(turned.terminated, ends, "{goal:?}");
        assert_eq!(turned.reward, -1.0);
    }
}

/// About one landing in ten on the flat hand knocks a layer of the physical cube out of its
/// good state; such a start is set down again, so every episode starts with a turnable cube.
#[test]
fn every_episode_on_the_physical_cube_starts_in_a_good_state() {
    let mut env =
        LayerOpEnv::new(ObjectKind::Cube, LayerMove::UPrime, LayerGoals::Evaluation).unwrap();
    for seed in 2_000_000..2_000_040 {
        env.reset(Some(seed));
        let misalignment = CubeState::read(env.sim()).unwrap().misalignment();
        assert!(
            misalignment < ALIGNED_TOLERANCE,
            "seed {seed}: the cube starts {misalignment:.3} rad off a quarter turn"
        );
    }
}

/// CubeRotEnv resets from recorded starts: numbered, seed k begins from start k (modulo their
/// number) and goes on exactly as the recorded simulation did; by share, never at 0 and
/// always at 1.
#[test]
fn cube_rot_env_resets_from_recorded_starts() {
    let scene = Scene::load(ObjectKind::Cube.scene()).unwrap();
    let goal = RotGoal::paper(RotMode::Pair);
    let mut source = CubeRotEnv::with_scene(scene.clone(), goal);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let starts: Vec<RecordedStart> = (0..2)
        .map(|k| {
            source.reset(Some(k));
            for _ in 0..5 {
                source.step(&random_action(&mut rng));
            }
            RecordedStart {
                state: source.sim().physics_state(),
                goal: pose_goal(source.resting_point(), PAPER_TARGETS[k as usize + 1]),
                failed: false,
            }
        })
        .collect();
    let action = random_action(&mut rng);
    let continued = source.step(&action).observation;
    let env = |pick| {
        let mix = StartMix {
            starts: starts.clone().into(),
            pick,
        };
        CubeRotEnv::with_scene(scene.clone(), goal).with_starts(Some(mix))
    };

    let mut numbered = env(StartPick::Numbered);
    let (first, _) = numbered.reset(Some(3));
    assert_eq!(first.desired_goal, starts[1].goal);
    assert_eq!(numbered.sim().physics_state(), starts[1].state);
    assert_eq!(numbered.step(&action).observation, continued);
    numbered.reset(Some(0));
    assert_eq!(numbered.sim().physics_state(), starts[0].state);

    let share = |share| StartPick::Share {
        share,
        failed_weight: 1.0,
    };
    let (mut never, mut always) = (env(share(0.0)), env(share(1.0)));
    let recorded = |env: &CubeRotEnv| starts.iter().any(|s| s.state == env.sim().physics_state());
    for seed in 0..8 {
        never.reset(Some(seed));
        always.reset(Some(seed));
        assert!(!recorded(&never) && recorded(&always), "seed {seed}");
    }
}

/// A faster control rate acts more often within the same 4 simulated seconds, from the same
/// placement; a rate that does not divide the paper's is refused.
#[test]
fn a_faster_control_rate_keeps_the_episode_four_seconds_long() {
    let scene = Scene::load(dexcube_sim::SceneKind::Rot).unwrap();
    let run = |substeps: usize| {
        let mut env = CubeRotEnv::with_scene(scene.clone(), RotGoal::paper(RotMode::Paper))
            .with_settings(EpisodeSettings {
                rate: ControlRate::every(substeps).unwrap(),
                ..EpisodeSettings::PAPER
            });
        let (first, _) = env.reset(Some(3));
        let began = env.sim().time();
        let mut steps = 0;
        loop {
            steps += 1;
            let t = env.step(&[0.0; 20]);
            if t.terminated || t.truncated {
                assert!(t.truncated, "a still hand keeps the cube");
                return (first.observation, steps, env.sim().time() - began);
            }
        }
    };
    let (paper_start, paper_steps, paper_time) = run(dexcube_sim::SUBSTEPS);
    let (fast_start, fast_steps, fast_time) = run(10);
    assert_eq!(paper_start, fast_start, "the same placement at either rate");
    assert_eq!((paper_steps, fast_steps), (dexcube_env::EPISODE_STEPS, 200));
    assert!((paper_time - 4.0).abs() < 1e-9 && (fast_time - 4.0).abs() < 1e-9);
    for refused in [0, 3, 40] {
        assert!(ControlRate::every(refused).is_err(), "{refused}");
    }
}

/// An episode set to a length other than the paper's is truncated at that step, and only
/// there, from the same placement.
#[test]
fn an_episode_set_longer_or_shorter_truncates_at_its_own_length() {
    let scene = Scene::load(dexcube_sim::SceneKind::Rot).unwrap();
    let run = |steps: Option<usize>| {
        let mut env = CubeRotEnv::with_scene(scene.clone(), RotGoal::paper(RotMode::Paper))
            .with_settings(EpisodeSettings {
                episode_steps: steps,
                ..EpisodeSettings::PAPER
            });
        let (first, _) = env.reset(Some(3));
        (1..)
            .find_map(|step| {
                let t = env.step(&[0.0; 20]);
                (t.terminated || t.truncated).then(|| {
                    assert!(t.truncated, "a still hand keeps the cube");
                    step
                })
            })
            .map(|step| (first.observation, step))
            .unwrap()
    };
    let (paper_start, paper_steps) = run(None);
    for steps in [37, 150] {
        let (start, truncated_at) = run(Some(steps));
        assert_eq!(start, paper_start, "the same placement at any length");
        assert_eq!(truncated_at, steps);
    }
    assert_eq!(paper_steps, dexcube_env::EPISODE_STEPS);
}

/// A slew limit moves each actuator's target at most that far per control step, towards the
/// action asked for, and reaches it in as many steps as the distance needs; without one the
/// target jumps at once.
#[test]
fn a_slew_limit_moves_each_target_at_most_that_far_per_step() {
    let scene = Scene::load(dexcube_sim::SceneKind::Cube).unwrap();
    let env = |slew| {
        let mut env =
            LayerOpEnv::with_scene(scene.clone(), LayerMove::UPrime, LayerGoals::Evaluation)
                .with_settings(EpisodeSettings {
                    action_slew: slew,
                    ..EpisodeSettings::PAPER
                });
        env.reset(Some(5));
        env
    };
    let (mut free, mut slewed) = (env(None), env(Some(0.3)));
    let held = slewed.sim().action();
    let asked: Vec<f64> = held
        .iter()
        .map(|h| if *h > 0.0 { -1.0 } else { 1.0 })
        .collect();
    let close = |a: [f64; 20]| a.iter().zip(&asked).all(|(x, y)| (x - y).abs() < 1e-9);
    free.step(&asked);
    assert!(close(free.sim().action()), "no limit: the target jumps");
    for step in 1..=7 {
        slewed.step(&asked);
        for (i, (now, target)) in slewed.sim().action().iter().zip(&asked).enumerate() {
            let expected =
                held[i] + (target - held[i]).clamp(-0.3 * step as f64, 0.3 * step as f64);
            assert!(
                (now - expected).abs() < 1e-9,
                "step {step}, actuator {i}: {now} against {expected}"
            );
        }
    }
    assert!(close(slewed.sim().action()), "reached within 2 / 0.3 steps");
}

/// Varied physics: each episode draws its friction, cube mass and damping scales from its
/// seed, within the spread, the same again for the same seed and others for another; a
/// spread of 0 keeps the scene's own physics.
#[test]
fn varied_physics_draws_each_episodes_scales_from_its_seed() {
    let scene = Scene::load(dexcube_sim::SceneKind::Cube).unwrap();
    let scales = |spread: f64, seed: u64| {
        let mut env =
            LayerOpEnv::with_scene(scene.clone(), LayerMove::UPrime, LayerGoals::Training)
                .with_settings(EpisodeSettings {
                    physics_spread: spread,
                    ..EpisodeSettings::PAPER
                });
        env.reset(Some(seed));
        let (now, nominal) = (env.sim().data().model(), scene.model());
        let friction = (0..nominal.geom_friction().len())
            .find(|&g| nominal.geom_friction()[g][0] > 0.0)
            .unwrap();
        let damped = (0..nominal.dof_damping().len())
            .find(|&d| nominal.dof_damping()[d] > 0.0)
            .unwrap();
        let cube = (0..nominal.body_mass().len())
            .find(|&b| {
                scene.model().body_subtreemass()[b] > 0.0
                    && now.body_mass()[b] != nominal.body_mass()[b]
            })
            .map_or(1.0, |b| now.body_mass()[b] / nominal.body_mass()[b]);
        [
            now.geom_friction()[friction][0] / nominal.geom_friction()[friction][0],
            cube,
            now.dof_damping()[damped] / nominal.dof_damping()[damped],
        ]
    };
    assert_eq!(scales(0.0, 5), [1.0; 3], "the paper's physics");
    let drawn = scales(0.3, 5);
    assert!(
        drawn
            .iter()
            .all(|s| (1.0 / 1.3..=1.3).contains(s) && *s != 1.0),
        "{drawn:?}"
    );
    assert_eq!(scales(0.3, 5), drawn, "the same seed, the same physics");
    assert_ne!(scales(0.3, 6), drawn, "another seed, other physics");
}

/// Both stages show the object's position where [`OBJECT_POSITION`] says, at reset and after
/// a step, on the rigid cube and the physical one: what a start gesture reads to tell where
/// the cube sits on the palm.
#[test]
fn both_stages_show_the_object_position_where_the_layout_says() {
    let rot = CubeRotEnv::new(RotMode::Pair).unwrap();
    let layer =
        LayerOpEnv::new(ObjectKind::Cube, LayerMove::UPrime, LayerGoals::Evaluation).unwrap();
    let envs: [Box<dyn SimulatedEnv>; 2] = [Box::new(rot), Box::new(layer)];
    let mut rng = ChaCha8Rng::seed_from_u64(53);
    for mut env in envs {
        let shows_its_position = |env: &dyn SimulatedEnv, observation: &[f64]| {
            let shown = &observation[OBJECT_POSITION..OBJECT_POSITION + 3];
            assert_eq!(shown, env.sim().object_pose().position);
        };
        let (first, _) = env.reset(Some(53));
        shows_its_position(env.as_ref(), &first.observation);
        let later = env.step(&random_action(&mut rng)).observation;
        shows_its_position(env.as_ref(), &later.observation);
    }
}

/// A start LayerOpEnv gives in mid-episode holds the angle its physical cube's layer has
/// turned since the episode began and the face whose layer turns, and an episode reset from
/// it sees exactly what the episode it was taken from saw then, and goes on alike, even where
/// the cube has tumbled so that another face is up: what `eval-stage --after-gesture`
/// records.
#[test]
fn a_stage_2_start_taken_in_mid_episode_resumes_that_episode() {
    let new_env =
        || LayerOpEnv::new(ObjectKind::Cube, LayerMove::UPrime, LayerGoals::Evaluation).unwrap();
    let face_up = |env: &LayerOpEnv| {
        let cube = CubeState::read(env.sim()).unwrap();
        face_toward(&cube.pose().orientation, [0.0, 0.0, 1.0])
    };
    let mut tumbled = 0;
    for seed in 0..8 {
        let mut env = new_env();
        env.reset(Some(seed));
        assert_eq!(
            env.fresh_start().goal[1],
            0.0,
            "nothing turned at a fresh reset"
        );
        let face_at_reset = face_up(&env);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut seen = None;
        for _ in 0..5 {
            seen = Some(env.step(&random_action(&mut rng)).observation);
        }
        let seen = seen.unwrap();
        let start = env.fresh_start();
        assert_eq!(start.goal[1], seen.achieved_goal[0]);
        tumbled += usize::from(face_up(&env) != face_at_reset);
        let mut resumed = new_env();
        let (first, _) = resumed.reset_from(&start).unwrap();
        assert_eq!(first.observation, seen.observation, "seed {seed}");
        let action = random_action(&mut rng);
        assert_eq!(
            resumed.step(&action).observation.observation,
            env.step(&action).observation.observation,
            "seed {seed}"
        );
    }
    assert!(
        tumbled > 0,
        "some cube tumbled to another face in five random steps"
    );
}
