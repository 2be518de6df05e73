//! A trained policy as shipped: the actor's weights (`NAME.safetensors`) and a JSON beside it
//! (`NAME.json`) with the sizes, the normalisers, the training configuration and whatever
//! metrics the trainer recorded. It acts without the critic or any optimiser state.
//!
//! A policy may also be an ensemble ([`Policy::ensemble`]): the first member's actor and card,
//! with the other members' actors beside it in the same files (their tensors named
//! `partner{i}.…`, their sizes and normalisers in the card's `partners`). It acts with the
//! mean of its members' deterministic actions.
//!
//! A policy may be shown its goal led on ([`Policy::led`], [`GoalLead`]), and an ensemble may
//! hand a stalled episode to one member ([`Policy::handing_over`], [`Handover`]); a Stage 1
//! policy may be shown the cube in the frame nearest its goal ([`Policy::in_nearest_frame`]).
//! Its card says how, and whoever runs it acts through [`Policy::episode`], which applies them.

use std::borrow::Cow;
use std::cell::LazyCell;
use std::path::{Path, PathBuf};

use burn::prelude::*;
use dexcube_env::{Goal, GoalLead, RotGoal, RotMode, in_object_frame};
use serde::{Deserialize, Serialize};

use crate::agent::{Agent, Dims, network_inputs};
use crate::checkpoint::{self, CheckpointError};
use crate::config::DdpgHerConfig;
use crate::guide::{self, CriticGuide, GuideCard};
use crate::handover::{Handover, HandoverWatch, Turn};
use crate::networks::Mlp;
use crate::normalizer::Normalizer;
use crate::params::{self, NamedTensor};
use crate::residual::{ResidualSetting, check_scale, residual_action};
use crate::start_gesture::StartGesture;
use crate::start_route::StartRoute;

/// Everything about a policy but its weights.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PolicyCard {
    pub dims: Dims,
    pub config: DdpgHerConfig,
    pub observation_norm: Normalizer,
    pub goal_norm: Normalizer,
    /// Free-form facts: environment, seed, steps, wall time, evaluation.
    pub metadata: serde_json::Value,
    /// The other members of an ensemble; empty for a single policy.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub partners: Vec<PartnerCard>,
    /// A run's critics choosing among actions near the policy's own; none for the paper's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub guide: Option<GuideCard>,
    /// The goal the policy is shown, led on past the one it is judged by; none for the
    /// paper's, which is shown its goal as it is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goal_lead: Option<GoalLead>,
    /// Whether the policy is shown the cube in the frame nearest its goal among those its
    /// test reads alike ([`Goal::nearest_frame`]); not for the paper's, which is shown the
    /// frame the cube is read in.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub nearest_frame: bool,
    /// The member an ensemble hands a stalled episode to, and when; none for the paper's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub handover: Option<Handover>,
    /// A gesture the hand makes before the policy first acts, where the cube starts towards
    /// the fingertips; none for the paper's, which acts from the first step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_gesture: Option<StartGesture>,
    /// Members that act alone in the episodes picked by where the cube starts (towards the
    /// thumb without a gesture, near square with one), the first that takes an episode
    /// winning; none for the paper's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub start_routes: Vec<StartRoute>,
    /// A correction trained on top of the policy as the rest of the card makes it act
    /// ([`crate::residual`]); none for the paper's. Its weights are the tensors named
    /// `residual.…`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub residual: Option<ResidualCard>,
}

/// A residual on a policy's card: its actor's sizes and normalisers (it observes the
/// policy's observation followed by the base's action), and how it joins the base.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ResidualCard {
    pub actor: PartnerCard,
    pub scale: f64,
}

/// One more member of an ensemble: the sizes of its actor and the normalisers it was trained
/// with. It reads the first `dims.observation` numbers of the ensemble's observation, so a
/// member trained on the paper's observations can join one whose view appends more.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PartnerCard {
    pub dims: Dims,
    pub hidden: Vec<usize>,
    pub observation_norm: Normalizer,
    pub goal_norm: Normalizer,
    /// The policy it was taken from, as given when the ensemble was made.
    pub source: PathBuf,
}

pub struct Policy {
    pub card: PolicyCard,
    pub(crate) actor: Mlp,
    /// The partners' actors, in the order of `card.partners`.
    partners: Vec<Mlp>,
    /// A run's critics choosing among actions near the actor's, when guided.
    guide: Option<CriticGuide>,
    /// The residual's actor, when the card has one.
    residual: Option<Mlp>,
    pub(crate) device: Device,
}

/// The tensor-name prefix of a residual's actor.
const RESIDUAL_PREFIX: &str = "residual.";

/// The tensor-name prefix of an ensemble's `i`-th partner.
fn partner_prefix(i: usize) -> String {
    format!("partner{i}.")
}

