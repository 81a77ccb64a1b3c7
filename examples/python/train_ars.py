"""Augmented Random Search (Mania, Guy & Recht 2018, ARS V2-t; NumPy only)
teaches the hexapod of ``fbd/HexapodWalk-v0`` to walk forward: a linear
policy ``a = clip(M·(s − μ)/σ, −1, 1)`` from the 60 observations (with the
gait clock) to the 18 joint targets, trained on the vector environment
(every rollout of an iteration stepped at once on Rust threads, the GIL
released).

    python examples/python/train_ars.py                      # a few minutes on 2 cores
    python examples/python/train_ars.py --iterations 2 --directions 2 \\
        --episode-seconds 0.2                                # CI smoke run
    python examples/python/train_ars.py --csv curve.csv --plot curve.png

Each iteration draws ``--directions`` random directions δ of ``M``,
rolls out ``M ± ν·δ`` on the same seed per pair (1 episode each) and the
unperturbed policy on ``--eval-envs`` fixed seeds (its return is the
learning curve), and moves ``M`` by ``α/(b·σ_R)·Σ (r₊ − r₋)·δ`` over the
``--top`` best directions; ``μ``, ``σ`` are the running mean and standard
deviation of the states seen. Prints one line per iteration and what the
final policy does (distance walked, sliding feet); ``--csv``
writes ``iteration, eval_return, mean_return, seconds``; ``--plot`` draws
the learning curve (needs matplotlib). The state statistics start from
one rollout of the zero policy per sub-environment.
"""

from __future__ import annotations

import argparse
import csv
import time
from typing import List, Tuple

import gymnasium
import numpy as np

import fbd  # noqa: F401  (registers fbd/HexapodWalk-v0)


class RunningStats:
    """Running mean and variance of the observations (Welford, batched)."""

    def __init__(self, n: int) -> None:
        self.count = 0
        self.mean = np.zeros(n)
        self.m2 = np.zeros(n)

    def push(self, x: np.ndarray) -> None:
        for row in np.atleast_2d(x):
            self.count += 1
            d = row - self.mean
            self.mean += d / self.count
            self.m2 += d * (row - self.mean)

    @property
    def std(self) -> np.ndarray:
        if self.count < 2:
            return np.ones_like(self.mean)
        s = np.sqrt(self.m2 / (self.count - 1))
        return np.where(s < 1e-8, 1.0, s)


