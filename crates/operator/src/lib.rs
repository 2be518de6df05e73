//! # dexcube-operator
//!
//! The hierarchical controller of Li et al.: the solver plans (optimally, or for the hand's
//! risk), and each move is carried out by two atomic actions on the physical cube, Stage 1
//! (cube rotation) and Stage 2 (U' layer turn), with the rollback mechanism checking pose,
//! good state and the move itself. Also the evaluation harness: Table I (success rate and
//! action number by move distance, with and without rollback) and the atomic actions alone.

pub mod eval;
pub mod operator;
pub mod stages;

pub use operator::{
    AlreadyUp, Event, Failure, Operator, OperatorConfig, Outcome, Planner, StageRecord, hand_cost,
    hand_price, move_plan, set_up_scramble,
};
