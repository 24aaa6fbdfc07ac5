#!/usr/bin/env python3
"""Plots and a table from `nbvh study` results (issue 11), made on the build machine (matplotlib:
Debian python3-matplotlib; the GPU machine has none).

usage: plot_study.py STUDY.json OUT_DIR

Writes OUT_DIR/error_vs_time.png (FLIP vs frame time with the Pareto front, paper Fig. 6),
error_vs_memory.png (FLIP vs memory with the equal-memory decimation curve, Fig. 7),
training_vs_error.png (training time vs FLIP, Fig. 8) and table.md (shaped like the paper's Table 1).
Every figure uses the mean over the study's cameras; hollow markers / '*' are rows within twice the
noise floor (not distinguishable from noise at the study's spp).
"""
import json
import os
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

MIB = 1024.0 * 1024.0


def rows_of(study, variant):
    return [r for r in study["mean_rows"] if r["variant"] == variant and r.get("flip") is not None]


def caption(study):
    s = study["settings"]
    text = (f"{os.path.basename(study['scene'])} on {study['device']} (driver {study['driver']}), commit "
            f"{study['commit']}; {s['width']}x{s['height']}, {s['spp']} spp vs a {s['ref_spp']}-spp reference, mean of "
            f"{len(study['cameras'])} cameras; frames {s['time_width']}x{s['time_height']} at {s['time_spp']} spp; "
            f"hollow: within 2x the noise floor")
    return "\n".join(textwrap.wrap(text, 150))


def pareto(points):
    """Points (x, y) not dominated by one with smaller-or-equal x and smaller y, sorted by x."""
    front, best = [], float("inf")
    for x, y in sorted(points):
        if y < best:
            front.append((x, y))
            best = y
    return front


def marker_face(r, color):
    return "none" if r["within_2x_floor"] else color


def floor_line(ax, study):
    floor = sum(c["noise_floor"] for c in study["cameras"]) / len(study["cameras"])
    ax.axhline(floor, color="grey", linestyle=":", linewidth=1)
    ax.text(ax.get_xlim()[0], floor, " noise floor", va="bottom", ha="left", fontsize=7, color="grey")
    return floor


def label(r):
    return f"{r['nodes']}n 2^{r['hash_log2']}"


def plot_time(study, path):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    colors = {"lod": "tab:blue", "switch": "tab:purple", "cap": "tab:olive"}
    neural = []
    for kind, color in colors.items():
        rows = rows_of(study, kind)
        for r in rows:
            ax.plot(r["frame_ms"], r["flip"], "o", color=color, markerfacecolor=marker_face(r, color), markersize=5)
            neural.append((r["frame_ms"], r["flip"]))
        if rows:
            ax.plot([], [], "o", color=color, label={"lod": "N-BVH, one LoD for all rays",
                                                      "switch": "N-BVH, coarsest LoD after the first hit",
                                                      "cap": "N-BVH, LoD 0, raised leaf budget"}[kind])
    for r in rows_of(study, "lod"):
        if r["lod"] == 0:
            ax.annotate(label(r), (r["frame_ms"], r["flip"]), fontsize=6, xytext=(3, 3), textcoords="offset points")
    front = pareto(neural)
    if front:
        ax.step([p[0] for p in front], [p[1] for p in front], where="post", color="tab:blue", alpha=0.5,
                label="Pareto front (N-BVH)")
    dec = rows_of(study, "decimated")
    if dec:
        ax.plot([r["frame_ms"] for r in dec], [r["flip"] for r in dec], "s", color="tab:orange",
                label="decimated mesh at equal memory")
    cl = rows_of(study, "classical")
    if cl:
        ax.plot([cl[0]["frame_ms"]], [cl[0]["flip"]], "*", color="black", markersize=10,
                label="classical (true mesh): its FLIP is the noise floor")
    eq = [(r["frame_ms"], r["equal_time_flip"]) for r in rows_of(study, "lod") if r.get("equal_time_flip") is not None]
    if eq:
        ax.plot([p[0] for p in eq], [p[1] for p in eq], "x", color="grey", label="classical at equal time")
    ax.set_xlabel(f"frame time, ms ({study['settings']['time_spp']} spp, GPU timestamps, median)")
    ax.set_ylabel("LDR-FLIP vs converged classical reference")
    floor_line(ax, study)
    ax.legend(fontsize=7)
    ax.set_title("Error vs frame time", fontsize=10)
    fig.text(0.01, 0.005, caption(study), fontsize=5.5, va="bottom")
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.savefig(path, dpi=150)
    plt.close(fig)


