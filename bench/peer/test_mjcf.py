#!/usr/bin/env python3
"""`fbd export mjcf` checked in MuJoCo: the exported hexapod is fbd's robot.

For random poses (seeded) of a hexapod configuration:

* MuJoCo loads the exported model and its keyframe "initial";
* forward kinematics: MuJoCo's sites hip{n}, knee{n}, tip{n} equal the
  points `fbd kinematics` prints, to 1e-9 m;
* the same with a model of three legs (`legs = [2, 3, 6]`);
* the body's angular velocity (inertial) is the configuration's
  `omega_deg`, and every hinge's qvel its `rate_deg`, to 1e-9;
* total mass equal to the configuration's (body + six legs), and the
  central body's inertia tensor (with products of inertia) to 1e-12;
* a configuration with only tips in contact has six contact spheres, the
  default one eighteen (tips, knees, hips);
* a height map exported as an hfield is fbd's ground: a CSV heightfield
  sampled from a plane, its height under vertical rays (`mj_ray`) at the
  samples is the plane's minus the sphere radius, to MuJoCo's float32
  storage (rows along +X, columns along +Z: orientation and scaling).

    python3 bench/peer/test_mjcf.py          # or: pytest bench/peer/test_mjcf.py

Needs `mujoco` (bench/peer/requirements.txt) and the `fbd` binary: $FBD_BIN,
else `cargo build --release` of this tree (honouring CARGO_TARGET_DIR).
"""

import json
import math
import os
import random
import subprocess
import sys
import tempfile
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
TOL = 1e-9


def fbd_bin():
    b = os.environ.get("FBD_BIN")
    if b:
        return b
    subprocess.run(["cargo", "build", "--release", "-q", "--bin", "fbd"], cwd=ROOT, check=True)
    target = os.environ.get("CARGO_TARGET_DIR", str(ROOT / "target"))
    return str(Path(target) / "release" / "fbd")


def random_config(rng, points='["tips", "knees", "hips"]', legs=(1, 2, 3, 4, 5, 6)):
    """A hexapod configuration with a random pose, spin and joint rates."""
    r = lambda lo, hi: round(rng.uniform(lo, hi), 6)  # noqa: E731
    ixx, izz = r(0.17, 0.2), r(0.17, 0.2)
    lines = [
        'model = "hexapod"',
        'dynamics = "fbd"',
        f"legs = {list(legs)}",
        "[body]",
        "mass = 9.0",
        # A valid tensor: Iyy below Ixx + Izz, small products of inertia.
        f"inertia = [{ixx}, {round(0.9 * (ixx + izz), 6)}, {izz}, {r(-0.002, 0.002)}, {r(-0.002, 0.002)}, {r(-0.002, 0.002)}]",
        "side = 0.27",
        "[leg]",
        "upper_length = 0.21",
        "upper_mass = 0.35",
        "lower_length = 0.4",
        "lower_mass = 1.2",
        "upper_com = 0.45",
        "lower_com = 0.7",
        "[contact]",
        f"points = {points}",
        "[initial]",
        f"position = [{r(-1, 1)}, {r(0.4, 0.9)}, {r(-1, 1)}]",
        f"velocity = [{r(-1, 1)}, {r(-1, 1)}, {r(-1, 1)}]",
        f"phi_deg = [{r(-40, 40)}, {r(-170, 170)}, {r(-40, 40)}]",
        f"omega_deg = [{r(-200, 200)}, {r(-200, 200)}, {r(-200, 200)}]",
    ]
    for n in legs:
        lines += [
            f"[initial.leg{n}]",
            f"theta_deg = [{r(-60, 60)}, {r(-90, 90)}, {r(190, 320)}]",
            f"rate_deg = [{r(-100, 100)}, {r(-100, 100)}, {r(-100, 100)}]",
        ]
    return "\n".join(lines) + "\n"


def load(fbd, text, tmp):
    """(MuJoCo model, data at the keyframe, fbd kinematics JSON)."""
    cfg = Path(tmp) / "robot.toml"
    cfg.write_text(text)
    xml = Path(tmp) / "robot.xml"
    subprocess.run([fbd, "export", "mjcf", str(cfg), "--out", str(xml)], check=True)
    kin = json.loads(subprocess.run([fbd, "kinematics", str(cfg)], check=True, capture_output=True, text=True).stdout)
    model = mujoco.MjModel.from_xml_path(str(xml))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("initial").id)
    mujoco.mj_forward(model, data)
    return model, data, kin


