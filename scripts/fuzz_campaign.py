#!/usr/bin/env python3
"""Black-box fuzz campaign on the restpose binary (docs/fuzzing.md).

Structure-aware mutants of the committed corpus (fuzz/seeds: robots/ and the tests'
fixtures) go through `check`, `analyze` and `verify` (on analyze's own JSON) with random
options, each run under a CPU-time limit (a wall-clock cap behind it) and a memory limit. Counted as faults:
  - panic: exit code 101, or death by a signal (other than the time limit's);
  - hang: a run that exceeds the CPU-time limit (or the wall-clock cap);
  - non-finite: `NaN`/`inf` in any output, or a JSON number written as `null`;
  - disagreement: analyze exits 0 and verify rejects analyze's own JSON (exit 4).
Each fault's input and command line are saved under OUT/faults/.

usage: scripts/fuzz_campaign.py --binary target/release/restpose --minutes 30 --out /tmp/campaign
"""

import argparse
import json
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "fuzz"))
from mutate import Mutator  # noqa: E402  (fuzz/mutate.py, the dictionary-driven mutator)

# JSON keys whose value may legitimately be null (absent, not a number).
NULLABLE = {
    "stability", "max_imbalance", "dof", "assembly_error", "mu", "friction", "value",
    "needed_mu", "lower", "upper", "limits", "eigenvalues_by", "softest_mode", "free_length",
    "effort_limit", "base", "reason", "suggestion", "limit", "at", "fraction",
}

# How Rust prints a non-finite f64 (`NaN`, `inf`, `-inf`), outside quoted input.
NONFINITE_TEXT = re.compile(r"(?<![A-Za-z_.])(NaN|-?inf)(?![A-Za-z_])")
QUOTED = re.compile(r'"[^"\n]*"|`[^`\n]*`')


def non_finite(text):
    """Non-finite numbers printed by restpose (not the input quoted back)."""
    return NONFINITE_TEXT.findall(QUOTED.sub("", text))


def limits(memory, cpu):
    """Address space `memory` bytes and `cpu` seconds of CPU time (SIGXCPU, then SIGKILL):
    on a loaded machine a CPU-time limit tells a hang from a slow start, a wall clock does not."""
    def apply():
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
        resource.setrlimit(resource.RLIMIT_CPU, (int(cpu), int(cpu) + 5))
    return apply


def nulls(value, path=""):
    """Paths of null values in a JSON document whose key is not nullable."""
    out = []
    if isinstance(value, dict):
        for k, v in value.items():
            if v is None and k not in NULLABLE:
                out.append(f"{path}.{k}")
            else:
                out.extend(nulls(v, f"{path}.{k}"))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            if v is None:
                out.append(f"{path}[{i}]")
            else:
                out.extend(nulls(v, f"{path}[{i}]"))
    return out


def random_options(rng, command, joints):
    opts = []
    if command in ("analyze", "verify", "check"):
        if rng.random() < 0.2:
            opts.append("--floating-base")
        if rng.random() < 0.2:
            opts.append("--ground")
        if rng.random() < 0.1:
            opts += ["--gravity"] + [rng.choice(["0", "-9.81", "9.81", "1e4", "3"]) for _ in range(3)]
        if rng.random() < 0.1:
            opts += ["--inertia-from-geometry", rng.choice(["1000", "1", "1e-3"])]
        if rng.random() < 0.1:
            opts += ["--base-xyz"] + [rng.choice(["0", "1", "-0.5"]) for _ in range(3)]
    if command in ("analyze", "verify"):
        if rng.random() < 0.3:
            opts += ["--limits", rng.choice(["enforce", "ignore"])]
        if rng.random() < 0.3:
            opts += ["--friction", rng.choice(["none", "stick"])]
        if rng.random() < 0.2:
            opts += ["--mu", rng.choice(["0", "0.5", "1e9"])]
        if rng.random() < 0.3:
            opts += ["--linear-algebra", rng.choice(["auto", "dense", "sparse"])]
    if command == "analyze":
        if rng.random() < 0.3:
            opts += ["--method", rng.choice(["newton", "bfgs", "dfp"])]
        if rng.random() < 0.2:
            opts += ["--load-steps", rng.choice(["0", "1", "3"])]
        if rng.random() < 0.2:
            opts.append("--allow-unstable")
        if rng.random() < 0.2:
            opts += ["--max-iterations", rng.choice(["1", "5", "50"])]
        if joints and rng.random() < 0.2:
            opts += ["--lock", f"{rng.choice(joints)}={rng.choice(['0', '0.5', '-1'])}"]
        if joints and rng.random() < 0.2:
            opts += ["--initial", f"{rng.choice(joints)}={rng.choice(['0', '1', '3.2'])}"]
    if command == "verify" and rng.random() < 0.2:
        opts += ["--force-tolerance", rng.choice(["1e-6", "1", "0"])]
    if command == "verify" and rng.random() < 0.1:
        opts.append("--eigenvalues")
    return opts


