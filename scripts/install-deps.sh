#!/usr/bin/env bash
# Installs every build, test and run dependency of BSLS on a fresh Debian 12
# machine, from Debian's own packages only. Safe to run again: apt skips what
# is already there. Needs root (or sudo).
set -euo pipefail

packages=(
  # toolchain and build
  build-essential cmake ninja-build ccache pkg-config git
  clang libclang-rt-14-dev          # libFuzzer and the sanitizer runtimes
  clang-format                      # the style check (tests/style)
  # processing library
  libopencv-dev
  libeigen3-dev
  # files, command line, logging
  nlohmann-json3-dev libcli11-dev libspdlog-dev libyaml-cpp-dev
  libssl-dev                        # SHA-256 of manifests and frames
  # capture daemon: store, hardware, services, privileges
  libsqlite3-dev                    # durable capture index
  libusb-1.0-0-dev                  # USB framestore
  zlib1g-dev                        # CRC-32 of the USB framestore protocol
  libgpiod-dev                      # slide controller (v1.6 API)
  libcap-dev                        # dropping capabilities
  libsystemd-dev                    # sd_notify, watchdog
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc
  python3-grpcio python3-protobuf python3-grpc-tools python3-numpy python3-yaml
  systemd                           # systemd-analyze security in the tests
  # tests and benchmarks
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  openssl                           # test certificates for the mutual-TLS tests
  python3
)

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
