#!/usr/bin/env python3
"""Plot and table of `nbvh converge` results (issue 11), made on the build machine (matplotlib: Debian
python3-matplotlib; the GPU machine has none).

usage: plot_convergence.py A.json [B.json ...] OUT.png

One panel per JSON (one scene each): against the samples per pixel of the compared images (log scale),
the noise floor (classical vs the reference), the independent FLIP (hybrid vs the reference), the
shared-seed FLIP (hybrid vs classical, one seed) and the independent FLIP less the floor in quadrature.
Prints a markdown table (one row per scene and spp) to stdout. Device, commit and command line of each
run go into the panel titles and the table's header lines.
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
    fig, axes = plt.subplots(1, len(runs), figsize=(5.2 * len(runs), 4.4), squeeze=False)
    for ax, run in zip(axes[0], runs):
        spp = [r["spp"] for r in run["rows"]]
        for key, label, style, colour in CURVES:
            ax.plot(spp, [r[key] for r in run["rows"]], style, color=colour, marker="o", ms=3, label=label)
        ax.set_xscale("log", base=2)
        ax.set_xlabel("samples per pixel of the compared images")
        ax.set_ylabel("LDR-FLIP")
        ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
        title = (f"{os.path.basename(run['scene'])}: {run['width']}x{run['height']}, reference {run['ref_spp']} spp; "
                 f"{run['device']}, commit {run['commit']}")
        ax.set_title("\n".join(textwrap.wrap(title, 60)), fontsize=8)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    for run in runs:
        print(f"{os.path.basename(run['scene'])}: {run['device']} (driver {run['driver']}), commit {run['commit']}; "
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
