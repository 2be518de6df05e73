"""Control steps per second of dexcube's environments from Python, beside Gymnasium-Robotics'.

``python -m dexcube.bench`` times, in one run on this machine:

- one ``dexcube/CubeRot-v0`` (the hand and the rigid cube) stepped from Python;
- the vector env of 8 of them on 1 and on 2 Rust threads;
- Gymnasium-Robotics' ``HandManipulateBlockRotateXYZ-v1`` (the same hand and MuJoCo), when
  ``gymnasium-robotics`` is installed. Its 1.4.2 compares a joint type read as a NumPy
  integer against MuJoCo's enum and fails an assertion on MuJoCo 3.17; the bench reads the
  type as the enum, the one change it makes.

Every environment takes uniformly random actions drawn from a seed. Figures are medians of
``--repeats`` timed runs, and ratios are taken within the run, since machines are noisy.
"""

from __future__ import annotations

import argparse
import statistics
import time

import gymnasium
import numpy as np

import dexcube


def steps_per_second(step, steps: int, repeats: int) -> float:
    rates = []
    for _ in range(repeats):
        start = time.perf_counter()
        step(steps)
        rates.append(steps / (time.perf_counter() - start))
    return statistics.median(rates)


def single(env, seed: int):
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)

    def run(steps: int) -> None:
        for _ in range(steps):
            _, _, terminated, truncated, _ = env.step(rng.uniform(-1, 1, env.action_space.shape))
            if terminated or truncated:
                env.reset()

    return run


def vector(env, seed: int):
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)

    def run(steps: int) -> None:
        for _ in range(steps // env.num_envs):
            env.step(rng.uniform(-1, 1, (env.num_envs, 20)))

    return run


def gymnasium_robotics_env():
    """HandManipulateBlockRotateXYZ-v1 with its joint types read as MuJoCo's enum, or None."""
    try:
        import gymnasium_robotics
        import mujoco
        from gymnasium_robotics.utils import mujoco_utils
    except ImportError:
        return None
    source = open(mujoco_utils.__file__).read()
    fixed = source.replace(
        "joint_type = model.jnt_type[joint_id]",
        "joint_type = mujoco.mjtJoint(int(model.jnt_type[joint_id]))",
    )
    exec(compile(fixed, mujoco_utils.__file__, "exec"), mujoco_utils.__dict__)
    assert mujoco_utils.mujoco is mujoco
    gymnasium.register_envs(gymnasium_robotics)
    # Its environments import the helpers by name: point them at the fixed ones.
    from gymnasium_robotics.envs.shadow_dexterous_hand import manipulate

    for name in ("get_joint_qpos", "set_joint_qpos", "get_joint_qvel", "set_joint_qvel"):
        for module in (manipulate, getattr(manipulate, "mujoco_utils", None)):
            if module is not None and hasattr(module, name):
                setattr(module, name, getattr(mujoco_utils, name))
    return gymnasium.make("HandManipulateBlockRotateXYZ-v1")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m dexcube.bench", description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=2000, help="control steps per timed run")
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per figure (median)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    rows = []
    one = steps_per_second(single(gymnasium.make("dexcube/CubeRot-v0"), args.seed), args.steps, args.repeats)
    rows.append(("dexcube/CubeRot-v0, one env", one))
    for threads in (1, 2):
        env = dexcube.make_vec("dexcube/CubeRot-v0", num_envs=8, num_threads=threads)
        rate = steps_per_second(vector(env, args.seed), args.steps, args.repeats)
        rows.append((f"dexcube/CubeRot-v0, vector of 8 on {threads} thread(s)", rate))
    theirs = gymnasium_robotics_env()
    if theirs is not None:
        rate = steps_per_second(single(theirs, args.seed), args.steps, args.repeats)
        rows.append(("Gymnasium-Robotics HandManipulateBlockRotateXYZ-v1, one env", rate))
    print(f"control steps/s, median of {args.repeats} runs of {args.steps} steps, seed {args.seed}")
    for name, rate in rows:
        print(f"  {name:<62} {rate:>8.0f}  ({rate / one:.2f}x one dexcube env)")
    if theirs is None:
        print("  (pip install gymnasium-robotics==1.4.2 to time Gymnasium-Robotics beside it)")
    else:
        print(f"  one dexcube env against Gymnasium-Robotics': {one / rows[-1][1]:.2f}x")


if __name__ == "__main__":
    main()
