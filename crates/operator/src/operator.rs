//! The Rubik's Cube Operator with the paper's rollback mechanism. For each planned move:
//!
//! 1. **Stage 1** brings the move's face up (the paper's three target orientations). With
//!    rollback, the pose is checked; if it is off, the cube is re-seated at a random pose
//!    and Stage 1 runs again.
//! 2. **Stage 2** turns the top layer U', once for a primed move, three times otherwise. With
//!    rollback, the cube is checked for a good state (every layer aligned); if it is not, it
//!    is restored: its layers are worked back to the nearest quarter turn and it is re-seated
//!    at a random pose on a flat hand (a simulation shortcut for the paper's
//!    "randomisation"); the move's remaining turns are then skipped, since another face may
//!    now be up, and the check below re-plans.
//! 3. With rollback, the facelets read from the physics are compared with the expected ones;
//!    if the move did not happen, the operator re-plans from what it sees. By default
//!    (`OperatorConfig::stage1_puzzle_check`) it also reads the puzzle after Stage 1 and, if
//!    a layer turned while the cube was re-posed, restores the good state if need be, skips
//!    the move's Stage 2 and goes straight to that check.
//!
//! Without rollback the plan runs open loop. Action number (AN) counts atomic actions, Stage 1
//! and Stage 2 runs alike; randomisations are counted apart.
//!
//! By default the operator plans for the hand: of the optimal plans it takes the one with the
//! fewest atomic actions (`hand_cost`: U' is one Stage 2 run, U three), and it skips Stage 1
//! when the face to turn is already up. Given a cost table ([`Planner::any_length`]) it takes
//! the cheapest plan of any length instead, with a Stage 1 priced above a turn
//! ([`hand_price`]). `OperatorConfig::plan_for_hand` off gives the paper's operator: the first
//! optimal plan, and Stage 1 before every move.

use dexcube_cube::{CostTable, DistanceTable, Face, Facelets, Move, Position, Solver};
use dexcube_env::is_square;
use dexcube_sim::cube::{CubeState, read_puzzle, snap_layers, turned_since};
use dexcube_sim::{Pose, Sim};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::stages::{
    Driving, STAGE1_FACES, Stage1, Stage2, StageRun, face_up, randomise_pose, stage1_target,
};

/// Why an attempt ended without a solved cube.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Failure {
    /// The cube fell off the hand.
    Dropped,
    /// The physics blew up.
    Diverged,
    /// The cube could not be brought to a good state, or its stickers could not be read.
    StuckMisaligned,
    /// The action budget ran out.
    OutOfActions,
    /// Open loop (no rollback): the plan ran but the cube is not solved.
    NotSolved,
}

/// What happened in one attempt.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    pub solved: bool,
    pub failure: Option<Failure>,
    /// Atomic actions run (Stage 1 and Stage 2 runs): the paper's AN.
    pub actions: usize,
    pub randomisations: usize,
    pub replans: usize,
    pub control_steps: usize,
    /// The stage (1 or 2) that dropped the cube or blew up the physics, and at which of its
    /// control steps (counting the hand's settling steps before the policy acts).
    pub failed_at: Option<(usize, usize)>,
    pub stages: StageRecord,
}

/// How the atomic actions fared inside one attempt, as the operator saw them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct StageRecord {
    /// Stage 1 runs that kept the cube on the palm, and those after which the pose check
    /// passed (a run that dropped it ended the attempt, and `Outcome::failed_at` names it).
    pub stage1_runs: usize,
    pub stage1_reached: usize,
    /// Stage 2 runs that kept the cube on the palm, and those that left it out of its good
    /// state (a layer part-way or another layer knocked out of square), whether or not the
    /// rollback then restored it.
    pub stage2_runs: usize,
    pub stage2_misaligned: usize,
    /// Stage 1 runs that kept the cube but left a layer turned from where it was when the
    /// run began (the puzzle changed, which the pose check does not see); `None` in records
    /// from before it was counted.
    pub stage1_turned: Option<usize>,
}

