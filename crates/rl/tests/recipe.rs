//! Recipes: phases run one after another in one folder, each ended by its rule, the next
//! starting from what the last one left; a recipe stopped part-way goes on exactly as an
//! uninterrupted one, and its curves and policy cover every phase.

use dexcube_rl::point_mass::PointMassEnv;
use dexcube_rl::recipe::{Phase, PhaseEnvs, Recipe, RecipeRun, run_recipe};
use dexcube_rl::train::Until;

mod common;
use common::{config, fresh_dir};

/// A two-phase recipe on the point mass: the first ends by its rule after one epoch (a mean
/// test success of 0 or more over one epoch), the second runs `second_epochs`, held near the
/// actor it starts from and exploring less.
fn recipe(second_epochs: usize) -> Recipe<String> {
    let phase = |name: &str, max_epochs, until, anchor| Phase {
        name: name.to_string(),
        env: format!("point mass ({name})"),
        max_epochs,
        until,
        noise_eps: None,
        random_eps: None,
        anchor,
        critic_only_epochs: 0,
    };
    Recipe {
        name: "test".into(),
        config: config().with_td3(),
        envs: 2,
        phases: vec![
            phase(
                "reach",
                5,
                Some(Until {
                    success: 0.0,
                    window: 1,
                }),
                0.0,
            ),
            Phase {
                noise_eps: Some(0.1),
                random_eps: Some(0.05),
                ..phase("reach-held", second_epochs, None, 1.0)
            },
        ],
    }
}

fn envs(setting: &String) -> Result<PhaseEnvs<PointMassEnv>, String> {
    Ok(PhaseEnvs {
        make: Box::new(PointMassEnv::default),
        label: setting.clone(),
        metadata: serde_json::json!({"env": setting}),
    })
}

fn run(dir: &std::path::Path) -> RecipeRun {
    RecipeRun {
        dir: dir.to_path_buf(),
        seed: 7,
        threads: 1,
        progress: false,
    }
}

/// The recipe's CSV without the columns of clock times, which no two runs share.
fn untimed_csv(dir: &std::path::Path) -> Vec<String> {
    let csv = std::fs::read_to_string(dir.join("metrics.csv")).unwrap();
    csv.lines()
        .map(|line| {
            let cells: Vec<&str> = line.split(',').collect();
            // hours (6) and env_steps_per_s (12) are clock times.
            cells
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != 6 && *i != 12)
                .map(|(_, c)| *c)
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect()
}

#[test]
fn a_recipe_runs_its_phases_in_turn_and_ships_the_last() {
    let dir = fresh_dir("dexcube-recipe-whole");
    let outcome = run_recipe(&recipe(3), &run(&dir), envs).unwrap();
    let phases: Vec<(usize, usize)> = outcome
        .metrics
        .iter()
        .map(|e| (e.phase, e.within.epoch))
        .collect();
    assert_eq!(
        phases,
        [(0, 0), (1, 0), (1, 1), (1, 2)],
        "the first phase ended by its rule"
    );
    // Totals run on across phases.
    let steps: Vec<usize> = outcome.metrics.iter().map(|e| e.env_steps).collect();
    assert!(steps.windows(2).all(|w| w[1] > w[0]), "{steps:?}");
    for file in [
        "phases/01-reach/checkpoint/state.json",
        "phases/02-reach-held/checkpoint/state.json",
        "success.png",
        "success-hours.png",
        "policy.safetensors",
    ] {
        assert!(dir.join(file).is_file(), "{file} written");
    }
    let csv = untimed_csv(&dir);
    assert_eq!(csv.len(), 5, "a header and four epochs");
    assert!(csv[1].starts_with("1,reach,0,0,"), "{}", csv[1]);
    assert!(csv[4].starts_with("2,reach-held,2,3,"), "{}", csv[4]);
    // The policy is the last phase's, with the recipe on its card.
    let card: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("policy.json")).unwrap()).unwrap();
    let recipe_card = &card["metadata"]["recipe"];
    assert_eq!(recipe_card["name"], "test");
    assert_eq!(recipe_card["seed"], 7);
    assert_eq!(recipe_card["phases"][1]["epochs"], 3);
    assert_eq!(
        card["metadata"]["environment"]["env"],
        "point mass (reach-held)"
    );
    let last = std::fs::read(dir.join("phases/02-reach-held/policy.safetensors")).unwrap();
    assert_eq!(std::fs::read(dir.join("policy.safetensors")).unwrap(), last);

    // Stopped after the second phase's first epoch, it goes on to the same end.
    let split = fresh_dir("dexcube-recipe-split");
    run_recipe(&recipe(1), &run(&split), envs).unwrap();
    assert_eq!(untimed_csv(&split).len(), 3, "two epochs so far");
    run_recipe(&recipe(3), &run(&split), envs).unwrap();
    assert_eq!(
        untimed_csv(&split),
        csv,
        "every epoch as the uninterrupted run's"
    );
    assert_eq!(
        std::fs::read(split.join("policy.safetensors")).unwrap(),
        last
    );
}

#[test]
fn a_recipe_that_cannot_run_says_why() {
    let dir = fresh_dir("dexcube-recipe-bad");
    let mut anchored = recipe(1);
    anchored.phases[0].anchor = 1.0;
    let mut unnamed = recipe(1);
    unnamed.phases[1].name = "a/b".into();
    let mut noisy = recipe(1);
    noisy.phases[1].noise_eps = Some(2.0);
    for (bad, says) in [
        (anchored, "starts from random weights"),
        (unnamed, "letters, digits"),
        (noisy, "between 0 and 1"),
        (
            Recipe {
                phases: vec![],
                ..recipe(1)
            },
            "no phases",
        ),
    ] {
        let err = run_recipe(&bad, &run(&dir), envs)
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains(says), "{err}");
    }
    let refused =
        |_: &String| -> Result<PhaseEnvs<PointMassEnv>, String> { Err("no such object".into()) };
    let err = run_recipe(&recipe(1), &run(&dir), refused)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("phase 'reach': no such object"), "{err}");
}
