"""Structure-aware mutator of URDF text, driven by fuzz/urdf.dict (the same operations as the
Rust mutator of fuzz/src/lib.rs): replace a number or an attribute value, rename an element,
an attribute or a name, duplicate or delete an element, insert a dictionary snippet."""

import os
import re

DICT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "urdf.dict")

ATTR = re.compile(r'([A-Za-z_:]+)="([^"]*)"')
NUMBER = re.compile(r"-?\d+(\.\d*)?([eE][-+]?\d+)?")
TAG = re.compile(r"<([A-Za-z_][A-Za-z0-9_:]*)")
SELF_CLOSING = re.compile(r"<[A-Za-z_][^<>]*/>")


def load_dictionary(path=DICT):
    d = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#") or "=" not in line:
                continue
            key, value = line.split("=", 1)
            value = value[1:-1].encode().decode("unicode_escape")
            d.setdefault(key.split("_", 1)[0], []).append(value)
    return d


class Mutator:
    def __init__(self, rng):
        self.rng = rng
        self.d = load_dictionary()

    def mutate(self, text, n):
        for _ in range(n):
            op = self.rng.choice([
                self.number, self.number, self.value, self.rename_name, self.tag, self.attribute,
                self.duplicate, self.delete, self.snippet, self.snippet,
            ])
            text = op(text)
        return text

    def pick(self, matches):
        return self.rng.choice(matches) if matches else None

    def number(self, text):
        attrs = [m for m in ATTR.finditer(text) if NUMBER.search(m.group(2))]
        m = self.pick(attrs)
        if not m:
            return text
        nums = list(NUMBER.finditer(m.group(2)))
        k = self.rng.choice(nums)
        v = m.group(2)
        v = v[:k.start()] + self.rng.choice(self.d["num"]) + v[k.end():]
        return text[:m.start(2)] + v + text[m.end(2):]

    def value(self, text):
        m = self.pick(list(ATTR.finditer(text)))
        if not m:
            return text
        names = [a.group(2) for a in ATTR.finditer(text) if a.group(1) in ("name", "link", "joint")]
        pool = self.d["word"] + self.d["num"] + names
        return text[:m.start(2)] + self.rng.choice(pool) + text[m.end(2):]

    def rename_name(self, text):
        names = [a for a in ATTR.finditer(text) if a.group(1) in ("name", "link", "joint")]
        m = self.pick(names)
        if not m:
            return text
        other = self.pick(names)
        new = other.group(2) if self.rng.random() < 0.5 else m.group(2) + "_fz"
        return text[:m.start(2)] + new + text[m.end(2):]

    def tag(self, text):
        m = self.pick(list(TAG.finditer(text)))
        if not m:
            return text
        new = self.rng.choice(self.d["tag"])
        old = m.group(1)
        out = text[:m.start(1)] + new + text[m.end(1):]
        # Its closing tag too, when it has one after it (keeps the document well-formed).
        close = out.find(f"</{old}>", m.start(1))
        if close >= 0 and self.rng.random() < 0.9:
            out = out[:close + 2] + new + out[close + 2 + len(old):]
        return out

    def attribute(self, text):
        m = self.pick(list(ATTR.finditer(text)))
        if not m:
            return text
        return text[:m.start(1)] + self.rng.choice(self.d["attr"]) + text[m.end(1):]

    def elements(self, text):
        """Self-closing elements and whole `<joint>`/`<link>`/`<mech:…>` elements."""
        spans = [(m.start(), m.end()) for m in SELF_CLOSING.finditer(text)]
        for t in ("joint", "link", "mech:loop_joint", "mech:spring", "collision", "inertial"):
            for m in re.finditer(f"<{t}[ >]", text):
                end = text.find(f"</{t}>", m.start())
                if end >= 0:
                    spans.append((m.start(), end + len(t) + 3))
        return spans

    def duplicate(self, text):
        s = self.pick(self.elements(text))
        if not s:
            return text
        return text[:s[1]] + text[s[0]:s[1]] + text[s[1]:]

    def delete(self, text):
        s = self.pick(self.elements(text))
        if not s:
            return text
        return text[:s[0]] + text[s[1]:]

    def snippet(self, text):
        links = [a.group(1) for a in re.finditer(r'<link name="([^"]+)"', text)] or ["world"]
        joints = [a.group(1) for a in re.finditer(r'<joint name="([^"]+)"', text)] or ["j"]
        s = self.rng.choice(self.d["snippet"])
        s = s.replace("LINK", self.rng.choice(links)).replace("JOINT", self.rng.choice(joints))
        at = text.rfind("</robot>")
        if at < 0:
            return text + s
        return text[:at] + s + "\n" + text[at:]
