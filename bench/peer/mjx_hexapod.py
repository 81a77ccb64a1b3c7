#!/usr/bin/env python3
"""The fbd hexapod in MuJoCo across cores and on a GPU: `mujoco.rollout` on
N threads and MuJoCo's JAX port (MJX) with N worlds in one batch.

The model is the one `fbd export mjcf` writes (as for mujoco_hexapod.py).
Every world starts from the keyframe "initial". ``stand``: the servos hold
the keyframe's targets; ``walk``: they track the kinematic gait's targets
(``--targets``, the trajectory.csv of the kinematic twin, see
mujoco_hexapod.py), the same for every world.

Prints one JSON object per measurement: {engine, case, worlds, threads,
steps, seconds, steps_per_second} where steps_per_second counts every
world's steps (worlds × steps / seconds). The MJX figure excludes the jit
compilation (one untimed warm-up call of the same shape).

    mjx_hexapod.py rollout stand.xml --steps 2000 --worlds 64 --threads 16
    mjx_hexapod.py mjx stand.xml --steps 1000 --worlds 8192
"""

import argparse
import json
import os
import time

import mujoco
import numpy as np

from mujoco_hexapod import gait_controls


def controls(model, case, steps, targets):
    if case == "walk":
        return gait_controls(model, targets, steps)
    key = model.key("initial").id
    return np.tile(model.key_ctrl[key], (steps, 1))


def initial(model):
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("initial").id)
    return data


def run_rollout(model, case, steps, worlds, threads, targets):
    from mujoco import rollout

    data = initial(model)
    nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    s0 = np.empty(nstate)
    mujoco.mj_getState(model, data, s0, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    ctrl = controls(model, case, steps, targets)
    state0 = np.tile(s0, (worlds, 1))
    control = np.tile(ctrl[None], (worlds, 1, 1))
    datas = [mujoco.MjData(model) for _ in range(threads)]
    out = np.empty((worlds, steps, nstate))
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        rollout.rollout([model] * worlds, datas, state0, control, nstep=steps, state=out)
        best = min(best, time.perf_counter() - t0)
    return best


def run_mjx(model, case, steps, worlds, targets):
    import jax
    import jax.numpy as jnp
    from mujoco import mjx

    data = initial(model)
    m = mjx.put_model(model)
    d0 = mjx.put_data(model, data)
    ctrl = jnp.asarray(controls(model, case, steps, targets))
    batch = jax.vmap(lambda _: d0)(jnp.arange(worlds))

    @jax.jit
    def simulate(d):
        def body(d, u):
            d = d.replace(ctrl=jnp.broadcast_to(u, d.ctrl.shape))
            return jax.vmap(mjx.step, in_axes=(None, 0))(m, d), None

        d, _ = jax.lax.scan(body, d, ctrl)
        return d

    jax.block_until_ready(simulate(batch))  # compile
    t0 = time.perf_counter()
    d = jax.block_until_ready(simulate(batch))
    seconds = time.perf_counter() - t0
    z = np.asarray(d.qpos[:, 1])
    return seconds, float(np.mean(z)), jax.devices()[0].device_kind


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("engine", choices=["rollout", "mjx"])
    p.add_argument("xml")
    p.add_argument("--case", choices=["stand", "walk"], default="stand")
    p.add_argument("--steps", type=int, required=True)
    p.add_argument("--worlds", type=int, required=True)
    p.add_argument("--threads", type=int, default=os.cpu_count())
    p.add_argument("--targets", help="walk: the kinematic twin's trajectory.csv")
    a = p.parse_args()
    model = mujoco.MjModel.from_xml_path(a.xml)
    out = {"engine": a.engine, "case": a.case, "worlds": a.worlds, "steps": a.steps, "mujoco": mujoco.__version__}
    if a.engine == "rollout":
        seconds = run_rollout(model, a.case, a.steps, a.worlds, a.threads, a.targets)
        out["threads"] = a.threads
    else:
        seconds, height, device = run_mjx(model, a.case, a.steps, a.worlds, a.targets)
        out["device"] = device
        out["mean_body_y_at_end"] = height
    out["seconds"] = seconds
    out["steps_per_second"] = a.worlds * a.steps / seconds
    print(json.dumps(out))


if __name__ == "__main__":
    main()
