//! The recipes `dexcube train` runs: what each phase trains on ([`PhaseEnv`]), the shipped
//! recipes of each skill ([`shipped`]: `dexcube`, ours, and `paper`, the paper's DDPG + HER),
//! and the environments a phase's settings build.
//!
//! A recipe is data: `dexcube train rot --print-recipe` prints one as JSON, and `--recipe
//! FILE` runs a file of that form.

use std::path::Path;

use anyhow::{Context, bail};
use dexcube_env::{EnvSettings, GoalEnv};
use dexcube_rl::DdpgHerConfig;
use dexcube_rl::recipe::{Phase, PhaseEnvs, Recipe};
use dexcube_rl::train::Until;
use dexcube_sim::Scene;
use serde::{Deserialize, Serialize};

use crate::env::{EnvKind, starts_for};

/// What one phase trains on: an environment's settings (`dexcube_env::EnvSettings`), under
/// the names of `dexcube env`'s flags.
pub type PhaseEnv = EnvSettings;

/// The environments of a phase of `skill` with `settings`, with their label and the facts a
/// policy card records of them; recorded starts are read from their file.
pub fn phase_envs(
    settings: &EnvSettings,
    skill: EnvKind,
) -> anyhow::Result<PhaseEnvs<Box<dyn GoalEnv>>> {
    let spec = settings
        .resolve(skill.skill())
        .map_err(anyhow::Error::msg)?;
    let starts = match &spec.starts {
        Some(setting) => {
            let scene = Scene::load(spec.object.scene())?;
            Some(starts_for(&setting.path, &scene, skill)?.0)
        }
        None => None,
    };
    let make = spec.maker(starts).map_err(anyhow::Error::msg)?;
    Ok(PhaseEnvs {
        make: Box::new(move || make() as Box<dyn GoalEnv>),
        label: spec.name(),
        metadata: spec.card_facts(),
    })
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
                    let envs = phase_envs(&phase.env, skill).unwrap();
                    let mut env = (envs.make)();
                    env.reset(Some(0));
                    let action = vec![0.0; env.spaces().action];
                    assert!(!env.step(&action).info.dropped, "{}", phase.name);
                }
            }
        }
    }
}
