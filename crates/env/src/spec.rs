//! An environment as settings: the one description that `dexcube env`'s flags, a recipe's
//! phases and Python's keyword arguments all come to. [`EnvSettings`] is the settings as
//! written (names and numbers, every one optional); [`EnvSettings::resolve`] checks them once
//! for a [`Skill`] and gives an [`EnvSpec`], which names its environment, says what a policy
//! card records of it, and builds it.

use std::path::PathBuf;
use std::sync::Arc;

use dexcube_sim::Scene;
use serde::{Deserialize, Serialize};

use crate::goal::{LayerGoal, RotGoal, RotMode};
use crate::hand_object::{EpisodeSettings, ObjectKind, View};
use crate::layer::{LayerGoals, LayerMove, LayerOpEnv};
use crate::rot::CubeRotEnv;
use crate::starts::{RecordedStart, StartMix, StartPick};
use crate::{ControlRate, SimError, SimulatedEnv};

/// The paper's angle threshold for both atomic actions, radians.
pub const PAPER_ANGLE_THRESHOLD: f64 = 0.1;

/// The two atomic actions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Skill {
    /// Stage 1, CubeRotEnv: bring the face to turn on top.
    Rot,
    /// Stage 2, LayerOpEnv: turn the top layer.
    Layer,
}

impl Skill {
    /// The name on the command line, and of run folders.
    pub fn name(self) -> &'static str {
        match self {
            Skill::Rot => "rot",
            Skill::Layer => "layer",
        }
    }

    /// The object each environment held before the object was a setting: runs and cards on
    /// it keep their old names.
    pub fn original_object(self) -> ObjectKind {
        match self {
            Skill::Rot => ObjectKind::Rigid,
            Skill::Layer => ObjectKind::Block,
        }
    }

    /// The object an environment holds when none is named.
    pub fn default_object(self) -> ObjectKind {
        match self {
            Skill::Rot => ObjectKind::Rigid,
            Skill::Layer => ObjectKind::Cube,
        }
    }
}

/// An environment's settings as written, each under the name of the `dexcube env` flag that
/// sets it (`see_misalignment` for `--see-misalignment`), with the same defaults.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EnvSettings {
    /// CubeRotEnv's success test: paper (whole orientation), axis (the target face up, any
    /// yaw) or pair (the target face or its opposite up, any yaw).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode: Option<String>,
    /// LayerOpEnv's move: U U' R R' F F' (U' by default).
    #[serde(rename = "move", skip_serializing_if = "Option::is_none")]
    pub layer_move: Option<String>,
    /// cube, block or rigid (CubeRotEnv's rigid cube and LayerOpEnv's physical cube by default).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub object: Option<String>,
    /// On the physical cube: success also needs every cubelet within 0.1 rad of a quarter
    /// turn; the goal gains the cube's misalignment.
    pub square: bool,
    /// CubeRotEnv on the physical cube: success also needs no layer turned (implies square).
    pub intact: bool,
    /// With intact: a turned layer ends the episode as a lasting failure, as a drop does.
    pub turn_ends: bool,
    /// On the physical cube: the observation gains the cube's misalignment.
    pub see_misalignment: bool,
    /// On the physical cube: the observation gains the hand's grip on the cube (six forces).
    pub see_grip: bool,
    /// LayerOpEnv: train on the evaluation goal, exactly a quarter turn, not goals up to it.
    pub quarter_goals: bool,
    /// The policy acts every this many 2 ms substeps (the paper's 20; a number that divides it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub control_substeps: Option<usize>,
    /// The success test's angle threshold in radians (the paper's 0.1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub angle_threshold: Option<f64>,
    /// Domain randomisation: friction, the object's mass and joint damping each scaled per
    /// episode by a factor log-uniform in [1/(1+S), 1+S] (0: the scene's own).
    pub physics_spread: f64,
    /// Recorded starts (`dexcube eval --record-starts`) to begin a share of episodes from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub starts: Option<PathBuf>,
    /// With starts: the probability that an episode begins from one (0.5).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_share: Option<f64>,
    /// With starts: how many times as often a start the recorded policy failed from is drawn (1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failed_weight: Option<f64>,
}

/// Recorded starts an environment begins a share of its episodes from.
#[derive(Clone, Debug, PartialEq)]
pub struct StartsSetting {
    pub path: PathBuf,
    pub share: f64,
    pub failed_weight: f64,
}

/// An environment's settings, checked: what [`EnvSettings::resolve`] gives.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvSpec {
    pub skill: Skill,
    pub mode: RotMode,
    pub layer_move: LayerMove,
    pub object: ObjectKind,
    /// Success also needs the cube left square (`square`, or implied by `intact`).
    pub square: bool,
    pub intact: bool,
    pub turn_ends: bool,
    pub view: View,
    pub quarter_goals: bool,
    pub rate: ControlRate,
    pub angle_threshold: f64,
    pub physics_spread: f64,
    pub starts: Option<StartsSetting>,
}

