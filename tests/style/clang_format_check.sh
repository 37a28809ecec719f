#!/usr/bin/env bash
# clang_format_check.sh CLANG_FORMAT SOURCE_DIR: fails, naming each file, when
# a C++ file differs from what the committed .clang-format makes of it.
set -euo pipefail
clang_format=$1
source_dir=$2
cd "$source_dir"
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files -- '*.cpp' '*.cc' '*.h')
else
  mapfile -t files < <(find bench clients common daemon processing proto simulator tests \
    -type f \( -name '*.cpp' -o -name '*.cc' -o -name '*.h' \) | sort)
fi
if [ ${#files[@]} -eq 0 ]; then
  echo "no C++ files found under $source_dir" >&2
  exit 1
fi
# One clang-format run over every file; it names each differing file in its
# warnings ("FILE:LINE:COL: error: code should be clang-formatted").
report=$("$clang_format" --dry-run -Werror "${files[@]}" 2>&1 >/dev/null) && status=0 || status=$?
if [ "$status" -ne 0 ]; then
  mapfile -t bad < <(printf '%s\n' "$report" | sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: error: .*/\1/p' | sort -u)
  echo "${#bad[@]} of ${#files[@]} files differ from .clang-format (run: clang-format -i FILE):" >&2
  printf '  %s\n' "${bad[@]}" >&2
  [ ${#bad[@]} -ne 0 ] || printf '%s\n' "$report" | head -20 >&2
  exit 1
fi
echo "${#files[@]} files match .clang-format"
