#!/usr/bin/env bash
# `cmake --install` installs a program stripped, with its debug information
# in a separate file (cmake/BslsSplitDebugInfo.cmake, docs/deployment.md
# "Debug information"). Installs one component into a temporary prefix and
# checks: the install says where the debug information went; the installed
# program has no .debug_info, has a .gnu_debuglink naming the debug file
# with its CRC-32, still runs, and is a small part of the built one; the
# debug file has .debug_info and the program's build id, and the build-id
# link leads to it; GDB (when installed) finds line information through it.
#
#   split_debug_info_test.sh CMAKE BUILD_DIR COMPONENT PROGRAM BUILT DEBUGDIR PYTHON [GDB]
#     PROGRAM  the installed file, relative to the prefix (sbin/bsls-processd)
#     BUILT    the same program in the build tree
#     DEBUGDIR BSLS_INSTALL_DEBUGDIR (lib/debug)
set -euo pipefail
cmake=$1 build=$2 component=$3 program=$4 built=$5 debugdir=$6 python=$7 gdb=${8:-}
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
fail() {
  echo "FAIL: $*"
  exit 1
}

log=$("$cmake" --install "$build" --prefix "$prefix" --component "$component")
printf '%s\n' "$log"
installed=$prefix/$program
debug=$prefix/$debugdir$prefix/$program.debug

# The install says where it put the debug information.
grep -qF "its debug information is in $debug" <<<"$log" ||
  fail "the install did not name $debug"

# The installed program: stripped, linked, still a program.
sections=$(readelf --wide --section-headers "$installed")
grep -q '[[:space:]]\.debug_info[[:space:]]' <<<"$sections" && fail "$installed still has .debug_info"
grep -q '[[:space:]]\.gnu_debuglink[[:space:]]' <<<"$sections" || fail "$installed has no .gnu_debuglink"
[ -x "$installed" ] || fail "$installed is not executable"
"$installed" --version >/dev/null || fail "$installed --version failed"

# The debug file: the DWARF, of this very build.
[ -f "$debug" ] || fail "no debug file $debug"
# (Output taken whole before grep: with pipefail, grep -q closing a pipe
# early would fail the writer with SIGPIPE.)
debug_sections=$(readelf --wide --section-headers "$debug" 2>/dev/null)
grep -q '[[:space:]]\.debug_info[[:space:]]' <<<"$debug_sections" || fail "$debug has no .debug_info"
id_of() { readelf --notes "$1" 2>/dev/null | sed -n 's/.*Build ID: \([0-9a-f]*\).*/\1/p'; }
build_id=$(id_of "$installed")
[ -n "$build_id" ] || fail "$installed has no build id"
[ "$(id_of "$debug")" = "$build_id" ] || fail "$debug is not of build $build_id"
link=$prefix/$debugdir/.build-id/${build_id:0:2}/${build_id:2}.debug
[ "$(readlink -f "$link")" = "$(readlink -f "$debug")" ] || fail "$link does not lead to $debug"

# .gnu_debuglink: the debug file's name, then (4-byte aligned) its CRC-32.
objcopy --dump-section ".gnu_debuglink=$prefix/debuglink" "$installed" "$prefix/scratch"
"$python" - "$prefix/debuglink" "$debug" <<'PY' || fail "the .gnu_debuglink does not match the debug file"
import os, struct, sys, zlib
link = open(sys.argv[1], "rb").read()
name = link[:link.index(b"\0")].decode()
crc = struct.unpack("<I", link[-4:])[0]
with open(sys.argv[2], "rb") as f:
    actual = zlib.crc32(f.read())
print(f".gnu_debuglink: {name}, CRC-32 {crc:08x}; debug file CRC-32 {actual:08x}")
sys.exit(0 if name == os.path.basename(sys.argv[2]) and crc == actual else 1)
PY

# Much smaller than the program in the build tree.
installed_bytes=$(stat -c %s "$installed")
built_bytes=$(stat -c %s "$built")
echo "installed $installed_bytes bytes, built $built_bytes bytes, debug file $(stat -c %s "$debug") bytes"
[ $((installed_bytes * 10)) -lt "$built_bytes" ] || fail "the installed program is not under a tenth of the built one"

# A debugger finds the source lines through the split file.
if [ -n "$gdb" ]; then
  where=$("$gdb" -batch -nx -iex "set debug-file-directory $prefix/$debugdir" \
    -ex "info line main" "$installed" 2>&1)
  printf '%s\n' "$where" | tail -1
  grep -q 'Line [0-9]* of ".*main\.cpp"' <<<"$where" || fail "gdb found no line information"
else
  echo "gdb not installed: the debugger check is skipped"
fi
echo "PASS"
