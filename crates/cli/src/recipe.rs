//! The recipes `dexcube train` runs: what each phase trains on ([`PhaseEnv`]), the shipped
//! recipes of each skill ([`shipped`]: `dexcube`, ours, and `paper`, the paper's DDPG + HER),
//! and the environments a phase's settings build.
//!
//! A recipe is data: `dexcube train rot --print-recipe` prints one as JSON, and `--recipe
//! FILE` runs a file of that form.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use dexcube_env::layer::LayerGoals;
use dexcube_env::{
    ControlRate, CubeRotEnv, EpisodeSettings, GoalEnv, LayerOpEnv, StartMix, StartPick,
};
use dexcube_rl::DdpgHerConfig;
use dexcube_rl::recipe::{Phase, PhaseEnvs, Recipe};
use dexcube_rl::train::Until;
use dexcube_sim::Scene;
use serde::{Deserialize, Serialize};

use crate::env::{
    EnvChoice, EnvKind, PAPER_ANGLE_THRESHOLD, angle_flag, physics_spread, starts_for,
};

/// What one phase trains on: the settings `dexcube env info` takes as flags, under the flags'
/// names (`see_misalignment` for `--see-misalignment`), with the same defaults.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PhaseEnv {
    /// CubeRotEnv's success test: paper, axis or pair.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode: Option<String>,
    /// LayerOpEnv's move: U U' R R' F F'.
    #[serde(rename = "move", skip_serializing_if = "Option::is_none")]
    pub layer_move: Option<String>,
    /// cube, block or rigid (the environment's own by default).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub object: Option<String>,
    pub square: bool,
    pub intact: bool,
    pub turn_ends: bool,
    pub see_misalignment: bool,
    pub see_grip: bool,
    /// LayerOpEnv: train on the evaluation goal, exactly a quarter turn, not goals up to it.
    pub quarter_goals: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub control_substeps: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub angle_threshold: Option<f64>,
    /// Domain randomisation: friction, the object's mass and joint damping each scaled per
    /// episode by a factor log-uniform in [1/(1+S), 1+S].
    pub physics_spread: f64,
    /// Recorded starts (`dexcube eval --record-starts`) to begin a share of episodes from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub starts: Option<PathBuf>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_share: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failed_weight: Option<f64>,
}

impl PhaseEnv {
    /// The environment these settings choose for `skill`, checked as `dexcube env` checks
    /// its flags.
    fn choice(&self, skill: EnvKind) -> anyhow::Result<EnvChoice> {
        if skill == EnvKind::Rot && (self.layer_move.is_some() || self.quarter_goals) {
            bail!("move and quarter_goals are LayerOpEnv's (train layer)");
        }
        if skill == EnvKind::Layer && self.mode.is_some() {
            bail!("mode is CubeRotEnv's success test (train rot)");
        }
        let mode = self.mode.as_deref().unwrap_or("paper");
        let layer_move = self.layer_move.as_deref().unwrap_or("U'");
        let angle_threshold = self.angle_threshold.unwrap_or(PAPER_ANGLE_THRESHOLD);
        angle_flag("angle_threshold", "", &angle_threshold.to_string())
            .map_err(anyhow::Error::msg)?;
        physics_spread(&self.physics_spread.to_string()).map_err(anyhow::Error::msg)?;
        Ok(EnvChoice {
            env: skill,
            mode: mode.parse().map_err(anyhow::Error::msg)?,
            layer_move: layer_move.parse().map_err(anyhow::Error::msg)?,
            object: self
                .object
                .as_deref()
                .map(str::parse)
                .transpose()
                .map_err(anyhow::Error::msg)?,
            square: self.square,
            intact: self.intact,
            turn_ends: self.turn_ends,
            see_misalignment: self.see_misalignment,
            see_grip: self.see_grip,
            control_rate: match self.control_substeps {
                Some(n) => ControlRate::every(n).map_err(anyhow::Error::msg)?,
                None => ControlRate::PAPER,
            },
            angle_threshold,
        })
    }

