"""Regenerates fuzz/seeds: the robots of robots/ and the URDF fixtures written as raw
strings in tests/it/*.rs (those without format placeholders), each at most 32 KiB."""

import glob
import hashlib
import os
import re

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "fuzz", "seeds")


def main():
    os.makedirs(OUT, exist_ok=True)
    for f in glob.glob(os.path.join(OUT, "*.urdf")):
        os.remove(f)
    files = sorted(glob.glob(os.path.join(ROOT, "robots", "*.urdf")))
    files += [os.path.join(ROOT, "robots", "solo12", "solo12_ground.urdf")]
    for path in files:
        with open(path) as f:
            text = f.read()
        with open(os.path.join(OUT, os.path.basename(path)), "w") as f:
            f.write(text)
    raw = re.compile(r'r#"(.*?)"#', re.S)
    n = 0
    for path in sorted(glob.glob(os.path.join(ROOT, "tests", "it", "**", "*.rs"), recursive=True)):
        with open(path) as f:
            src = f.read()
        for m in raw.finditer(src):
            text = m.group(1)
            if "<robot" not in text or "</robot>" not in text or re.search(r"\{[a-z_]*\}", text):
                continue
            if len(text) > 32 << 10:
                continue
            digest = hashlib.sha1(text.encode()).hexdigest()[:8]
            name = f"{os.path.splitext(os.path.basename(path))[0]}_{digest}.urdf"
            with open(os.path.join(OUT, name), "w") as f:
                f.write(text)
            n += 1
    print(f"{len(files)} robots, {n} test fixtures in {OUT}")


if __name__ == "__main__":
    main()
