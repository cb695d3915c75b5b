#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Checks the tracked tree as a reader meets it (the test docs:tree):
- no work-log wording ("stop 12", "issue #7", "stops 3-4"): the git history holds that;
- every relative link of a Markdown file resolves to a file of the repository, and its #anchor to a
  heading of that file (GitHub's anchor rule);
- no link or path that points outside the repository (a relative link climbing above the root, an
  absolute local path).
Usage: tools/check_docs.py [ROOT]   (exit 1 with one line per problem)"""
import re
import subprocess
import sys
from pathlib import Path

TEXT = {".md", ".cpp", ".hpp", ".h", ".inl", ".glsl", ".comp", ".vert", ".frag", ".sh", ".py",
        ".txt", ".cmake", ".json", ".mjs", ".in", ""}
WORK_LOG = re.compile(r"(?<![A-Za-z_])(stops?|issues?)\s?#?[0-9]", re.IGNORECASE)
LINK = re.compile(r"\]\(([^)\s]+)\)")
LOCAL_PATH = re.compile(r"(?<![A-Za-z0-9_.])/(work|home|tmp/work)/[A-Za-z]")


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but - and _ dropped, spaces -> -."""
    text = re.sub(r"`|\*", "", heading.strip()).lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors_of(path: Path) -> set:
    found, seen = set(), {}
    in_code = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            in_code = not in_code
        if in_code:
            continue
        m = re.match(r"#{1,6}\s+(.*)", line)
        if m:
            a = anchor(m.group(1))
            n = seen.get(a, 0)
            seen[a] = n + 1
            found.add(a if n == 0 else f"{a}-{n}")
    return found


def main() -> int:
    root = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent).resolve()
    files = subprocess.run(["git", "-C", str(root), "ls-files", "-co", "--exclude-standard"],
                           check=True, capture_output=True, text=True).stdout.split()
    problems = []
    for name in files:
        path = root / name
        if path.suffix not in TEXT or not path.is_file() or name.startswith("tests/fuzz/"):
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            if name != "tools/check_docs.py" and WORK_LOG.search(line):
                problems.append(f"{name}:{number}: work-log wording: {line.strip()[:120]}")
            if name != "tools/check_docs.py" and LOCAL_PATH.search(line):
                problems.append(f"{name}:{number}: a path outside the repository: {line.strip()[:120]}")
        if path.suffix != ".md":
            continue
        for number, line in enumerate(text.splitlines(), 1):
            for target in LINK.findall(line):
                if re.match(r"[a-z]+:", target):  # https:, mailto:
                    continue
                file_part, _, fragment = target.partition("#")
                linked = (path.parent / file_part).resolve() if file_part else path
                if root not in linked.parents and linked != root:
                    problems.append(f"{name}:{number}: link outside the repository: {target}")
                elif not linked.exists():
                    problems.append(f"{name}:{number}: broken link: {target}")
                elif fragment and linked.suffix == ".md" and fragment not in anchors_of(linked):
                    problems.append(f"{name}:{number}: no heading for #{fragment} in {file_part or name}")
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
