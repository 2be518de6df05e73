"""The solver, the shipped policies and bad input, from Python."""

import csv
import subprocess

import gymnasium
import numpy as np
import pytest

import dexcube
from conftest import DEXCUBE, MODELS


def test_the_solver_and_scrambles_use_the_cli_s_convention():
    assert dexcube.solve("UFUFRRRRFDFDDBDBLLLLUBUB") == ["R'"]
    assert dexcube.solve("UUUURRRRFFFFDDDDLLLLBBBB") == []
    for facelets, moves in dexcube.scramble(7, count=5, seed=3):
        assert len(moves) == 7
        assert dexcube.apply_moves(" ".join(moves)) == facelets
        assert len(dexcube.solve(facelets, method="ida")) == 7
    cli = subprocess.run(
        [DEXCUBE, "scramble", "--distance", "7", "--count", "5", "--seed", "3"],
        capture_output=True, text=True, check=True,
    )
    assert cli.stdout.split() == [f for f, _ in dexcube.scramble(7, count=5, seed=3)]


def test_a_shipped_policy_runs_its_episodes_as_eval_stage_does(tmp_path):
    seed, episodes = 5, 3
    episodes_csv = tmp_path / "episodes.csv"
    subprocess.run(
        [DEXCUBE, "eval-stage", "rot", "--object", "rigid", "--rot-policy", MODELS / "rot-rigid",
         "--episodes", str(episodes), "--seed", str(seed), "--threads", "1",
         "--episodes-csv", episodes_csv],
        capture_output=True, check=True,
    )
    rows = list(csv.DictReader(episodes_csv.open()))
    policy = dexcube.Policy.load(str(MODELS / "rot-rigid"))
    env = gymnasium.make("dexcube/CubeRot-v0", mode="pair", object="rigid")
    for k, row in enumerate(rows):
        obs, _ = env.reset(seed=seed + k)
        while True:
            action = policy.act(obs["observation"].tolist(), obs["desired_goal"].tolist())
            obs, _, terminated, truncated, info = env.step(action)
            if terminated or truncated:
                break
        assert row["ending"] == ("success" if info["is_success"] else row["ending"])
        assert info["is_success"] == (row["ending"] == "success")
        assert f"{info['angle_error']:.6f}" == row["angle_error"], f"episode {k}"
        assert f"{info['position_error']:.6f}" == row["position_error"], f"episode {k}"


@pytest.mark.parametrize(
    "call, says",
    [
        (lambda: dexcube.solve("uuuuRRRRFFFFDDDDLLLLBBBB"), "lower-case 'u'"),
        (lambda: dexcube.solve("UUUURRRRFFFFDDDDLLLLBBB"), "wrong length"),
        (lambda: dexcube.apply_moves("R u"), "cannot read the moves"),
        (lambda: dexcube.scramble(15), "largest distance is 14"),
        (lambda: dexcube.Policy.load("/no/such/policy"), "/no/such/policy"),
        (lambda: gymnasium.make("dexcube/LayerOp-v0", move="X"), "X"),
        (lambda: gymnasium.make("dexcube/CubeRot-v0", see_grip=True), "see_grip is for the physical cube"),
        (lambda: gymnasium.make("dexcube/CubeRot-v0", colour="red"), "unknown field `colour`"),
        (lambda: gymnasium.make("dexcube/CubeRot-v0", control_substeps=3), "3 substeps"),
        (lambda: dexcube.make_vec("dexcube/Nothing-v0"), "unknown environment"),
        (lambda: dexcube.make_vec("dexcube/CubeRot-v0", num_envs=0), "at least 1"),
    ],
)
def test_bad_input_raises_with_its_reason(call, says):
    with pytest.raises(ValueError, match=None) as raised:
        call()
    assert says in str(raised.value)


def test_a_policy_given_the_wrong_sizes_and_an_env_given_a_bad_action_raise():
    policy = dexcube.Policy.load(str(MODELS / "rot-rigid"))
    with pytest.raises(ValueError, match="an observation of 61 numbers and a goal of 7"):
        policy.act([0.0] * 3, [0.0] * 7)
    env = gymnasium.make("dexcube/CubeRot-v0").unwrapped
    env.reset(seed=0)
    with pytest.raises(ValueError, match="an action has 20 numbers, not 3"):
        env.step(np.zeros(3))
    vec = dexcube.make_vec("dexcube/CubeRot-v0", num_envs=2, num_threads=1)
    vec.reset(seed=0)
    with pytest.raises(ValueError):
        vec.step(np.zeros((2, 3)))
