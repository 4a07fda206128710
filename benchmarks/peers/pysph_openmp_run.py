"""Run a PySPH example script with OpenMP switched on.

Usage: /usr/bin/python3 pysph_openmp_run.py EXAMPLE.py [PySPH application options...]

Debian's PySPH 1.0~b1 has only --no-openmp (no --openmp) and compyle's default is OpenMP
off, so the generated kernels would run on one thread whatever OMP_NUM_THREADS says. This
sets compyle's global configuration to use OpenMP before the example builds its solver; the
thread count is then OMP_NUM_THREADS. The example itself is run unchanged, as __main__.
"""
import runpy
import sys

from compyle.config import get_config


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: pysph_openmp_run.py EXAMPLE.py [options...]")
    get_config().use_openmp = True
    script = sys.argv[1]
    sys.argv = [script] + sys.argv[2:]
    runpy.run_path(script, run_name="__main__")


if __name__ == "__main__":
    main()
