#!/usr/bin/env python3
"""docs/paper-map.md names a file and a function for every equation and every line of Algorithm 1: each file must
exist and each function must be defined in the files named on its row (or their header / source counterparts), so
that the map cannot go stale. Also checks that Eqs. 1-6 and every statement line of Algorithm 1 (1-11, 13-16, 18,
22, 24) appear in the map.
Usage: paper_map_test.py REPOSITORY_ROOT"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
text = (root / "docs/paper-map.md").read_text()
failures = []


def counterparts(path):
    """The file and its header or source twin (src/m/x.cpp <-> include/canyon/m/x.hpp)."""
    files = [path]
    if path.startswith("src/") and path.endswith(".cpp"):
        files.append("include/canyon/" + path[len("src/"):-4] + ".hpp")
    if path.startswith("include/canyon/") and path.endswith(".hpp"):
        files.append("src/" + path[len("include/canyon/"):-4] + ".cpp")
    return [f for f in files if (root / f).is_file()]


def defined(identifier, sources):
    """`Class::member` or `name`: the last part is declared or defined in the sources (and the class, if any)."""
    parts = identifier.split("::")
    name = parts[-1]
    owner = parts[-2] if len(parts) >= 2 and parts[-2][:1].isupper() else None
    body = "\n".join(sources)
    if not re.search(r"\b" + re.escape(name) + r"\b\s*[({;]|(class|struct)\s+" + re.escape(name) + r"\b", body):
        return False
    return owner is None or re.search(r"\b" + re.escape(owner) + r"\b", body) is not None


rows = [line for line in text.splitlines() if line.startswith("|") and not line.startswith("|---")]
equations = set()
lines = set()
for row in rows:
    cells = [c.strip() for c in row.strip("|").split("|")]
    if len(cells) < 3 or cells[-1] == "function":
        continue
    files = [f for f in re.findall(r"`([^`]+\.(?:cpp|hpp))`", cells[-2])]
    functions = [f for f in re.findall(r"`([A-Za-z_][\w:]*)`", cells[-1])]
    if not files or not functions:
        failures.append(f"row without a file or a function: {row}")
        continue
    sources = []
    for f in files:
        if not (root / f).is_file():
            failures.append(f"{f}: no such file (row: {cells[0]})")
        for twin in counterparts(f):
            sources.append((root / twin).read_text())
    for function in functions:
        if not defined(function, sources):
            failures.append(f"{function}: not found in {', '.join(files)} (row: {cells[0]})")
    equations.update(int(n) for n in re.findall(r"Eqs?\. (\d)", cells[0]))
    for a, b in re.findall(r"Eqs\. (\d)-(\d)", cells[0]):
        equations.update(range(int(a), int(b) + 1))
    if re.fullmatch(r"\d+(-\d+)?", cells[0]):
        a, _, b = cells[0].partition("-")
        lines.update(range(int(a), int(b or a) + 1))

for n in range(1, 7):
    if n not in equations:
        failures.append(f"Eq. {n} is not in the map")
for n in [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 14, 15, 16, 18, 22, 24]:
    if n not in lines:
        failures.append(f"Algorithm 1, line {n} is not in the map")

for f in failures:
    print("paper map:", f)
print(f"paper map: {len(rows)} rows, {len(failures)} problems")
sys.exit(1 if failures else 0)
