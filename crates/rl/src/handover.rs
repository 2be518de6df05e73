//! When an ensemble hands its episode to one of its members ([`Handover`]), and the watch
//! that decides it through one episode ([`HandoverWatch`]).
//!
//! An ensemble acts with the mean of its members' actions. Where the members would turn the
//! cube different ways, the mean can turn it neither way, and the cube stalls: session 50 in
//! `results/TRAINING.md` found the states where `models/rot` stayed stuck more than half a
//! radian from its pose are ones each member alone mostly leaves. A policy with a handover
//! acts as the ensemble until the cube has stalled, then as the one member for the rest of
//! the episode. It may instead act as another member alone until then: one policy falling
//! back on another; and it may let go for some steps before the member acts, which lets a
//! single policy try again itself (session 51).

use serde::{Deserialize, Serialize};

/// Hands the episode to member `member` (0 is the first) once the cube has gone `patience`
/// control steps in a row neither meeting its test nor coming `progress` radians nearer its
/// goal than it has yet been. A patience of 0 hands over before the first step: the member
/// alone. Until then the ensemble acts with its members' mean action, or, where `first`
/// names a member, with that member's alone: one policy falling back on another.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Handover {
    pub member: usize,
    pub patience: usize,
    pub progress: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first: Option<usize>,
    /// Control steps the hand takes the neutral action for once handed over (the flat hand
    /// every episode settles on), before the member acts: letting go and trying again.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub let_go: Option<usize>,
    /// Another member for the episodes whose cube is still far from its goal when it stalls;
    /// the rest go to `member` (session 60).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub far: Option<FarHandover>,
}

/// Where a stalled cube is at least `beyond` radians from its goal on the step the handover
/// comes, the episode goes to member `member` instead of the handover's own. Session 50 found
/// the members alone best at different distances: `models/rot-td3-19` near the pose, the seen
/// run's `epoch-0047` a quarter turn off.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FarHandover {
    pub member: usize,
    pub beyond: f64,
}

impl Handover {
    /// The member a stall with the cube `angle` radians from its goal is handed to.
    pub fn member_for(&self, angle: f64) -> usize {
        match self.far {
            Some(far) if angle >= far.beyond => far.member,
            _ => self.member,
        }
    }
}

/// What the handover does, in words, for a policy's card and the command that makes it.
impl std::fmt::Display for Handover {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "handing over to member {} after {} steps without {} rad of progress",
            self.member, self.patience, self.progress
        )?;
        if let Some(first) = self.first {
            write!(f, ", member {first} acting alone until then")?;
        }
        if let Some(far) = self.far {
            write!(
                f,
                ", or to member {} where the cube is {} rad or more from its goal then",
                far.member, far.beyond
            )?;
        }
        if let Some(steps) = self.let_go {
            write!(f, ", letting go for {steps} steps first")?;
        }
        Ok(())
    }
}

/// Who acts on a step of an episode with a handover ([`HandoverWatch::turn`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Turn {
    /// Not handed over yet: the ensemble, or the member named to act first.
    Before,
    /// Handed over, and the hand still letting go: the neutral action.
    LettingGo,
    /// Handed over: the member named.
    Member(usize),
}

/// What a handover keeps of one episode: the nearest the cube has come to its goal, how many
/// steps it has stalled since, and, once that reaches the patience, the member it was handed
/// to; the count then stops.
#[derive(Clone, Debug)]
pub struct HandoverWatch {
    handover: Handover,
    nearest: f64,
    stalled: usize,
    handed_to: Option<usize>,
    since_handover: usize,
}

impl HandoverWatch {
    pub fn new(handover: Handover) -> HandoverWatch {
        HandoverWatch {
            handover,
            nearest: f64::INFINITY,
            stalled: 0,
            handed_to: None,
            since_handover: 0,
        }
    }