    /// The environments of a phase of `skill` with these settings, with their label and the
    /// facts a policy card records of them.
    pub fn envs(&self, skill: EnvKind) -> anyhow::Result<PhaseEnvs<Box<dyn GoalEnv>>> {
        let choice = self.choice(skill)?;
        let object = choice.object()?;
        let view = choice.view()?;
        if self.starts.is_none() && (self.start_share.is_some() || self.failed_weight.is_some()) {
            bail!("start_share and failed_weight weigh recorded starts: name them in starts");
        }
        let share = self.start_share.unwrap_or(0.5);
        let failed_weight = self.failed_weight.unwrap_or(1.0);
        if !(0.0..=1.0).contains(&share) {
            bail!("start_share must be between 0 and 1, not {share}");
        }
        if !(failed_weight.is_finite() && failed_weight > 0.0) {
            bail!("failed_weight must be a positive number, not {failed_weight}");
        }
        if self.starts.is_some()
            && skill == EnvKind::Layer
            && self.layer_move.as_deref().is_some_and(|m| m != "U'")
        {
            bail!(
                "starts for layer are the operator's Stage 2 starts: train them with the move U'"
            );
        }
        let scene = Scene::load(object.scene())?;
        let starts = match &self.starts {
            Some(path) => Some(StartMix {
                starts: starts_for(path, &scene, skill)?.0,
                pick: StartPick::Share {
                    share,
                    failed_weight,
                },
            }),
            None => None,
        };
        let settings = EpisodeSettings {
            rate: choice.control_rate,
            physics_spread: self.physics_spread,
            ..EpisodeSettings::PAPER
        };
        let metadata = serde_json::json!({
            "env": skill.name(),
            "goals": if self.quarter_goals { "quarter turn" } else { "uniform" },
            "success": format!(
                "{}{}",
                match skill {
                    EnvKind::Rot => "pose",
                    EnvKind::Layer => "angle",
                },
                choice.success_suffix("cube ")?
            ),
            "observation": view.name().map_or("paper".to_string(), |name| format!("with the {name}")),
            "object": object.name(),
            "mode": (skill == EnvKind::Rot).then(|| choice.mode.name()),
            "starts": self.starts.as_ref().map(|p| p.display().to_string()),
            "start_share": self.starts.as_ref().map(|_| share),
            "failed_weight": self.starts.as_ref().map(|_| failed_weight),
            "control_substeps": choice.control_rate.substeps(),
            "physics_spread": self.physics_spread,
            "angle_threshold": choice.angle_threshold,
        });
        let make: Box<dyn Fn() -> Box<dyn GoalEnv>> = match skill {
            EnvKind::Rot => {
                let goal = choice.rot_goal()?;
                Box::new(move || {
                    Box::new(
                        CubeRotEnv::with_scene(scene.clone(), goal)
                            .with_view(view)
                            .with_starts(starts.clone())
                            .with_settings(settings),
                    ) as Box<dyn GoalEnv>
                })
            }
            EnvKind::Layer => {
                let (layer_move, goal) = (choice.layer_move, choice.layer_goal()?);
                let goals = if self.quarter_goals {
                    LayerGoals::Evaluation
                } else {
                    LayerGoals::Training
                };
                Box::new(move || {
                    Box::new(
                        LayerOpEnv::with_scene(scene.clone(), layer_move, goals)
                            .with_goal(goal)
                            .with_view(view)
                            .with_starts(starts.clone())
                            .with_settings(settings),
                    ) as Box<dyn GoalEnv>
                })
            }
        };
        Ok(PhaseEnvs {
            make,
            label: choice.name()?,
            metadata,
        })
    }
}

/// A recipe as a run keeps it (`DIR/recipe.json`): the skill, the seed and the recipe.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecipeFile {
    pub skill: String,
    pub seed: u64,
    pub recipe: Recipe<PhaseEnv>,
}

impl RecipeFile {
    pub fn skill(&self) -> anyhow::Result<EnvKind> {
        match self.skill.as_str() {
            "rot" => Ok(EnvKind::Rot),
            "layer" => Ok(EnvKind::Layer),
            other => bail!("the skill '{other}' is neither rot nor layer"),
        }
    }
}

/// The names of the shipped recipes.
pub const SHIPPED: [&str; 2] = ["dexcube", "paper"];

/// The recipe `name` (a shipped one or a JSON file of one) for `skill`.
pub fn named(name: &str, skill: EnvKind) -> anyhow::Result<Recipe<PhaseEnv>> {
    if let Some(recipe) = shipped(name, skill) {
        return Ok(recipe);
    }
    let path = Path::new(name);
    if !path.is_file() {
        bail!(
            "no recipe '{name}': name a shipped one ({}) or a JSON file of one (`dexcube train \
             {} --print-recipe` prints the shipped one to start from)",
            SHIPPED.join(", "),
            skill.name()
        );
    }
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read the recipe {}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| {
        anyhow::anyhow!(
            "{} is not a recipe ({e}); `dexcube train {} --print-recipe` prints one to start from",
            path.display(),
            skill.name()
        )
    })
}

