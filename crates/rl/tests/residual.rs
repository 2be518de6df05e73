//! Residual policy learning: the environment that trains a residual acts as its base with the
//! residual's action added, a residual begins at zero, and the policy that ships base and
//! residual together acts as that environment did in training.

use std::path::Path;
use std::sync::Arc;

use dexcube_env::{GoalEnv, GoalLead};
use dexcube_rl::point_mass::{POINT_MASS_STEPS, PointGoal, PointMassEnv};
use dexcube_rl::residual::{ResidualEnv, ResidualSetting, residual_action};
use dexcube_rl::{Policy, TrainOptions, train};

mod common;
use common::{config, fresh_dir};

const SCALE: f64 = 0.25;

fn options(dir: &Path, epochs: usize) -> TrainOptions {
    TrainOptions {
        out_dir: Some(dir.to_path_buf()),
        snapshot_every: 1,
        metadata: serde_json::json!({"env": "point mass"}),
        ..TrainOptions::in_memory("point mass", epochs, 2, 1, 3)
    }
}

fn load(prefix: &Path) -> Policy {
    Policy::load(prefix, &burn::prelude::Device::flex()).unwrap()
}

/// The error's message of what must fail.
fn refused<T, E: std::fmt::Display>(result: Result<T, E>) -> String {
    match result {
        Ok(_) => panic!("not refused"),
        Err(e) => e.to_string(),
    }
}

/// The positions of one point-mass episode seeded `seed`, acted by `policy` through its card.
fn positions_acted_by(policy: &Policy, seed: u64) -> Vec<Vec<f64>> {
    let mut env = PointMassEnv::default();
    let (mut obs, _) = env.reset(Some(seed));
    let mut acting = policy.episode();
    let mut positions = Vec::new();
    for _ in 0..POINT_MASS_STEPS {
        let achieved = obs.achieved_goal.clone();
        let action =
            acting.act_toward(&obs.observation, &obs.desired_goal, || achieved, &PointGoal);
        obs = env.step(&action).observation;
        positions.push(obs.observation.clone());
    }
    positions
}

/// The positions of one episode seeded `seed` in the residual environment on `base`, the
/// residual acted by `actor` (a policy observing the base's action too).
fn positions_in_training(base: &Arc<Policy>, actor: &Policy, seed: u64) -> Vec<Vec<f64>> {
    let mut env = ResidualEnv::new(PointMassEnv::default(), base.clone(), SCALE).unwrap();
    let (mut obs, _) = env.reset(Some(seed));
    let mut positions = Vec::new();
    for _ in 0..POINT_MASS_STEPS {
        let residual = actor.act(&obs.observation, &obs.desired_goal);
        obs = env.step(&residual).observation;
        positions.push(obs.observation[..2].to_vec());
    }
    positions
}

#[test]
fn the_residual_environment_shows_the_base_s_action_and_adds_the_residual_to_it() {
    let dir = fresh_dir("dexcube-rl-residual-env");
    train(PointMassEnv::default, config(), &options(&dir, 1)).unwrap();
    let base = Arc::new(load(&dir.join("policy")));
    let mut env = ResidualEnv::new(PointMassEnv::default(), base.clone(), SCALE).unwrap();
    assert_eq!(
        env.spaces().observation,
        4,
        "the position, then the base's action"
    );
    let mut plain = PointMassEnv::default();
    let (mut obs, _) = env.reset(Some(5));
    let (mut plain_obs, _) = plain.reset(Some(5));
    // Residuals that push the sum past the action range, and none at all.
    for residual in [[1.0, -1.0], [0.0, 0.0], [-1.0, 0.4]] {
        let base_action = base.act(&plain_obs.observation, &plain_obs.desired_goal);
        let shown = [plain_obs.observation.clone(), base_action.clone()].concat();
        assert_eq!(obs.observation, shown);
        assert_eq!(obs.desired_goal, plain_obs.desired_goal);
        let taken = residual_action(&base_action, &residual, SCALE);
        let expected: Vec<f64> = (base_action.iter().zip(residual))
            .map(|(b, r)| (b + SCALE * r).clamp(-1.0, 1.0))
            .collect();
        assert_eq!(taken, expected);
        let transition = env.step(&residual);
        let plain_transition = plain.step(&taken);
        assert_eq!(transition.reward, plain_transition.reward);
        (obs, plain_obs) = (transition.observation, plain_transition.observation);
    }
    for scale in [0.0, 1.5, f64::NAN] {
        let message = refused(ResidualEnv::new(
            PointMassEnv::default(),
            base.clone(),
            scale,
        ));
        assert!(message.contains("above 0 and at most 1"), "{message}");
    }
}

