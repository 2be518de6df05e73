//! What the learner's integration tests share: a small, quick configuration and a fresh
//! folder for a run.

use dexcube_rl::DdpgHerConfig;

/// The published configuration on small networks and short epochs, for runs of seconds.
pub fn config() -> DdpgHerConfig {
    DdpgHerConfig {
        hidden: vec![32, 32],
        cycles_per_epoch: 3,
        batches_per_cycle: 5,
        test_episodes: 4,
        ..DdpgHerConfig::default()
    }
}

/// An empty folder `name` under the system's temporary one, whatever an earlier run left.
pub fn fresh_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}
