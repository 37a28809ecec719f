#!/usr/bin/env bash
# The hardened unit's exposure as systemd rates it (at most the limit given
# as the second argument), the resource limits and sandbox settings every
# service unit must have, and the unit, sysusers and tmpfiles files as
# systemd parses them.
# Without systemd-analyze the test is skipped (exit 77, CTest's
# SKIP_RETURN_CODE) with a line that says so, rather than left out unseen.
set -euo pipefail
unit=$1
limit=$2
if ! command -v systemd-analyze >/dev/null 2>&1; then
  echo "SKIP: systemd-analyze is not installed (Debian package systemd); ${unit##*/}'s exposure (limit $limit) and settings are not checked"
  exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$unit" "$work/"
name=$(basename "$unit")
report=$(systemd-analyze security --offline=true --no-pager "$work/$name" 2>&1)
exposure=$(printf '%s\n' "$report" | sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\).*/\1/p')
if [ -z "$exposure" ]; then
  printf '%s\n' "$report"
  echo "FAIL: systemd-analyze gave no exposure level for $name"
  exit 1
fi
echo "$name: exposure $exposure (limit $limit)"
if ! awk -v e="$exposure" -v l="$limit" 'BEGIN { exit !(e <= l) }'; then
  printf '%s\n' "$report" | grep '✗'
  echo "FAIL: exposure $exposure of $name is above $limit"
  exit 1
fi
# The resource limits and the sandbox every BSLS service unit must set:
# what a flood or a bug can take, and the system calls it may make.
for setting in '^LimitNOFILE=[0-9]+$' '^MemoryMax=[0-9]+[KMGT]?$' '^TasksMax=[0-9]+$' \
               '^NoNewPrivileges=yes$' '^SystemCallArchitectures=native$' \
               '^SystemCallFilter=@system-service( |$)' '^CapabilityBoundingSet=' \
               '^ProtectSystem=strict$'; do
  if ! grep -Eq "$setting" "$unit"; then
    echo "FAIL: $name does not set $setting"
    exit 1
  fi
done
# The unit parses without warnings about unknown settings.
if systemd-analyze verify --man=no "$work/$name" 2>&1 | grep -i "unknown\|invalid\|failed to parse"; then
  echo "FAIL: systemd-analyze verify complains about $name"
  exit 1
fi