    /// Says who acts on the step about to be acted on. Until the handover it reads the step
    /// through `read`: the cube's angle from its goal, and whether it meets its test. The
    /// angle on the step the handover comes chooses the member ([`Handover::member_for`]),
    /// which acts to the end of the episode (after letting go, where the handover says so);
    /// the step need not be read again.
    pub fn turn(&mut self, read: impl FnOnce() -> (f64, bool)) -> Turn {
        let member = match self.handed_to {
            Some(member) => member,
            None => {
                let (angle, met) = read();
                let nearer = angle < self.nearest - self.handover.progress;
                if nearer {
                    self.nearest = angle;
                }
                self.stalled = if met || nearer { 0 } else { self.stalled + 1 };
                if self.stalled < self.handover.patience {
                    return Turn::Before;
                }
                *self.handed_to.insert(self.handover.member_for(angle))
            }
        };
        self.since_handover += 1;
        if self.since_handover <= self.handover.let_go.unwrap_or(0) {
            Turn::LettingGo
        } else {
            Turn::Member(member)
        }
    }

    /// The member the episode was handed to, once it has been.
    pub fn handed_to(&self) -> Option<usize> {
        self.handed_to
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether the member acts on a step with the cube `angle` from its goal, `met` when it
    /// meets its test.
    trait MemberActs {
        fn member_acts(&mut self, angle: f64, met: bool) -> bool;
    }

    impl MemberActs for HandoverWatch {
        fn member_acts(&mut self, angle: f64, met: bool) -> bool {
            matches!(self.turn(|| (angle, met)), Turn::Member(_))
        }
    }

    fn handover(patience: usize) -> Handover {
        Handover {
            member: 1,
            patience,
            progress: 0.05,
            first: None,
            let_go: None,
            far: None,
        }
    }

    fn watch(patience: usize) -> HandoverWatch {
        HandoverWatch::new(handover(patience))
    }

    #[test]
    fn hands_over_after_patience_steps_without_progress_and_stays_handed_over() {
        let mut w = watch(3);
        // Coming nearer by more than the progress each step: never stalled.
        for angle in [1.5, 1.4, 1.3, 1.2] {
            assert!(!w.member_acts(angle, false));
        }
        // Nearer by less than the progress counts as stalled: the third such step hands over.
        assert!(!w.member_acts(1.18, false));
        assert!(!w.member_acts(1.17, false));
        assert!(w.member_acts(1.16, false));
        // Once handed over, even progress and the test met keep the member acting.
        assert!(w.member_acts(0.2, false) && w.member_acts(0.0, true));
        assert_eq!(w.handed_to(), Some(1));
    }

    #[test]
    fn a_cube_at_its_goal_is_not_stalled() {
        let mut w = watch(2);
        assert!(!w.member_acts(0.5, false));
        for _ in 0..50 {
            assert!(
                !w.member_acts(0.05, true),
                "holding the goal is not stalling"
            );
        }
        // Lost from the goal and not coming back within 0.05 rad of the nearest (0.05).
        assert!(!w.member_acts(0.15, false));
        assert!(w.member_acts(0.15, false));
    }

    #[test]
    fn a_patience_of_zero_hands_over_before_the_first_step() {
        let mut w = watch(0);
        assert!(w.member_acts(1.0, false));
    }

    #[test]
    fn a_stall_far_from_the_goal_goes_to_the_far_member_and_the_rest_to_the_member() {
        let far = Some(FarHandover {
            member: 0,
            beyond: 0.8,
        });
        // The member is chosen by the angle on the step the handover comes, and kept.
        for (angle, member) in [(1.2, 0), (0.8, 0), (0.79, 1), (0.3, 1)] {
            let mut w = HandoverWatch::new(Handover { far, ..handover(2) });
            assert_eq!(w.turn(|| (angle, false)), Turn::Before);
            assert_eq!(w.turn(|| (angle, false)), Turn::Before);
            assert_eq!(
                w.turn(|| (angle, false)),
                Turn::Member(member),
                "{angle} rad"
            );
            assert_eq!(w.turn(|| (0.1, false)), Turn::Member(member), "kept");
            assert_eq!(w.handed_to(), Some(member));
        }
        // Without a far member every stall goes to the member, however far.
        let mut w = watch(0);
        assert_eq!(w.turn(|| (1.5, false)), Turn::Member(1));
    }
}
