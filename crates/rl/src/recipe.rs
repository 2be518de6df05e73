//! Recipes: how a skill is learned from random weights in one run, as a list of phases. Each
//! phase trains on its own environments (an object, a success test, a view, its starts) with
//! its own exploration and anchor, and ends by a rule read from its own test success, or
//! after its last epoch; the next phase starts from the networks and normalisers the last one
//! left ([`TrainOptions::init_from`], which widens them where the next phase observes more).
//! Nobody picks a snapshot: the recipe's policy is the last phase's latest.
//!
//! A run of a recipe in `DIR` keeps:
//! - `phases/NN-NAME/`: each phase's run, with its checkpoint, curve and snapshots;
//! - `metrics.csv`: every epoch of every phase, with the phase's name and the steps, episodes
//!   and hours counted from the recipe's start;
//! - `success.png` and `success-hours.png`: test success against env steps and against hours,
//!   a colour per phase;
//! - `policy.safetensors` and `policy.json`: the policy, once the last phase is done.
//!
//! A run killed at any moment goes on where it stopped with [`run_recipe`] again: finished
//! phases are read back, the phase under way resumes exactly from its last checkpoint.
//!
//! What a phase's environment is (`S`) is the caller's: this crate sees only the environment
//! contract, and a phase's settings travel as data.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use burn::prelude::Device;
use dexcube_env::GoalEnv;
use serde::{Deserialize, Serialize};

use crate::checkpoint;
use crate::config::DdpgHerConfig;
use crate::plot::{Series, line_plot};
use crate::policy::Policy;
use crate::train::{EpochMetrics, RunCurve, TrainError, TrainOptions, Until, train};

/// A skill's training, phase by phase.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Recipe<S> {
    /// The recipe's name (`dexcube`, `paper`).
    pub name: String,
    /// The learner's hyperparameters, every phase's (their sizes stay through the recipe).
    pub config: DdpgHerConfig,
    /// Environments stepped together; each gives one episode per cycle.
    pub envs: usize,
    pub phases: Vec<Phase<S>>,
}

/// One phase of a recipe.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Phase<S> {
    /// A short name for the phase's folder and curve (`axis-rigid`).
    pub name: String,
    /// What the phase trains on.
    pub env: S,
    /// The phase's last epoch, if its rule has not ended it first.
    pub max_epochs: usize,
    /// The rule that ends the phase early; none runs it to its last epoch.
    pub until: Option<Until>,
    /// Exploration in this phase, where it differs from the recipe's configuration.
    pub noise_eps: Option<f64>,
    pub random_eps: Option<f64>,
    /// Weight of the penalty that holds the actor near the one the phase starts from (0: none).
    pub anchor: f64,
    /// The phase's first epochs in which only the critics learn.
    pub critic_only_epochs: usize,
}

/// Where and how a recipe runs.
pub struct RecipeRun {
    pub dir: PathBuf,
    pub seed: u64,
    /// Threads stepping the environments.
    pub threads: usize,
    /// Show a progress bar per phase.
    pub progress: bool,
}

/// A phase's environments as the caller builds them from its settings.
pub struct PhaseEnvs<E> {
    pub make: Box<dyn Fn() -> E>,
    /// What the phase trains, for curves and policy cards.
    pub label: String,
    /// Facts about the environment, for policy cards.
    pub metadata: serde_json::Value,
}

/// What a recipe run came to.
pub struct RecipeOutcome {
    /// Every epoch, phase by phase.
    pub metrics: Vec<RecipeEpoch>,
    /// The recipe's policy (`DIR/policy`), once its last phase is done.
    pub policy: PathBuf,
}

/// One epoch of a recipe: its phase's record, with the recipe's totals.
#[derive(Clone, Debug, PartialEq)]
pub struct RecipeEpoch {
    pub phase: usize,
    pub phase_name: String,
    pub within: EpochMetrics,
    /// Counted from the recipe's start.
    pub episodes: usize,
    pub env_steps: usize,
    pub wall_s: f64,
}

impl<S> Recipe<S> {
    /// The folder of phase `k` of a run in `dir`.
    pub fn phase_dir(&self, dir: &Path, k: usize) -> PathBuf {
        dir.join("phases")
            .join(format!("{:02}-{}", k + 1, self.phases[k].name))
    }

    /// The seed of phase `k` of a run seeded `seed`: each phase draws its own episodes.
    pub fn phase_seed(seed: u64, k: usize) -> u64 {
        seed.wrapping_add((k as u64) << 40)
    }

