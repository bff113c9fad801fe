#!/usr/bin/env python3
"""The include layers (docs/architecture.md, "Layers"): fails on an include that points up.

Top level, low to high: engine -> compute -> render -> app; inside engine/, low to high:
geometry -> scene -> sampling -> solver -> surgery -> run. A file may include its own layer
and the layers below it, never one above, and a layered folder includes no other folder of
the repository (tests/, python/, tools/ ...). Includes outside the repository (system,
generated headers such as phyxel_spv/) are not looked at.

  check_layers.py [ROOT]     check the tree at ROOT (default: this repository); each offending
                             include is printed as FILE:LINE: why; exit status 1 if any
  check_layers.py --graph    the include edges between folders with their counts
  check_layers.py --self-test  the check against small planted trees
"""

import argparse
import collections
import os
import re
import sys
import tempfile

# The one place the order is written; low to high.
TOP_LAYERS = ["engine", "compute", "render", "app"]
ENGINE_LAYERS = ["geometry", "scene", "sampling", "solver", "surgery", "run"]
# Folders on another's level: bench/ is the `phyxel bench` driver, app's level.
SAME_LAYER = {"bench": "app"}

SOURCE_SUFFIXES = (".h", ".hpp", ".cpp", ".cc", ".inl", ".glsl", ".comp")
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def layer_of(path):
    """(name, rank) of a repository-relative path's layer, or None outside the layered folders.

    Engine folders rank below compute; a file directly in engine/ or in a folder missing from
    ENGINE_LAYERS gets rank None (reported: every engine folder must have its place)."""
    parts = path.split("/")
    top = parts[0]
    level = SAME_LAYER.get(top, top)
    if level not in TOP_LAYERS:
        return None
    if level != "engine":
        return top, len(ENGINE_LAYERS) + TOP_LAYERS.index(level)
    if len(parts) > 2 and parts[1] in ENGINE_LAYERS:
        return "engine/" + parts[1], ENGINE_LAYERS.index(parts[1])
    return "engine/" + (parts[1] if len(parts) > 2 else ""), None


def resolve(root, source, target):
    """The repository-relative path an include names, or None (not a file of the repository)."""
    first = target.split("/")[0]
    if "/" in target and os.path.isdir(os.path.join(root, first)) and first not in (".", ".."):
        return os.path.normpath(target)
    local = os.path.normpath(os.path.join(os.path.dirname(source), target))
    if not local.startswith("..") and os.path.isfile(os.path.join(root, local)):
        return local
    return None


def includes(root):
    """Every project include of the layered folders: (source, line number, target)."""
    for top in TOP_LAYERS + list(SAME_LAYER):
        for folder, dirs, files in os.walk(os.path.join(root, top)):
            dirs.sort()
            for name in sorted(files):
                if not name.endswith(SOURCE_SUFFIXES):
                    continue
                full = os.path.join(folder, name)
                source = os.path.relpath(full, root).replace(os.sep, "/")
                with open(full, encoding="utf-8", errors="replace") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if m:
                            target = resolve(root, source, m.group(1))
                            if target is not None:
                                yield source, number, target.replace(os.sep, "/")


def order_text(layers):
    return " -> ".join(layers)


def offence(source, target):
    """Why source may not include target, or None where it may."""
    src, tgt = layer_of(source), layer_of(target)
    if src[1] is None:
        return "%s is not a layer: give it its place in ENGINE_LAYERS (%s)" % (
            src[0], os.path.relpath(__file__))
    if tgt is None:
        return "%s includes %s, outside the layers (%s)" % (
            src[0], target.split("/")[0] + "/", order_text(TOP_LAYERS))
    if tgt[1] is None:
        return "%s is not a layer: give it its place in ENGINE_LAYERS (%s)" % (
            tgt[0], os.path.relpath(__file__))
    if tgt[1] <= src[1]:
        return None
    order = ENGINE_LAYERS if src[0].startswith("engine/") and tgt[0].startswith("engine/") \
        else TOP_LAYERS
    return "%s includes %s, a layer above it (%s); move the shared type down" % (
        src[0], tgt[0], order_text(order))


def check(root):
    """The offending includes as 'FILE:LINE: why' lines."""
    return ["%s:%d: %s" % (s, n, why)
            for s, n, t in includes(root) for why in [offence(s, t)] if why]


