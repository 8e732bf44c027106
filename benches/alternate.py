#!/usr/bin/env python3
"""Whole-process timings of commands run alternately (the machine's speed drifts: compare two
builds only within one series).

    python3 benches/alternate.py N label1 'command 1' label2 'command 2' ...

Runs the commands in turn, N rounds; prints each one's median wall time and median CPU time
(user + system of the child, from getrusage) and their ratios to the first command's.

Round k starts with command k mod M (M commands) and keeps their cyclic order, so that each
command follows a different one from round to round: a run can be slowed by what ran just
before it (session 38: mimalloc 2.x right after 3.x, 1.05 of its time when run first), and a
fixed order would charge that to the same command every round.
"""
import resource
import statistics
import subprocess
import sys
import time

n = int(sys.argv[1])
pairs = list(zip(sys.argv[2::2], sys.argv[3::2]))
res = {label: ([], []) for label, _ in pairs}
for k in range(n):
    for label, command in pairs[k % len(pairs):] + pairs[:k % len(pairs)]:
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(command, shell=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        t1 = time.perf_counter()
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        res[label][0].append(t1 - t0)
        res[label][1].append((r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime))
base = None
for label, _ in pairs:
    wall = statistics.median(res[label][0]) * 1e3
    cpu = statistics.median(res[label][1]) * 1e3
    if base is None:
        base = (wall, cpu)
    print(f"{label:28s} wall {wall:9.2f} ms  cpu {cpu:9.2f} ms   "
          f"ratio(cpu) {cpu / base[1]:.3f}  ratio(wall) {wall / base[0]:.3f}")