/// A policy's card and weights as stored, read for combining with others.
fn read_stored(prefix: &Path) -> Result<(PathBuf, PolicyCard, Vec<NamedTensor>), CheckpointError> {
    let weights = policy_file(prefix, "safetensors");
    let card = PolicyCard::read(prefix)?;
    let tensors = checkpoint::load_tensors(&weights)?;
    Ok((weights, card, tensors))
}

/// Writes a policy's weights and card at `prefix` (`prefix.safetensors` and `prefix.json`).
fn store(prefix: &Path, tensors: &[NamedTensor], card: &PolicyCard) -> Result<(), CheckpointError> {
    checkpoint::save_tensors(&policy_file(prefix, "safetensors"), tensors)?;
    checkpoint::save_json(&policy_file(prefix, "json"), card)
}

/// The metadata of a policy made from the one at `source` (its card `card`) by `command`: its
/// label with `how` after it, its environment, and the source under `key` ("guided", "led").
fn derived_metadata(
    card: &PolicyCard,
    how: String,
    (key, source): (&str, &Path),
    command: &str,
) -> serde_json::Value {
    let label = card.metadata["label"].as_str().unwrap_or("a policy");
    serde_json::json!({
        "label": format!("{label}, {how}"),
        "environment": card.metadata["environment"],
        key: source,
        "command": command,
    })
}

/// Writes at `out` the policy at `policy` with its card changed by `change` (which refuses
/// with a message saying why) and its weights as they were; the new card's metadata names the
/// source under `key` and says `how` it was made, by `command`.
fn restated(
    policy: &Path,
    (out, command): (&Path, &str),
    (key, how): (&str, String),
    change: impl FnOnce(&mut PolicyCard) -> Result<(), String>,
) -> Result<(), CheckpointError> {
    let (weights, mut card, tensors) = read_stored(policy)?;
    refuse_residual(&weights, &card, "changed")?;
    change(&mut card).map_err(|message| CheckpointError::Refused {
        path: weights,
        message,
    })?;
    card.metadata = derived_metadata(&card, how, (key, policy), command);
    store(out, &tensors, &card)
}

/// The same for a single policy, refusing an ensemble with a message saying it cannot be
/// `used` ("averaged", "joined", "trained from"): whatever combines or trains from policies
/// takes each member's one actor.
pub(crate) fn read_single(
    prefix: &Path,
    used: &str,
) -> Result<(PathBuf, PolicyCard, Vec<NamedTensor>), CheckpointError> {
    let (weights, card, tensors) = read_stored(prefix)?;
    refuse_residual(&weights, &card, used)?;
    if let Some(lead) = &card.goal_lead {
        return Err(mismatch(
            &weights,
            format!(
                "it is shown its goal led on (by {} within {} rad) and cannot be {used}: use the \
                 policy it was made from (its card's metadata.led names it)",
                lead.share, lead.within
            ),
        ));
    }
    if card.nearest_frame {
        return Err(mismatch(
            &weights,
            format!(
                "it is shown the cube in the frame nearest its goal and cannot be {used}: use \
                 the policy it was made from (its card's metadata.nearest_frame names it)"
            ),
        ));
    }
    if let Some(gesture) = &card.start_gesture {
        return Err(mismatch(
            &weights,
            format!(
                "it makes a start gesture ({gesture}) and cannot be {used}: use the policy it \
                 was made from (its card's metadata.start_gesture names it)"
            ),
        ));
    }
    if let Some(guide) = &card.guide {
        return Err(mismatch(
            &weights,
            format!(
                "it is guided by the critics of {} and cannot be {used}: use the policy it was \
                 made from (its card's metadata.guided names it)",
                guide.run.display()
            ),
        ));
    }
    if card.partners.is_empty() {
        return Ok((weights, card, tensors));
    }
    Err(mismatch(
        &weights,
        format!(
            "it is an ensemble already, an ensemble of {} policies, and cannot be {used}: use \
             one of its members (its card's metadata.ensemble names them)",
            card.members()
        ),
    ))
}

/// Refuses a policy with a residual, which was trained on top of the card as it is and so
/// cannot be `used` ("changed", "joined", "guided").
fn refuse_residual(weights: &Path, card: &PolicyCard, used: &str) -> Result<(), CheckpointError> {
    match &card.residual {
        Some(_) => Err(mismatch(
            weights,
            format!(
                "it acts with a residual trained on top of it as it is, and cannot be {used}: \
                 use its base (its card's metadata.residual_of names it), and train a residual \
                 on top of whatever is made from that"
            ),
        )),
        None => Ok(()),
    }
}

impl PolicyCard {
    /// The card of the policy at `prefix`, without its weights.
    pub fn read(prefix: &Path) -> Result<PolicyCard, CheckpointError> {
        checkpoint::load_json(&policy_file(prefix, "json"))
    }

    /// How many actors act together: 1, or an ensemble's members.
    pub fn members(&self) -> usize {
        1 + self.partners.len()
    }

