#!/usr/bin/env python3
"""Runs the Taylor scenes of scenes/ at several resolutions and thread counts and prints a
Markdown table of final length and footprint diameter beside the measured values, the outline
error against shared/data/taylor-profiles, wall time and node-steps per second.

Usage: tools/taylor_table.py [--gpa build/apps/gpa] [--spacings 0.381,0.254,0.1905]
                             [--threads 1,2] [--scenes taylor-copper-190,...] [--work /tmp/taylor]
Standard library only; run from the repository root (../shared beside it).
"""
import argparse, csv, json, os, re, subprocess, sys

OUTLINES = {
    "taylor-copper-130": "taylorCuJohnsonCook130.dat",
    "taylor-copper-146": "taylorCuJohnsonCook146.dat",
    "taylor-copper-190": "taylorCuZerilliArmstrong.dat",
    "taylor-steel-208": "taylorStJohnsonCook208.dat",
    "taylor-steel-282": "taylorStJohnsonCook282.dat",
    "taylor-steel-343": "taylorStJohnsonCook343.dat",
}


def read_outline(path):
    pts = [tuple(map(float, line.split())) for line in open(path) if line.strip()]
    return pts


def side_of_outline(pts):
    """The measured side: from the footprint corner up to the top, as (height, radius) in mm."""
    side = [(h, r) for r, h in pts if r > 0.0]
    side.sort()
    return side


def computed_radius(profile, height_mm):
    rows = [(float(r["height_m"]) * 1e3, float(r["radius_m"]) * 1e3) for r in profile]
    rows = [(h, r) for h, r in rows if r > 0.0]
    best = None
    for (h0, r0), (h1, r1) in zip(rows, rows[1:]):
        if h0 <= height_mm <= h1:
            t = (height_mm - h0) / (h1 - h0) if h1 > h0 else 0.0
            best = r0 + t * (r1 - r0)
    return best


def outline_error(run_dir, outline_file):
    profile = list(csv.DictReader(open(os.path.join(run_dir, "profile.csv"))))
    side = side_of_outline(read_outline(outline_file))
    errors = []
    for h, r in side:
        if h <= 0.5:  # the footprint corner: compared through the footprint diameter instead
            continue
        c = computed_radius(profile, h)
        if c is not None:
            errors.append(abs(c - r))
    return (max(errors), sum(errors) / len(errors)) if errors else (float("nan"), float("nan"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gpa", default="build/apps/gpa")
    ap.add_argument("--spacings", default="0.381,0.254,0.1905")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--scenes", default=",".join(OUTLINES))
    ap.add_argument("--work", default="/tmp/gpa-taylor")
    ap.add_argument("--shared", default="../shared")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    print("| scene | spacing mm | nodes | threads | L mm | L meas. | L err | D mm | D meas. | D err | outline max/mean mm | steps | wall s | node-steps/s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for scene in a.scenes.split(","):
        text = open(os.path.join("scenes", scene + ".toml")).read()
        for spacing in a.spacings.split(","):
            variant = re.sub(r'spacing = "[^"]*"', f'spacing = "{spacing} mm"', text)
            path = os.path.join(a.work, f"{scene}-{spacing}.toml")
            open(path, "w").write(variant)
            for threads in a.threads.split(","):
                out = os.path.join(a.work, f"{scene}-{spacing}-t{threads}")
                subprocess.run([a.gpa, "run", path, "-o", out, "--threads", threads, "--overwrite", "-q"],
                               check=True, stdout=subprocess.DEVNULL)
                s = json.load(open(os.path.join(out, "summary.json")))
                ref = {r["key"]: r for r in s["reference"]}
                L, D = ref["final_length"], ref["footprint_diameter"]
                omax, omean = outline_error(out, os.path.join(a.shared, "data/taylor-profiles", OUTLINES[scene]))
                print(f"| {scene} | {spacing} | {s['real_nodes']} | {threads} | {L['computed']*1e3:.2f} | {L['reference']*1e3:.2f} | "
                      f"{100*L['relative_error']:+.1f} % | {D['computed']*1e3:.2f} | {D['reference']*1e3:.2f} | {100*D['relative_error']:+.1f} % | "
                      f"{omax:.2f} / {omean:.2f} | {s['steps']} | {s['wall_seconds']:.1f} | {s['node_steps_per_second']/1e6:.2f} M |", flush=True)


if __name__ == "__main__":
    main()