def rollouts(
    venv: "gymnasium.vector.VectorEnv",
    policies: np.ndarray,
    mean: np.ndarray,
    std: np.ndarray,
    seeds: List[int],
) -> Tuple[np.ndarray, np.ndarray]:
    """One episode per sub-environment, sub-environment i driven by
    ``policies[i]``: the returns and the states seen."""
    n = len(policies)
    obs, _ = venv.reset(seed=seeds)
    returns = np.zeros(n)
    done = np.zeros(n, dtype=bool)
    states = [obs]
    while not done.all():
        x = (obs - mean) / std
        actions = np.clip(np.einsum("nij,nj->ni", policies, x), -1.0, 1.0)
        obs, reward, term, trunc, _ = venv.step(actions)
        returns += np.where(done, 0.0, reward)
        live = ~done
        done |= term | trunc
        states.append(obs[live & ~(term | trunc)])
    return returns, np.concatenate(states)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--iterations", type=int, default=60)
    p.add_argument("--directions", type=int, default=8, help="N: directions per iteration")
    p.add_argument("--top", type=int, default=4, help="b: best directions used in the update")
    p.add_argument("--step-size", type=float, default=0.02, help="α")
    p.add_argument("--noise", type=float, default=0.02, help="ν")
    p.add_argument("--eval-envs", type=int, default=2)
    p.add_argument("--episode-seconds", type=float, default=2.0)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--csv", help="write the learning curve here")
    p.add_argument("--save", help="write the policy (M, mean, std) here (.npz)")
    p.add_argument("--plot", help="draw the learning curve here (PNG or SVG)")
    args = p.parse_args()

    n, b, e = args.directions, min(args.top, args.directions), args.eval_envs
    venv = gymnasium.make_vec(
        "fbd/HexapodWalk-v0",
        num_envs=2 * n + e,
        vectorization_mode="vector_entry_point",
        episode_seconds=args.episode_seconds,
    )
    obs_dim = venv.single_observation_space.shape[0]
    act_dim = venv.single_action_space.shape[0]
    rng = np.random.default_rng(args.seed)
    m = np.zeros((act_dim, obs_dim))
    stats = RunningStats(obs_dim)
    eval_seeds = [10_000 + i for i in range(e)]
    curve = []
    start = time.perf_counter()
    # The state statistics of the initial (zero) policy first.
    _, states = rollouts(venv, np.zeros((2 * n + e, act_dim, obs_dim)), stats.mean, stats.std, list(range(2 * n + e)))
    stats.push(states)
    for it in range(args.iterations + 1):
        deltas = rng.standard_normal((n, act_dim, obs_dim))
        policies = np.concatenate([m + args.noise * deltas, m - args.noise * deltas, np.repeat(m[None], e, 0)])
        pair_seeds = [int(s) for s in rng.integers(0, 2**31, size=n)]
        seeds = pair_seeds + pair_seeds + eval_seeds
        mean, std = stats.mean.copy(), stats.std.copy()
        returns, states = rollouts(venv, policies, mean, std, seeds)
        stats.push(states)
        plus, minus, evals = returns[:n], returns[n : 2 * n], returns[2 * n :]
        elapsed = time.perf_counter() - start
        curve.append((it, float(evals.mean()), float(returns[: 2 * n].mean()), elapsed))
        print(
            f"iteration {it:3d}  eval return {evals.mean():8.3f}  "
            f"mean of rollouts {returns[:2 * n].mean():8.3f}  {elapsed:6.1f} s",
            flush=True,
        )
        if it == args.iterations:
            break
        best = np.argsort(-np.maximum(plus, minus))[:b]
        sigma = np.concatenate([plus[best], minus[best]]).std()
        sigma = sigma if sigma > 1e-8 else 1.0
        step = np.einsum("k,kij->ij", plus[best] - minus[best], deltas[best])
        m += args.step_size / (b * sigma) * step
    venv.close()

    # What the final policy does on the first evaluation seed.
    env = gymnasium.make("fbd/HexapodWalk-v0", episode_seconds=args.episode_seconds).unwrapped
    obs, _ = env.reset(seed=eval_seeds[0] if eval_seeds else 0)
    q0 = env.sim.q
    slides = steps = 0
    done = False
    while not done:
        a = np.clip(m @ ((obs - mean) / std), -1.0, 1.0)
        obs, _, term, trunc, _ = env.step(a)
        steps += 1
        slides += int(np.sum(obs[46:52] == 2.0))
        done = term or trunc
    q = env.sim.q
    print(
        f"final policy: {-(q[2] - q0[2]):.3f} m forward, {q[0] - q0[0]:+.3f} m sideways in "
        f"{env.sim.t:.2f} s ({'terminated' if term else 'to the time limit'}), body height "
        f"{q[1]:.3f} m, yaw {np.degrees(q[4]):+.1f}°, feet sliding in {slides / (6 * steps):.0%} of the foot-periods"
    )
    if args.save:
        np.savez(args.save, M=m, mean=mean, std=std)

    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["iteration", "eval_return", "mean_return", "seconds"])
            w.writerows(curve)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        c = np.array(curve)
        fig, ax = plt.subplots(figsize=(6.4, 3.6))
        ax.plot(c[:, 0], c[:, 1], label="policy (eval seeds)")
        ax.plot(c[:, 0], c[:, 2], alpha=0.6, label="mean of the ±δ rollouts")
        ax.set_xlabel("ARS iteration")
        ax.set_ylabel("episode return")
        ax.set_title(
            f"fbd/HexapodWalk-v0, ARS ({2 * n + e} rollouts/iteration, {c[-1, 3]:.0f} s)"
        )
        ax.grid(alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"learning curve: {args.plot}")


if __name__ == "__main__":
    main()
