//! One atomic action run on its own, outside the operator, as `eval-stage` and `distil` run
//! it: the object and control rate a stage policy was trained at, the environment it acts in
//! (with the goal and view its card names), and the paper's test of an episode's end.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::bail;
use dexcube_env::layer::LayerGoals;
use dexcube_env::{
    ControlRate, CubeRotEnv, EpisodeSettings, Info, LayerGoal, LayerMove, LayerOpEnv, ObjectKind,
    RotGoal, RotMode, SimulatedEnv, StartMix,
};
use dexcube_operator::eval::PolicyFiles;
use dexcube_operator::stages::{PolicyStage1, PolicyStage2, trained_control_rate};
use dexcube_rl::Policy;
use dexcube_rl::policy::policy_file;
use dexcube_sim::Scene;

use crate::env::{EnvKind, original_object, suited};

/// Where a stage policy's episodes run, and how their ends are judged.
pub struct StageSetup {
    pub stage: EnvKind,
    /// The policy's files (prefix of NAME.safetensors and NAME.json).
    pub prefix: PathBuf,
    rot_mode: RotMode,
    /// The object the episodes run on, and the one the policy was trained on.
    pub object: ObjectKind,
    pub trained_object: ObjectKind,
    pub scene: Arc<Scene>,
    /// How the episodes run: at the rate the policy acts at, the paper's otherwise unless a
    /// caller sets a physics spread (`eval-stage --physics-spread`) or an episode length
    /// (`eval-stage --episode-steps`).
    pub settings: EpisodeSettings,
    /// The rate the policy was trained at.
    pub trained_rate: ControlRate,
    /// The paper's success test: position (Stage 1) and angle thresholds.
    pub thresholds: (f64, f64),
}

impl StageSetup {
    /// The set-up for `stage`'s policy among `files`, on `object` and at `control_rate` where
    /// given, else on the object and at the rate it was trained at.
    pub fn new(
        stage: EnvKind,
        files: &PolicyFiles,
        object: Option<ObjectKind>,
        control_rate: Option<ControlRate>,
    ) -> anyhow::Result<StageSetup> {
        let prefix = match stage {
            EnvKind::Rot => files.rot.clone(),
            EnvKind::Layer => files.layer.clone(),
        };
        let rot_goal = RotGoal::paper(files.rot_mode);
        let thresholds = match stage {
            EnvKind::Rot => (rot_goal.position_threshold, rot_goal.angle_threshold),
            EnvKind::Layer => (f64::INFINITY, LayerGoal::default().angle_threshold),
        };
        let policy = Policy::load(&prefix, &burn::prelude::Device::flex())?;
        let trained_object = trained_on(&policy, &prefix, stage)?;
        let trained_rate = trained_control_rate(&policy, &prefix)?;
        let object = match object {
            Some(object) => suited(stage, object)?,
            None => trained_object,
        };
        Ok(StageSetup {
            stage,
            rot_mode: files.rot_mode,
            object,
            trained_object,
            scene: Scene::load(object.scene())?,
            settings: EpisodeSettings {
                rate: control_rate.unwrap_or(trained_rate),
                ..EpisodeSettings::PAPER
            },
            trained_rate,
            thresholds,
            prefix,
        })
    }

    /// The environment `policy` (loaded from `self.prefix`) acts in: its stage's, with the
    /// goal and view its card names, beginning from `starts` where given.
    pub fn env(
        &self,
        policy: &Policy,
        starts: Option<StartMix>,
    ) -> anyhow::Result<Box<dyn SimulatedEnv>> {
        let prefix = &self.prefix;
        let view = match self.stage {
            EnvKind::Rot => PolicyStage1::trained_view(policy, prefix)?,
            EnvKind::Layer => PolicyStage2::trained_view(policy, prefix)?,
        };
        if let Some(seen) = view.name()
            && self.object != ObjectKind::Cube
        {
            bail!(
                "{} was trained seeing the {seen}, a view of the physical cube: run it with \
                 --object cube",
                prefix.display()
            );
        }
        Ok(match self.stage {
            EnvKind::Rot => {
                let goal = PolicyStage1::trained_goal(policy, self.rot_mode, prefix)?;
                let env = CubeRotEnv::with_scene(self.scene.clone(), goal)
                    .with_view(view)
                    .with_settings(self.settings);
                Box::new(env.with_starts(starts))
            }
            EnvKind::Layer => {
                let env = LayerOpEnv::with_scene(
                    self.scene.clone(),
                    LayerMove::UPrime,
                    LayerGoals::Evaluation,
                )
                .with_goal(PolicyStage2::trained_goal(policy, prefix)?)
                .with_view(view)
                .with_settings(self.settings);
                Box::new(env.with_starts(starts))
            }
        })
    }
}

/// Whether a step met the paper's test, position and angle within `thresholds`, with the
/// object on the palm. A policy trained on a stricter test (Stage 2 left square) is still
/// judged by the paper's here; the good state is counted beside it.
pub fn meets_paper_test(info: &Info, (position, angle): (f64, f64)) -> bool {
    !info.dropped
        && info.physics_error.is_none()
        && info.position_error < position
        && info.angle_error < angle
}

/// The object a policy (loaded from `prefix`) was trained on, from its card (cards from before
/// the object was an option were trained on the rigid cube for Stage 1 and on the block for
/// Stage 2).
fn trained_on(policy: &Policy, prefix: &Path, env: EnvKind) -> anyhow::Result<ObjectKind> {
    let object = match policy.card.metadata["environment"]["object"].as_str() {
        Some(name) => name.parse().map_err(|e: String| {
            anyhow::anyhow!("{}: {e}", policy_file(prefix, "json").display())
        })?,
        None => original_object(env),
    };
    suited(env, object)
}
