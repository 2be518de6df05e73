"""The Gymnasium environments: Gymnasium's own checks, HER's reward, seeding, rendering."""

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import dexcube


@pytest.mark.parametrize(
    "env_id, settings",
    [
        ("dexcube/CubeRot-v0", {}),
        ("dexcube/CubeRot-v0", {"mode": "pair", "object": "cube", "square": True, "see_misalignment": True}),
        ("dexcube/LayerOp-v0", {"move": "U'"}),
        ("dexcube/LayerOp-v0", {"object": "block", "quarter_goals": True}),
    ],
)
def test_gymnasium_check_env_passes(env_id, settings):
    env = gymnasium.make(env_id, **settings)
    check_env(env.unwrapped, skip_render_check=True)


def test_the_spaces_follow_the_settings():
    sizes = lambda env: {k: s.shape for k, s in env.observation_space.spaces.items()}  # noqa: E731
    assert sizes(gymnasium.make("dexcube/CubeRot-v0")) == {
        "observation": (61,), "achieved_goal": (7,), "desired_goal": (7,)
    }
    seen = gymnasium.make("dexcube/LayerOp-v0", square=True, see_misalignment=True)
    assert sizes(seen) == {"observation": (63,), "achieved_goal": (2,), "desired_goal": (2,)}
    assert seen.action_space.shape == (20,)
    assert seen.unwrapped.label == "LayerOpEnv (U', cube, left square, misalignment seen)"


def test_compute_reward_agrees_with_step_over_relabelled_goals():
    env = gymnasium.make("dexcube/CubeRot-v0", mode="axis").unwrapped
    obs, _ = env.reset(seed=3)
    achieved, desired, rewards = [], [], []
    for _ in range(40):
        obs, reward, terminated, truncated, _ = env.step(np.zeros(20))
        achieved.append(obs["achieved_goal"])
        desired.append(obs["desired_goal"])
        rewards.append(reward)
    achieved, desired = np.array(achieved), np.array(desired)
    assert np.array_equal(env.compute_reward(achieved, desired, None), rewards)
    # Relabelled as HER does: each step's goal replaced by a later achieved goal.
    later = np.roll(achieved, -5, axis=0)
    relabelled = env.compute_reward(achieved, later, None)
    assert relabelled.shape == (40,)
    assert set(np.unique(relabelled)) <= {0.0, -1.0}
    # Its own achieved goal is a success: the sparse reward's 0.
    assert np.array_equal(env.compute_reward(achieved, achieved, None), np.zeros(40))
    # Any leading shape, as a replay buffer batches them.
    assert env.compute_reward(achieved.reshape(4, 10, 7), desired.reshape(4, 10, 7), None).shape == (4, 10)


def trajectory(env, seed, steps=30):
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    rows = [obs["observation"]]
    for _ in range(steps):
        obs, *_ = env.step(rng.uniform(-1, 1, 20))
        rows.append(obs["observation"])
    return np.array(rows)


def test_the_same_seed_gives_the_same_trajectory():
    env = gymnasium.make("dexcube/LayerOp-v0")
    first, again = trajectory(env, 11), trajectory(env, 11)
    assert np.array_equal(first, again)
    assert not np.array_equal(first, trajectory(env, 12))


def test_a_vector_env_steps_as_its_environments_do_on_any_thread_count():
    seed, steps, n = 21, 25, 3
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1, 1, (steps, n, 20))
    runs = []
    for threads in (1, 2):
        vec = dexcube.make_vec("dexcube/CubeRot-v0", num_envs=n, num_threads=threads, mode="pair")
        obs, _ = vec.reset(seed=seed)
        rows = [obs["observation"]]
        for a in actions:
            obs, reward, terminated, truncated, _ = vec.step(a)
            rows.append(obs["observation"])
        runs.append(np.array(rows))
    assert np.array_equal(runs[0], runs[1]), "the thread count changes nothing"
    # Environment i of the vector is the environment reset with seed + i.
    single = gymnasium.make("dexcube/CubeRot-v0", mode="pair").unwrapped
    for i in range(n):
        obs, _ = single.reset(seed=seed + i)
        rows = [obs["observation"]]
        for a in actions:
            obs, *_ = single.step(a[i])
            rows.append(obs["observation"])
        assert np.array_equal(np.array(rows), runs[0][:, i]), f"environment {i}"


def test_a_vector_env_resets_an_ended_episode_in_the_same_step():
    vec = dexcube.make_vec("dexcube/CubeRot-v0", num_envs=2, num_threads=1)
    vec.reset(seed=0)
    ended_at = None
    for t in range(101):
        obs, reward, terminated, truncated, infos = vec.step(np.zeros((2, 20)))
        if truncated.any():
            ended_at = t
            break
    assert ended_at == 99, "an episode is 100 control steps"
    assert infos["_final_obs"].all()
    final = infos["final_obs"][0]["observation"]
    assert not np.array_equal(final, obs["observation"][0]), "the row starts the next episode"
    assert vec.compute_reward(obs["achieved_goal"], obs["achieved_goal"]).tolist() == [0.0, 0.0]


def test_rgb_array_frames_come_from_the_offscreen_renderer():
    env = gymnasium.make("dexcube/CubeRot-v0", render_mode="rgb_array", width=64, height=48)
    env.reset(seed=0)
    frame = env.render()
    assert frame.shape == (48, 64, 3) and frame.dtype == np.uint8
    assert frame.std() > 0, "a picture, not a blank"
