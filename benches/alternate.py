#!/usr/bin/env python3
"""Whole-process timings of commands run alternately (the machine's speed drifts: compare two
builds only within one series).

    python3 benches/alternate.py N label1 'command 1' label2 'command 2' ...

Runs the commands in turn, N rounds; prints each one's median wall time and median CPU time
(user + system of the run, from `wait4`) and their ratios to the first command's, then a
second line with the medians of the user and the system time apart and the CPU time's spread
(quartiles and extremes).

Round k starts with command k mod M (M commands) and keeps their cyclic order, so that each
command follows a different one from round to round: a run can be slowed by what ran just
before it (session 38: mimalloc 2.x right after 3.x, 1.05 of its time when run first), and a
fixed order would charge that to the same command every round.

User and system apart (session 39): on the virtual machine the figures of BENCHMARKS.md come
from, a first touch of a fresh 4 KiB page costs the kernel 1.5 - 2.5 us, so a third of a
chain's CPU time can be system time that follows the heap's peak, not the code's speed; and
with transparent huge pages the runs split into a fast and a slow mode (system time 4 - 19 ms
against 80 - 126 ms on the 1,000-rung ladder), which a median alone hides. The second line also
gives the median number of minor page faults of a run (`wait4`'s, of the shell and the command
together: `sh -c /bin/true` alone takes about 110 here), the measure of the pages it touched.
"""
import os
import statistics
import subprocess
import sys
import time

n = int(sys.argv[1])
pairs = list(zip(sys.argv[2::2], sys.argv[3::2]))
# Per label: wall, CPU, user and system times [s], minor page faults.
res = {label: ([], [], [], [], []) for label, _ in pairs}
for k in range(n):
    for label, command in pairs[k % len(pairs):] + pairs[:k % len(pairs)]:
        t0 = time.perf_counter()
        child = subprocess.Popen(command, shell=True, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
        # The child's own usage (with its reaped children: the command under the shell).
        _, status, usage = os.wait4(child.pid, 0)
        # Reaped here: tell `Popen`, so that it does not wait for the child again.
        child.returncode = os.waitstatus_to_exitcode(status)
        t1 = time.perf_counter()
        user, system = usage.ru_utime, usage.ru_stime
        values = (t1 - t0, user + system, user, system, usage.ru_minflt)
        for series, value in zip(res[label], values):
            series.append(value)


def quartiles(values):
    """Lower quartile, median and upper quartile (the median of each half for the quartiles)."""
    v = sorted(values)
    half = len(v) // 2
    low, high = v[:half] or v, v[len(v) - half:] or v
    return statistics.median(low), statistics.median(v), statistics.median(high)


base = None
for label, _ in pairs:
    wall_s, cpu_s, user_s, sys_s, faults = res[label]
    wall = statistics.median(wall_s) * 1e3
    cpu = statistics.median(cpu_s) * 1e3
    if base is None:
        base = (wall, cpu)
    print(f"{label:28s} wall {wall:9.2f} ms  cpu {cpu:9.2f} ms   "
          f"ratio(cpu) {cpu / base[1]:.3f}  ratio(wall) {wall / base[0]:.3f}")
    q1, _, q3 = quartiles(cpu_s)
    print(f"{'':28s} user {statistics.median(user_s) * 1e3:9.2f} ms  "
          f"system {statistics.median(sys_s) * 1e3:7.2f} ms   "
          f"cpu min {min(cpu_s) * 1e3:.2f} q1 {q1 * 1e3:.2f} q3 {q3 * 1e3:.2f} "
          f"max {max(cpu_s) * 1e3:.2f} ms   faults {statistics.median(faults):.0f}")
