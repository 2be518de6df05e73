//! An ensemble member that acts alone where the cube starts towards the thumb
//! ([`StartRoute`]).
//!
//! Session 58 in `results/TRAINING.md` found that Stage 2 fails from about a quarter of the
//! placements more than from the rest: those towards the thumb (x below the palm's resting
//! point) fail three to four times as often, on the wrist's side as on the fingertips'. A card
//! that already hands the fingertips' side to a specialist ([`crate::start_gesture`]) can
//! hand the thumb's quarter of the rest to a third member trained there. As with the gesture,
//! the route is decided from the policy's own view at the first step.

use serde::{Deserialize, Serialize};

use crate::agent::Dims;
use crate::start_gesture::observes_cube_position;

/// Where the cube's position across the palm (x; the thumb lies towards -x, the little finger
/// towards +x) sits in the observations both stages share.
pub const CUBE_X: usize = dexcube_env::OBJECT_POSITION;

/// In an episode that makes no start gesture and whose cube starts with its x below `below_x`
/// (the palm's resting point, in world metres: towards the thumb), ensemble member `member`
/// acts alone, before and after any handover; every other episode goes on as the card says.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StartRoute {
    pub below_x: f64,
    pub member: usize,
}

/// What the route does, in words, for a policy's card and the command that makes it.
impl std::fmt::Display for StartRoute {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "member {} acting alone where the cube starts with x below {} and no start gesture \
             is made",
            self.member, self.below_x
        )
    }
}

impl StartRoute {
    /// Whether an episode whose first observation is `observation` is routed to the member.
    pub fn applies(&self, observation: &[f64]) -> bool {
        observation[CUBE_X] < self.below_x
    }

    /// Why the route cannot be taken by a policy of `dims` with `members` ensemble members, if
    /// it cannot (a member it lacks is the card's to refuse, as for a handover).
    pub fn check(&self, dims: Dims, members: usize) -> Result<(), String> {
        observes_cube_position(dims, "start route")?;
        if members < 2 {
            return Err(
                "it is a single policy, with no member to route to: make an ensemble first \
                 (`dexcube ensemble`)"
                    .into(),
            );
        }
        Ok(())
    }
}
