"""Read the outputs of PySPH's taylor_bar and of gpa's taylor_bar.toml, print one Markdown table.

Run by run_pysph_taylor.sh with Debian's /usr/bin/python3 (numpy and pysph from Debian
packages; nothing from pip):

    /usr/bin/python3 taylor_compare.py --pysph-dir D1 --pysph-process-seconds T1 \
        --gpa-dir D2 --gpa-process-seconds T2 --dx 0.384848e-3 [--out results.md]

Both final shapes are measured by the same rule from the final particle/node positions, so
that neither code's wall position enters (PySPH's wall is a repulsive force, so its particles
stand off the plate line y = 0 by a varying gap):

* length    = (highest - lowest particle along the bar) + dx
* footprint = (widest extent across the bar of the particles within dx of the lowest one) + dx
* width     = (widest extent across the bar of all particles) + dx (the mushroom's widest)

With the initial lattice this gives 21 dx x 67 dx for both. gpa's own summary.json numbers
(its rule: max distance from the wall + d/2; width of the nodes within one diameter of the
wall) are printed below the table.
"""
import argparse
import glob
import json
import os
import re
import struct
import sys

import numpy


def shape(x, y, dx):
    """Length along y, footprint width and largest width across x of a particle set."""
    y_lo = y.min()
    length = y.max() - y_lo + dx
    foot = y < y_lo + dx
    footprint = x[foot].max() - x[foot].min() + dx
    return length, footprint, x.max() - x.min() + dx


# --- PySPH ----------------------------------------------------------------------------------

def read_pysph(directory, dx):
    from pysph.solver.utils import get_files, load
    files = get_files(directory, fname="taylor_bar")
    if len(files) < 2:
        sys.exit(f"taylor_compare: no PySPH output files in {directory}")
    first, last = load(files[0]), load(files[-1])
    bar0, bar = first["arrays"]["bar"], last["arrays"]["bar"]
    sd = last["solver_data"]
    log = open(os.path.join(directory, "taylor_bar.log")).read()

    def took(what):
        m = re.findall(rf"{what} took: ([0-9.eE+-]+) secs", log)
        return float(m[-1]) if m else float("nan")

    n = bar.get_number_of_particles()
    run = took("Run")
    return {
        "particles": n,
        "wall_particles": last["arrays"]["plate"].get_number_of_particles(),
        "t": float(sd["t"]),
        "steps": int(sd["count"]),
        "dt": float(sd["dt"]),
        "loop_seconds": run,
        "setup_seconds": took("Setup"),
        "shape0": shape(bar0.x, bar0.y, dx),
        "shape": shape(bar.x, bar.y, dx),
        "gap": float(bar.y.min()),
        "rate": n * int(sd["count"]) / run,
    }


# --- gpa ------------------------------------------------------------------------------------

