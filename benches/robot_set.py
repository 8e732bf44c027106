#!/usr/bin/env python3
"""Whole-process CPU of two builds on a set of real robots, run alternately (the machine's speed
drifts: compare two builds only within one series).

    python3 benches/robot_set.py ROUNDS DIR BIN_A BIN_B [--package NAME=DIR]

Runs `BIN analyze FILE -q --json OUT` with default options (hanging, limits enforced) on every
`*.urdf` under DIR (`random_urdfs/` of pybullet_data left out), BIN_A and BIN_B alternately
ROUNDS times per file (the order swapped every round), `MIMALLOC_ALLOW_THP=0` as in
BENCHMARKS.md; CPU = user + system of the child (`wait4`). Prints the ten files with the
largest median under BIN_A (median A, median B, ratio) and the sums of the medians over all
files. The sets of BENCHMARKS.md ("Real robots"), from the venv of scripts/peers_venv.sh
(example-robot-data 6.0.0 and pybullet 3.2.7 from PyPI):

    SITE=~/.cache/restpose-peers/venv/lib/python3.11/site-packages
    ERD=$SITE/cmeel.prefix/share/example-robot-data/robots
    python3 benches/robot_set.py 5 $ERD OLD NEW --package example-robot-data=$ERD
    python3 benches/robot_set.py 3 $SITE/pybullet_data OLD NEW

A file a build refuses counts with its time like any other.
"""
import glob
import os
import statistics
import subprocess
import sys
import tempfile


def main():
    args = sys.argv[1:]
    package = []
    if "--package" in args:
        i = args.index("--package")
        package = ["--package", args[i + 1]]
        del args[i : i + 2]
    if len(args) != 4:
        sys.exit(__doc__)
    rounds, folder, a, b = int(args[0]), args[1].rstrip("/"), args[2], args[3]
    files = sorted(
        f
        for f in glob.glob(folder + "/**/*.urdf", recursive=True)
        if "/random_urdfs/" not in f
    )
    env = dict(os.environ, MIMALLOC_ALLOW_THP="0")
    out = os.path.join(tempfile.mkdtemp(), "rest.json")

    def cpu_ms(binary, urdf):
        cmd = [binary, "analyze", urdf, "-q", "--json", out] + package
        p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
        _, _, usage = os.wait4(p.pid, 0)
        return (usage.ru_utime + usage.ru_stime) * 1e3

    rows = []
    for f in files:
        ta, tb = [], []
        for r in range(rounds):
            first, second = ((a, ta), (b, tb)) if r % 2 == 0 else ((b, tb), (a, ta))
            first[1].append(cpu_ms(first[0], f))
            second[1].append(cpu_ms(second[0], f))
        rows.append((statistics.median(ta), statistics.median(tb), os.path.relpath(f, folder)))
    for ma, mb, name in sorted(rows, reverse=True)[:10]:
        print(f"{ma:8.2f} {mb:8.2f} {mb / ma:6.3f}  {name}")
    sa, sb = sum(r[0] for r in rows), sum(r[1] for r in rows)
    print(f"{len(files)} files: A {sa:.1f} ms, B {sb:.1f} ms CPU (sums of medians), B/A {sb / sa:.3f}")


if __name__ == "__main__":
    main()
