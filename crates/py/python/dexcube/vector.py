"""Many dexcube environments stepped on Rust threads, behind Gymnasium's ``VectorEnv``.

The physics runs with the GIL released, and arrays cross as one buffer each, not per
environment. An environment whose episode ends is reset in the same step (Gymnasium's
same-step autoreset): its row holds the next episode's first observation, and
``infos["final_obs"]`` the last one, marked in ``infos["_final_obs"]``. A physics blow-up
ends that environment's episode (``terminated``) and is named in ``infos["physics_error"]``.
"""

from __future__ import annotations

import json
from typing import Any

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import _dexcube
from .envs import _settings_json, goal_spaces, rewards

_SKILLS = {"dexcube/CubeRot-v0": "rot", "dexcube/LayerOp-v0": "layer"}


class DexcubeVectorEnv(VectorEnv):
    """``num_envs`` environments of one kind, stepped on ``num_threads`` Rust threads."""

    metadata = {"autoreset_mode": AutoresetMode.SAME_STEP}

    def __init__(self, skill: str, num_envs: int = 8, num_threads: int = 2, **settings: Any):
        self._envs = _dexcube.VecEnv(skill, _settings_json(settings), num_envs, num_threads)
        obs, goal, act = self._envs.spaces()
        self._sizes = (obs, goal, act)
        self.num_envs = num_envs
        self.single_observation_space, self.single_action_space = goal_spaces(obs, goal, act)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)

    def _unpack(self, out, resetting: bool):
        (obs, achieved, desired, reward), terminated, truncated, success, dropped, finals, errors = out
        n, (o, g, _) = self.num_envs, self._sizes
        rows = lambda b, k: np.frombuffer(b, dtype=np.float64).reshape(n, k).copy()  # noqa: E731
        observation = {
            "observation": rows(obs, o),
            "achieved_goal": rows(achieved, g),
            "desired_goal": rows(desired, g),
        }
        infos: dict[str, Any] = {
            "is_success": np.asarray(success),
            "_is_success": np.ones(n, dtype=bool),
            "dropped": np.asarray(dropped),
            "_dropped": np.ones(n, dtype=bool),
        }
        ended = np.asarray([f is not None for f in finals])
        if ended.any():
            final = np.empty(n, dtype=object)
            for i, parts in enumerate(finals):
                if parts is not None:
                    final[i] = {
                        key: np.asarray(part, dtype=np.float64)
                        for key, part in zip(("observation", "achieved_goal", "desired_goal"), parts)
                    }
            infos["final_obs"], infos["_final_obs"] = final, ended
        if any(e is not None for e in errors):
            infos["physics_error"] = np.asarray(errors, dtype=object)
            infos["_physics_error"] = np.asarray([e is not None for e in errors])
        if resetting:
            return observation, infos
        reward = np.frombuffer(reward, dtype=np.float64).copy()
        return observation, reward, np.asarray(terminated), np.asarray(truncated), infos

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Resets every environment, environment i with ``seed + i``."""
        if seed is not None:
            self._np_random, self._np_random_seed = gymnasium.utils.seeding.np_random(seed)
        return self._unpack(self._envs.reset(seed), resetting=True)

    def step(self, actions):
        actions = np.ascontiguousarray(actions, dtype=np.float64).reshape(self.num_envs, -1)
        return self._unpack(self._envs.step(actions.tobytes()), resetting=False)

    def compute_reward(self, achieved_goal, desired_goal, info=None) -> np.ndarray:
        """The rewards ``step`` gives for these goals, over a batch (for HER relabelling)."""
        return rewards(self._envs, achieved_goal, desired_goal, self._sizes[1])


def make_vec(env_id: str, num_envs: int = 8, num_threads: int = 2, **settings: Any) -> DexcubeVectorEnv:
    """``num_envs`` environments of the registered ``env_id`` (``dexcube/CubeRot-v0`` or
    ``dexcube/LayerOp-v0``), stepped on ``num_threads`` Rust threads; settings as for
    ``gymnasium.make``."""
    if env_id not in _SKILLS:
        raise ValueError(f"unknown environment {env_id!r}: use one of {sorted(_SKILLS)}")
    return DexcubeVectorEnv(_SKILLS[env_id], num_envs, num_threads, **settings)