impl Default for StageRecord {
    /// No runs yet, every count recorded.
    fn default() -> StageRecord {
        StageRecord {
            stage1_runs: 0,
            stage1_reached: 0,
            stage2_runs: 0,
            stage2_misaligned: 0,
            stage1_turned: Some(0),
        }
    }
}

impl Outcome {
    /// Counts one atomic action of `stage`; a dropped cube or a blow-up ends the attempt.
    fn count(&mut self, stage: usize, run: &StageRun) -> Option<Failure> {
        self.actions += 1;
        self.control_steps += run.steps;
        let failure = if run.dropped {
            Some(Failure::Dropped)
        } else if run.diverged {
            Some(Failure::Diverged)
        } else {
            None
        };
        if failure.is_some() {
            self.failed_at = Some((stage, run.steps));
        }
        failure
    }

    /// Why the attempt failed, and where if a stage ended it ("Dropped in Stage 1 at step
    /// 14"); empty if it did not fail.
    pub fn failure_text(&self) -> String {
        match (self.failure, self.failed_at) {
            (Some(failure), Some((stage, step))) => {
                format!("{failure:?} in Stage {stage} at step {step}")
            }
            (Some(failure), None) => format!("{failure:?}"),
            (None, _) => String::new(),
        }
    }
}

/// Something the operator did, for narration.
#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    Plan(Vec<Move>),
    Stage1 {
        /// The face the move needs on top.
        face: Face,
        /// The face on top when Stage 1 ended (the opposite one also serves in pair mode).
        landed: Face,
        attempt: usize,
        ok: bool,
    },
    /// The face the move needs is already up: no Stage 1.
    AlreadyUp(Face),
    Stage2 {
        turn: usize,
        of: usize,
    },
    Randomised(&'static str),
    MoveDone(Move),
    Replan(Vec<Move>),
    /// With rollback and the puzzle checked after Stage 1: Stage 1 left a layer turned, so
    /// the move's Stage 2 is skipped, the cube restored to its good state if the layer
    /// stopped short, and the move check re-plans.
    Stage1TurnedLayer,
    /// A stage ended the attempt: the cube fell, or the physics blew up.
    Ended {
        stage: usize,
        failure: Failure,
    },
}

#[derive(Clone, Copy, Debug)]
pub struct OperatorConfig {
    pub rollback: bool,
    /// Atomic actions allowed before giving up.
    pub max_actions: usize,
    /// Stage 1 attempts per move (with rollback) before going on anyway.
    pub stage1_attempts: usize,
    /// Restores of a misaligned cube per move before giving up.
    pub restores: usize,
    /// Plan for the hand: the optimal plan of fewest actions, and no Stage 1 for a face that
    /// is already up. Off: the paper's operator.
    pub plan_for_hand: bool,
    /// How the policies are run on the cube.
    pub driving: Driving,
    /// Planning for the hand, when a move's face counts as already up, so that its Stage 1
    /// is skipped.
    pub already_up: AlreadyUp,
    /// With rollback, Stage 1 also needs the cube in its good state: a cube it leaves with a
    /// layer skewed is squared up and re-posed by randomisation, as a pose that is off is.
    pub stage1_good_state: bool,
    /// Planning for the hand, price each plan's first move knowing which face is up now (by
    /// the test that skips Stage 1), rather than as if a Stage 1 were always needed first.
    pub plan_from_face_up: bool,
    /// With rollback, read the puzzle after Stage 1 too: if a layer turned while the cube was
    /// re-posed, the plan no longer fits, so the move's Stage 2 is skipped and the operator
    /// re-plans from what it sees, rather than turning first and finding out after. On by
    /// default since session 32 (Table I: 1,339 cubes against 1,332, fewer actions for 250
    /// of the cubes both solved against 21); the paper's operator has no such check.
    pub stage1_puzzle_check: bool,
}