    /// What on the card, besides the weights, decides how the policy acts: its guide's
    /// settings (how many candidates, how far, drawn from which seed), its goal lead, its
    /// handover, its start gesture and its start routes.
    /// None for a policy that acts on its weights alone.
    pub fn acting_settings(&self) -> Option<serde_json::Value> {
        let mut settings = serde_json::Map::new();
        if let Some(guide) = &self.guide {
            settings.insert(
                "guide".into(),
                serde_json::json!({
                    "candidates": guide.candidates,
                    "spread": guide.spread,
                    "seed": guide.seed,
                }),
            );
        }
        if let Some(lead) = &self.goal_lead {
            settings.insert("goal_lead".into(), serde_json::json!(lead));
        }
        if self.nearest_frame {
            settings.insert("nearest_frame".into(), serde_json::json!(true));
        }
        if let Some(handover) = &self.handover {
            settings.insert("handover".into(), serde_json::json!(handover));
        }
        if let Some(residual) = &self.residual {
            let source = &residual.actor.source;
            settings.insert(
                "residual".into(),
                serde_json::json!({"scale": residual.scale, "actor": source}),
            );
        }
        if let Some(gesture) = &self.start_gesture {
            settings.insert("start_gesture".into(), serde_json::json!(gesture));
        }
        if !self.start_routes.is_empty() {
            settings.insert("start_routes".into(), serde_json::json!(self.start_routes));
        }
        (!settings.is_empty()).then_some(serde_json::Value::Object(settings))
    }
}

/// Why an ensemble of `members` cannot name `member` (counted from 0), if it cannot.
fn has_member(members: usize, member: usize) -> Result<(), String> {
    if member >= members {
        return Err(format!(
            "it has {members} members (0 to {}), not a member {member}",
            members - 1,
        ));
    }
    Ok(())
}

/// The error for stored weights or cards at `path` that do not fit what they are used for.
fn mismatch(path: &Path, message: String) -> CheckpointError {
    CheckpointError::Mismatch {
        path: path.to_path_buf(),
        message,
    }
}

/// A policy's file with `extension` (`safetensors` or `json`) beside `prefix` (see
/// [`checkpoint::file_beside`]): `models/rot.json` names the same policy as `models/rot`.
pub fn policy_file(prefix: &Path, extension: &str) -> PathBuf {
    checkpoint::file_beside(prefix, extension, &["safetensors", "json"])
}

impl Policy {
    /// Saves an agent's actor as a policy at each of `prefixes` (the latest, the best, a
    /// snapshot: one read of the weights serves them all).
    pub fn save(
        agent: &Agent,
        prefixes: &[PathBuf],
        metadata: serde_json::Value,
    ) -> Result<(), CheckpointError> {
        let card = PolicyCard {
            dims: agent.dims,
            config: agent.config.clone(),
            observation_norm: agent.observation_norm.clone(),
            goal_norm: agent.goal_norm.clone(),
            metadata,
            partners: Vec::new(),
            guide: None,
            goal_lead: None,
            nearest_frame: false,
            handover: None,
            start_gesture: None,
            start_routes: Vec::new(),
            residual: None,
        };
        let actor = agent.actor_params();
        for prefix in prefixes {
            store(prefix, &actor, &card)?;
        }
        Ok(())
    }

    /// Writes at `out` the weight average of the policies at `members` (stochastic weight
    /// averaging over one run's snapshots): each actor weight is the mean of the members',
    /// and the normalisers pool the members' statistics. The members must share the network
    /// and the environment's sizes. The card keeps the first member's configuration, label and
    /// environment, and records the members and `command`, the command that averaged them.
    pub fn average(members: &[PathBuf], out: &Path, command: &str) -> Result<(), CheckpointError> {
        let mut loaded = Vec::with_capacity(members.len());
        for member in members {
            let (weights, card, mut tensors) = read_single(member, "averaged")?;
            tensors.sort_by(|a, b| a.name.cmp(&b.name));
            loaded.push((weights, card, tensors));
        }
        let Some(((_, first_card, first), rest)) = loaded.split_first() else {
            return Err(mismatch(out, "no policies to average".to_string()));
        };
        // The tensors' names and shapes are the network's sizes; the normalisers, pooled
        // below, check the environment's.
        fn layout(tensors: &[NamedTensor]) -> Vec<(&str, &[usize])> {
            tensors
                .iter()
                .map(|t| (t.name.as_str(), t.shape.as_slice()))
                .collect()
        }
        let first_layout = layout(first);
        let mut mean = first.clone();
        for (weights, _, tensors) in rest {
            if layout(tensors) != first_layout {
                return Err(mismatch(
                    weights,
                    format!("other network sizes than {}", members[0].display()),
                ));
            }
            for (total, tensor) in mean.iter_mut().zip(tensors) {
                for (t, v) in total.values.iter_mut().zip(&tensor.values) {
                    *t += v;
                }
            }
        }
        let scale = 1.0 / members.len() as f32;
        for tensor in &mut mean {
            tensor.values.iter_mut().for_each(|v| *v *= scale);
        }
        let pooled = |pick: fn(&PolicyCard) -> &Normalizer| {
            let members: Vec<&Normalizer> = loaded.iter().map(|(_, card, _)| pick(card)).collect();
            Normalizer::pooled(&members).ok_or_else(|| {
                mismatch(
                    out,
                    "the members' normalisers differ in size or settings".to_string(),
                )
            })
        };
        let head = &first_card.metadata;
        let card = PolicyCard {
            observation_norm: pooled(|c| &c.observation_norm)?,
            goal_norm: pooled(|c| &c.goal_norm)?,
            metadata: serde_json::json!({
                "label": head["label"],
                "environment": head["environment"],
                "averaged": members,
                "command": command,
            }),
            ..first_card.clone()
        };
        store(out, &mean, &card)
    }