/// Makes environments of one spec, as many as a vectorised run steps. Each is a
/// [`SimulatedEnv`], so that it can be rendered too, and a goal environment as it stands.
pub type EnvMaker = Arc<dyn Fn() -> Box<dyn SimulatedEnv> + Send + Sync>;

impl EnvSettings {
    /// The settings checked for `skill`; says what is wrong with the first that does not fit.
    pub fn resolve(&self, skill: Skill) -> Result<EnvSpec, String> {
        if skill == Skill::Rot && (self.layer_move.is_some() || self.quarter_goals) {
            return Err("move and quarter_goals are LayerOpEnv's (the layer skill)".into());
        }
        if skill == Skill::Layer && self.mode.is_some() {
            return Err("mode is CubeRotEnv's success test (the rot skill)".into());
        }
        let mode: RotMode = self.mode.as_deref().unwrap_or("paper").parse()?;
        let layer_move: LayerMove = self.layer_move.as_deref().unwrap_or("U'").parse()?;
        let object = match self.object.as_deref() {
            Some(name) => name.parse()?,
            None => skill.default_object(),
        };
        match (skill, object) {
            (Skill::Rot, ObjectKind::Block) => {
                return Err(
                    "CubeRotEnv holds the rigid or the physical cube: use object rigid or cube"
                        .into(),
                );
            }
            (Skill::Layer, ObjectKind::Rigid) => {
                return Err("LayerOpEnv needs a layer to turn: use object cube or block".into());
            }
            _ => {}
        }
        let cube = object == ObjectKind::Cube;
        if self.intact && skill != Skill::Rot {
            return Err(
                "intact is for CubeRotEnv (the rot skill), which re-poses the cube \
                        without turning a layer; LayerOpEnv's task is to turn one"
                    .into(),
            );
        }
        if self.turn_ends && !self.intact {
            return Err(
                "turn_ends needs intact: a turn ends only an episode that must keep \
                        the cube intact"
                    .into(),
            );
        }
        for (name, asked) in [
            ("square", self.square),
            ("intact", self.intact),
            ("see_misalignment", self.see_misalignment),
            ("see_grip", self.see_grip),
        ] {
            if asked && !cube {
                return Err(format!(
                    "{name} is for the physical cube, whose layers can be left out of line: \
                     use object cube"
                ));
            }
        }
        let rate = match self.control_substeps {
            Some(n) => ControlRate::every(n)?,
            None => ControlRate::PAPER,
        };
        let angle_threshold = self.angle_threshold.unwrap_or(PAPER_ANGLE_THRESHOLD);
        if !(angle_threshold > 0.0 && angle_threshold < std::f64::consts::PI) {
            return Err(format!(
                "angle_threshold must be an angle in radians above 0 and below π (the paper's \
                 is 0.1), not {angle_threshold}"
            ));
        }
        if !(self.physics_spread >= 0.0 && self.physics_spread.is_finite()) {
            return Err(format!(
                "physics_spread must be 0 or more (0.3 scales each by 1/1.3 to 1.3), not {}",
                self.physics_spread
            ));
        }
        let starts = match &self.starts {
            None if self.start_share.is_some() || self.failed_weight.is_some() => {
                return Err(
                    "start_share and failed_weight weigh recorded starts: name them in starts"
                        .into(),
                );
            }
            None => None,
            Some(path) => {
                let (share, failed_weight) = (
                    self.start_share.unwrap_or(0.5),
                    self.failed_weight.unwrap_or(1.0),
                );
                if !(0.0..=1.0).contains(&share) {
                    return Err(format!("start_share must be between 0 and 1, not {share}"));
                }
                if !(failed_weight.is_finite() && failed_weight > 0.0) {
                    return Err(format!(
                        "failed_weight must be a positive number, not {failed_weight}"
                    ));
                }
                if skill == Skill::Layer && layer_move != LayerMove::UPrime {
                    return Err("starts for layer are the operator's Stage 2 starts: train \
                                them with the move U'"
                        .into());
                }
                Some(StartsSetting {
                    path: path.clone(),
                    share,
                    failed_weight,
                })
            }
        };
        Ok(EnvSpec {
            skill,
            mode,
            layer_move,
            object,
            square: self.square || self.intact,
            intact: self.intact,
            turn_ends: self.turn_ends,
            view: View {
                misalignment: self.see_misalignment,
                grip: self.see_grip,
            },
            quarter_goals: self.quarter_goals,
            rate,
            angle_threshold,
            physics_spread: self.physics_spread,
            starts,
        })
    }
}

impl EnvSpec {
    /// CubeRotEnv's success test: the paper's in its mode, or the good state as well, with
    /// intact no layer turned too, and with turn_ends the episode ended at a turn.
    pub fn rot_goal(&self) -> RotGoal {
        let paper = RotGoal {
            angle_threshold: self.angle_threshold,
            ..RotGoal::paper(self.mode)
        };
        match (self.square, self.intact, self.turn_ends) {
            (_, true, true) => paper.ending_on_turn(),
            (_, true, false) => paper.left_intact(),
            (true, false, _) => paper.left_square(),
            (false, false, _) => paper,
        }
    }