/// A phase on `env`, ended by `until` or after `max_epochs`, exploring and learning as the
/// recipe does.
fn phase(name: &str, env: PhaseEnv, max_epochs: usize, until: Option<Until>) -> Phase<PhaseEnv> {
    Phase {
        name: name.to_string(),
        env,
        max_epochs,
        until,
        noise_eps: None,
        random_eps: None,
        anchor: 0.0,
        critic_only_epochs: 0,
    }
}

/// A phase that moves the policy onto the physical cube: it explores less, since 30% random
/// actions skew a layer in nearly every episode, and holds the actor near the one it starts
/// from (anchor 10) while the critics first learn the cube's values alone for two epochs (the
/// fine-tunes that made `models/rot-anchor57` and `models/layer-anchor69`; without the
/// anchor, the first such fine-tunes sank to 0.58 from 0.83).
fn onto_the_cube(phase: Phase<PhaseEnv>) -> Phase<PhaseEnv> {
    Phase {
        noise_eps: Some(0.1),
        random_eps: Some(0.05),
        anchor: 10.0,
        critic_only_epochs: 2,
        ..phase
    }
}

/// Ends a phase once its last five epochs' test success averages `success`.
fn mean_of_five(success: f64) -> Option<Until> {
    Some(Until { success, window: 5 })
}

/// The shipped recipe `name` for `skill`, if there is one.
///
/// - `dexcube` is the curriculum of today's defaults, made one run with TD3's critics
///   throughout (they beat DDPG's on U' at all three seeds, and in Stage 1's fine-tune):
///   - Stage 1: axis mode on the rigid cube, then pair mode, then the physical cube with the
///     square test and the misalignment seen;
///   - Stage 2: U' on the two-layer block with goals up to a quarter turn, then exactly a
///     quarter turn, then the physical cube with the square test and the misalignment seen.
/// - `paper` is DDPG + HER at the HER baselines' settings, which the paper trained with, on
///   its own task in one phase: the whole pose on the rigid cube, or U' on the physical cube.
pub fn shipped(name: &str, skill: EnvKind) -> Option<Recipe<PhaseEnv>> {
    let env = |mode: Option<&str>, object: &str| PhaseEnv {
        mode: mode.map(str::to_string),
        object: Some(object.to_string()),
        ..PhaseEnv::default()
    };
    let on_cube = |mode: Option<&str>| PhaseEnv {
        square: true,
        see_misalignment: true,
        ..env(mode, "cube")
    };
    let phases = match (name, skill) {
        ("paper", EnvKind::Rot) => {
            vec![phase("paper-rigid", env(Some("paper"), "rigid"), 150, None)]
        }
        ("paper", EnvKind::Layer) => vec![phase("Up-cube", env(None, "cube"), 150, None)],
        ("dexcube", EnvKind::Rot) => vec![
            phase(
                "axis-rigid",
                env(Some("axis"), "rigid"),
                80,
                mean_of_five(0.25),
            ),
            phase(
                "pair-rigid",
                env(Some("pair"), "rigid"),
                120,
                mean_of_five(0.85),
            ),
            onto_the_cube(phase(
                "pair-cube-square",
                on_cube(Some("pair")),
                60,
                mean_of_five(0.95),
            )),
        ],
        ("dexcube", EnvKind::Layer) => vec![
            phase("Up-block", env(None, "block"), 60, mean_of_five(0.8)),
            phase(
                "Up-block-quarter",
                PhaseEnv {
                    quarter_goals: true,
                    ..env(None, "block")
                },
                40,
                mean_of_five(0.85),
            ),
            onto_the_cube(phase(
                "Up-cube-square",
                PhaseEnv {
                    quarter_goals: true,
                    ..on_cube(None)
                },
                80,
                mean_of_five(0.95),
            )),
        ],
        _ => return None,
    };
    let config = DdpgHerConfig::default();
    Some(Recipe {
        name: name.to_string(),
        config: if name == "paper" {
            config
        } else {
            config.with_td3()
        },
        envs: 8,
        phases,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every phase of every shipped recipe builds its environments and steps them, and each
    /// recipe passes its own checks.
    #[test]
    fn the_shipped_recipes_build_every_phase() {
        for skill in [EnvKind::Rot, EnvKind::Layer] {
            for name in SHIPPED {
                let recipe = shipped(name, skill).expect("shipped");
                recipe.check().unwrap();
                for phase in &recipe.phases {
                    let envs = phase.env.envs(skill).unwrap();
                    let mut env = (envs.make)();
                    env.reset(Some(0));
                    let action = vec![0.0; env.spaces().action];
                    assert!(!env.step(&action).info.dropped, "{}", phase.name);
                }
            }
        }
    }
}