    /// Writes at `out` an ensemble of the policies at `members`: one policy that acts with the
    /// mean of their deterministic actions, each member reading its own inputs through its own
    /// normalisers. The first member gives the card (its configuration, label and environment,
    /// so the ensemble is run as it would be) and must observe at least as much as each other
    /// member: the others read the leading part of its observation. Members must share the goal
    /// and the action sizes. The card records the members and `command`, the command that
    /// joined them.
    pub fn ensemble(members: &[PathBuf], out: &Path, command: &str) -> Result<(), CheckpointError> {
        let Some((first, rest)) = members.split_first() else {
            return Err(mismatch(out, "no policies to join".to_string()));
        };
        let (_, head, mut tensors) = read_single(first, "joined")?;
        let mut partners = Vec::with_capacity(rest.len());
        for member in rest {
            let (weights, card, member_tensors) = read_single(member, "joined")?;
            let dims = card.dims;
            if dims.goal != head.dims.goal
                || dims.action != head.dims.action
                || dims.observation > head.dims.observation
            {
                return Err(mismatch(
                    &weights,
                    format!(
                        "its sizes {dims:?} do not fit the first member's {:?}: members share \
                         the goal and the action, and the first observes the most",
                        head.dims
                    ),
                ));
            }
            tensors.extend(params::prefixed(
                member_tensors,
                &partner_prefix(partners.len()),
            ));
            partners.push(PartnerCard {
                dims,
                hidden: card.config.hidden,
                observation_norm: card.observation_norm,
                goal_norm: card.goal_norm,
                source: member.clone(),
            });
        }
        let card = PolicyCard {
            metadata: serde_json::json!({
                "label": format!(
                    "ensemble of {}, first {}",
                    members.len(),
                    head.metadata["label"].as_str().unwrap_or("an unlabelled policy")
                ),
                "environment": head.metadata["environment"],
                "ensemble": members,
                "command": command,
            }),
            partners,
            ..head
        };
        store(out, &tensors, &card)
    }

    /// Writes at `out` the policy at `policy` (a single one or an ensemble) guided by the
    /// critics of the training run in `run` ([`CriticGuide`]): `candidates` actions beside its
    /// own, each `spread` times a standard normal direction drawn from `seed`. The critics must
    /// take the observations, goals and actions the policy does. The card records the run and
    /// `command`, the command that guided it.
    pub fn guide(
        policy: &Path,
        run: &Path,
        (candidates, spread, seed): (usize, f64, u64),
        out: &Path,
        command: &str,
    ) -> Result<(), CheckpointError> {
        let (weights, card, mut tensors) = read_stored(policy)?;
        refuse_residual(&weights, &card, "guided")?;
        if card.guide.is_some() {
            return Err(mismatch(
                &weights,
                "it is guided already: guide the policy it was made from".to_string(),
            ));
        }
        let (guide, dims, critics) = guide::read_run(run, (candidates, spread, seed))?;
        if dims != card.dims {
            return Err(mismatch(
                run,
                format!(
                    "its critics take sizes {dims:?}, the policy {:?}: guide a policy with the \
                     critics of the run it came from, or of one trained on its observations",
                    card.dims
                ),
            ));
        }
        tensors.extend(critics);
        let how = format!("guided by the critics of {}", run.display());
        let card = PolicyCard {
            metadata: derived_metadata(&card, how, ("guided", policy), command),
            guide: Some(guide),
            ..card
        };
        store(out, &tensors, &card)
    }

    /// Writes at `out` the policy at `policy` (a single one, an ensemble or a guided one)
    /// shown its goal led on as `lead` says ([`GoalLead`]); its weights are unchanged. The card
    /// records the policy and `command`, the command that led it.
    pub fn led(
        policy: &Path,
        lead: GoalLead,
        out: &Path,
        command: &str,
    ) -> Result<(), CheckpointError> {
        let how = format!(
            "its goal led on by {} within {} rad",
            lead.share, lead.within
        );
        restated(policy, (out, command), ("led", how), |card| {
            if card.goal_lead.is_some() {
                return Err("its goal is led on already: lead the policy it was made from".into());
            }
            card.goal_lead = Some(lead);
            Ok(())
        })
    }