def vtp_points(path):
    """Points of a gpa .vtp (raw appended data, UInt64 headers) as an (n, 3) array."""
    raw = open(path, "rb").read()
    head_end = raw.index(b'<AppendedData encoding="raw">')
    head = raw[:head_end].decode("utf-8", "replace")
    if 'header_type="UInt64"' not in head:
        sys.exit(f"taylor_compare: {path}: expected header_type UInt64")
    m = re.search(r'<Points>\s*<DataArray type="Float64" NumberOfComponents="3" format="appended" '
                  r'offset="(\d+)"', head)
    if not m:
        sys.exit(f"taylor_compare: {path}: no appended Float64 Points array")
    base = raw.index(b"_", head_end) + 1
    at = base + int(m.group(1))
    (nbytes,) = struct.unpack_from("<Q", raw, at)
    return numpy.frombuffer(raw, dtype="<f8", count=nbytes // 8, offset=at + 8).reshape(-1, 3)


def read_gpa(directory, dx):
    summary = json.load(open(os.path.join(directory, "summary.json")))
    snaps = sorted(glob.glob(os.path.join(directory, "particles_*.vtp")))
    if len(snaps) < 2:
        sys.exit(f"taylor_compare: no gpa snapshots in {directory}")
    p0, p = vtp_points(snaps[0]), vtp_points(snaps[-1])
    dts = []
    with open(os.path.join(directory, "history.csv")) as f:
        cols = f.readline().strip().split(",")
        k = cols.index("dt_s")
        for line in f:
            v = float(line.split(",")[k])
            if v > 0:
                dts.append(v)
    n, steps = summary["real_nodes"], summary["steps"]
    return {
        "particles": n,
        "ghosts": summary["ghost_nodes"],
        "t": summary["time_s"],
        "steps": steps,
        "dt_first": dts[0], "dt_min": min(dts), "dt_max": max(dts),
        "dt_mean": summary["time_s"] / steps,
        "loop_seconds": summary["wall_seconds"],
        "step_seconds": summary["step_seconds"],
        "shape0": shape(p0[:, 0], p0[:, 1], dx),
        "shape": shape(p[:, 0], p[:, 1], dx),
        "own_length": summary["final"]["length_m"],
        "own_footprint": summary["final"]["footprint_diameter_m"],
        "rate": n * steps / summary["wall_seconds"],
        "own_rate": summary["node_steps_per_second"],
        "status": summary["status"],
    }


# --- table ----------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pysph-dir", required=True)
    ap.add_argument("--pysph-process-seconds", type=float, required=True)
    ap.add_argument("--gpa-dir", required=True)
    ap.add_argument("--gpa-process-seconds", type=float, required=True)
    ap.add_argument("--dx", type=float, default=0.384848e-3)
    ap.add_argument("--out")
    a = ap.parse_args()

    ps, g = read_pysph(a.pysph_dir, a.dx), read_gpa(a.gpa_dir, a.dx)
    mm = lambda v: f"{v * 1e3:.2f} mm"
    ns = lambda v: f"{v * 1e9:.3g} ns"
    L0p, W0p, _ = ps["shape0"]
    Lp, Wp, Mp = ps["shape"]
    L0g, W0g, _ = g["shape0"]
    Lg, Wg, Mg = g["shape"]
    rows = [
        ("simulated time", f"{ps['t'] * 1e6:.2f} us", f"{g['t'] * 1e6:.2f} us"),
        ("particles / nodes moved", f"{ps['particles']} (+{ps['wall_particles']} wall particles)",
         f"{g['particles']} (+ ghosts, {g['ghosts']} at the end)"),
        ("time step", f"{ns(ps['dt'])} fixed",
         f"CFL 0.4: {ns(g['dt_first'])} first, {ns(g['dt_min'])} - {ns(g['dt_max'])}, mean {ns(g['dt_mean'])}"),
        ("steps", f"{ps['steps']}", f"{g['steps']}"),
        ("wall time, solver loop", f"{ps['loop_seconds']:.1f} s (setup {ps['setup_seconds']:.1f} s more)",
         f"{g['loop_seconds']:.2f} s"),
        ("wall time, whole process", f"{a.pysph_process_seconds:.1f} s", f"{a.gpa_process_seconds:.2f} s"),
        ("particle-steps per second (loop)", f"{ps['rate']:.3g}", f"{g['rate']:.3g}"),
        ("final length (initial)", f"{mm(Lp)} ({mm(L0p)}), L/L0 = {Lp / L0p:.3f}",
         f"{mm(Lg)} ({mm(L0g)}), L/L0 = {Lg / L0g:.3f}"),
        ("final footprint width (initial)", f"{mm(Wp)} ({mm(W0p)}), W/W0 = {Wp / W0p:.3f}",
         f"{mm(Wg)} ({mm(W0g)}), W/W0 = {Wg / W0g:.3f}"),
        ("final largest width", f"{mm(Mp)}, /W0 = {Mp / W0p:.3f}", f"{mm(Mg)}, /W0 = {Mg / W0g:.3f}"),
    ]
    lines = ["| | PySPH taylor_bar (s = 1.8) | gpa taylor_bar.toml |", "|---|---|---|"]
    lines += [f"| {r[0]} | {r[1]} | {r[2]} |" for r in rows]
    lines += [
        "",
        f"Ratio of wall times, PySPH / gpa: solver loops {ps['loop_seconds'] / g['loop_seconds']:.1f}x, "
        f"whole processes {a.pysph_process_seconds / a.gpa_process_seconds:.1f}x. The loop ratio is "
        f"the product of PySPH's {ps['steps'] / g['steps']:.3g}x more steps (1 ns fixed against gpa's "
        f"mean {ns(g['dt_mean'])}) and its {g['rate'] / ps['rate']:.3g}x lower particle-step rate.",
        f"Shapes by one rule for both: length = extent along the bar + dx, footprint = width of the "
        f"particles within dx of the lowest + dx, largest width = whole extent across + dx (dx = {a.dx * 1e3:.6g} mm). PySPH's lowest particle "
        f"ends {mm(ps['gap'])} above its plate line (repulsive wall). gpa's own summary: length "
        f"{mm(g['own_length'])}, footprint {mm(g['own_footprint'])}, {g['own_rate']:.3g} node-steps/s, "
        f"status {g['status']}.",
        "Both on 2 threads (PySPH: OpenMP, OMP_NUM_THREADS=2; gpa: --threads 2), run one after the "
        "other; the PySPH setup time (code generation and C compilation, cached in ~/.pysph) is left "
        "out of its loop time.",
    ]
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
