#!/usr/bin/env python3
"""Every relative link of the README, docs/ and deploy/README.md leads somewhere: the file exists and, where the link
names a heading (#anchor), the heading exists in that file (GitHub's anchors: lower case, punctuation dropped, spaces
to hyphens, a repeated heading gets -1, -2, ...). Links that leave the repository (../shared) and web addresses are
not checked. So that moving a page or renaming a heading cannot leave the front door pointing nowhere.
Usage: links_test.py REPOSITORY_ROOT"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^```.*?^```", re.M | re.S)


def anchors(path):
    """The anchors GitHub gives the headings of a Markdown file."""
    seen = {}
    result = set()
    for line in FENCE.sub("", path.read_text()).splitlines():
        match = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not match:
            continue
        slug = re.sub(r"[^\w\- ]", "", match.group(1).strip().lower()).replace(" ", "-")
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        result.add(slug if count == 0 else f"{slug}-{count}")
    return result


def check(page, failures):
    text = FENCE.sub("", page.read_text())
    for number, line in enumerate(text.splitlines(), 1):
        for target in LINK.findall(line):
            if re.match(r"^[a-z]+:", target):
                continue
            path_part, _, anchor = target.partition("#")
            destination = (page.parent / path_part).resolve() if path_part else page
            where = f"{page.relative_to(root)}:{number}: {target}"
            if root not in destination.parents and destination != root:
                continue
            if not destination.exists():
                failures.append(f"{where}: no file {destination.relative_to(root)}")
                continue
            if anchor and destination.suffix == ".md" and anchor not in anchors(destination):
                failures.append(f"{where}: no heading #{anchor} in {destination.relative_to(root)}")


def main():
    pages = [root / "README.md", root / "deploy/README.md", *sorted((root / "docs").rglob("*.md"))]
    failures = []
    for page in pages:
        check(page, failures)
    for failure in failures:
        print(failure)
    print(f"{len(pages)} pages, {len(failures)} broken links")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