    /// Writes at `out` the policy at `policy` (any but one with a residual) shown the cube in
    /// the frame nearest its goal at every step ([`Goal::nearest_frame`]); its weights are
    /// unchanged. The card records the policy and `command`, the command that made it.
    pub fn in_nearest_frame(
        policy: &Path,
        out: &Path,
        command: &str,
    ) -> Result<(), CheckpointError> {
        let how = "shown the cube in the frame nearest its goal".to_string();
        restated(policy, (out, command), ("nearest_frame", how), |card| {
            if card.nearest_frame {
                let already = "it is shown the cube in the frame nearest its goal already";
                return Err(already.into());
            }
            if RotGoal::of_size(RotMode::Pair, card.dims.goal).is_none() {
                return Err(format!(
                    "its goals have {} numbers, not a pose (Stage 1's 7 or 8): only Stage 1's \
                     test reads the cube alike in more than one frame (Stage 2 already reads \
                     the layer that stays in the frame nearest upright)",
                    card.dims.goal
                ));
            }
            card.nearest_frame = true;
            Ok(())
        })
    }

    /// Writes at `out` the ensemble at `policy` (led on or not) handing a stalled episode to
    /// one member as `handover` says ([`Handover`]); its weights are unchanged. A single policy
    /// may hand the episode to itself if it lets go first. The card records the policy and
    /// `command`, the command that made it.
    pub fn handing_over(
        policy: &Path,
        handover: Handover,
        out: &Path,
        command: &str,
    ) -> Result<(), CheckpointError> {
        let how = handover.to_string();
        restated(policy, (out, command), ("handing_over", how), |card| {
            if card.handover.is_some() {
                return Err(
                    "it hands over already: start from the ensemble it was made from".into(),
                );
            }
            // Letting go, a policy may hand the episode to itself: it tries again.
            let letting_go = handover.let_go.is_some();
            let members = card.members();
            if members == 1 && !letting_go {
                return Err(
                    "it is a single policy, with no member to hand over to: make an ensemble \
                     first (`dexcube ensemble`), or let it go and try again itself (`--let-go`)"
                        .into(),
                );
            }
            let far = handover.far.map(|far| far.member);
            for member in [Some(handover.member), handover.first, far]
                .into_iter()
                .flatten()
            {
                has_member(members, member)?;
            }
            if far == Some(handover.member) {
                return Err(format!(
                    "member {} takes the far-off stalls and the others alike: name another \
                     member for the far-off ones, or leave them out",
                    handover.member
                ));
            }
            // The members a stall may be handed to; the one acting first is not among them.
            let handed_to = |member| member == handover.member || far == Some(member);
            if let Some(first) = handover
                .first
                .filter(|&first| handed_to(first) && !letting_go)
            {
                return Err(format!(
                    "member {first} would hand over to itself: name another member to act \
                     first, or let it go first (`--let-go`)"
                ));
            }
            card.handover = Some(handover);
            Ok(())
        })
    }

    /// Writes at `out` the policy at `policy` (any: single, ensemble, led, handing over)
    /// making `gesture` before it first acts where the cube starts towards the fingertips
    /// ([`StartGesture`]); its weights are unchanged. The card records the policy and
    /// `command`, the command that made it.
    pub fn with_start_gesture(
        policy: &Path,
        gesture: StartGesture,
        out: &Path,
        command: &str,
    ) -> Result<(), CheckpointError> {
        let how = gesture.to_string();
        restated(policy, (out, command), ("start_gesture", how), |card| {
            if card.start_gesture.is_some() {
                let already =
                    "it makes a start gesture already: start from the policy it was made from";
                return Err(already.into());
            }
            gesture.check(card.dims)?;
            let members = card.members();
            if let Some(member) = gesture.member.filter(|&m| m >= members) {
                return Err(format!(
                    "it has {members} member(s) (0 to {}), not a member {member} to act where \
                     the gesture is made",
                    members - 1
                ));
            }
            card.start_gesture = Some(gesture);
            Ok(())
        })
    }

    /// Writes at `out` the ensemble at `policy` (with any of the settings above) routing the
    /// episodes `route` picks by where the cube starts to one member ([`StartRoute`]), after
    /// any routes it has; its weights are unchanged. The card records the policy and
    /// `command`, the command that made it.
    pub fn with_start_route(
        policy: &Path,
        route: StartRoute,
        out: &Path,
        command: &str,
    ) -> Result<(), CheckpointError> {
        let how = route.to_string();
        restated(policy, (out, command), ("start_route", how), |card| {
            if card.start_routes.iter().any(|r| r.same_kind(&route)) {
                let already = "it routes such episodes already: start from the policy it was \
                               made from";
                return Err(already.into());
            }
            route.check(card.dims, card.members(), card.start_gesture.is_some())?;
            has_member(card.members(), route.member)?;
            card.start_routes.push(route);
            Ok(())
        })
    }

