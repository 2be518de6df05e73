//! A gesture the hand makes before a policy first acts, where the cube starts towards the
//! fingertips ([`StartGesture`]).
//!
//! Session 53 in `results/TRAINING.md` found that Stage 2 fails from about a fifth of the
//! placements on the fingertips' side of the palm's resting point and from one in fifty
//! elsewhere, mostly by the placement rather than by chance (session 37), and that the four
//! fingers' knuckles held straight for the first few steps, before the policy acts, mend most
//! of those failures. The gesture is decided by the policy's own view at the first step: the
//! cube's position is part of every observation. An ensemble's card may name a member to act
//! alone in the episodes that make the gesture: a specialist for that side (session 55).

use serde::{Deserialize, Serialize};

use crate::agent::Dims;

/// Where the cube's position along the hand (y; the fingertips lie towards -y, the wrist
/// towards +y) sits in the observations both stages share.
pub const CUBE_Y: usize = dexcube_env::OBJECT_POSITION + 1;

/// For the first `steps` control steps of an episode whose cube starts with its y below
/// `below_y` (the palm's resting point, in world metres: towards the fingertips), the
/// actuators `actuators` take the action `action` and the rest the neutral action 0 (the flat
/// hand every episode settles on); then the policy acts as its card says. Elsewhere the policy
/// acts from the first step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StartGesture {
    pub actuators: Vec<usize>,
    pub action: f64,
    pub steps: usize,
    pub below_y: f64,
    /// The ensemble member that acts alone in the episodes that make the gesture, before and
    /// after any handover (a specialist for the fingertips' side); none: those episodes go
    /// on as the card says for every episode.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub member: Option<usize>,
}

/// What the gesture does, in words, for a policy's card and the command that makes it.
impl std::fmt::Display for StartGesture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "actuators {} at {} for the first {} steps where the cube starts with y below {}",
            self.actuator_list(),
            self.action,
            self.steps,
            self.below_y
        )?;
        if let Some(member) = self.member {
            write!(f, ", member {member} acting alone in those episodes")?;
        }
        Ok(())
    }
}

impl StartGesture {
    /// The actuators, comma separated, as `dexcube start-gesture --actuators` takes them.
    pub fn actuator_list(&self) -> String {
        let actuators: Vec<String> = self.actuators.iter().map(usize::to_string).collect();
        actuators.join(",")
    }

    /// The action of the gesture for a hand of `actions` actuators.
    pub fn action(&self, actions: usize) -> Vec<f64> {
        let mut out = vec![0.0; actions];
        for &k in &self.actuators {
            out[k] = self.action;
        }
        out
    }

    /// Whether an episode whose first observation is `observation` makes the gesture.
    pub fn applies(&self, observation: &[f64]) -> bool {
        observation[CUBE_Y] < self.below_y
    }

    /// Why the gesture cannot be made by a policy of `dims` (a hand of `dims.action`
    /// actuators, observing the cube's position), if it cannot.
    pub fn check(&self, dims: Dims) -> Result<(), String> {
        let actions = dims.action;
        observes_cube_position(dims, "start gesture")?;
        if let Some(k) = self.actuators.iter().find(|&&k| k >= actions) {
            return Err(format!(
                "the hand has {actions} actuators (0 to {}), not an actuator {k}",
                actions - 1
            ));
        }
        if !(-1.0..=1.0).contains(&self.action) {
            return Err(format!(
                "an action is between -1 and 1, not {}",
                self.action
            ));
        }
        if self.actuators.is_empty() || self.steps == 0 {
            return Err("a gesture needs at least one actuator and one step".into());
        }
        Ok(())
    }
}

/// Why a policy of `dims` cannot be given a setting (`what`) decided by where the cube starts
/// on the palm, if it does not observe the cube's position.
pub(crate) fn observes_cube_position(dims: Dims, what: &str) -> Result<(), String> {
    if dims.observation <= CUBE_Y {
        return Err(format!(
            "it observes {} numbers, without the cube's position: a {what} is for a stage \
             policy of the hand",
            dims.observation
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn knuckles() -> StartGesture {
        StartGesture {
            actuators: vec![3, 6, 9, 13],
            action: -1.0,
            steps: 5,
            below_y: 0.87,
            member: None,
        }
    }

    #[test]
    fn the_gesture_moves_only_its_actuators() {
        let action = knuckles().action(20);
        assert_eq!(action.len(), 20);
        for (k, a) in action.iter().enumerate() {
            let expected = if [3, 6, 9, 13].contains(&k) {
                -1.0
            } else {
                0.0
            };
            assert_eq!(*a, expected, "actuator {k}");
        }
    }

    #[test]
    fn it_applies_only_towards_the_fingertips() {
        let mut observation = vec![0.0; 62];
        observation[CUBE_Y] = 0.869;
        assert!(knuckles().applies(&observation));
        observation[CUBE_Y] = 0.871;
        assert!(!knuckles().applies(&observation));
    }

    #[test]
    fn a_gesture_the_hand_cannot_make_is_refused() {
        let stage2 = Dims {
            observation: 62,
            goal: 1,
            action: 20,
        };
        assert!(knuckles().check(stage2).is_ok());
        let point_mass = Dims {
            observation: 4,
            ..stage2
        };
        assert!(
            knuckles()
                .check(point_mass)
                .unwrap_err()
                .contains("without the cube")
        );
        let too_far = StartGesture {
            actuators: vec![3, 20],
            ..knuckles()
        };
        assert!(
            too_far
                .check(stage2)
                .unwrap_err()
                .contains("not an actuator 20")
        );
        let too_much = StartGesture {
            action: 1.5,
            ..knuckles()
        };
        assert!(too_much.check(stage2).unwrap_err().contains("not 1.5"));
        let no_steps = StartGesture {
            steps: 0,
            ..knuckles()
        };
        assert!(no_steps.check(stage2).is_err());
    }
}
