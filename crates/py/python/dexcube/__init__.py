"""dexcube: a simulated 24-DoF Shadow Hand learning to solve a 2x2x2 Rubik's cube.

Importing it registers two goal-conditioned Gymnasium environments in Gymnasium-Robotics'
shape (a ``Dict`` observation of ``observation``, ``achieved_goal`` and ``desired_goal``,
and a vectorised ``compute_reward`` for HER):

- ``dexcube/CubeRot-v0`` (Stage 1, CubeRotEnv): re-pose the cube on the palm;
- ``dexcube/LayerOp-v0`` (Stage 2, LayerOpEnv): turn a layer of the physical cube.

``make_vec`` steps many of them on Rust threads with the GIL released. ``solve`` and
``scramble`` are the optimal planner; ``Policy`` loads a shipped or trained policy.
"""

from __future__ import annotations

import gymnasium

from ._dexcube import Policy, apply_moves, scramble, solve
from .envs import CubeRotEnv, DexcubeGoalEnv, LayerOpEnv, PhysicsError
from .vector import DexcubeVectorEnv, make_vec

__all__ = [
    "CubeRotEnv",
    "DexcubeGoalEnv",
    "DexcubeVectorEnv",
    "LayerOpEnv",
    "PhysicsError",
    "Policy",
    "apply_moves",
    "make_vec",
    "scramble",
    "solve",
]

for _id, _entry in (
    ("dexcube/CubeRot-v0", "dexcube.envs:CubeRotEnv"),
    ("dexcube/LayerOp-v0", "dexcube.envs:LayerOpEnv"),
):
    if _id not in gymnasium.registry:
        # The environments end their own episodes (100 control steps), so no TimeLimit.
        gymnasium.register(id=_id, entry_point=_entry)