def plot_memory(study, path):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    lod0 = [r for r in rows_of(study, "lod")]
    for r in lod0:
        ax.plot(r["memory_bytes"] / MIB, r["flip"], "o", color="tab:blue", markerfacecolor=marker_face(r, "tab:blue"),
                markersize=5)
        if r["lod"] == 0:
            ax.annotate(label(r), (r["memory_bytes"] / MIB, r["flip"]), fontsize=6, xytext=(3, 3),
                        textcoords="offset points")
    ax.plot([], [], "o", color="tab:blue", label="N-BVH (every LoD: a model of that cut)")
    dec = sorted(rows_of(study, "decimated"), key=lambda r: r["memory_bytes"])
    if dec:
        ax.plot([r["memory_bytes"] / MIB for r in dec], [r["flip"] for r in dec], "s-", color="tab:orange",
                label="meshoptimizer decimation at the model's bytes")
    cl = rows_of(study, "classical")
    if cl:
        ax.plot([cl[0]["memory_bytes"] / MIB], [cl[0]["flip"]], "*", color="black", markersize=10,
                label="full meshes + BLAS")
    ax.set_xscale("log")
    ax.set_xlabel("GPU memory of the neural assets' representation, MiB")
    ax.set_ylabel("LDR-FLIP vs converged classical reference")
    floor_line(ax, study)
    ax.legend(fontsize=7)
    ax.set_title("Error vs memory", fontsize=10)
    fig.text(0.01, 0.005, caption(study), fontsize=5.5, va="bottom")
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.savefig(path, dpi=150)
    plt.close(fig)


def plot_training(study, path):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for r in rows_of(study, "lod"):
        if r["lod"] != 0:
            continue
        ax.plot(r["train_seconds"], r["flip"], "o", color="tab:green", markerfacecolor=marker_face(r, "tab:green"))
        ax.annotate(label(r), (r["train_seconds"], r["flip"]), fontsize=6, xytext=(3, 3), textcoords="offset points")
    ax.set_xlabel(f"training time, s ({study['training_backend']}: {study['training_device']})")
    ax.set_ylabel("LDR-FLIP at LoD 0 vs converged classical reference")
    floor_line(ax, study)
    ax.set_title("Training time vs error", fontsize=10)
    fig.text(0.01, 0.005, caption(study), fontsize=5.5, va="bottom")
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.savefig(path, dpi=150)
    plt.close(fig)


def fmt(v, spec):
    return "-" if v is None else format(v, spec)


def pct(v):  # a share as a percentage, "-" when absent (studies written before the column existed)
    return "-" if v is None else f"{100.0 * v:.3g} %"