    /// Says what is wrong with a recipe that cannot run.
    pub fn check(&self) -> Result<(), String> {
        if self.phases.is_empty() {
            return Err(format!("the recipe '{}' has no phases", self.name));
        }
        if self.envs == 0 {
            return Err(format!("the recipe '{}' steps no environments", self.name));
        }
        for phase in &self.phases {
            let name = &phase.name;
            if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-') {
                return Err(format!(
                    "the phase name '{name}' must be letters, digits and '-' (it names a folder)"
                ));
            }
            if phase.max_epochs == 0 {
                return Err(format!("the phase '{name}' has no epochs"));
            }
            for (what, value) in [
                ("noise_eps", phase.noise_eps),
                ("random_eps", phase.random_eps),
            ] {
                if value.is_some_and(|v| !(0.0..=1.0).contains(&v)) {
                    return Err(format!(
                        "the phase '{name}''s {what} must be between 0 and 1"
                    ));
                }
            }
            if !(phase.anchor >= 0.0 && phase.anchor.is_finite()) {
                return Err(format!("the phase '{name}''s anchor must be 0 or more"));
            }
        }
        if self.phases[0].anchor > 0.0 {
            return Err(format!(
                "the first phase, '{}', starts from random weights: an anchor would hold the \
                 actor near them",
                self.phases[0].name
            ));
        }
        Ok(())
    }

    /// The phase's configuration: the recipe's with the phase's exploration and anchor.
    fn phase_config(&self, k: usize) -> DdpgHerConfig {
        let phase = &self.phases[k];
        DdpgHerConfig {
            noise_eps: phase.noise_eps.unwrap_or(self.config.noise_eps),
            random_eps: phase.random_eps.unwrap_or(self.config.random_eps),
            anchor: phase.anchor,
            ..self.config.clone()
        }
    }
}

/// Whether the run of phase `k` in `dir` is done: its rule met, or its last epoch run.
fn phase_done<S>(recipe: &Recipe<S>, k: usize, metrics: &[EpochMetrics]) -> bool {
    let phase = &recipe.phases[k];
    metrics.len() >= phase.max_epochs || phase.until.is_some_and(|rule| rule.met(metrics))
}

/// Runs `recipe` (or goes on with it where a run in `run.dir` stopped), phase by phase, on
/// the environments `make` builds for each phase's settings.
pub fn run_recipe<S, E: GoalEnv>(
    recipe: &Recipe<S>,
    run: &RecipeRun,
    make: impl Fn(&S) -> Result<PhaseEnvs<E>, String>,
) -> Result<RecipeOutcome, TrainError> {
    recipe.check().map_err(TrainError::Recipe)?;
    let mut done: Vec<Vec<EpochMetrics>> = Vec::new();
    for k in 0..recipe.phases.len() {
        let phase = &recipe.phases[k];
        let dir = recipe.phase_dir(&run.dir, k);
        let begun = RunCurve::read(&dir).ok().map(|run| run.metrics);
        if let Some(metrics) = begun.as_ref().filter(|m| phase_done(recipe, k, m)) {
            done.push(metrics.clone());
            continue;
        }
        let envs = make(&phase.env)
            .map_err(|message| TrainError::Recipe(format!("phase '{}': {message}", phase.name)))?;
        let (names, whole, before) = (phase_names(recipe), run.dir.clone(), done.clone());
        let options = TrainOptions {
            epochs: phase.max_epochs,
            envs: recipe.envs,
            threads: run.threads,
            seed: Recipe::<S>::phase_seed(run.seed, k),
            out_dir: Some(dir.clone()),
            resume: begun.is_some(),
            init_from: (k > 0).then(|| recipe.phase_dir(&run.dir, k - 1)),
            init_actor: None,
            snapshot_every: 0,
            critic_only_epochs: phase.critic_only_epochs,
            zero_output: false,
            until: phase.until,
            after_epoch: Some(Arc::new(move |metrics: &[EpochMetrics]| {
                let mut all = before.clone();
                all.push(metrics.to_vec());
                write_curves(&whole, &names, &all)
            })),
            progress: run.progress,
            label: format!(
                "phase {}/{} {}: {}",
                k + 1,
                recipe.phases.len(),
                phase.name,
                envs.label
            ),
            metadata: envs.metadata,
        };
        let trained = train(envs.make, recipe.phase_config(k), &options)?;
        done.push(trained.metrics);
    }
    write_curves(&run.dir, &phase_names(recipe), &done)?;
    let last = recipe.phase_dir(&run.dir, recipe.phases.len() - 1);
    let policy = run.dir.join("policy");
    let shipped = Policy::load(&last.join("policy"), &Device::flex())?;
    let mut metadata = shipped.card.metadata.clone();
    metadata["recipe"] = serde_json::json!({
        "name": recipe.name,
        "seed": run.seed,
        "phases": recipe.phases.iter().zip(&done).map(|(phase, metrics)| serde_json::json!({
            "name": phase.name,
            "epochs": metrics.len(),
            "episodes": metrics.last().map_or(0, |m| m.episodes),
            "env_steps": metrics.last().map_or(0, |m| m.env_steps),
            "wall_s": metrics.last().map_or(0.0, |m| m.wall_s),
        })).collect::<Vec<_>>(),
        "env_steps": done.iter().filter_map(|m| m.last()).map(|m| m.env_steps).sum::<usize>(),
        "wall_s": done.iter().filter_map(|m| m.last()).map(|m| m.wall_s).sum::<f64>(),
    });
    shipped.first_member(metadata).write(&policy)?;
    Ok(RecipeOutcome {
        metrics: recipe_epochs(&phase_names(recipe), &done),
        policy,
    })
}

