"""Every written pose round-trips (issue 21): the 15 legged robots of example-robot-data that
scripts/pinocchio_corpus.py stands on the ground (servos about their SRDF state, sticking
contacts), each analysed with `--write-urdf` (into another folder than the robot's),
`--write-joint-states` and `--json` (run by round_trip.sh).

For each robot:
  1. the written URDF, analysed again with the same options (and the `--servo JOINT=K@REF`
     options `--write-urdf`'s note names, for servos whose reference is their start), converges
     in 0 iterations to the same energy (1e-9 relative);
  2. `restpose verify` passes the written YAML and JSON poses (dense), and the JSON pose with
     `--linear-algebra sparse`.

Prints one line per robot; exits 1 on any failure.
"""

import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pinocchio_corpus as corpus  # noqa: E402

RESTPOSE = os.environ["RESTPOSE"]
ERD = os.environ["ERD_ROBOTS"]


def run(args):
    return subprocess.run([RESTPOSE, *args], capture_output=True, text=True, timeout=corpus.TIMEOUT)


def main():
    failures = 0
    with tempfile.TemporaryDirectory() as out:
        for urdf, srdf, state in corpus.STANDING:
            name = f"{urdf} ({state})"
            model = ["--floating-base", "--ground", "--friction", "stick", "--servo", "all=1000",
                     "--srdf", f"{ERD}/{srdf}", "--srdf-state", state,
                     "--package", f"example-robot-data={ERD}/.."]
            stem = os.path.join(out, urdf.replace("/", "_"))
            written, yaml, first, again = (stem + ".urdf", stem + ".yaml", stem + ".json",
                                           stem + "-again.json")
            r = run(["analyze", f"{ERD}/{urdf}", *model, "--load-steps", "1", "-q", "--json", first,
                     "--write-urdf", written, "--write-joint-states", yaml])
            if r.returncode != 0:
                print(f"FAIL {name}: analyze exited {r.returncode}: {r.stderr.strip()[-300:]}")
                failures += 1
                continue
            keep = []
            for line in r.stderr.splitlines():
                if "to keep these servos add: " in line:
                    keep = line.split("to keep these servos add: ", 1)[1].split()
            a = json.load(open(first))
            bad = []
            r2 = run(["analyze", written, *model, *keep, "--load-steps", "1", "-q", "--json", again])
            if r2.returncode != 0:
                bad.append(f"re-analysis exited {r2.returncode}: {r2.stderr.strip()[-300:]}")
            else:
                b = json.load(open(again))
                dv = b["potential_energy"] - a["potential_energy"]
                if b["iterations"] != 0 or abs(dv) > 1e-9 * max(1.0, abs(a["potential_energy"])):
                    bad.append(f"re-analysis: {b['iterations']} iterations, energy {dv:+.3e} J")
            for pose, extra in [(yaml, []), (first, []), (first, ["--linear-algebra", "sparse"])]:
                v = run(["verify", f"{ERD}/{urdf}", *model, "--pose", pose, *extra])
                if v.returncode != 0:
                    bad.append(f"verify {os.path.basename(pose)} {' '.join(extra)} exited "
                               f"{v.returncode}")
            failures += bool(bad)
            print(f"{'FAIL' if bad else 'ok  '} {name}: {a['iterations']} iterations, "
                  f"V = {a['potential_energy']:.9f} J, {len(keep) // 2} servo reference(s) "
                  f"given again{'; ' + '; '.join(bad) if bad else ''}")
    print(f"round trips: {len(corpus.STANDING)} robots, {failures} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