    /// Writes at `out` the policy at `base` (any: single, ensemble, led, handing over, with
    /// gestures and routes) with the residual actor at `actor` on top of it
    /// ([`crate::residual`]); the base's weights are unchanged. The actor must come from a run
    /// trained on top of a policy with the base's sizes (its card's `metadata.environment`
    /// says so, and at which scale), observing the base's observation followed by its action.
    /// The card records both and `command`, the command that made it.
    pub fn with_residual(
        base: &Path,
        actor: &Path,
        out: &Path,
        command: &str,
    ) -> Result<(), CheckpointError> {
        let (base_weights, card, mut tensors) = read_stored(base)?;
        refuse_residual(&base_weights, &card, "the base of another")?;
        let (weights, actor_card, actor_tensors) = read_single(actor, "a residual")?;
        let setting: ResidualSetting =
            serde_json::from_value(actor_card.metadata["environment"]["residual"].clone())
                .map_err(|_| {
                    mismatch(
                        &weights,
                        "it was not trained as a residual (its card's metadata.environment \
                         has no residual; a residual is trained in a ResidualEnv)"
                            .to_string(),
                    )
                })?;
        check_scale(setting.scale).map_err(|message| mismatch(&weights, message))?;
        let (dims, needed) = (actor_card.dims, card.dims);
        if (dims.observation, dims.goal, dims.action)
            != (
                needed.observation + needed.action,
                needed.goal,
                needed.action,
            )
        {
            return Err(mismatch(
                &weights,
                format!(
                    "its sizes {dims:?} do not fit a residual on {} ({needed:?}): it observes \
                     the base's observation followed by its action, toward the base's goal",
                    base.display()
                ),
            ));
        }
        tensors.extend(params::prefixed(actor_tensors, RESIDUAL_PREFIX));
        let how = format!(
            "with the residual {} at scale {}",
            actor.display(),
            setting.scale
        );
        let card = PolicyCard {
            metadata: derived_metadata(&card, how, ("residual_of", base), command),
            residual: Some(ResidualCard {
                actor: PartnerCard {
                    dims,
                    hidden: actor_card.config.hidden,
                    observation_norm: actor_card.observation_norm,
                    goal_norm: actor_card.goal_norm,
                    source: actor.to_path_buf(),
                },
                scale: setting.scale,
            }),
            ..card
        };
        store(out, &tensors, &card)
    }

    /// Loads the policy at `prefix` onto `device`.
    pub fn load(prefix: &Path, device: &Device) -> Result<Policy, CheckpointError> {
        let (weights, card, tensors) = read_stored(prefix)?;
        let build = |dims: Dims, hidden: &[usize], tensors: &[NamedTensor]| {
            let actor = Mlp::new(dims.observation + dims.goal, hidden, dims.action, device);
            params::write(actor, tensors, |_, given| given.to_vec())
                .map_err(|e| mismatch(&weights, e.to_string()))
        };
        let actor = build(card.dims, &card.config.hidden, &tensors)?;
        let partners = card
            .partners
            .iter()
            .enumerate()
            .map(|(i, partner)| {
                let own = params::under_prefix(&tensors, &partner_prefix(i));
                build(partner.dims, &partner.hidden, &own)
            })
            .collect::<Result<_, _>>()?;
        let guide = card
            .guide
            .as_ref()
            .map(|g| CriticGuide::build(g, card.dims, &tensors, &weights, device))
            .transpose()?;
        let residual = card
            .residual
            .as_ref()
            .map(|residual| {
                let own = params::under_prefix(&tensors, RESIDUAL_PREFIX);
                build(residual.actor.dims, &residual.actor.hidden, &own)
            })
            .transpose()?;
        Ok(Policy {
            card,
            actor,
            partners,
            guide,
            residual,
            device: device.clone(),
        })
    }

    /// The first member alone (an ensemble's first policy, or a single policy itself), as a
    /// single policy with the card it had, `metadata` in place of its card's.
    pub fn first_member(&self, metadata: serde_json::Value) -> Policy {
        let mut single = self.with_actor(self.actor.clone());
        single.card.metadata = metadata;
        single
    }

    /// The first member's card and normalisers with `actor`'s weights, as a single policy.
    pub(crate) fn with_actor(&self, actor: Mlp) -> Policy {
        Policy {
            card: PolicyCard {
                partners: Vec::new(),
                guide: None,
                goal_lead: None,
                nearest_frame: false,
                handover: None,
                start_gesture: None,
                start_routes: Vec::new(),
                residual: None,
                ..self.card.clone()
            },
            actor,
            partners: Vec::new(),
            guide: None,
            residual: None,
            device: self.device.clone(),
        }
    }