def table(study):
    s = study["settings"]
    cl = rows_of(study, "classical")
    lines = [f"# nbvh study: {study['scene']}", "",
             f"Device: {study['device']} (driver {study['driver']}); training: {study['training_backend']} "
             f"({study['training_device']}). Commit `{study['commit']}`, {study['written_utc']}.", "",
             f"Command: `{study['command_line']}`", "",
             f"Images {s['width']}x{s['height']}, {s['spp']} spp (seed {s['seed']}; "
             f"{s.get('sampler', 'random')} sampler) against a classical reference of "
             f"{s['ref_spp']} spp (seed {s['reference_seed']}), LDR-FLIP, mean over {len(study['cameras'])} cameras; "
             f"frame time: median of {s['repeat']} frames of {s['time_spp']} spp at {s['time_width']}x{s['time_height']}"
             f" after a warm-up; per-ray leaf budget {s['max_leaves']}, {s['leaves_per_round']} leaves per round, "
             f"MLP {s.get('neural_kernel') or s['neural_path']}.", ""]
    if cl:
        c = cl[0]
        lines += [f"Classical (the {study['neural_meshes']['count']} neural mesh(es) as triangles: "
                  f"{study['neural_meshes']['triangles']} triangles, {c['memory_bytes'] / MIB:.2f} MiB with BLAS): "
                  f"{c['frame_ms']:.3f} ms per frame; noise floor (classical {s['spp']} spp, other seed, vs the "
                  f"reference) **{c['flip']:.4f}**" +
                  ("" if c["converged"] else " (larger than the 0.005 the issue asks: rows whose FLIP is under 3x it "
                                              "are not converged)") + ".", ""]
        per_cam = [r for r in study["rows"] if r["variant"] in ("lod", "switch")]
        means = rows_of(study, "lod") + rows_of(study, "switch")
        floors = " / ".join(f"{r['noise_floor']:.4f}" for r in sorted(
            (r for r in study["rows"] if r["variant"] == "classical"), key=lambda r: r["camera"]))
        lines += [f"Per camera: noise floors {floors}; LoD and switch rows that meet the issue's rule (floor <= 0.005 "
                  f"or <= a third of the FLIP): {sum(bool(r['converged']) for r in per_cam)} of {len(per_cam)} "
                  f"per camera, {sum(bool(r['converged']) for r in means)} of {len(means)} means (`converged` in "
                  "study.json and study.csv).", ""]
    lines += ["| nodes | hash | LoD | memory MiB | vs mesh+BLAS | training s | frame ms | x classical | queries/ray | rays capped | FLIP | "
              "FLIP, same seed | decimated FLIP (equal memory) | classical FLIP (equal time, spp) |",
              "| ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    dec = {r["config"]: r for r in rows_of(study, "decimated")}
    for r in sorted(rows_of(study, "lod") + rows_of(study, "switch") + rows_of(study, "cap"),
                    key=lambda r: (r["config"], r["variant"] != "lod", r["lod"], r["secondary_lod"])):
        lod = (f"{r['lod']}" if r["variant"] == "lod" else
               f"{r['lod']} then {r['secondary_lod']}" if r["variant"] == "switch" else
               f"{r['lod']}, <= {r['max_leaves']} leaves (image change vs the default budget: FLIP "
               f"{fmt(r.get('flip_vs_base_cap'), '.4f')})")
        d = dec.get(r["config"]) if r["variant"] == "lod" and r["lod"] == 0 else None
        mark = " *" if r["within_2x_floor"] else ""
        lines.append(
            f"| {r['nodes']} | 2^{r['hash_log2']} | {lod} | {r['memory_bytes'] / MIB:.2f} | {fmt(r['compression'], '.1f')}x | "
            f"{fmt(r['train_seconds'], '.1f')} | {fmt(r['frame_ms'], '.3f')} | {fmt(r['ratio_to_classical'], '.2f')} | "
            f"{fmt(r['queries_per_ray'], '.2f')} | {pct(r.get('leaf_cap_fraction'))} | {fmt(r['flip'], '.4f')}{mark} | "
            f"{fmt(r.get('flip_same_seed'), '.4f')} | "
            + (f"{d['flip']:.4f} ({d['triangles']} tris)" if d else "") + " | "
            + (f"{r['equal_time_flip']:.4f} ({r['equal_time_spp']})" if r.get("equal_time_flip") is not None else "")
            + " |")
    lines += ["", "The raised leaf budget row: how much the default per-ray budget changes the image (same seed and spp as "
              "LoD 0, so noise cancels) and what more leaves cost in time; its extra queries per ray are the leaves "
              "the default budget cuts off. Rays capped: the share of path and shadow rays that the leaf budget left with a "
              "leaf in front of their best hit.", "", "FLIP, same seed: against the classical render of the same seed and spp "
              "instead of the reference: the noise the two images share cancels, so it lies closer to the converged error "
              "where the hybrid's paths stay correlated with the triangles' (how close, per scene: results/study/README.md, "
              "Convergence).", "", "`*`: within twice the noise floor (not distinguishable from noise at this spp). Memory: the model with "
              "only this LoD's nodes (grid, MLP and its transposed copy, level table, nodes and their bounds, asset "
              "table); every LoD resident: see study.json `resident_bytes`.", ""]
    return "\n".join(lines)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1]) as f:
        study = json.load(f)
    out = sys.argv[2]
    os.makedirs(out, exist_ok=True)
    plot_time(study, os.path.join(out, "error_vs_time.png"))
    plot_memory(study, os.path.join(out, "error_vs_memory.png"))
    plot_training(study, os.path.join(out, "training_vs_error.png"))
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write(table(study))
    print(f"wrote {out}/error_vs_time.png, error_vs_memory.png, training_vs_error.png, table.md")


if __name__ == "__main__":
    main()
