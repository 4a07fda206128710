#!/usr/bin/env python3
"""Prints the Markdown tables of docs/validation.md (issue 10) from the reports that
scripts/impact_study.sh writes to docs/study/impact/CASE.txt: the hypervelocity impacts (crater,
spall layer, failed nodes, steps, wall and CPU time) and the perforation (residual velocities at
two speeds and the Recht-Ipson ballistic limit through them, against the measured 184.5 m/s).

Usage: python3 tools/impact_table.py [--dir docs/study/impact]
Standard library only; run from the repository root. A case without a report is listed as not run.
"""
import argparse, math, os, re

MEASURED_BALLISTIC_LIMIT = 184.5  # m/s, Borvik, Langseth, Hopperstad and Malo (1999), 12 mm plate


def read_report(path):
    """The report's 'key value' words, as a dict of strings (the rows string kept whole)."""
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        return None
    words = {}
    for line in open(path):
        parts = line.split()
        if parts and parts[0] == "rows_from_rear_face":
            words["rows"] = parts[1] if len(parts) > 1 else ""
            continue
        if parts and parts[0] == "spall_layer" and len(parts) > 1 and parts[1] == "none":
            words["spall_layer"] = "none"
            continue
        for k, v in zip(parts[0::2], parts[1::2]):
            words[k] = v
        m = re.search(r"\(rows (\d+)-(\d+)", line)
        if m:
            words["spall_rows"] = f"{m.group(1)}-{m.group(2)}"
    return words


def hypervelocity_table(folder, kind, spacings):
    print(f"| spacing | connectivity | crater depth | crater diameter | spall layer centre / thickness | failed nodes | "
          f"steps | wall | CPU | node-steps per CPU second |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for s in spacings:
        for c in ("automatic", "variable"):
            w = read_report(os.path.join(folder, f"{kind}-{s}-{c}.txt"))
            if w is None:
                print(f"| {s} mm | {c} | not run | | | | | | | |")
                continue
            spacing = f"{w['spacing_mm']} / {w['projectile_spacing_mm']} mm" if kind == "small" else f"{w['spacing_mm']} mm"
            if "spall_layer_centre_mm" in w:
                spall = f"{float(w['spall_layer_centre_mm']):.1f} / {float(w['spall_layer_thickness_mm']):.1f} mm"
            else:
                spall = "none"
            cpu = f"{float(w['cpu_s']):.1f} s" if "cpu_s" in w else "-"
            # node-steps over the process's CPU time: the wall-clock rate of a shared machine is not
            # the program's (node_steps_per_s x wall_s is the run's node-step count)
            node_steps = float(w["node_steps_per_s"]) * float(w["wall_s"])
            rate = f"{node_steps / float(w['cpu_s']):.3g}" if "cpu_s" in w and float(w["cpu_s"]) > 0 else "-"
            print(f"| {spacing} | {c} | {float(w['crater_depth_mm']):.2f} mm | {float(w['crater_diameter_mm']):.1f} mm | {spall} | "
                  f"{w['failed_nodes']} | {w['steps']} | {float(w['wall_s']):.1f} s | {cpu} | {rate} |")


def recht_ipson(v1, r1, v2, r2):
    """a and the ballistic limit of v_r^2 = a^2 (v^2 - v_bl^2) through two shots."""
    a2 = (r2 * r2 - r1 * r1) / (v2 * v2 - v1 * v1)
    if a2 <= 0.0:
        return None, None
    bl2 = v1 * v1 - r1 * r1 / a2
    return math.sqrt(a2), (math.sqrt(bl2) if bl2 > 0.0 else 0.0)


def perforation_table(folder, spacings, speeds=(250, 300)):
    print("| spacing | connectivity | residual velocity at 250 / 300 m/s | a | ballistic limit | against 184.5 m/s | "
          "failed nodes | steps | CPU |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s in spacings:
        for c in ("variable", "automatic"):
            shots = [read_report(os.path.join(folder, f"perforation-{s}-{c}-{v}.txt")) for v in speeds]
            if any(w is None for w in shots):
                print(f"| {s} mm | {c} | not run | | | | | | |")
                continue
            r = [float(w["residual_velocity_m_s"]) for w in shots]
            a, limit = recht_ipson(speeds[0], r[0], speeds[1], r[1])
            fit = "no fit" if a is None else f"{a:.3f}"
            bl = "-" if limit is None else f"{limit:.1f} m/s"
            err = "-" if limit is None else f"{100.0 * (limit / MEASURED_BALLISTIC_LIMIT - 1.0):+.1f} %"
            failed = " / ".join(w["failed_nodes"] for w in shots)
            steps = " / ".join(w["steps"] for w in shots)
            cpu = " / ".join(f"{float(w['cpu_s']):.0f} s" if "cpu_s" in w else "-" for w in shots)
            print(f"| {s} mm | {c} | {r[0]:.1f} / {r[1]:.1f} m/s | {fit} | {bl} | {err} | {failed} | {steps} | {cpu} |")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dir", default="docs/study/impact")
    args = p.parse_args()
    print("Hypervelocity impact, the paper's Fig. 7 projectile (scenes/hypervelocity-spall.toml)\n")
    hypervelocity_table(args.dir, "spall", ("0.8", "0.4", "0.2"))
    print("\nHypervelocity impact, the projectile of the paper's text (scenes/hypervelocity-small.toml)\n")
    hypervelocity_table(args.dir, "small", ("0.8", "0.4", "0.2"))
    print("\nPerforation, Weldox 460 E (scenes/perforation-weldox-460e.toml), Recht-Ipson fit through 250 and 300 m/s\n")
    perforation_table(args.dir, ("0.7", "0.5", "0.35"))


if __name__ == "__main__":
    main()