class Campaign:
    def __init__(self, args):
        self.args = args
        self.rng = random.Random(args.seed)
        self.counts = {"mutants": 0, "executions": 0, "panics": 0, "hangs": 0,
                       "non_finite": 0, "disagreements": 0, "errors_exit_1": 0}
        self.mutator = Mutator(self.rng)
        self.seeds = []
        for d in args.corpus:
            for name in sorted(os.listdir(d)):
                if name.endswith(".urdf"):
                    with open(os.path.join(d, name), encoding="utf-8", errors="replace") as f:
                        self.seeds.append((name, f.read()))
        os.makedirs(os.path.join(args.out, "faults"), exist_ok=True)
        self.work = tempfile.mkdtemp(prefix="restpose-campaign-")

    def run(self, cmd):
        self.counts["executions"] += 1
        try:
            p = subprocess.run(
                cmd, capture_output=True, timeout=self.args.wall,
                preexec_fn=limits(self.args.memory << 20, self.args.timeout), cwd=self.work,
            )
            if p.returncode in (-signal.SIGXCPU, -signal.SIGKILL):
                return None, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")
            return p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")
        except subprocess.TimeoutExpired as e:
            return None, (e.stdout or b"").decode(errors="replace"), (e.stderr or b"").decode(errors="replace")

    def fault(self, kind, name, text, cmd, detail):
        self.counts[kind] += 1
        k = sum(self.counts[x] for x in ("panics", "hangs", "non_finite", "disagreements"))
        base = os.path.join(self.args.out, "faults", f"{k:04d}_{kind}")
        with open(base + ".urdf", "w") as f:
            f.write(text)
        with open(base + ".txt", "w") as f:
            f.write(f"seed: {name}\ncommand: {' '.join(cmd)}\n\n{detail}\n")
        print(f"[{kind}] {name}: {' '.join(cmd[1:3])} -> {detail[:200]}", flush=True)

    def judge(self, name, text, cmd, rc, out, err, json_path=None):
        if rc is None:
            self.fault("hangs", name, text, cmd,
                       f"over {self.args.timeout} s of CPU or {self.args.wall} s of wall time\n{err[-2000:]}")
            return
        if rc == 101 or rc < 0:
            self.fault("panics", name, text, cmd, f"exit {rc}\n{err[-4000:]}")
            return
        found = non_finite(out + err)
        # A link or joint the mutant named `inf` or `NaN` is listed by its name.
        named = set(re.findall(r'(?:name|link|joint)="(-?inf|NaN)"', text))
        found = [f for f in found if f not in named]
        if found:
            self.fault("non_finite", name, text, cmd, f"text {found[:5]}\n{out[-2000:]}\n{err[-2000:]}")
            return
        if json_path and os.path.exists(json_path):
            try:
                with open(json_path) as f:
                    doc = json.load(f)
                bad = nulls(doc)
                if bad:
                    self.fault("non_finite", name, text, cmd, f"JSON nulls {bad[:10]}")
            except (ValueError, OSError) as e:
                self.fault("non_finite", name, text, cmd, f"unreadable JSON: {e}")

    def one(self):
        name, seed = self.rng.choice(self.seeds)
        text = self.mutator.mutate(seed, self.rng.randint(1, 4))
        self.counts["mutants"] += 1
        path = os.path.join(self.work, "m.urdf")
        with open(path, "w") as f:
            f.write(text)
        joints = re.findall(r'<joint[^>]*name="([^"]+)"', text)
        b = self.args.binary
        cmd = [b, "check", path] + random_options(self.rng, "check", joints)
        rc, out, err = self.run(cmd)
        self.judge(name, text, cmd, rc, out, err)
        if rc == 1:
            self.counts["errors_exit_1"] += 1
        result = os.path.join(self.work, "r.json")
        if os.path.exists(result):
            os.remove(result)
        aopts = random_options(self.rng, "analyze", joints)
        cmd = [b, "analyze", path, "--json", result] + aopts
        analyze_cmd = cmd
        rc, out, err = self.run(cmd)
        self.judge(name, text, cmd, rc, out, err, result)
        analyzed = rc
        if not os.path.exists(result):
            return
        # verify on analyze's own answer, with the options that shape the model and the
        # unilateral checks as analyze had them (the agreement check), or random ones.
        same = self.rng.random() < 0.5
        if same:
            keep = []
            i = 0
            while i < len(aopts):
                o = aopts[i]
                n = {"--floating-base": 0, "--ground": 0, "--gravity": 3, "--limits": 1,
                     "--friction": 1, "--mu": 1, "--linear-algebra": 1, "--base-xyz": 3,
                     "--inertia-from-geometry": 1, "--lock": 1}.get(o)
                if n is not None and o != "--lock":
                    keep += aopts[i:i + 1 + n]
                i += 1 + ({"--method": 1, "--load-steps": 1, "--max-iterations": 1,
                           "--initial": 1, "--lock": 1}.get(o, n or 0))
            vopts = keep
        else:
            vopts = random_options(self.rng, "verify", joints)
        vjson = os.path.join(self.work, "v.json")
        if os.path.exists(vjson):
            os.remove(vjson)
        locked = "--lock" in aopts
        cmd = [b, "verify", path, "--pose", result, "--json", vjson] + vopts
        rc, out, err = self.run(cmd)
        self.judge(name, text, cmd, rc, out, err, vjson)
        if same and not locked and analyzed == 0 and rc == 4:
            self.fault("disagreements", name, text, cmd,
                       f"analyze exit 0 ({' '.join(analyze_cmd)}), verify exit 4\n{err[-2000:]}")

    def report(self, started):
        c = dict(self.counts)
        c["seconds"] = round(time.time() - started, 1)
        return c

    def main(self):
        started = time.time()
        deadline = started + 60 * self.args.minutes
        last = started
        while time.time() < deadline:
            self.one()
            if time.time() - last > 60:
                last = time.time()
                print(json.dumps(self.report(started)), flush=True)
        summary = self.report(started)
        with open(os.path.join(self.args.out, "summary.json"), "w") as f:
            json.dump(summary, f, indent=2)
        print(json.dumps(summary, indent=2))
        shutil.rmtree(self.work, ignore_errors=True)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=os.path.join(ROOT, "target/release/restpose"))
    ap.add_argument("--minutes", type=float, default=30)
    ap.add_argument("--timeout", type=float, default=20, help="CPU time per run [s]")
    ap.add_argument("--wall", type=float, default=300, help="wall time per run [s]")
    ap.add_argument("--memory", type=int, default=4096, help="per run [MiB]")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="/tmp/restpose-campaign")
    ap.add_argument("--corpus", nargs="*", default=[os.path.join(ROOT, "fuzz/seeds")])
    Campaign(ap.parse_args()).main()
