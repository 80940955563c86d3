#!/usr/bin/env python3
"""Which .cpp files clang-tidy must check again (scripts/check-tidy.sh --since-record, --record).

  tidy_changed.py REPO BUILD RECORD CHANGED FILE...   (ninja -t deps on stdin)
      prints the FILEs that include (or are) a path in CHANGED (repository paths, one per line) by the build's
      dependency list, or whose compile command differs from RECORD's hash for it (or RECORD has none).
  tidy_changed.py --record REPO BUILD COMMIT FILE...
      prints a record: COMMIT, then "HASH PATH" per FILE (PATH relative to REPO).
A compile command is hashed with the repository and build folders replaced by placeholders, so that a record made in
one clone holds in another.
"""
import hashlib
import json
import os
import sys


def command_hashes(repo, build):
    with open(os.path.join(build, "compile_commands.json")) as f:
        entries = json.load(f)
    hashes = {}
    for e in entries:
        command = e.get("command") or " ".join(e.get("arguments", []))
        command = command.replace(build, "@BUILD@").replace(repo, "@SRC@")
        hashes[e["file"]] = hashlib.sha256(command.encode()).hexdigest()[:16]
    return hashes


def read_record(path):
    recorded = {}
    with open(path) as f:
        for line in f.read().splitlines()[1:]:
            if line.strip():
                digest, rel = line.split(" ", 1)
                recorded[rel] = digest
    return recorded


def sources_including(changed, deps_text):
    hit, deps = set(), []
    for line in deps_text.splitlines() + [""]:
        if line.startswith((" ", "\t")):
            deps.append(line.strip())
            continue
        if deps and changed.intersection(deps):
            hit.add(deps[0])
        deps = []
    return hit


def main(argv):
    if argv[1] == "--record":
        repo, build, commit, files = argv[2], argv[3], argv[4], argv[5:]
        hashes = command_hashes(repo, build)
        print(commit)
        for f in files:
            print(hashes[f], os.path.relpath(f, repo))
        return 0
    repo, build, record, changed_text, files = argv[1], argv[2], argv[3], argv[4], argv[5:]
    changed = {os.path.join(repo, p) for p in changed_text.split("\n") if p}
    hit = sources_including(changed, sys.stdin.read())
    hashes = command_hashes(repo, build)
    recorded = read_record(record)
    for f in files:
        if f in hit or f in changed or recorded.get(os.path.relpath(f, repo)) != hashes.get(f):
            print(f)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
