#!/usr/bin/env python3
"""No compile line but the allowed files' names an absolute path of this tree.

ccache with a base directory (CMakeLists.txt) rewrites the paths of sources
and include folders, so a fresh clone in another folder takes its objects
from the cache; it cannot rewrite a path inside a -D definition. A test that
needs a path of the build (data, a program) takes it from
bsls/testing/build_paths.h, whose one source carries them.

usage: compile_defines_check.py BUILD_DIR SOURCE_DIR ALLOWED_SOURCE...
Reads BUILD_DIR/build.ninja (exit 77, skipped, under another generator).
"""
import os
import sys


def main():
    build_dir, source_dir = os.path.realpath(sys.argv[1]), os.path.realpath(sys.argv[2])
    allowed = {os.path.join(source_dir, path) for path in sys.argv[3:]}
    ninja = os.path.join(build_dir, "build.ninja")
    if not os.path.exists(ninja):
        print(f"{ninja}: not a Ninja build tree; nothing checked")
        return 77
    roots = (source_dir, build_dir, os.path.dirname(source_dir))
    offenders = []
    source = None
    with open(ninja, encoding="utf-8") as lines:
        for line in lines:
            if line.startswith("build ") and ".o: CXX_COMPILER" in line:
                fields = line.split()
                source = fields[3] if len(fields) > 3 else None
            elif line.startswith("  DEFINES = ") and source is not None:
                if source not in allowed and any(root in line for root in roots):
                    offenders.append(f"{source}: {line.strip()}")
                source = None
    for offender in offenders:
        print(offender)
    if offenders:
        print(f"{len(offenders)} compile lines name a path of the tree in a definition: "
              "take it from bsls/testing/build_paths.h instead")
        return 1
    print("no compile line but the allowed ones names a path of the tree")
    return 0


if __name__ == "__main__":
    sys.exit(main())
