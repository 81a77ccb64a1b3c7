"""The paper's Fig. 7 from Python: the fall of §6 (Δt = 0.01 s, μS = 0.4,
μD = 0.3, passive joints), tip positions of both legs against time (graph 1)
and the forces on the tips (graph 2), with the contact events marked.

    python examples/python/paper_fall.py [--out fig7.png] [--config FILE]

Needs matplotlib (pip install matplotlib).
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import fbd  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description="The paper's Fig. 7 with matplotlib.")
    ap.add_argument("--out", default="fig7.png", help="the image to write (default fig7.png)")
    ap.add_argument("--config", default=None, help="configuration (default: the paper's §6 fall)")
    a = ap.parse_args()

    r = fbd.run(a.config)
    t = r["t"]
    fig, (g1, g2) = plt.subplots(2, 1, figsize=(8, 7.5), sharex=True)
    for leg, style in ((3, "-"), (4, "--")):
        g1.plot(t, r[f"tip{leg}_x"], style, color="tab:blue", label=f"X tip {leg}")
        g1.plot(t, r[f"tip{leg}_y"], style, color="tab:orange", label=f"Y tip {leg}")
        g2.plot(t, r[f"fa{leg}"], style, color="tab:green", label=f"friction Fa{leg}")
        g2.plot(t, r[f"n{leg}"], style, color="tab:red", label=f"normal N{leg}")
    # The paper's events (touchdown of each tip, the first slip): the
    # `t` of an event is the start of the first step solved in the new
    # state (a touchdown at t puts the tip on the ground at t + Δt).
    lines = []
    for e in r.events:
        if e["point"] != "tip" or not (e["from"] == "ST1" or e["to"] == "ST3"):
            continue
        for g in (g1, g2):
            g.axvline(e["t"], color="grey", lw=0.6, ls=":")
        what = "touchdown" if e["from"] == "ST1" else "slip"
        lines.append(f"{e['t']:.2f} s  {what}, leg {e['leg']}")
    g1.text(
        0.98,
        0.5,
        "events (dotted):\n" + "\n".join(lines),
        transform=g1.transAxes,
        ha="right",
        va="center",
        fontsize=8,
        bbox={"boxstyle": "round", "fc": "white", "alpha": 0.8},
    )
    g1.set_ylabel("Position (m)")
    g1.set_title("Graph 1: tip positions of legs 3 and 4, inertial frame")
    g2.set_ylabel("Force (N)")
    g2.set_xlabel("Time (s)")
    g2.set_title("Graph 2: forces on the tips (terrain tangent and normal)")
    for g in (g1, g2):
        g.grid(alpha=0.3)
        g.legend(fontsize=8, ncol=2)
    fig.suptitle(f"fbd — the paper's §6 fall ({r.source})", fontsize=10)
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)
    tips = [e for e in r.events if e["point"] == "tip"]
    print(f"wrote {a.out}: {r.rows} steps; tip events:")
    for e in tips:
        print(f"  t = {e['t']:.2f} s  leg {e['leg']}  {e['from']} -> {e['to']}")


if __name__ == "__main__":
    main()
