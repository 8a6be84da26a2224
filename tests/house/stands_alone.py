#!/usr/bin/env python3
"""The repository stands alone: no tracked file points at a path outside it.

Fails on any tracked text file that names a relative path climbing out of the repository
(`../shared/...`, or a markdown link whose target resolves outside the root), an absolute path
into a developer's machine (/work/, /home/), or a paper by an internal file name instead of its
authors and year (docs/references.md lists the citations). Markdown links to files inside the
repository must resolve to an existing file. Checks itself first on a small tree with one
violation of each kind.

Usage: stands_alone.py [ROOT]
"""
import os
import re
import subprocess
import sys
import tempfile

FORBIDDEN = [
    (re.compile(r"\.\./shared\b"), "a path outside the repository (../shared)"),
    (re.compile(r"\b[0-9]{3}_[0-9a-f]{16}\.txt\b"), "a paper named by an internal file name"),
    (re.compile(r"\bseeds?/[0-9]{3}\b|\bseed 00[0-9]\b", re.I), "a paper named by an internal number"),
    (re.compile(r"(?<![\w.])/(work|home)/[\w.-]+/"), "an absolute path of a developer's machine"),
]
LINK = re.compile(r"\]\(([^)\s]+)\)")
TEXT = (".md", ".cpp", ".hpp", ".in", ".txt", ".sh", ".py", ".bash", ".json", ".cmake", ".xml", ".yml", ".yaml")


def tracked(root):
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], capture_output=True, check=True).stdout
        return [f for f in out.decode().split("\0") if f]
    except (OSError, subprocess.CalledProcessError):
        files = []
        for d, dirs, names in os.walk(root):
            dirs[:] = [x for x in dirs if not x.startswith((".", "build", "output"))]
            files += [os.path.relpath(os.path.join(d, n), root) for n in names]
        return files


def check(root, files):
    problems = []
    me = os.path.relpath(os.path.abspath(__file__), os.path.abspath(root))
    for rel in sorted(files):
        if rel == me or not (rel.endswith(TEXT) or os.path.basename(rel) in ("CMakeLists.txt", "run")):
            continue
        path = os.path.join(root, rel)
        try:
            text = open(path, encoding="utf-8").read()
        except (OSError, UnicodeDecodeError):
            continue
        for pattern, what in FORBIDDEN:
            for m in pattern.finditer(text):
                line = text.count("\n", 0, m.start()) + 1
                problems.append("%s:%d: %r: %s" % (rel, line, m.group(0), what))
        if rel.endswith(".md"):
            for m in LINK.finditer(text):
                target = m.group(1).split("#")[0]
                if not target or re.match(r"^[a-z]+:", target):
                    continue
                line = text.count("\n", 0, m.start()) + 1
                resolved = os.path.normpath(os.path.join(os.path.dirname(rel), target))
                if resolved.startswith(".."):
                    problems.append("%s:%d: link %s leads outside the repository" % (rel, line, target))
                elif not os.path.exists(os.path.join(root, resolved)):
                    problems.append("%s:%d: link %s: no such file" % (rel, line, target))
    return problems


def self_test():
    files = {
        "a.md": "see [design](../shared/DESIGN.md) and [x](docs/missing.md) and [ok](b.cpp)\n",
        "b.cpp": "// after seed 003 Sec. 4\n// see 000_03676414dd2e0b94.txt\n// built in /work/main/build/\n",
    }
    with tempfile.TemporaryDirectory() as tmp:
        for rel, body in files.items():
            open(os.path.join(tmp, rel), "w").write(body)
        found = "\n".join(check(tmp, list(files)))
    expected = ["../shared", "leads outside the repository", "docs/missing.md: no such file",
                "internal number", "internal file name", "developer's machine"]
    missed = [e for e in expected if e not in found]
    if missed or "[ok]" in found:
        print("stands_alone.py: its self-test missed %s; it reported:\n%s" % (missed, found))
        sys.exit(1)


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
    self_test()
    files = tracked(root)
    problems = check(root, files)
    for p in problems:
        print(p)
    if problems:
        print("%d references outside the repository" % len(problems))
        sys.exit(1)
    print("stands alone: %d tracked files, no reference outside the repository" % len(files))


if __name__ == "__main__":
    main()
