//! Ensemble members that act alone in the episodes picked by where the cube starts
//! ([`StartRoute`]).
//!
//! Session 58 in `results/TRAINING.md` found that Stage 2 fails from about a quarter of the
//! placements more than from the rest: those towards the thumb (x below the palm's resting
//! point) fail three to four times as often, on the wrist's side as on the fingertips'. A card
//! that already hands the fingertips' side to a specialist ([`crate::start_gesture`]) can
//! hand the thumb's quarter of the rest to a third member trained there. Session 59 found the
//! same of the episodes that make the gesture with the cube near square to the hand: a third
//! of them, and two thirds of their failures. Every route is decided from the policy's own
//! view at the first step, before any gesture, and the first that takes the episode wins.

use serde::{Deserialize, Serialize};

use crate::agent::Dims;
use crate::start_gesture::observes_cube_position;

/// Where the cube's position across the palm (x; the thumb lies towards -x, the little finger
/// towards +x) sits in the observations both stages share.
pub const CUBE_X: usize = dexcube_env::OBJECT_POSITION;

/// Where the cube's orientation (a unit quaternion, w first) sits in them, after its position.
pub const CUBE_ORIENTATION: usize = dexcube_env::OBJECT_POSITION + 3;

/// The cube's yaw from square to the hand, in degrees from 0 to 45, as a policy sees it in
/// `observation` ([`dexcube_sim::cube::yaw_from_square`] of the orientation it is shown: the
/// frame of the layer that stays, which may differ from the cube's own by its misalignment).
pub fn yaw_seen(observation: &[f64]) -> f64 {
    let orientation = observation[CUBE_ORIENTATION..CUBE_ORIENTATION + 4]
        .try_into()
        .expect("four numbers");
    dexcube_sim::cube::yaw_from_square(orientation)
}

/// In the episodes `episodes` picks, ensemble member `member` acts alone, before and after
/// any handover; every other episode goes on as the card says.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StartRoute {
    pub member: usize,
    pub episodes: RoutedEpisodes,
}

/// Which episodes a [`StartRoute`] takes, by where the cube starts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RoutedEpisodes {
    /// Those that make no start gesture and whose cube starts with its x below `below_x` (the
    /// palm's resting point, in world metres: towards the thumb; session 58).
    TowardsThumb { below_x: f64 },
    /// Those that make the card's start gesture and whose cube starts within `max_yaw`
    /// degrees of square to the hand ([`yaw_seen`]; session 59).
    GesturedNearSquare { max_yaw: f64 },
}

/// What the route does, in words, for a policy's card and the command that makes it.
impl std::fmt::Display for StartRoute {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "member {} acting alone where ", self.member)?;
        match self.episodes {
            RoutedEpisodes::TowardsThumb { below_x } => write!(
                f,
                "the cube starts with x below {below_x} and no start gesture is made"
            ),
            RoutedEpisodes::GesturedNearSquare { max_yaw } => write!(
                f,
                "the start gesture is made and the cube starts within {max_yaw} degrees of \
                 square"
            ),
        }
    }
}

impl StartRoute {
    /// Whether an episode whose first observation is `observation`, and which makes the start
    /// gesture or not (`gestured`), is routed to the member.
    pub fn applies(&self, observation: &[f64], gestured: bool) -> bool {
        match self.episodes {
            RoutedEpisodes::TowardsThumb { below_x } => !gestured && observation[CUBE_X] < below_x,
            RoutedEpisodes::GesturedNearSquare { max_yaw } => {
                gestured && yaw_seen(observation) <= max_yaw
            }
        }
    }

    /// Why the route cannot be taken by a policy of `dims` with `members` ensemble members,
    /// making a start gesture or not (`gesturing`), if it cannot (a member it lacks is the
    /// card's to refuse, as for a handover).
    pub fn check(&self, dims: Dims, members: usize, gesturing: bool) -> Result<(), String> {
        observes_cube_position(dims, "start route")?;
        if members < 2 {
            return Err(
                "it is a single policy, with no member to route to: make an ensemble first \
                 (`dexcube ensemble`)"
                    .into(),
            );
        }
        if let RoutedEpisodes::GesturedNearSquare { max_yaw } = self.episodes {
            if !(0.0..=45.0).contains(&max_yaw) {
                return Err(format!(
                    "a yaw from square is 0 to 45 degrees, not {max_yaw}"
                ));
            }
            if !gesturing {
                return Err(
                    "it makes no start gesture, so no episode would be routed: give it one \
                     first (`dexcube start-gesture`)"
                        .into(),
                );
            }
        }
        Ok(())
    }

    /// Whether this route and `other` pick the same kind of episodes, which one card cannot
    /// route twice.
    pub fn same_kind(&self, other: &StartRoute) -> bool {
        std::mem::discriminant(&self.episodes) == std::mem::discriminant(&other.episodes)
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_2;

    use dexcube_sim::rotation::{IDENTITY, about, mul};

    use super::*;

    /// A first observation with the cube at `x` across the palm and turned to `orientation`.
    fn observation(x: f64, orientation: [f64; 4]) -> Vec<f64> {
        let mut observation = vec![0.0; CUBE_ORIENTATION + 4];
        observation[CUBE_X] = x;
        observation[CUBE_ORIENTATION..].copy_from_slice(&orientation);
        observation
    }

    #[test]
    fn a_near_square_route_reads_the_yaw_from_square_on_any_face() {
        let route = StartRoute {
            member: 1,
            episodes: RoutedEpisodes::GesturedNearSquare { max_yaw: 15.0 },
        };
        let on_its_side = about([1.0, 0.0, 0.0], FRAC_PI_2);
        for (yaw, near_square) in [(10.0, true), (80.0, true), (-100.0, true), (30.0, false)] {
            for lying in [IDENTITY, on_its_side] {
                let turned = mul(&about([0.0, 0.0, 1.0], f64::to_radians(yaw)), &lying);
                let seen = observation(0.0, turned);
                assert_eq!(route.applies(&seen, true), near_square, "yaw {yaw}");
                assert!(!route.applies(&seen, false), "no gesture, no route");
            }
        }
    }

    #[test]
    fn a_thumbs_side_route_takes_only_episodes_without_the_gesture() {
        let route = StartRoute {
            member: 1,
            episodes: RoutedEpisodes::TowardsThumb { below_x: 1.0 },
        };
        assert!(route.applies(&observation(0.99, IDENTITY), false));
        assert!(!route.applies(&observation(0.99, IDENTITY), true));
        assert!(!route.applies(&observation(1.01, IDENTITY), false));
    }
}
