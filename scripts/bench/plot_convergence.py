#!/usr/bin/env python3
"""Plot and table of `nbvh converge` results (issue 11), made on the build machine (matplotlib: Debian
python3-matplotlib; the GPU machine has none).

usage: plot_convergence.py A.json [B.json ...] OUT.png

One panel per scene: against the samples per pixel of the compared images (log scale), the noise floor
(classical vs the reference), the independent FLIP (hybrid vs the reference), the shared-seed FLIP
(hybrid vs classical, one seed) and the independent FLIP less the floor in quadrature. Runs of one scene
with another --sampler (the JSON's "sampler"; converge.sh SAMPLERS) share its panel: the default
sampler (sobol) bold, the others thin. Prints a markdown table (one per run) to stdout. Device, commit
and command line of each run go into the panel titles and the table's header lines.
"""
import json
import os
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

CURVES = [("noise_floor", "noise floor (classical vs reference)", ":", "tab:gray"),
          ("flip", "independent (hybrid vs reference)", "--", "tab:red"),
          ("flip_less_floor", "independent less floor (quadrature)", "-.", "tab:orange"),
          ("flip_same_seed", "shared seed (hybrid vs classical)", "-", "tab:blue")]


def main(argv):
    if len(argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    runs = []
    for path in argv[1:-1]:
        with open(path) as f:
            runs.append(json.load(f))
    out = argv[-1]
    scenes = []
    for run in runs:
        if run["scene"] not in scenes:
            scenes.append(run["scene"])
    fig, axes = plt.subplots(1, len(scenes), figsize=(5.2 * len(scenes), 4.4), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        mine = [run for run in runs if run["scene"] == scene]
        for run in mine:
            sampler = run.get("sampler", "random")  # runs before the Sobol sampler used independent numbers
            bold = sampler == "sobol" or len(mine) == 1
            spp = [r["spp"] for r in run["rows"]]
            for key, label, style, colour in CURVES:
                ax.plot(spp, [r[key] for r in run["rows"]], style, color=colour, marker="o", ms=3 if bold else 2,
                        lw=1.6 if bold else 0.8, alpha=1.0 if bold else 0.45,
                        label=f"{label}, --sampler {sampler}" if len(mine) > 1 else label)
        ax.set_xscale("log", base=2)
        ax.set_xlabel("samples per pixel of the compared images")
        ax.set_ylabel("LDR-FLIP")
        ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
        run = mine[0]
        title = (f"{os.path.basename(scene)}: {run['width']}x{run['height']}, reference {run['ref_spp']} spp; "
                 f"{run['device']}, commit {run['commit']}")
        ax.set_title("\n".join(textwrap.wrap(title, 60)), fontsize=8)
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    for run in runs:
        print(f"{os.path.basename(run['scene'])}, --sampler {run.get('sampler', 'random')}: {run['device']} "
              f"(driver {run['driver']}), commit {run['commit']}; "
              f"`{run['command_line']}`\n")
        print("| spp | noise floor | independent | less floor | shared seed |")
        print("| ---: | ---: | ---: | ---: | ---: |")
        for r in run["rows"]:
            print(f"| {r['spp']} | {r['noise_floor']:.4f} | {r['flip']:.4f} | {r['flip_less_floor']:.4f} | "
                  f"{r['flip_same_seed']:.4f} |")
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