    /// Writes a single policy at `prefix` (`prefix.safetensors` and `prefix.json`).
    pub fn write(&self, prefix: &Path) -> Result<(), CheckpointError> {
        if !self.partners.is_empty() || self.guide.is_some() {
            return Err(mismatch(
                prefix,
                "an ensemble or a guided policy is written by `Policy::ensemble` or \
                 `Policy::guide`, from what it is made of"
                    .to_string(),
            ));
        }
        store(prefix, &params::read(&self.actor), &self.card)
    }

    /// How many actors act together: 1, or an ensemble's members.
    pub fn members(&self) -> usize {
        self.card.members()
    }

    /// The policy acting through one episode, as its card says: shown its goal led on, and
    /// handing over when stalled, where it says so.
    pub fn episode(&self) -> Acting<'_> {
        self.resume(EpisodeMemory {
            watch: self.card.handover.map(HandoverWatch::new),
            ..EpisodeMemory::default()
        })
    }

    /// The policy acting on through an episode whose memory `memory` was kept apart
    /// ([`Acting::into_memory`]), as an environment that holds the policy does.
    pub fn resume(&self, memory: EpisodeMemory) -> Acting<'_> {
        Acting {
            policy: self,
            memory,
        }
    }

    /// The deterministic action for one observation and the goal it is shown: an ensemble's is
    /// the mean of its members'.
    pub fn act(&self, observation: &[f64], goal: &[f64]) -> Vec<f64> {
        let mut total = self.member_action(0, observation, goal);
        for member in 1..self.members() {
            let action = self.member_action(member, observation, goal);
            total.iter_mut().zip(action).for_each(|(t, a)| *t += a);
        }
        let scale = 1.0 / self.members() as f64;
        total.iter_mut().for_each(|t| *t *= scale);
        match &self.guide {
            Some(guide) => guide.choose(observation, goal, total),
            None => total,
        }
    }

    /// Member `member`'s action alone (0 is the first), from the leading part of the
    /// observation that its normaliser takes.
    fn member_action(&self, member: usize, observation: &[f64], goal: &[f64]) -> Vec<f64> {
        let card = &self.card;
        let (actor, observation_norm, goal_norm) = match member {
            0 => (&self.actor, &card.observation_norm, &card.goal_norm),
            k => {
                let partner = &card.partners[k - 1];
                let norms = (&partner.observation_norm, &partner.goal_norm);
                (&self.partners[k - 1], norms.0, norms.1)
            }
        };
        self.actor_action(actor, (observation_norm, goal_norm), observation, goal)
    }

    /// `actor`'s deterministic action for one observation and goal, read through `norms`
    /// (observation, goal).
    fn actor_action(
        &self,
        actor: &Mlp,
        (observation_norm, goal_norm): (&Normalizer, &Normalizer),
        observation: &[f64],
        goal: &[f64],
    ) -> Vec<f64> {
        let x = network_inputs(
            observation_norm,
            goal_norm,
            observation,
            goal,
            1,
            &self.device,
        );
        let out = actor.forward(x).tanh().into_data().convert::<f64>();
        out.try_to_vec::<f64>().unwrap_or_default()
    }

    /// `base`, the card's action without its residual, with the residual's correction added
    /// where the card has one: the residual observes `observation` followed by `base`, toward
    /// `desired` (the goal itself, as in training, not one led on).
    fn with_residual_action(
        &self,
        observation: &[f64],
        desired: &[f64],
        base: Vec<f64>,
    ) -> Vec<f64> {
        let (Some(actor), Some(card)) = (&self.residual, &self.card.residual) else {
            return base;
        };
        let seen: Vec<f64> = observation.iter().chain(&base).copied().collect();
        let norms = (&card.actor.observation_norm, &card.actor.goal_norm);
        let correction = self.actor_action(actor, norms, &seen, desired);
        residual_action(&base, &correction, card.scale)
    }
}

/// A policy acting through one episode ([`Policy::episode`]).
pub struct Acting<'a> {
    policy: &'a Policy,
    memory: EpisodeMemory,
}

/// What a policy keeps of one episode: what its handover watches, the steps acted, and what
/// the first step decided.
#[derive(Default)]
pub struct EpisodeMemory {
    watch: Option<HandoverWatch>,
    /// Control steps acted so far.
    steps: usize,
    /// The start gesture's action, where this episode makes it (decided at the first step; it
    /// lasts the card's `start_gesture.steps`).
    gesture: Option<Vec<f64>>,
    /// Which of the card's start routes took this episode, if any (decided at the first step,
    /// before any gesture).
    route: Option<usize>,
}