impl Default for OperatorConfig {
    fn default() -> Self {
        OperatorConfig {
            rollback: true,
            max_actions: 100,
            stage1_attempts: 3,
            restores: 2,
            plan_for_hand: true,
            driving: Driving::FOR_HAND,
            already_up: AlreadyUp::Pose,
            stage1_good_state: false,
            plan_from_face_up: false,
            stage1_puzzle_check: true,
        }
    }
}

/// When the operator planning for the hand skips a move's Stage 1 because its face is
/// already up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AlreadyUp {
    /// Stage 1's own test passes: the face up within its angle test (0.1 rad) and the cube
    /// within 0.01 m of its resting point.
    Pose,
    /// The face up within Stage 1's angle test, wherever the cube lies on the palm.
    Face,
    /// The move's layer pair lies top and bottom (the face or its opposite points more
    /// nearly up than any other), however the cube is tilted or placed: what Stage 2 needs,
    /// and how the second and third turns of a U, R or F move already begin.
    Top,
}

/// Which face to bring up and how many U' turns make a move (the solver plans in U, R, F).
pub fn move_plan(m: Move) -> (Face, usize) {
    let up = match m.face {
        Face::R => Face::R,
        // The paper's F pose lifts B. Turning B' on top moves the B layer against the F layer
        // exactly as F' does (X and its opposite face's X turn the layers the same way
        // relative to each other), so it serves the F moves.
        Face::F => Face::B,
        _ => Face::U,
    };
    // One U' on top is U', R' or B' (= F'); three make U, R or F.
    (up, if m.quarters == 3 { 1 } else { 3 })
}

/// The atomic actions each move costs the hand, as a price for `cheapest_optimal`: one or
/// three Stage 2 turns, and a Stage 1 unless the face the move needs is up already: after a
/// move that needed the same face up, or, for a plan's first move, when `up_now` is that face.
pub fn hand_cost(up_now: Option<Face>) -> impl Fn(Option<Move>, Move) -> u32 {
    let price = hand_price(1);
    move |before, m| {
        let up_before = before.map_or(up_now, |b| Some(move_plan(b).0));
        price(up_before.map(Face::axis), m)
    }
}

/// What a move costs the hand when a Stage 1 is priced at `stage1` U' turns, as a price for
/// a [`CostTable`]: its one or three turns, and a Stage 1 unless the last move turned about
/// the same axis (`None`: the axis up is not known, or no face is up). At 1 it counts atomic
/// actions; above 1 it weighs the risk: a Stage 1 drops the cube far more often than a turn.
pub fn hand_price(stage1: u32) -> impl Fn(Option<usize>, Move) -> u32 + Copy {
    move |axis_before, m| {
        let (up, turns) = move_plan(m);
        turns as u32 + stage1 * u32::from(axis_before != Some(up.axis()))
    }
}

/// Where the operator's plans come from.
#[derive(Clone, Copy)]
pub struct Planner<'a> {
    /// Optimal plans: the paper's planner's first, or, planning for the hand, the one of
    /// fewest atomic actions.
    pub optimal: &'a DistanceTable,
    /// Planning for the hand, the cheapest plan of any length instead, at the prices this
    /// table was built with (see [`hand_price`]).
    pub any_length: Option<&'a CostTable>,
}

/// The rollback's test of the cube's pose after Stage 1: (simulation, target position, target
/// orientation) -> reached.
pub type PoseCheck = dyn Fn(&Sim, [f64; 3], [f64; 4]) -> bool;

pub struct Operator<'a> {
    pub config: OperatorConfig,
    pub stage1: &'a mut dyn Stage1,
    pub stage1_accepts: &'a PoseCheck,
    pub stage2: &'a mut dyn Stage2,
    pub planner: Planner<'a>,
    pub resting: [f64; 3],
    pub rng: ChaCha8Rng,
    /// Called after every control step, e.g. to record a video.
    pub watch: &'a mut dyn FnMut(&mut Sim),
}

