#!/usr/bin/python3
"""Hand-kept documentation that must follow the tree (issue 22):

1. every "docs/ARCHITECTURE.md §N" cited anywhere in the tracked text names a
   section "## N." of docs/ARCHITECTURE.md (its numbers are the stable anchors);
2. README's "Layout of the repository" names every tracked folder of the first two
   levels and every folder of daemon/core/ (as "name/").

Usage: check_docs.py SOURCE_DIR. Needs git (the tracked files); skips honestly
(exit 77) in a source tree without it. Python 3 standard library only.
"""
import os
import re
import subprocess
import sys

SKIP = 77


def tracked_files(src):
    try:
        out = subprocess.run(["git", "-C", src, "ls-files"], check=True, capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    return out.split("\n")[:-1] if out else []


def main():
    src = sys.argv[1]
    files = tracked_files(src)
    if not files:
        print("check_docs: no git checkout at %s (a source tarball): skipped" % src)
        return SKIP
    problems = []

    with open(os.path.join(src, "docs", "ARCHITECTURE.md"), encoding="utf-8") as f:
        sections = set(re.findall(r"^## (\d+)\. ", f.read(), re.M))
    for path in files:
        if not re.search(r"\.(cpp|h|py|sh|md|txt|cmake|lcm|toml|in)$", path):
            continue
        try:
            with open(os.path.join(src, path), encoding="utf-8") as f:
                text = f.read()
        except (OSError, UnicodeDecodeError):
            continue
        for lineno, line in enumerate(text.split("\n"), 1):
            cited = [number for n in re.findall(r"ARCHITECTURE\.md`?\)?:? \(?((?:§\d+(?:, )?)+)", line)
                     for number in re.findall(r"§(\d+)", n)]
            # Program output (effect sources, help texts) spells it in ASCII.
            cited += re.findall(r"ARCHITECTURE\.md section (\d+)", line)
            for number in cited:
                if number not in sections:
                    problems.append("%s:%d: cites docs/ARCHITECTURE.md §%s, which has no section \"## %s.\""
                                    % (path, lineno, number, number))

    with open(os.path.join(src, "README.md"), encoding="utf-8") as f:
        readme = f.read()
    m = re.search(r"^## Layout of the repository\n(.*?)(?=^## |\Z)", readme, re.M | re.S)
    if not m:
        problems.append("README.md: no section \"## Layout of the repository\"")
    else:
        layout = m.group(1)
        folders = set()
        for path in files:
            parts = path.split("/")[:-1]
            if parts:
                folders.add(parts[0])
            if len(parts) >= 2:
                folders.add("/".join(parts[:2]))
            if len(parts) >= 3 and parts[:2] == ["daemon", "core"]:
                folders.add("/".join(parts[:3]))
        for folder in sorted(folders):
            name = folder.split("/")[-1] + "/"
            if name.startswith("."):
                name = folder.split("/")[-1]
            if name not in layout:
                problems.append("README.md, \"Layout of the repository\": the folder %s is not named (as \"%s\")"
                                % (folder, name))

    for p in problems:
        print(p)
    if problems:
        print("check_docs: %d problem(s): update docs/ARCHITECTURE.md or README.md" % len(problems))
        return 1
    print("check_docs: %d tracked files; ARCHITECTURE.md sections %s; README layout names every folder"
          % (len(files), ", ".join(sorted(sections, key=int))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