def graph(root):
    """Folder -> folder include edges with their counts, as text lines."""
    edges = collections.Counter()
    for s, _, t in includes(root):
        a, b = layer_of(s), layer_of(t)
        edges[(a[0] if a else s.split("/")[0], b[0] if b else t.split("/")[0])] += 1
    return ["%4d  %s -> %s" % (c, a, b) for (a, b), c in sorted(edges.items())]


def plant(root, files):
    for path, text in files.items():
        full = os.path.join(root, path)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w", encoding="utf-8") as f:
            f.write(text)


def self_test():
    """The check finds exactly the planted back-includes, each at its file and line."""
    clean = {
        "engine/geometry/shape.h": "#pragma once\n#include <vector>\n",
        "engine/scene/scene.h": '#include "engine/geometry/shape.h"\n',
        "engine/solver/solver.h": '#include "engine/scene/scene.h"\n#include "solver_local.h"\n',
        "engine/solver/solver_local.h": "// same folder, relative\n",
        "engine/run/run.cpp": '#include "engine/solver/solver.h"\n#include "phyxel_spv/x.h"\n',
        "compute/gpu.cpp": '#include "engine/run/run.cpp"\n',
        "render/draw.cpp": '#include "compute/gpu.cpp"\n#include "engine/scene/scene.h"\n',
        "app/main.cpp": '#include "render/draw.cpp"\n',
        "tests/scene/t.cpp": '#include "app/main.cpp"\n',
        "third_party/x.h": '#include "app/main.cpp"\n',
    }
    planted = {
        "engine/geometry/mesh.h": ('// back\n#include "engine/scene/scene.h"\n', 2, "scene"),
        "engine/scene/scene_json.cpp": ('  #  include "../solver/solver.h"\n', 1, "solver"),
        "engine/solver/cpu.h": ('#include <x>\n\n#include "engine/surgery/tool.h"\n', 3,
                                "surgery"),
        "engine/surgery/tool.h": ('#include "engine/run/run.cpp"\n', 1, "run"),
        "engine/types/vec.h": ("\n", None, None),
        "engine/sampling/set.h": ('#include "engine/types/vec.h"\n', 1, "not a layer"),
        "engine/geometry/gpu.h": ('#include "compute/gpu.cpp"\n', 1, "compute"),
        "compute/draw.h": ('#include "render/draw.cpp"\n', 1, "render"),
        "render/cli.h": ('#include "app/main.cpp"\n', 1, "app"),
        "engine/run/test.h": ('#include "tests/scene/t.cpp"\n', 1, "tests/"),
    }
    failures = []
    with tempfile.TemporaryDirectory() as root:
        plant(root, clean)
        if check(root):
            failures.append("a clean tree gave: %s" % check(root))
        plant(root, {path: text for path, (text, _, _) in planted.items()})
        found = check(root)
        expected = {"%s:%d" % (p, n): word for p, (_, n, word) in planted.items() if n}
        for where, word in expected.items():
            hits = [f for f in found if f.startswith(where + ":")]
            if len(hits) != 1 or word not in hits[0]:
                failures.append("%s (%s): expected one offence, got %s" % (where, word, hits))
        extra = [f for f in found if f.split(": ")[0] not in expected]
        if extra:
            failures.append("offences nobody planted: %s" % extra)
    for f in failures:
        print("self-test: " + f)
    print("self-test: %s (%d planted back-includes)" % ("FAILED" if failures else "passed",
                                                        len(expected)))
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("root", nargs="?",
                        default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser.add_argument("--graph", action="store_true", help="print folder -> folder edges")
    parser.add_argument("--self-test", action="store_true", help="check against planted trees")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    if not os.path.isdir(os.path.join(args.root, "engine")):
        print("%s: no engine/ folder; pass the repository's root" % args.root)
        return 2
    if args.graph:
        print("\n".join(graph(args.root)))
        return 0
    found = check(args.root)
    for line in found:
        print(line)
    print("layers: %d back-include%s (order %s; engine/: %s)" % (
        len(found), "" if len(found) == 1 else "s", order_text(TOP_LAYERS),
        order_text(ENGINE_LAYERS)))
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