impl Operator<'_> {
    /// Solves the cube in `sim`, reporting each event to `narrate`.
    pub fn solve(&mut self, sim: &mut Sim, narrate: &mut dyn FnMut(&Event)) -> Outcome {
        let mut outcome = Outcome::default();
        let Some(start) = read_puzzle(sim) else {
            outcome.failure = Some(Failure::StuckMisaligned);
            return outcome;
        };
        let mut plan = self.plan(sim, &start);
        narrate(&Event::Plan(plan.clone()));
        let mut expected = start;
        while let Some(&m) = plan.first() {
            if outcome.actions >= self.config.max_actions {
                outcome.failure = Some(Failure::OutOfActions);
                return outcome;
            }
            if let Some(failure) = self.execute(sim, m, &mut outcome, narrate) {
                outcome.failure = Some(failure);
                return outcome;
            }
            expected = expected.apply(m);
            plan.remove(0);
            if !self.config.rollback {
                narrate(&Event::MoveDone(m));
                continue;
            }
            // Check that the move happened; if not, re-plan from what is there.
            match read_puzzle(sim) {
                Some(seen) if Position::of(&seen) == Position::of(&expected) => {
                    narrate(&Event::MoveDone(m))
                }
                Some(seen) => {
                    plan = self.plan(sim, &seen);
                    expected = seen;
                    outcome.replans += 1;
                    narrate(&Event::Replan(plan.clone()));
                }
                None => {
                    outcome.failure = Some(Failure::StuckMisaligned);
                    return outcome;
                }
            }
        }
        let solved = CubeState::read(sim).is_some_and(|s| {
            s.is_aligned() && s.facelets_in_cube_frame().is_ok_and(|f| f.is_solved())
        });
        outcome.solved = solved;
        if !solved {
            outcome.failure = Some(if self.config.rollback {
                Failure::StuckMisaligned
            } else {
                Failure::NotSolved
            });
        }
        outcome
    }

    /// A plan from `cube`: the hand's cheapest, of any length or of the optimal ones, or the
    /// solver's first optimal plan.
    fn plan(&self, sim: &Sim, cube: &Facelets) -> Vec<Move> {
        let position = Position::of(cube);
        if !self.config.plan_for_hand {
            return self.planner.optimal.solve(&position);
        }
        let up_now = if self.config.plan_from_face_up {
            STAGE1_FACES
                .into_iter()
                .find(|&face| self.already_up(sim, face))
        } else {
            None
        };
        match self.planner.any_length {
            Some(costs) => costs.cheapest(&position, up_now.map(Face::axis)),
            None => self
                .planner
                .optimal
                .cheapest_optimal(&position, hand_cost(up_now)),
        }
    }

    /// Whether the cube in `sim` already has `up` up, by the test that skips Stage 1.
    fn already_up(&self, sim: &Sim, up: Face) -> bool {
        let target = stage1_target(up);
        match self.config.already_up {
            AlreadyUp::Pose => (self.stage1_accepts)(sim, self.resting, target),
            AlreadyUp::Face => (self.stage1_accepts)(sim, sim.object_pose().position, target),
            AlreadyUp::Top => face_up(sim).axis() == up.axis(),
        }
    }

    /// Both stages of one move, with the rollback checks; a failure ends the attempt.
    fn execute(
        &mut self,
        sim: &mut Sim,
        m: Move,
        outcome: &mut Outcome,
        narrate: &mut dyn FnMut(&Event),
    ) -> Option<Failure> {
        let (up, turns) = move_plan(m);
        let target = stage1_target(up);
        let mut stage1_attempts = self.config.stage1_attempts;
        if self.config.plan_for_hand && self.already_up(sim, up) {
            narrate(&Event::AlreadyUp(up));
            stage1_attempts = 0;
        }
        // With the check, the puzzle as the move began: a layer turned by any of its Stage 1
        // runs (a run's own count misses one whose start or end cannot be read).
        let check_puzzle =
            self.config.rollback && self.config.stage1_puzzle_check && stage1_attempts > 0;
        let puzzle_at_move = check_puzzle.then(|| read_puzzle(sim)).flatten();
        for attempt in 1..=stage1_attempts {
            let puzzle_before = read_puzzle(sim);
            let run = self.stage1.run(sim, self.resting, target, &mut *self.watch);
            if let Some(failure) = outcome.count(1, &run) {
                narrate(&Event::Ended { stage: 1, failure });
                return Some(failure);
            }
            let posed = (self.stage1_accepts)(sim, self.resting, target);
            let square = !self.config.stage1_good_state || is_square(sim);
            let ok = posed && square;
            outcome.stages.stage1_runs += 1;
            outcome.stages.stage1_reached += usize::from(posed);
            let turned = turned_since(puzzle_before.as_ref(), sim);
            let counted = &mut outcome.stages.stage1_turned;
            *counted = counted.map(|n| n + usize::from(turned));
            narrate(&Event::Stage1 {
                face: up,
                landed: face_up(sim),
                attempt,
                ok,
            });
            if ok || !self.config.rollback || attempt == stage1_attempts {
                break;
            }
            if !square {
                snap_layers(sim);
            }
            randomise_pose(sim, self.resting, &mut self.rng);
            outcome.randomisations += 1;
            narrate(&Event::Randomised(if square {
                "the pose was off: random pose, then Stage 1 again"
            } else {
                "not in a good state: layers restored, random pose, then Stage 1 again"
            }));
        }
        if turned_since(puzzle_at_move.as_ref(), sim) {
            narrate(&Event::Stage1TurnedLayer);
            // A layer Stage 1 dragged round may have stopped short of a quarter turn: the
            // cube is put back in its good state before the move check reads it.
            return self.restore_good_state(sim, outcome, narrate).err();
        }
        for turn in 1..=turns {
            let run = self.stage2.run(sim, &mut *self.watch);
            let failure = outcome.count(2, &run);
            narrate(&Event::Stage2 { turn, of: turns });
            if let Some(failure) = failure {
                narrate(&Event::Ended { stage: 2, failure });
                return Some(failure);
            }
            outcome.stages.stage2_runs += 1;
            outcome.stages.stage2_misaligned += usize::from(!is_square(sim));
            if self.config.rollback {
                // A restored cube lies in a random pose: the rest of this move's turns
                // would turn whatever face is up. The move check re-plans from here.
                match self.restore_good_state(sim, outcome, narrate) {
                    Ok(0) => {}
                    Ok(_) => break,
                    Err(failure) => return Some(failure),
                }
            }
        }
        None
    }

    /// The rollback's restore: while the cube is out of its good state, its layers are worked
    /// back to the nearest quarter turn and it is re-seated at a random pose, at most
    /// `OperatorConfig::restores` times. Returns how many restores it took.
    fn restore_good_state(
        &mut self,
        sim: &mut Sim,
        outcome: &mut Outcome,
        narrate: &mut dyn FnMut(&Event),
    ) -> Result<usize, Failure> {
        let mut restores = 0;
        while !is_square(sim) {
            if restores == self.config.restores {
                return Err(Failure::StuckMisaligned);
            }
            snap_layers(sim);
            randomise_pose(sim, self.resting, &mut self.rng);
            restores += 1;
            outcome.randomisations += 1;
            narrate(&Event::Randomised(
                "not in a good state: layers restored, random pose",
            ));
        }
        Ok(restores)
    }
}

/// Places a scrambled cube on the palm: `scramble` turned kinematically from solved, at rest.
pub fn set_up_scramble(sim: &mut Sim, scramble: &[Move], resting: [f64; 3]) {
    sim.reset();
    sim.set_object_pose(&Pose {
        position: resting,
        orientation: dexcube_sim::rotation::IDENTITY,
    });
    for &m in scramble {
        dexcube_sim::cube::turn_face(sim, m);
    }
    sim.forward();
}
