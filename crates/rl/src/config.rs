//! Every DDPG + HER hyperparameter in one struct. The defaults are those of the HER baselines
//! (Andrychowicz et al., "Hindsight Experience Replay", NeurIPS 2017; OpenAI baselines,
//! `her/experiment/config.py`, `DEFAULT_PARAMS`), which Li et al. trained with. TD3's changes
//! to DDPG are options beside them, off by default ([`DdpgHerConfig::with_td3`]).

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DdpgHerConfig {
    /// Hidden layers of both networks (baselines: `layers` 3, `hidden` 256; the paper's 3x256).
    pub hidden: Vec<usize>,
    /// Adam learning rate of the actor (`pi_lr`).
    pub actor_lr: f64,
    /// Adam learning rate of the critic (`Q_lr`).
    pub critic_lr: f64,
    /// Transitions per optimisation batch (`batch_size`).
    pub batch_size: usize,
    /// Target networks keep this share of themselves at each update (`polyak`).
    pub polyak: f64,
    /// Weight of the squared-action penalty in the actor's loss (`action_l2`).
    pub action_l2: f64,
    /// Discount; baselines use 1 - 1/T with T the episode length (100 here).
    pub gamma: f64,
    /// Replay capacity in transitions (`buffer_size`).
    pub buffer_size: usize,
    /// HER "future" relabelling: k relabelled goals per real one, probability k/(k+1) = 0.8.
    pub replay_k: usize,
    /// Relabel with Hindsight Experience Replay; off gives plain DDPG, for ablations.
    pub her: bool,
    /// Normalised inputs are clipped to ±this (`norm_clip`).
    pub norm_clip: f64,
    /// Smallest standard deviation a normaliser divides by (`norm_eps`).
    pub norm_eps: f64,
    /// Raw observations and goals are clipped to ±this first (`clip_obs`).
    pub clip_obs: f64,
    /// Gaussian exploration noise, as a share of the action range (`noise_eps`).
    pub noise_eps: f64,
    /// Probability of a uniformly random action while exploring (`random_eps`).
    pub random_eps: f64,
    /// Cycles per epoch (`n_cycles`).
    pub cycles_per_epoch: usize,
    /// Optimisation batches per cycle (`n_batches`).
    pub batches_per_cycle: usize,
    /// Deterministic test episodes per epoch (`n_test_rollouts`).
    pub test_episodes: usize,
    /// Weight of a penalty on the actor's squared distance from the actor it was warm-started
    /// with (the anchor), in its loss beside `action_l2`. Not in DDPG or the baselines (0):
    /// behaviour regularisation towards a reference policy, as TD3+BC (Fujimoto and Gu,
    /// NeurIPS 2021) regularises towards the data, for fine-tuning a policy that already
    /// works on a new object without its first updates undoing it.
    pub anchor: f64,
    /// TD3's clipped double-Q learning (Fujimoto, van Hoof and Meger, "Addressing Function
    /// Approximation Error in Actor-Critic Methods", ICML 2018): a second critic with its own
    /// target, and regression targets from the smaller of the two target critics, against
    /// DDPG's overestimation. Not in DDPG (false).
    pub twin_critics: bool,
    /// TD3's target policy smoothing: the standard deviation of Gaussian noise added to the
    /// target actor's action in the targets, as a share of the action range (TD3: 0.2;
    /// DDPG: 0).
    pub target_noise: f64,
    /// The smoothing noise is clipped to ±this (TD3: 0.5).
    pub target_noise_clip: f64,
    /// The actor learns on every this many optimisation steps, the critics on all of them
    /// (TD3's delayed policy updates: 2; DDPG: 1). The targets follow once per cycle, as in
    /// the HER baselines, for both.
    pub policy_delay: usize,
    /// What a terminal failure (the object dropped) is worth in the critic's targets, as a
    /// multiple of the absorbing floor -1/(1-γ), the targets' clip widened to match
    /// ([`DdpgHerConfig::lowest_target`]; 1: the floor, the return of missing for ever).
    /// Above 1 a drop costs more than any run of misses can, as it does in the operator,
    /// where a drop loses the cube and a miss costs one more try. Not in DDPG or the
    /// baselines, whose tasks have no terminal states (1).
    pub drop_cost: f64,
}

impl Default for DdpgHerConfig {
    fn default() -> Self {
        DdpgHerConfig {
            hidden: vec![256, 256, 256],
            actor_lr: 1e-3,
            critic_lr: 1e-3,
            batch_size: 256,
            polyak: 0.95,
            action_l2: 1.0,
            gamma: 1.0 - 1.0 / 100.0,
            buffer_size: 1_000_000,
            replay_k: 4,
            her: true,
            norm_clip: 5.0,
            norm_eps: 0.01,
            clip_obs: 200.0,
            noise_eps: 0.2,
            random_eps: 0.3,
            cycles_per_epoch: 50,
            batches_per_cycle: 40,
            test_episodes: 10,
            anchor: 0.0,
            twin_critics: false,
            target_noise: 0.0,
            target_noise_clip: 0.5,
            policy_delay: 1,
            drop_cost: 1.0,
        }
    }
}

impl DdpgHerConfig {
    /// This configuration with TD3's three changes to DDPG at Fujimoto et al.'s values (twin
    /// critics, target policy smoothing 0.2 clipped to 0.5, the actor updated every second
    /// step); everything else, HER included, as it was.
    pub fn with_td3(self) -> Self {
        DdpgHerConfig {
            twin_critics: true,
            target_noise: 0.2,
            target_noise_clip: 0.5,
            policy_delay: 2,
            ..self
        }
    }

    /// 1/(1-γ): the floor, what missing for ever is worth below 0 (baselines' `clip_return`).
    pub fn clip_return(&self) -> f64 {
        1.0 / (1.0 - self.gamma)
    }

    /// The lowest target, -drop_cost/(1-γ): what a drop is worth, and where the targets are
    /// clipped below (the range of a sparse -1/0 return, widened by the drop's cost).
    pub fn lowest_target(&self) -> f64 {
        -self.drop_cost * self.clip_return()
    }

    /// Probability that a sampled transition gets a relabelled goal.
    pub fn future_probability(&self) -> f64 {
        if self.her {
            1.0 - 1.0 / (1.0 + self.replay_k as f64)
        } else {
            0.0
        }
    }
}
