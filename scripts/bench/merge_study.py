#!/usr/bin/env python3
"""Joins `nbvh study` runs of one scene that swept different configurations into one study.json
(issue 11: one GPU call is limited to 10 minutes, so a 3x3 sweep may come back in parts, e.g. nodes
1000,2395 in one call and NODES=8000 in the next).

usage: merge_study.py OUT.json PART.json [PART.json ...]

The parts must describe the same study: scene, settings and cameras (views, exposures and noise floors:
the same reference and floor renders) equal, else it exits non-zero naming the difference. Configurations
are renumbered in part order. The result keeps each part's commit and command (`parts`), joins the
commits in `commit` ('A (configs 1-6) + B (configs 7-9)') so that the plots' captions name them, and is
complete when the joined configurations cover the whole nodes x hash grid they span.
"""
import json
import sys


def fail(msg):
    sys.exit(f"merge_study.py: {msg}")


def without_cap(settings):
    return {k: v for k, v in (settings or {}).items() if k != "cap_study"}


def main(argv):
    if len(argv) < 3:
        fail("usage: merge_study.py OUT.json PART.json [PART.json ...]")
    out_path, paths = argv[1], argv[2:]
    parts = []
    for p in paths:
        try:
            with open(p) as f:
                parts.append(json.load(f))
        except (OSError, ValueError) as e:
            fail(f"{p}: {e}")
    base = parts[0]
    for p, s in zip(paths[1:], parts[1:]):
        for key in ("scene", "device", "flip_metric"):
            if s.get(key) != base.get(key):
                fail(f"{p}: '{key}' differs from {paths[0]}'s")
        # The raised-leaf-budget rows run in one part only (study_multi.sh): cap_study may differ.
        if without_cap(s.get("settings")) != without_cap(base.get("settings")):
            fail(f"{p}: 'settings' differ from {paths[0]}'s")
        if len(s["cameras"]) != len(base["cameras"]):
            fail(f"{p}: {len(s['cameras'])} cameras, {paths[0]} has {len(base['cameras'])}")
        for a, b in zip(base["cameras"], s["cameras"]):
            for key in ("view", "exposure_stops", "noise_floor"):
                if a.get(key) != b.get(key):
                    fail(f"{p}: camera {a['camera']} '{key}' differs ({b.get(key)} vs {a.get(key)}): "
                         "not the same reference")
    merged = dict(base)
    merged["settings"] = dict(base["settings"], cap_study=max(s["settings"].get("cap_study", 0) for s in parts))
    merged["configs"], merged["rows"], merged["mean_rows"], merged["parts"], commits = [], [], [], [], []
    offset = 0
    for p, s in zip(paths, parts):
        remap = {c["config"]: offset + i for i, c in enumerate(s["configs"])}
        for c in s["configs"]:
            merged["configs"].append(dict(c, config=remap[c["config"]]))
        for key in ("rows", "mean_rows"):
            # Rows of no configuration (the classical reference rows, config -1) are the same in every part
            # (checked above through the noise floors): the first part's are kept, once.
            merged[key] += [dict(r, config=remap[r["config"]]) if r["config"] in remap else dict(r)
                            for r in s[key] if r["config"] in remap or p == paths[0]]
        first, last = offset + 1, offset + len(s["configs"])
        commits.append(f"{s['commit']} (configs {first}-{last})")
        merged["parts"].append({"file": p, "commit": s["commit"], "command_line": s["command_line"],
                                "started_utc": s["started_utc"], "configs": [first, last],
                                "stop_reason": s.get("stop_reason", "")})
        offset += len(s["configs"])
    merged["commit"] = " + ".join(commits)
    merged["command_line"] = " ; ".join(s["command_line"] for s in parts)
    merged["configs_done"] = sum(s.get("configs_done", len(s["configs"])) for s in parts)
    merged["configs_planned"] = merged["configs_done"]
    # Complete when the joined configurations cover the whole nodes x hash grid they span.
    grid = {(c["nodes_target"], c["hash_log2"]) for c in merged["configs"]}
    merged["complete"] = len(grid) == len({n for n, _ in grid}) * len({h for _, h in grid})
    merged["stop_reason"] = ""
    merged["written_utc"] = max(s["written_utc"] for s in parts)
    with open(out_path, "w") as f:
        json.dump(merged, f, indent=1)
    print(f"wrote {out_path}: {offset} configurations from {len(parts)} parts")


if __name__ == "__main__":
    main(sys.argv)
