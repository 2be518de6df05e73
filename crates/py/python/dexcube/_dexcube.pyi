"""The Rust side of dexcube (crates/py): the environments, the vector env, the planner and
the policies. Use them through ``dexcube`` and Gymnasium rather than directly."""

from os import PathLike

Parts = tuple[list[float], list[float], list[float]]
"""An observation's three parts: observation, achieved goal, desired goal."""

class Env:
    """One CubeRotEnv (``skill="rot"``) or LayerOpEnv (``"layer"``), built from an
    environment's settings as JSON (the names of ``dexcube env``'s flags)."""

    def __init__(self, skill: str, settings: str) -> None: ...
    @property
    def label(self) -> str: ...
    def spaces(self) -> tuple[int, int, int]:
        """(observation, goal, action) sizes."""
    def reset(self, seed: int | None = None) -> tuple[Parts, dict]: ...
    def step(self, action: list[float]) -> tuple[Parts, float, bool, bool, dict]: ...
    def compute_reward(self, achieved: list[float], desired: list[float]) -> list[float]:
        """The rewards of rows of goals, flattened row after row."""
    def render(self, width: int = 480, height: int = 360) -> tuple[int, int, bytes]:
        """(width, height, RGB bytes, rows top to bottom)."""

class VecEnv:
    """``num_envs`` environments stepped on ``num_threads`` Rust threads, the GIL released."""

    def __init__(self, skill: str, settings: str, num_envs: int, num_threads: int) -> None: ...
    def __len__(self) -> int: ...
    def spaces(self) -> tuple[int, int, int]: ...
    def reset(self, seed: int | None = None) -> tuple: ...
    def step(self, actions: bytes) -> tuple:
        """Actions as float64 bytes, environments x action size. Returns the flattened
        observations, achieved goals, desired goals and rewards as float64 bytes, then per
        environment terminated, truncated, success, dropped, the final observation of an
        episode that ended (else None) and any physics error."""
    def compute_reward(self, achieved: list[float], desired: list[float]) -> list[float]: ...

class Policy:
    """A trained policy (a shipped one under ``models/``, or ``DIR/policy`` of a run)."""

    @staticmethod
    def load(prefix: str | PathLike[str]) -> Policy: ...
    @property
    def label(self) -> str: ...
    def spaces(self) -> tuple[int, int, int]: ...
    def act(self, observation: list[float], goal: list[float]) -> list[float]:
        """The deterministic action (an ensemble's: its members' mean)."""

def solve(facelets: str, method: str = "table") -> list[str]:
    """An optimal quarter-turn solution of 24 facelet letters, faces in order U R F D L B."""

def apply_moves(moves: str) -> str:
    """The cube a move sequence such as "R U F' D2" makes from solved."""

def scramble(distance: int, count: int = 1, seed: int = 0) -> list[tuple[str, list[str]]]:
    """``count`` cubes drawn uniformly at ``distance`` quarter turns: (facelets, moves)."""