fn phase_names<S>(recipe: &Recipe<S>) -> Vec<String> {
    recipe.phases.iter().map(|p| p.name.clone()).collect()
}

/// The phases' epochs as the recipe's, with totals counted from its start.
fn recipe_epochs(names: &[String], phases: &[Vec<EpochMetrics>]) -> Vec<RecipeEpoch> {
    let (mut episodes, mut env_steps, mut wall_s) = (0, 0, 0.0);
    let mut out = Vec::new();
    for (k, metrics) in phases.iter().enumerate() {
        for m in metrics {
            out.push(RecipeEpoch {
                phase: k,
                phase_name: names[k].clone(),
                within: m.clone(),
                episodes: episodes + m.episodes,
                env_steps: env_steps + m.env_steps,
                wall_s: wall_s + m.wall_s,
            });
        }
        if let Some(last) = metrics.last() {
            (episodes, env_steps, wall_s) = (
                episodes + last.episodes,
                env_steps + last.env_steps,
                wall_s + last.wall_s,
            );
        }
    }
    out
}

const CSV_HEADER: &str = "phase,phase_name,phase_epoch,epoch,episodes,env_steps,hours,test_success,train_success,mean_q,critic_loss,actor_loss,env_steps_per_s";

/// Writes the recipe's `metrics.csv`, `success.png` (against env steps) and
/// `success-hours.png` (against hours) in `dir`.
fn write_curves(
    dir: &Path,
    names: &[String],
    phases: &[Vec<EpochMetrics>],
) -> Result<(), TrainError> {
    let epochs = recipe_epochs(names, phases);
    let rows = epochs.iter().enumerate().map(|(i, e)| {
        let m = &e.within;
        format!(
            "{},{},{},{i},{},{},{:.4},{:.4},{:.4},{:.4},{:.6},{:.6},{:.1}",
            e.phase + 1,
            e.phase_name,
            m.epoch,
            e.episodes,
            e.env_steps,
            e.wall_s / 3600.0,
            m.test_success,
            m.train_success,
            m.mean_q,
            m.critic_loss,
            m.actor_loss,
            m.env_steps_per_s
        )
    });
    let csv: Vec<String> = std::iter::once(CSV_HEADER.to_string())
        .chain(rows)
        .collect();
    checkpoint::write_atomically(&dir.join("metrics.csv"), (csv.join("\n") + "\n").as_bytes())?;
    let series = |x: fn(&RecipeEpoch) -> f64| -> Vec<Series> {
        names
            .iter()
            .enumerate()
            .map(|(k, name)| Series {
                label: format!("{}. {name}", k + 1),
                points: epochs
                    .iter()
                    .filter(|e| e.phase == k)
                    .map(|e| (x(e), e.within.test_success))
                    .collect(),
                band: None,
            })
            .collect()
    };
    for (file, x_label, x) in [
        (
            "success.png",
            "env steps (millions)",
            (|e: &RecipeEpoch| e.env_steps as f64 / 1e6) as fn(&RecipeEpoch) -> f64,
        ),
        (
            "success-hours.png",
            "hours of training",
            |e: &RecipeEpoch| e.wall_s / 3600.0,
        ),
    ] {
        if let Err(e) = line_plot(
            &dir.join(file),
            "test success through the recipe",
            x_label,
            "test success rate",
            1.0,
            &series(x),
        ) {
            eprintln!("warning: no {file}: {e}");
        }
    }
    Ok(())
}
