#!/usr/bin/env python3
"""Checks the module graph: no module includes another it does not depend on.

Usage: check-modules.py [ROOT]      (default: the repository this script is in)
       check-modules.py --self-test

The graph is the one CMakeLists.txt states: every `frenetic_module(NAME deps...)` call, whose
`frenetic::X` dependencies (and theirs) are the modules NAME may include. A file of module M is
any file under src/M/, include/frenetic/M/ or (for the cost terms, part of `cost`'s users)
costs/; an include names module X when it is "frenetic/X/..." or "X/..." (a private header of
src/X/). The headers at the top of include/frenetic/ (status.h, check.h, units.h) belong to no
module and may be included anywhere. Prints one line per include outside the graph,
"FILE:LINE: module M includes X (not among its dependencies: ...)", and exits 1 if there is any;
exit 2 when CMakeLists.txt states no module.
"""
import os
import re
import sys

MODULE_CALL = re.compile(r"^[ \t]*frenetic_module\(\s*(\w+)([^)]*)\)", re.S | re.M)
DEPENDENCY = re.compile(r"frenetic::(\w+)")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def read_graph(cmake_text):
    direct = {}
    for m in MODULE_CALL.finditer(cmake_text):
        direct[m.group(1)] = set(DEPENDENCY.findall(m.group(2)))
    closure = {}

    def reach(mod, seen):
        for dep in direct.get(mod, ()):
            if dep not in seen:
                seen.add(dep)
                reach(dep, seen)
        return seen

    for mod in direct:
        closure[mod] = reach(mod, set())
    return closure


def module_of_include(path, modules):
    parts = path.split("/")
    if parts[0] == "frenetic" and len(parts) > 2 and parts[1] in modules:
        return parts[1]
    if len(parts) > 1 and parts[0] in modules:
        return parts[0]
    return None


def files_of(root, modules):
    """(module, path) of every source file that belongs to a module."""
    places = []
    for mod in modules:
        places.append((mod, os.path.join(root, "src", mod)))
        places.append((mod, os.path.join(root, "include", "frenetic", mod)))
    # The cost terms are compiled into their own library, linked to `cost` only.
    places.append(("cost", os.path.join(root, "costs")))
    for mod, top in places:
        for base, _, names in os.walk(top):
            for name in sorted(names):
                if name.endswith((".h", ".cc")):
                    yield mod, os.path.join(base, name)


def check(root):
    try:
        with open(os.path.join(root, "CMakeLists.txt")) as f:
            graph = read_graph(f.read())
    except OSError as e:
        return 2, [f"check-modules: cannot read CMakeLists.txt: {e}"]
    if not graph:
        return 2, ["check-modules: CMakeLists.txt states no frenetic_module()"]
    problems = []
    for mod, path in files_of(root, graph):
        with open(path, errors="replace") as f:
            for line_no, line in enumerate(f, 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                other = module_of_include(m.group(1), graph)
                if other is None or other == mod or other in graph[mod]:
                    continue
                allowed = ", ".join(sorted(graph[mod])) or "none"
                problems.append(f"{os.path.relpath(path, root)}:{line_no}: module {mod} includes "
                                f"{other} (not among its dependencies: {allowed})")
    return (1 if problems else 0), problems


def self_test():
    import tempfile
    with tempfile.TemporaryDirectory() as root:
        def write(rel, text):
            os.makedirs(os.path.dirname(os.path.join(root, rel)), exist_ok=True)
            with open(os.path.join(root, rel), "w") as f:
                f.write(text)
        write("CMakeLists.txt", "frenetic_module(a)\nfrenetic_module(b frenetic::a\n  x)\n"
                                "frenetic_module(c frenetic::b)\n")
        write("src/a/a.cc", '#include "frenetic/a/a.h"\n#include "frenetic/status.h"\n')
        write("src/c/c.cc", '#include "frenetic/a/a.h"\n#include "b/private.h"\n')
        write("src/b/b.cc", '#include "frenetic/a/a.h"\n')
        code, problems = check(root)
        assert code == 0, problems  # c reaches a through b
        write("src/a/bad.cc", '#include <vector>\n  #include "frenetic/c/c.h"\n')
        code, problems = check(root)
        assert code == 1 and len(problems) == 1, problems
        assert problems[0].startswith("src/a/bad.cc:2: module a includes c"), problems
        write("CMakeLists.txt", "project(x)\n")
        code, _ = check(root)
        assert code == 2
    print("check-modules: self-test passed")
    return 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.dirname(
        os.path.abspath(__file__)))
    code, problems = check(root)
    for p in problems:
        print(p)
    if code == 0:
        print("check-modules: every include is within the module graph of CMakeLists.txt")
    return code


if __name__ == "__main__":
    sys.exit(main())
