"""What the imported-robot tests share: a ``model = "robot"`` configuration
for a state (and accelerations), and ``fbd kinematics`` / ``fbd inverse``
of it as JSON."""

from __future__ import annotations

import json
import pathlib
import subprocess

import numpy as np

# fbd's body frame ← a z-up description's root frame (x → −z, y → −x, z → y).
TURN = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]])


def _vec(v) -> str:
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


def _table(d) -> str:
    return "{ " + ", ".join(f'"{k}" = {float(v)!r}' for k, v in d.items()) + " }"


def write_config(path: pathlib.Path, description: pathlib.Path, *, kind="urdf", up="z",
                 contacts=None, position=(0, 0, 0), phi=(0, 0, 0), velocity=(0, 0, 0),
                 omega=(0, 0, 0), angles=None, rates=None, acceleration=(0, 0, 0),
                 alpha=(0, 0, 0), accelerations=None) -> pathlib.Path:
    """A configuration of the robot in ``description`` (angles in degrees,
    angular rates and accelerations in rad/s and rad/s²)."""
    text = f'model = "robot"\n[robot]\n{kind} = "{description}"\nup = "{up}"\n'
    if contacts is not None:
        text += f"contacts = {json.dumps(list(contacts))}\n"
    text += (
        f"[initial]\nposition = {_vec(position)}\nphi_deg = {_vec(np.degrees(phi))}\n"
        f"velocity = {_vec(velocity)}\nomega_deg = {_vec(np.degrees(omega))}\n"
        f"joints_deg = {_table(angles or {})}\nrates_deg = {_table(rates or {})}\n"
        f"[inverse]\nacceleration = {_vec(acceleration)}\nalpha_deg = {_vec(np.degrees(alpha))}\n"
        f"joints_deg = {_table(accelerations or {})}\n"
    )
    path.write_text(text)
    return path


def fbd_json(cli, command: str, config: pathlib.Path) -> dict:
    """``fbd COMMAND CONFIG`` as JSON (the command must succeed)."""
    out = subprocess.run([str(cli), command, str(config)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)
