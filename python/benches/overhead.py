"""What a solve costs from Python against the same solve in Rust, with Pinocchio's Python
beside it, on published robots (example-robot-data).

    python python/benches/overhead.py --rust-bench PATH [--repeats 200] [--rounds 5]

PATH is the compiled `benches/solve_file.rs` (`cargo bench --bench solve_file --no-run`
names it). Run in the venv of `python/ci.sh` (restpose-urdf, pin, example-robot-data).

Each robot gets the springs of `python/tests/test_pinocchio.py` (K (θ − REF) on every
revolute, continuous and prismatic joint), limits ignored, so that the three solve the same
problem:
- Rust: `restpose::solve` + `AnalysisResult::new` in process (median of REPEATS);
- Python: `model.solve(limits="ignore")` (median of REPEATS): the Rust work plus argument
  conversion, GIL release and the `Result` object;
- Pinocchio: Newton on joint coordinates in Python, K(q − REF) + g(q) = 0 with
  `computeGeneralizedGravity` and `computeGeneralizedGravityDerivatives` (+ K), from the
  neutral configuration to max|residual| < 1e-8 N m (median of REPEATS / 10).
Rust and Python alternate, ROUNDS times, in one series (the machine's speed drifts); the
overhead is the median over rounds of (Python ÷ Rust − 1). The rest poses are compared.
"""

from __future__ import annotations

import argparse
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import restpose

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from conftest import example_robot_data_dir  # noqa: E402
from test_pinocchio import K, REF, joints_of, with_springs  # noqa: E402

import pinocchio as pin  # noqa: E402

ROBOTS = [
    "ur_description/urdf/ur5_robot.urdf",
    "panda_description/urdf/panda.urdf",
    "solo_description/robots/solo12.urdf",
    "talos_data/robots/talos_full_v2.urdf",
]


def rust_times(bench: str, path: Path, repeats: int) -> tuple[float, float, int]:
    """Median and minimum [s] of the Rust solve, and its iterations."""
    out = subprocess.run(
        [bench, str(path), str(repeats), "--limits-ignore"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    m = re.search(r"median_us=([\d.]+) min_us=([\d.]+) iterations=(\d+)", out)
    assert m, out
    return float(m.group(1)) * 1e-6, float(m.group(2)) * 1e-6, int(m.group(3))


def python_times(model, repeats: int) -> tuple[float, float]:
    """Median and minimum [s] of `model.solve` from Python."""
    model.solve(limits="ignore")
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        model.solve(limits="ignore")
        times.append(time.perf_counter() - t)
    return statistics.median(times), min(times)


def overhead(bench, path, model, repeats, rounds):
    """Rust and Python alternately: medians, minima, iterations, and the per-round ratios."""
    rust, py, by_median, by_min = [], [], [], []
    for _ in range(rounds):
        r_med, r_min, iterations = rust_times(bench, path, repeats)
        p_med, p_min = python_times(model, repeats)
        rust.append(r_med)
        py.append(p_med)
        by_median.append(p_med / r_med - 1)
        by_min.append(p_min / r_min - 1)
    return rust, py, by_median, by_min, iterations


def pct(xs):
    return f"{statistics.median(xs) * 100:+.1f} % ({min(xs) * 100:+.1f} … {max(xs) * 100:+.1f})"


def pinocchio_newton(pmodel, k, ref):
    data = pmodel.createData()
    q = pin.neutral(pmodel)
    for it in range(100):
        angles = np.array([theta(pmodel, q, j) for j in range(1, pmodel.njoints)])
        r = k * (angles - ref) + pin.computeGeneralizedGravity(pmodel, data, q)
        if np.abs(r).max() < 1e-8:
            return q, it
        h = pin.computeGeneralizedGravityDerivatives(pmodel, data, q) + np.diag(k)
        q = pin.integrate(pmodel, q, -np.linalg.solve(h, r))
    raise RuntimeError("Pinocchio Newton did not converge")


def theta(pmodel, q, j):
    joint = pmodel.joints[j]
    if joint.nq == 2:
        return np.arctan2(q[joint.idx_q + 1], q[joint.idx_q])
    return q[joint.idx_q]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rust-bench", required=True)
    ap.add_argument("--repeats", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=5)
    a = ap.parse_args()
    root = example_robot_data_dir()
    packages = {d.name: d for d in root.iterdir() if d.is_dir()}
    print(f"restpose-urdf {restpose.__version__}, pin {pin.__version__}, numpy {np.__version__}")
    print(
        "| robot | dof | iterations | Rust solve [µs] | Python solve [µs] | Python ÷ Rust − 1, "
        "medians (median, range over rounds) | same, minima | Pinocchio Newton in Python [µs] "
        "| Pinocchio ÷ restpose-Python | max |Δθ| [rad] |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    repo_robots = Path(__file__).resolve().parents[2] / "robots"
    for name in ("pendulum.urdf", "ur5_class.urdf"):
        path = repo_robots / name
        model = restpose.load(path)
        result = model.solve(limits="ignore")
        rust, py, by_median, by_min, iterations = overhead(
            a.rust_bench, path, model, a.repeats, a.rounds
        )
        print(
            f"| {name} (repository) | {result.dof} | {iterations} | {statistics.median(rust) * 1e6:.1f} "
            f"| {statistics.median(py) * 1e6:.1f} | {pct(by_median)} | {pct(by_min)} | — | — | — |"
        )
    with tempfile.TemporaryDirectory() as tmp:
        for rel in ROBOTS:
            src = root / rel
            raw = re.sub(r"<mimic\b[^>]*/>", "", src.read_text(encoding="utf-8"))
            sprung = with_springs(raw)
            # next to the original, so that relative mesh paths resolve alike
            path = Path(tmp) / src.name
            path.write_text(sprung, encoding="utf-8")
            model = restpose.load(path, packages=packages)
            result = model.solve(limits="ignore")
            pmodel = pin.buildModelFromXML(raw)
            kinds = dict(joints_of(raw))
            names = [pmodel.names[j] for j in range(1, pmodel.njoints)]
            k = np.array([K[kinds[n]] for n in names])
            ref = np.array([REF[kinds[n]] for n in names])
            rust, py, by_median, by_min, iterations = overhead(
                a.rust_bench, path, model, a.repeats, a.rounds
            )
            q, _ = pinocchio_newton(pmodel, k, ref)
            pin_times = []
            for _ in range(max(3, a.repeats // 10)):
                t = time.perf_counter()
                pinocchio_newton(pmodel, k, ref)
                pin_times.append(time.perf_counter() - t)
            dtheta = max(
                abs(theta(pmodel, q, j) - result.joint(pmodel.names[j])[0])
                for j in range(1, pmodel.njoints)
            )
            tp = statistics.median(pin_times)
            print(
                f"| {src.name} | {result.dof} | {iterations} | {statistics.median(rust) * 1e6:.1f} "
                f"| {statistics.median(py) * 1e6:.1f} | {pct(by_median)} | {pct(by_min)} | {tp * 1e6:.1f} "
                f"| {tp / statistics.median(py):.2f} | {dtheta:.1e} |"
            )


if __name__ == "__main__":
    main()
