"""CubeRotEnv and LayerOpEnv as Gymnasium environments, over the Rust environments.

Keyword arguments are the settings ``dexcube env`` takes as flags, under the flags' names
(``see_misalignment`` for ``--see-misalignment``): ``mode``, ``object``, ``square``,
``intact``, ``turn_ends``, ``see_misalignment``, ``see_grip``, ``control_substeps``,
``angle_threshold`` and ``physics_spread`` for both, and ``move`` and ``quarter_goals`` for
LayerOpEnv. A setting that does not fit raises ``ValueError`` saying why.
"""

from __future__ import annotations

import json
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from . import _dexcube


class PhysicsError(RuntimeError):
    """The simulation blew up during a step; reset the environment to go on."""


def _settings_json(settings: dict[str, Any]) -> str:
    return json.dumps({k: v for k, v in settings.items() if v is not None})


def goal_spaces(obs: int, goal: int, act: int) -> tuple[spaces.Dict, spaces.Box]:
    """The observation and action spaces of an environment of these sizes."""
    box = lambda n: spaces.Box(-np.inf, np.inf, shape=(n,), dtype=np.float64)  # noqa: E731
    observation = spaces.Dict(
        {"observation": box(obs), "achieved_goal": box(goal), "desired_goal": box(goal)}
    )
    return observation, spaces.Box(-1.0, 1.0, shape=(act,), dtype=np.float32)


def rewards(raw, achieved_goal, desired_goal, goal_size: int) -> np.ndarray:
    """The sparse rewards (0 on success, else -1) of goals of any leading shape."""
    achieved = np.asarray(achieved_goal, dtype=np.float64)
    desired = np.asarray(desired_goal, dtype=np.float64)
    if achieved.shape != desired.shape or achieved.shape[-1:] != (goal_size,):
        raise ValueError(
            f"achieved and desired goals must have the same shape ending in {goal_size}, "
            f"not {achieved.shape} and {desired.shape}"
        )
    flat = raw.compute_reward(achieved.ravel().tolist(), desired.ravel().tolist())
    return np.asarray(flat, dtype=np.float64).reshape(achieved.shape[:-1])


class DexcubeGoalEnv(gymnasium.Env):
    """A goal-conditioned hand environment; ``skill`` is ``"rot"`` or ``"layer"``."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}

    def __init__(
        self,
        skill: str,
        render_mode: str | None = None,
        width: int = 480,
        height: int = 360,
        **settings: Any,
    ) -> None:
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', not {render_mode!r}")
        self._env = _dexcube.Env(skill, _settings_json(settings))
        self.skill, self.settings = skill, settings
        self.render_mode, self._size = render_mode, (width, height)
        obs, goal, act = self._env.spaces()
        self._goal_size = goal
        self.observation_space, self.action_space = goal_spaces(obs, goal, act)

    @property
    def label(self) -> str:
        """The environment's name, as runs and policy cards name it."""
        return self._env.label

    @staticmethod
    def _obs(parts) -> dict[str, np.ndarray]:
        o, a, d = parts
        return {
            "observation": np.asarray(o, dtype=np.float64),
            "achieved_goal": np.asarray(a, dtype=np.float64),
            "desired_goal": np.asarray(d, dtype=np.float64),
        }

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        parts, info = self._env.reset(seed)
        return self._obs(parts), info

    def step(self, action):
        action = np.asarray(action, dtype=np.float64).reshape(-1)
        parts, reward, terminated, truncated, info = self._env.step(action.tolist())
        if info["physics_error"] is not None:
            raise PhysicsError(info["physics_error"])
        return self._obs(parts), reward, terminated, truncated, info

    def compute_reward(self, achieved_goal, desired_goal, info=None) -> np.ndarray:
        """The rewards ``step`` gives for these goals, over a batch (for HER relabelling)."""
        return rewards(self._env, achieved_goal, desired_goal, self._goal_size)

    def compute_terminated(self, achieved_goal, desired_goal, info=None) -> bool:
        """Only a drop or a blow-up ends an episode early; success does not."""
        return bool(info and (info.get("dropped") or info.get("physics_error")))

    def compute_truncated(self, achieved_goal, desired_goal, info=None) -> bool:
        return False

    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array":
            return None
        width, height, rgb = self._env.render(*self._size)
        return np.frombuffer(rgb, dtype=np.uint8).reshape(height, width, 3)


class CubeRotEnv(DexcubeGoalEnv):
    """Stage 1: re-pose the cube on the palm (``mode`` paper, axis or pair)."""

    def __init__(self, render_mode: str | None = None, **settings: Any) -> None:
        super().__init__("rot", render_mode=render_mode, **settings)


class LayerOpEnv(DexcubeGoalEnv):
    """Stage 2: turn a layer of the cube (``move`` U U' R R' F F', U' by default)."""

    def __init__(self, render_mode: str | None = None, **settings: Any) -> None:
        super().__init__("layer", render_mode=render_mode, **settings)
