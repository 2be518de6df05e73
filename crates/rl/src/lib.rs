//! # dexcube-rl
//!
//! DDPG (Lillicrap et al. 2016) with Hindsight Experience Replay (Andrychowicz et al. 2017),
//! as the paper trained its two atomic actions, on burn. Read it top to bottom:
//!
//! - [`config`]: every hyperparameter, with the HER baselines' defaults, cited;
//! - [`normalizer`]: running statistics of observations and goals;
//! - [`networks`] and [`agent`]: the actor, the critic, their targets and the update;
//! - [`replay`]: the HER buffer, relabelling goals at sampling time;
//! - [`rollout`]: episodes from a `VecEnv`;
//! - [`train`]: the epoch / cycle / batch schedule with checkpoints, curves and exact resume;
//! - [`recipe`]: a skill learned from random weights in one run of phases, each ended by a
//!   rule read from its own test success;
//! - [`start_file`]: recorded Stage 1 starts on disk, to train and evaluate from;
//! - [`seeds`]: learning curves across seeds, mean ± one standard deviation;
//! - [`policy`]: a trained actor as shipped, with its normalisers;
//! - [`guide`]: a run's critics choosing among actions near a policy's own;
//! - [`handover`]: an ensemble handing a stalled episode to one member, or a policy letting go
//!   and trying again;
//! - [`start_gesture`]: a gesture the hand makes before a policy first acts, where the cube
//!   starts towards the fingertips;
//! - [`start_route`]: ensemble members that act alone in the episodes picked by where the
//!   cube starts (towards the thumb, or near square where the start gesture is made);
//! - [`residual`]: a correction learned on top of a fixed policy that works (residual policy
//!   learning), and the environment that trains it;
//! - [`distil`]: one actor fitted to act as another policy (an ensemble) does, by DAgger;
//! - [`point_mass`]: a small reaching task that proves the learner in seconds.
//!
//! Networks run on burn's `flex` CPU backend with one intra-op thread; the code names no
//! backend, so a CUDA device runs it unchanged where burn is built with `cuda`.

pub mod agent;
pub mod checkpoint;
pub mod config;
pub mod distil;
pub mod guide;
pub mod handover;
pub mod networks;
pub mod normalizer;
pub mod params;
pub mod plot;
pub mod point_mass;
pub mod policy;
pub mod recipe;
pub mod replay;
pub mod residual;
pub mod rollout;
pub mod seeds;
pub mod start_file;
pub mod start_gesture;
pub mod start_route;
pub mod train;

pub use agent::{Agent, Dims, Learners, SavedAnchor};
pub use config::DdpgHerConfig;
pub use policy::Policy;
pub use train::{EpochMetrics, TrainOptions, train};