impl Acting<'_> {
    /// The episode's memory, to act on later through [`Policy::resume`].
    pub fn into_memory(self) -> EpisodeMemory {
        self.memory
    }

    /// The deterministic action toward `desired` for one observation, judged by `test`: the
    /// start gesture's for its first steps where the card has one and the cube started towards
    /// the fingertips; then, where the card says so, with the observation and the object's goal
    /// now read in the object's frame nearest `desired` ([`Goal::nearest_frame`]), shown the
    /// goal led on from the object's goal now, and by the member handed over to once the
    /// episode has stalled, or throughout by the member of the start route that took the
    /// episode, or else of the gesture, where either names one; `achieved` reads the object's
    /// goal only for these.
    /// A residual on the card, if any, adds its correction to that action
    /// ([`crate::residual`]).
    pub fn act_toward(
        &mut self,
        observation: &[f64],
        desired: &[f64],
        achieved: impl FnOnce() -> Vec<f64>,
        test: &dyn Goal,
    ) -> Vec<f64> {
        let base = self.base_toward(observation, desired, achieved, test);
        self.policy.with_residual_action(observation, desired, base)
    }

    /// The action as the card says without its residual: what a residual was trained on top of.
    fn base_toward(
        &mut self,
        observation: &[f64],
        desired: &[f64],
        achieved: impl FnOnce() -> Vec<f64>,
        test: &dyn Goal,
    ) -> Vec<f64> {
        let policy = self.policy;
        let card = &policy.card;
        if self.memory.steps == 0 {
            // The first step: where the cube starts decides the gesture and the route.
            let gesture = card.start_gesture.as_ref();
            self.memory.gesture = gesture
                .filter(|gesture| gesture.applies(observation))
                .map(|gesture| gesture.action(card.dims.action));
            let gestured = self.memory.gesture.is_some();
            self.memory.route =
                (card.start_routes.iter()).position(|route| route.applies(observation, gestured));
        }
        self.memory.steps += 1;
        if let (Some(action), Some(gesture)) = (&self.memory.gesture, &card.start_gesture)
            && self.memory.steps <= gesture.steps
        {
            return action.clone();
        }
        // Shown the cube in the frame nearest its goal, every member reads the observation and
        // the cube's goal now in that frame; the test reads them alike in either.
        let read = LazyCell::new(achieved);
        let frame = (card.nearest_frame)
            .then(|| test.nearest_frame(&read, desired))
            .flatten();
        let observation = match &frame {
            Some((g, _)) => Cow::Owned(in_object_frame(observation, g)),
            None => Cow::Borrowed(observation),
        };
        // A specialist member acts alone, before and after any handover, in the episodes a
        // start route took or that made the gesture; otherwise the member the turn names, or
        // all of them.
        let routed = self.memory.route.map(|k| card.start_routes[k].member);
        let gesture_member = card
            .start_gesture
            .as_ref()
            .and_then(|gesture| gesture.member);
        let specialist = routed.or(self.memory.gesture.as_ref().and(gesture_member));
        let act = |member: Option<usize>, goal: &[f64]| match specialist.or(member) {
            Some(member) => policy.member_action(member, &observation, goal),
            None => policy.act(&observation, goal),
        };
        let lead = policy.card.goal_lead;
        if lead.is_none() && self.memory.watch.is_none() {
            return act(None, desired);
        }
        let now = match &frame {
            Some((_, reached)) => reached.as_slice(),
            None => read.as_slice(),
        };
        let shown = match lead {
            Some(lead) => test.led(now, desired, lead),
            None => desired.to_vec(),
        };
        let turn = self.memory.watch.as_mut().map_or(Turn::Before, |watch| {
            watch.turn(|| (test.errors(now, desired).1, test.is_success(now, desired)))
        });
        match (turn, policy.card.handover) {
            (Turn::LettingGo, _) => vec![0.0; policy.card.dims.action],
            (Turn::Member(member), _) => act(Some(member), &shown),
            (Turn::Before, Some(handover)) => act(handover.first, &shown),
            _ => act(None, &shown),
        }
    }

    /// Which of the card's start routes took the episode to its member, if any.
    pub fn route(&self) -> Option<usize> {
        self.memory.route
    }

    /// Whether the episode began with the start gesture.
    pub fn gestured(&self) -> bool {
        self.memory.gesture.is_some()
    }

    /// Whether the action last given was the start gesture's last: the policy itself acts
    /// next, from the state that action leads to.
    pub fn gesture_just_made(&self) -> bool {
        self.gestured()
            && self.policy.card.start_gesture.as_ref().map(|g| g.steps) == Some(self.memory.steps)
    }

    /// Whether the episode has been handed to a member.
    pub fn handed_over(&self) -> bool {
        self.handed_to().is_some()
    }

    /// The member the episode has been handed to, if it has been.
    pub fn handed_to(&self) -> Option<usize> {
        self.memory
            .watch
            .as_ref()
            .and_then(HandoverWatch::handed_to)
    }
}
