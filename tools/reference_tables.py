#!/usr/bin/env python3
"""The tables of docs/validation.md, "GPA against element references" (issue 13), from the study of
record (docs/study/references/<scene>/study.csv, written by scripts/reference_study.sh) and the element
references (scenes/references/<scene>.elements.toml): element reference, GPA at each resolution and the
experiment side by side, with L*, D*, PW*, the peaks, the outline distance and the cost.

Usage: python3 tools/reference_tables.py [SCENE...]
"""
import csv
import os
import re
import sys
import tomllib

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def experiment(scene):
    text = open(os.path.join(ROOT, "scenes", scene + ".toml")).read()
    out = {}
    for key in ("final_length", "footprint_diameter"):
        m = re.search(r'^%s = "([0-9.]+) mm"' % key, text, re.M)
        if m:
            out[key] = float(m.group(1)) * 1e-3
    m = re.search(r'^elements = "(.*)"', text, re.M)
    return out, (m.group(1) if m else None)


def fmt(v, digits=4):
    return "-" if v is None or v == "" else f"{float(v):.{digits}f}"


def pct(a, b):
    if a in (None, "") or b in (None, ""):
        return "-"
    return f"{100 * (float(a) / float(b) - 1):+.1f} %"


def main(scenes):
    for scene in scenes:
        exp, ref_file = experiment(scene)
        ref = tomllib.load(open(os.path.join(ROOT, "scenes", ref_file), "rb")) if ref_file else {"values": {}}
        vals = ref.get("values", {})
        rows = list(csv.DictReader(open(os.path.join(ROOT, "docs/study/references", scene, "study.csv"))))
        print(f"\n#### {scene}\n")
        print("| run | cell mm | L mm | L* | vs exp. | D mm | D* | vs exp. | PW J | PW* | peak strain | peak* | peak T K | "
              "outline dist. mm | face roughness | steps | wall s (1 thread) |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        def rv(k):
            v = vals.get(k)
            return v["value"] if v else None
        r_l, r_d, r_pw, r_pk, r_t = (rv(k) for k in ("final_length", "footprint_diameter", "plastic_work",
                                                      "peak_plastic_strain", "peak_temperature"))
        kinds = ", ".join(f"{k.replace('_diameter','').replace('final_','')}: {v['kind']}" for k, v in vals.items())
        print(f"| elements, reference ({kinds}) | {', '.join(f'{1e3*h:.3g}' for h in ref.get('cell_sizes_m', []))} | "
              f"{fmt(r_l and r_l*1e3)} | 1 | {pct(r_l, exp.get('final_length'))} | {fmt(r_d and r_d*1e3)} | 1 | "
              f"{pct(r_d, exp.get('footprint_diameter'))} | {fmt(r_pw, 2)} | 1 | {fmt(r_pk, 3)} | 1 | {fmt(r_t, 0)} | 0 | - | - | - |")
        for r in rows:
            if r["status"] != "finished":
                print(f"| {r['series']} {r['refinement']} | failed: {r['message']} |")
                continue
            print(f"| {r['series']}, {float(r['refinement']):.3g} | {1e3*float(r['cell_size_m']):.4g} | "
                  f"{fmt(float(r['final_length_m'])*1e3)} | {fmt(r.get('L_star'))} | {pct(r['final_length_m'], exp.get('final_length'))} | "
                  f"{fmt(float(r['footprint_diameter_m'])*1e3)} | {fmt(r.get('D_star'))} | {pct(r['footprint_diameter_m'], exp.get('footprint_diameter'))} | "
                  f"{fmt(r['plastic_work_J'], 2)} | {fmt(r.get('PW_star'))} | {fmt(r.get('peak_plastic_strain'), 3)} | "
                  f"{fmt(r.get('peak_plastic_strain_star'), 3)} | {fmt(r.get('peak_temperature_K'), 0)} | "
                  f"{fmt(r.get('outline_distance_m') and float(r['outline_distance_m'])*1e3, 3)} | {fmt(r.get('face_roughness'), 3)} | "
                  f"{r['steps']} | {float(r['wall_s']):.1f} |")
        if exp:
            print(f"| experiment | | {fmt(exp.get('final_length', 0)*1e3, 2)} | | | {fmt(exp.get('footprint_diameter', 0)*1e3, 2)} | | | | | | | | | | | |")


if __name__ == "__main__":
    main(sys.argv[1:] or ["taylor-steel-208", "taylor-steel-282", "taylor-steel-343", "taylor-copper-130", "taylor-copper-146",
                          "taylor-copper-190", "armco-cylinder-nodal"])
