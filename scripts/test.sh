#!/usr/bin/env bash
# Runs the whole BSLS test suite from a clean clone: installs the Debian
# dependencies, builds and tests the product (RelWithDebInfo), then builds it
# again with clang, AddressSanitizer and UndefinedBehaviorSanitizer, runs the
# same tests there (except those labelled `accuracy`: figures on full frames
# or the whole chain against the acceptance bounds, whose code the other tests
# already run under the sanitizers at a fraction of the time; `timing`;
# `python`: the Python clients driving the services, whose C++ side the
# services' own tests and the malformed-request load run there; and `load`:
# the failover's hundred sessions, whose calls the other service tests make),
# and runs the libFuzzer targets for a bounded time. The malformed-request
# load is 2,000 calls per service there instead of 10,000: the sanitizer stage
# looks for memory errors and leaks, the first stage for the issue's figure.
#
#   scripts/test.sh            everything
#   BSLS_TEST_QUICK=1 ...      the first build and its tests only
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
jobs=$(nproc)

bash scripts/install-deps.sh
stage_start=$SECONDS
stage_done() { echo "== $1: $((SECONDS - stage_start)) s"; stage_start=$SECONDS; }

echo "== build: RelWithDebInfo (gcc)"
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build/release -j "$jobs"
stage_done "build RelWithDebInfo"
echo "== tests: RelWithDebInfo"
ctest --test-dir build/release --output-on-failure -j "$jobs"
stage_done "tests RelWithDebInfo"

if [ "${BSLS_TEST_QUICK:-0}" = 1 ]; then exit 0; fi

echo "== build: AddressSanitizer + UBSan + libFuzzer (clang)"
CC=clang CXX=clang++ cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS="-O2" -DBSLS_SANITIZE=address,undefined -DBSLS_FUZZ=ON \
  -DBSLS_BUILD_BENCH=OFF >/dev/null
cmake --build build/asan -j "$jobs"
stage_done "build ASan + UBSan"
echo "== tests: AddressSanitizer + UBSan (fuzz included, accuracy figures left to the first stage)"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir build/asan --output-on-failure -j "$jobs" -LE "accuracy|timing|python|load"
stage_done "tests ASan + UBSan"
echo "== all tests passed in $root"
