#!/usr/bin/env python3
"""The house rules of docs/architecture.md, checked from the source tree.

Reads the module table of docs/architecture.md ("Modules and their order": module, what it owns,
the modules it may include) and checks every file of src/ and include/trivox/:
  - each quoted include resolves to a file of the tree, and its module is the file's own, the
    base, or one the table lets the file's module include;
  - public headers include only public headers;
  - OpenVDB and OpenImageIO headers appear only in .cpp files of src/io/;
  - include/trivox/ has a folder for every module folder of src/ (but cli) and no other.
Before checking the tree it checks itself on a small tree with one violation of each kind, so
that a checker that lets everything pass fails here.

Usage: module_order.py [ROOT]   (ROOT: the repository, default: two folders up from this file)
"""
import os
import re
import sys
import tempfile

HEAVY = ("openvdb/", "OpenImageIO/")
INCLUDE = re.compile(r'^[ \t]*#[ \t]*include\s*([<"])([^>"]+)[>"]', re.M)


def read_table(root):
    """{module: set of modules it may include}, in the table's order."""
    text = open(os.path.join(root, "docs", "architecture.md"), encoding="utf-8").read()
    start = text.find("## Modules and their order")
    if start < 0:
        raise SystemExit("docs/architecture.md: no section 'Modules and their order'")
    allowed = {}
    for line in text[start:].splitlines()[1:]:
        if line.startswith("## "):
            break
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 3 or cells[0] in ("module", "") or set(cells[0]) <= set("-"):
            continue
        names = {n.strip() for n in cells[2].split(",") if n.strip()}
        allowed[cells[0]] = names
    if "base" not in allowed or len(allowed) < 3:
        raise SystemExit("docs/architecture.md: the module table lists %s; expected base and the modules"
                         % sorted(allowed))
    order = list(allowed)
    for m, names in allowed.items():
        for n in names:
            if n not in allowed:
                raise SystemExit("docs/architecture.md: %s may include %s, which is not a module of the table" % (m, n))
            if order.index(n) >= order.index(m):
                raise SystemExit("docs/architecture.md: %s may include %s, which comes later in the table" % (m, n))
    return allowed


def module_of(rel):
    """The module of a path relative to the root (src/..., include/trivox/...), or None."""
    parts = rel.split("/")
    if parts[0] == "src":
        if len(parts) == 2 or parts[1] == "detail":
            return "base"
        return parts[1]
    if parts[0] == "include" and len(parts) >= 3 and parts[1] == "trivox":
        return "base" if len(parts) == 3 else parts[2]
    return None


def check(root, allowed):
    problems = []
    src_modules, inc_modules = set(), set()
    for top in ("src", os.path.join("include", "trivox")):
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, top)):
            dirnames.sort()
            rel_dir = os.path.relpath(dirpath, root).replace(os.sep, "/")
            depth = rel_dir.count("/")
            if top == "src" and depth == 1 and rel_dir != "src/detail":
                src_modules.add(rel_dir.split("/")[1])
            if top != "src" and depth == 2:
                inc_modules.add(rel_dir.split("/")[2])
            for name in sorted(filenames):
                if not name.endswith((".cpp", ".hpp", ".hpp.in", ".h")):
                    continue
                rel = rel_dir + "/" + name
                mod = module_of(rel)
                public = rel.startswith("include/")
                if mod not in allowed:
                    problems.append("%s: module %s is not in docs/architecture.md's table" % (rel, mod))
                    continue
                text = open(os.path.join(root, rel), encoding="utf-8").read()
                for m in INCLUDE.finditer(text):
                    kind, target = m.group(1), m.group(2)
                    line = text.count("\n", 0, m.start()) + 1
                    where = "%s:%d: #include %s" % (rel, line, target)
                    if kind == "<":
                        if target.startswith(HEAVY) and not (rel.startswith("src/io/") and name.endswith(".cpp")):
                            problems.append(where + ": OpenVDB and OpenImageIO belong in .cpp files of src/io/ only")
                        continue
                    if target.startswith("trivox/"):
                        resolved = "include/" + target
                        if target == "trivox/version.hpp":
                            resolved = "include/trivox/version.hpp.in"
                    else:
                        if public:
                            problems.append(where + ": a public header includes a private one")
                            continue
                        resolved = os.path.normpath(os.path.join(rel_dir, target)).replace(os.sep, "/")
                    if not os.path.isfile(os.path.join(root, resolved)):
                        problems.append(where + ": no such file in the tree (%s)" % resolved)
                        continue
                    tmod = module_of(resolved)
                    if tmod is None:
                        problems.append(where + ": outside src/ and include/trivox/")
                    elif tmod != mod and tmod != "base" and tmod not in allowed[mod]:
                        problems.append(where + ": %s may not include %s (docs/architecture.md)" % (mod, tmod))
    src_modules.discard("cli")
    for m in sorted(src_modules - inc_modules):
        problems.append("include/trivox/%s/: missing; include/trivox/ mirrors src/" % m)
    for m in sorted(inc_modules - src_modules):
        problems.append("src/%s/: missing; include/trivox/ mirrors src/" % m)
    return problems


def self_test(allowed):
    """A small tree with one violation of each kind: each must be reported."""
    files = {
        "docs/architecture.md": "",
        "include/trivox/error.hpp": "",
        "include/trivox/spline/a.hpp": '#include "trivox/error.hpp"\n',
        "include/trivox/geom/b.hpp": '#include "trivox/spline/a.hpp"\n#include "../../../src/geom/p.hpp"\n',
        "src/spline/a.cpp": '#include "trivox/geom/b.hpp"\n',           # against the order
        "src/geom/p.hpp": "",
        "src/geom/b.cpp": '#include <openvdb/openvdb.h>\n#include "missing.hpp"\n',
        "src/lonely/c.cpp": "",                                          # not in the table
        "include/trivox/orphan/d.hpp": "",                               # no src/orphan
    }
    with tempfile.TemporaryDirectory() as tmp:
        for rel, body in files.items():
            path = os.path.join(tmp, rel)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            open(path, "w").write(body)
        found = "\n".join(check(tmp, allowed))
    expected = ["spline may not include geom", "a public header includes a private one",
                "belong in .cpp files of src/io/ only", "no such file in the tree",
                "module lonely is not in", "src/orphan/: missing", "include/trivox/lonely/: missing"]
    missed = [e for e in expected if e not in found]
    if missed:
        print("module_order.py: its self-test missed: %s\nit reported:\n%s" % (missed, found))
        sys.exit(1)


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
    allowed = read_table(root)
    self_test(allowed)
    problems = check(root, allowed)
    for p in problems:
        print(p)
    if problems:
        print("%d violations of the house rules (docs/architecture.md)" % len(problems))
        sys.exit(1)
    print("module order: %d modules, every include in order" % len(allowed))


if __name__ == "__main__":
    main()