#[test]
fn a_residual_starts_at_zero_and_ships_with_its_base_acting_as_in_training() {
    let dir = fresh_dir("dexcube-rl-residual");
    let base_prefix = dir.join("base/policy");
    train(
        PointMassEnv::default,
        config(),
        &options(&dir.join("base"), 1),
    )
    .unwrap();
    let base = Arc::new(load(&base_prefix));
    // The residual's run: a critic-only epoch, then one that moves the actor.
    let run = dir.join("residual");
    let setting = ResidualSetting {
        of: base_prefix.clone(),
        scale: SCALE,
    };
    let residual_options = TrainOptions {
        zero_output: true,
        critic_only_epochs: 1,
        metadata: serde_json::json!({"env": "point mass", "residual": setting}),
        ..options(&run, 2)
    };
    let make = || ResidualEnv::new(PointMassEnv::default(), base.clone(), SCALE).unwrap();
    train(make, config(), &residual_options).unwrap();
    let (unmoved, moved) = (
        run.join("snapshots/epoch-0000"),
        run.join("snapshots/epoch-0001"),
    );
    let (zero, learned) = (load(&unmoved), load(&moved));
    let mut env = make();
    let (obs, _) = env.reset(Some(1));
    assert_eq!(zero.act(&obs.observation, &obs.desired_goal), [0.0, 0.0]);
    assert_ne!(learned.act(&obs.observation, &obs.desired_goal), [0.0, 0.0]);
    // Shipped with the base, the zero residual acts as the base, and the learned one as the
    // residual environment acted with it.
    let ship = |actor: &Path, name: &str| {
        let out = dir.join(name);
        Policy::with_residual(&base_prefix, actor, &out, "dexcube residual ...").map(|()| out)
    };
    let (as_base, shipped) = (
        load(&ship(&unmoved, "zero").unwrap()),
        load(&ship(&moved, "learned").unwrap()),
    );
    let residual_card = shipped.card.residual.as_ref().unwrap();
    assert_eq!(residual_card.scale, SCALE);
    assert_eq!(residual_card.actor.source, moved);
    assert_eq!(
        shipped.card.metadata["residual_of"],
        base_prefix.display().to_string()
    );
    assert!(shipped.card.acting_settings().unwrap()["residual"]["scale"] == SCALE);
    for seed in 0..3 {
        let of_base = positions_acted_by(&base, seed);
        assert_eq!(positions_acted_by(&as_base, seed), of_base);
        let of_shipped = positions_acted_by(&shipped, seed);
        assert_eq!(of_shipped, positions_in_training(&base, &learned, seed));
        assert_ne!(of_shipped, of_base, "the learned residual moves the point");
    }
    // What does not fit is refused with a message naming why.
    let message = refused(ship(&base_prefix, "x"));
    assert!(message.contains("not trained as a residual"), "{message}");
    let message = refused(Policy::with_residual(
        &moved,
        &moved,
        &dir.join("x"),
        "test",
    ));
    assert!(message.contains("do not fit a residual on"), "{message}");
    let with_one = dir.join("learned");
    let lead = GoalLead {
        share: 0.5,
        within: 0.5,
    };
    for message in [
        refused(Policy::with_residual(
            &with_one,
            &moved,
            &dir.join("x"),
            "test",
        )),
        refused(Policy::led(&with_one, lead, &dir.join("x"), "test")),
        refused(Policy::ensemble(
            &[with_one.clone(), base_prefix.clone()],
            &dir.join("x"),
            "test",
        )),
    ] {
        assert!(
            message.contains("acts with a residual trained on top of it"),
            "{message}"
        );
    }
    let message = refused(ResidualEnv::new(
        PointMassEnv::default(),
        Arc::new(shipped),
        SCALE,
    ));
    assert!(message.contains("has a residual already"), "{message}");
    let message = refused(ResidualEnv::new(
        PointMassEnv::default(),
        Arc::new(learned),
        SCALE,
    ));
    assert!(message.contains("the base policy takes"), "{message}");
    // A zero output starts a fresh actor; a warm start brings its own.
    let warm = TrainOptions {
        init_actor: Some(base_prefix),
        ..residual_options
    };
    let message = refused(train(make, config(), &warm));
    assert!(
        message.contains("a zero output starts a fresh actor"),
        "{message}"
    );
}