def values(text, key):
    """The numbers of `key = [...]` in a TOML text (first occurrence after
    its table header is irrelevant here: keys are unique per table)."""
    out = []
    for line in text.splitlines():
        if line.startswith(key + " = ["):
            out.append([float(v) for v in line.split("[", 1)[1].rstrip("]").split(",")])
    return out


def test_forward_kinematics_masses_and_velocities():
    fbd = fbd_bin()
    rng = random.Random(20261122)
    for legs in [(1, 2, 3, 4, 5, 6)] * 4 + [(2, 3, 6)]:
        text = random_config(rng, legs=legs)
        with tempfile.TemporaryDirectory() as tmp:
            model, data, kin = load(fbd, text, tmp)
        worst = 0.0
        assert model.nbody == 1 + 1 + 2 * len(legs) and model.njnt == 1 + 3 * len(legs)
        for leg in (leg for leg in kin["legs"] if leg["leg"] in legs):
            for point in ("hip", "knee", "tip"):
                got = data.site(f"{point}{leg['leg']}").xpos
                err = float(np.abs(got - np.array(leg[point])).max())
                worst = max(worst, err)
                assert err < TOL, f"leg {leg['leg']} {point}: MuJoCo {got} vs fbd {leg[point]}"
        mass = 9.0 + len(legs) * (0.35 + 1.2)
        assert abs(model.body_mass.sum() - mass) < 1e-12, (model.body_mass.sum(), mass)
        # The central body's inertia tensor (MuJoCo stores it diagonalised).
        b = model.body("body").id
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[b])
        rot = rot.reshape(3, 3)
        tensor = rot @ np.diag(model.body_inertia[b]) @ rot.T
        ixx, iyy, izz, ixy, ixz, iyz = values(text, "inertia")[0]
        want = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        assert np.abs(tensor - want).max() < 1e-12, (tensor, want)
        # Angular velocity of the central body, inertial frame.
        vel = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, model.body("body").id, vel, 0)
        omega = np.radians(values(text, "omega_deg")[0])
        assert np.abs(vel[:3] - omega).max() < TOL, (vel[:3], omega)
        assert np.abs(vel[3:] - np.array(values(text, "velocity")[0])).max() < TOL
        rates = np.radians(np.array(values(text, "rate_deg")).ravel())
        assert np.abs(data.qvel[6:] - rates).max() < TOL
        print(f"legs {legs}: max |MuJoCo site − fbd point| = {worst:.1e} m")


def test_contact_spheres():
    fbd = fbd_bin()
    rng = random.Random(7)
    for points, count in (('["tips"]', 6), ('["tips", "knees", "hips"]', 18)):
        with tempfile.TemporaryDirectory() as tmp:
            model, _, _ = load(fbd, random_config(rng, points), tmp)
        spheres = sum(1 for g in range(model.ngeom) if model.geom_contype[g] == 1)
        assert spheres == count, (points, spheres)


def test_hfield_is_fbds_height_map():
    fbd = fbd_bin()

    def plane(x, z):
        return 0.02 + 0.1 * x - 0.05 * z + 0.03 * x * z

    with tempfile.TemporaryDirectory() as tmp:
        rows = [",".join(str(plane(-1 + 0.5 * i, -0.6 + 0.4 * j)) for j in range(4)) for i in range(5)]
        (Path(tmp) / "g.csv").write_text("\n".join(rows) + "\n")
        text = (
            'model = "hexapod"\n[initial]\nposition = [0.0, 2.0, 0.0]\n'
            '[terrain]\nkind = "heightfield"\nfile = "g.csv"\nsize = [2.0, 1.2]\n'
        )
        model, data, _ = load(fbd, text, tmp)
    ground = np.array([1, 0, 0, 0, 0, 0], dtype=np.uint8)
    worst = 0.0
    for i in range(5):
        for j in range(4):
            x = min(max(-1 + 0.5 * i, -0.999), 0.999)
            z = min(max(-0.6 + 0.4 * j, -0.599), 0.599)
            hit = np.array([-1], dtype=np.int32)
            d = mujoco.mj_ray(model, data, np.array([x, 1.0, z]), np.array([0.0, -1.0, 0.0]), ground, 1, -1, hit)
            assert model.geom(hit[0]).name == "ground"
            worst = max(worst, abs(1.0 - d - (plane(x, z) - 0.01)))
    assert worst < 1e-4, worst


if __name__ == "__main__":
    test_forward_kinematics_masses_and_velocities()
    test_contact_spheres()
    test_hfield_is_fbds_height_map()
    print("test_mjcf: all passed (MuJoCo", mujoco.__version__ + ")")
    sys.exit(0)