    /// LayerOpEnv's success test: the paper's, or the good state as well.
    pub fn layer_goal(&self) -> LayerGoal {
        let goal = if self.square {
            LayerGoal::square()
        } else {
            LayerGoal::default()
        };
        LayerGoal {
            angle_threshold: self.angle_threshold,
            ..goal
        }
    }

    /// How the success test's name goes on after the stage's own part, `cube` naming the
    /// object or not: ", left square" (", cube left square"), then " and intact", and how a
    /// turn ends the episode.
    pub fn success_suffix(&self, cube: &str) -> String {
        let square = if self.square {
            format!(", {cube}left square")
        } else {
            String::new()
        };
        let intact = match (self.intact, self.turn_ends) {
            (true, true) => " and intact, a turn ending the episode",
            (true, false) => " and intact",
            (false, _) => "",
        };
        square + intact
    }

    /// The object, when it is not the environment's original one and so is named in the
    /// run's label and folder.
    pub fn named_object(&self) -> Option<ObjectKind> {
        (self.object != self.skill.original_object()).then_some(self.object)
    }

    /// The environment's label, as runs and cards name it: `CubeRotEnv (pair mode, cube, left
    /// square, misalignment seen)`. Runs on each environment's original object keep the label
    /// they had before the object was a setting.
    pub fn name(&self) -> String {
        let what = match self.skill {
            Skill::Rot => format!("CubeRotEnv ({} mode", self.mode.name()),
            Skill::Layer => format!("LayerOpEnv ({}", self.layer_move.name()),
        };
        let seen = self
            .view
            .name()
            .map(|name| format!(", {name} seen"))
            .unwrap_or_default()
            + &if self.rate == ControlRate::PAPER {
                String::new()
            } else {
                format!(", acting every {} substeps", self.rate)
            }
            + &if self.angle_threshold == PAPER_ANGLE_THRESHOLD {
                String::new()
            } else {
                format!(", trained to {} rad", self.angle_threshold)
            };
        let square = self.success_suffix("");
        match self.named_object() {
            None => format!("{what}{square}{seen})"),
            Some(object) => format!("{what}, {}{square}{seen})", object.name()),
        }
    }

    /// What a policy card records of the environment it was trained on (its `environment`).
    pub fn card_facts(&self) -> serde_json::Value {
        let starts = self.starts.as_ref();
        serde_json::json!({
            "env": self.skill.name(),
            "goals": if self.quarter_goals { "quarter turn" } else { "uniform" },
            "success": format!(
                "{}{}",
                match self.skill {
                    Skill::Rot => "pose",
                    Skill::Layer => "angle",
                },
                self.success_suffix("cube ")
            ),
            "observation": self
                .view
                .name()
                .map_or("paper".to_string(), |name| format!("with the {name}")),
            "object": self.object.name(),
            "mode": (self.skill == Skill::Rot).then(|| self.mode.name()),
            "starts": starts.map(|s| s.path.display().to_string()),
            "start_share": starts.map(|s| s.share),
            "failed_weight": starts.map(|s| s.failed_weight),
            "control_substeps": self.rate.substeps(),
            "physics_spread": self.physics_spread,
            "angle_threshold": self.angle_threshold,
        })
    }

    /// What makes this environment, with `starts` loaded from its starts file (the caller
    /// reads the file: the environments do not know its format). Fails if the scene does not
    /// load, or if starts are named and none are given.
    pub fn maker(&self, starts: Option<Arc<[RecordedStart]>>) -> Result<EnvMaker, String> {
        let scene = Scene::load(self.object.scene()).map_err(|e: SimError| e.to_string())?;
        let starts = match (&self.starts, starts) {
            (Some(setting), Some(starts)) => Some(StartMix {
                starts,
                pick: StartPick::Share {
                    share: setting.share,
                    failed_weight: setting.failed_weight,
                },
            }),
            (Some(setting), None) => {
                return Err(format!(
                    "the starts {} were named and not loaded",
                    setting.path.display()
                ));
            }
            (None, _) => None,
        };
        let settings = EpisodeSettings {
            rate: self.rate,
            physics_spread: self.physics_spread,
            ..EpisodeSettings::PAPER
        };
        let view = self.view;
        Ok(match self.skill {
            Skill::Rot => {
                let goal = self.rot_goal();
                Arc::new(move || {
                    Box::new(
                        CubeRotEnv::with_scene(scene.clone(), goal)
                            .with_view(view)
                            .with_starts(starts.clone())
                            .with_settings(settings),
                    ) as Box<dyn SimulatedEnv>
                })
            }
            Skill::Layer => {
                let (layer_move, goal) = (self.layer_move, self.layer_goal());
                let goals = if self.quarter_goals {
                    LayerGoals::Evaluation
                } else {
                    LayerGoals::Training
                };
                Arc::new(move || {
                    Box::new(
                        LayerOpEnv::with_scene(scene.clone(), layer_move, goals)
                            .with_goal(goal)
                            .with_view(view)
                            .with_starts(starts.clone())
                            .with_settings(settings),
                    ) as Box<dyn SimulatedEnv>
                })
            }
        })
    }
}
